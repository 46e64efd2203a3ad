# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Figure 1 — the wedged disc
#
# **What the paper says** (Moreau 2005, §1).  A circular rigid body $B$ lies in contact with
# two fixed circular obstacles and is released at rest under gravity, with Coulomb friction.
# "A possible evolution consists in $B$ losing contact and falling freely.  But, if the
# friction angle $\gamma$ is large enough, $B$ may also remain *wedged*.  In the latter case,
# contact forces remain undetermined in some range": "any position of $I$ on some vertical
# segment corresponds to contact forces values balancing gravity and compatible with Coulomb
# friction" (caption of figure 1).  The contact forces at $t_0$, "the intensity of wedging",
# are the missing state data.
#
# **What was computed.**  The paper gives no dimensions; we choose a symmetric geometry
# (`config.yaml`, section `fig1_wedged`), derive the set of wedged force states in closed form
# (below), and compare with (i) an ensemble of one-step NLGS runs from rest, from random
# initial guesses (normal forces log-uniform over a range of weights, tangential forces
# uniform in the Coulomb cone) and from the zero guess, each with a random review order;
# (ii) two evolutions from the same state that differ only in the initial guess of the first
# step; (iii) the same random exploration over a range of friction angles.

# %%
from pathlib import Path

import matplotlib
import xarray as xr
import yaml
from IPython.display import Markdown, display

from ncd.figures.fig1_wedged import page
from ncd.figures.fig1_wedged.claims import JUDGES
from ncd.figures.fig1_wedged.measure import Wedge
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save

matplotlib.use("Agg")  # the figure is shown once, as the saved PNG
# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
snakemake = paths("fig1_wedged", ["ensemble", "evolutions", "sweep"], globals().get("snakemake"))
ens = xr.load_dataset(snakemake.input.ensemble)
evo = xr.load_dataset(snakemake.input.evolutions)
swp = xr.load_dataset(snakemake.input.sweep)
cfg = yaml.safe_load(ens.attrs["config_yaml"])
wedge = Wedge.from_config(cfg)
results = results_dir(snakemake)

# %%
Path(snakemake.output.png).with_suffix(".caption.rst").write_text(page.caption(ens, swp, wedge))
save(page.plot(ens, evo, swp, wedge), snakemake.output, dpi=100, show=True)

# %% [markdown]
# (a) $B$ between the two fixed discs, the Coulomb cones (orange), the lines of action of
# six wedged runs and the closed-form segment of $I$ (red; filled end reached at
# $N = N_{\min}$, open end a limit).  (b) The dashed box of (a): the point $I$ of every
# wedged run.  (c) The height of $I$ against the normal force: closed form (red line),
# runs (dots).  (d) Height of $B$ in two evolutions from the same state: zero guess at every
# step, or a wedged first guess followed by warm starts.  (e) Their contact forces.
# (f) Fraction of random-guess runs that stay wedged against the friction angle.
#
# ## What was measured

# %%
display(Markdown(page.setup_sentence(wedge, float(ens.attrs["h"]))))
display(Markdown(page.ensemble_sentence(ens, wedge)))
display(Markdown(claim_markdown("s1-segment", results, JUDGES)))
display(Markdown(claim_markdown("s1-forces-undetermined", results, JUDGES)))

# %% [markdown]
# ### Which solution a run reaches

# %%
display(Markdown(page.second_contact_sentence(ens, wedge)))

# %% [markdown]
# ### Two evolutions from one state

# %%
display(Markdown(page.evolutions_sentence(evo, wedge)))
display(Markdown(claim_markdown("s1-two-evolutions", results, JUDGES)))
display(Markdown(claim_markdown("s1-forces-as-state", results, JUDGES)))

# %% [markdown]
# ### The friction angle

# %%
display(Markdown(page.sweep_sentence(swp, wedge, cfg["ensemble"]["force_max"])))
display(Markdown(claim_markdown("s1-wedging-threshold", results, JUDGES)))

# %% [markdown]
# ## The closed form: the admissible contact forces and the segment of $I$
#
# **Geometry.**  $B$ (radius $R$, mass $m$, centre $O$ at the origin) touches two fixed
# discs of radius $r$ centred at $C_{0,1} = \big(\mp(R+r)\cos\beta,\ (R+r)\sin\beta\big)$,
# above $O$.  The contact normals, from obstacle to $B$, point downward-inward:
# $n_0 = (\cos\beta, -\sin\beta)$, $n_1 = (-\cos\beta, -\sin\beta)$; tangents
# $t_i = (-n_{i,y}, n_{i,x})$, i.e. $t_0 = (\sin\beta, \cos\beta)$,
# $t_1 = (\sin\beta, -\cos\beta)$.  The contact points are $P_i = -R\,n_i$, both at height
# $R\sin\beta$, and the force on $B$ at contact $i$ is $F_i = N_i n_i + T_i t_i$.
#
# **Falling is always a solution.**  With zero contact impulses the end-of-step velocity
# is the free one, $u_f = h g = (0, -gh)$, and the normal relative velocities
# $U_{n,i} = u_f\cdot n_i = gh\sin\beta > 0$: both contacts open.  So free fall solves the
# one-step problem for every $\mu$ (and the zero guess lands on it at once: each contact,
# solved alone, sees a separating velocity).
#
# **Equilibrium** ($u_f = 0$).  Moments about $O$: the normal forces pass through $O$ and
# $P_i \times T_i t_i = -R\,T_i$, so $T_0 + T_1 = 0$; write $T_0 = T$, $T_1 = -T$.
# Horizontal forces: $(N_0 - N_1)\cos\beta + (T_0 + T_1)\sin\beta = 0$, hence $N_0 = N_1 = N$.
# Vertical forces: $2\,(T\cos\beta - N\sin\beta) = mg$, i.e.
# $$T = \frac{mg/2 + N\sin\beta}{\cos\beta}.$$
# Four unknowns, three equations: the equilibrium forces form a line parametrized by $N$.
#
# **Coulomb** ($N \ge 0$, $|T| \le \mu N$ at both contacts; $T > 0$): with $\mu = \tan\gamma$,
# $T \le \mu N \iff N\,(\mu\cos\beta - \sin\beta) \ge mg/2 \iff N \sin(\gamma-\beta) \ge \tfrac{1}{2} mg \cos\gamma$.
# Hence
# $$\boxed{\text{wedging is possible} \iff \gamma > \beta},\qquad
#   N \ \ge\ N_{\min} = \frac{mg\,\cos\gamma}{2\sin(\gamma-\beta)},$$
# with no upper bound: the admissible force states form the half-line
# $N \in [N_{\min}, \infty)$, $T$ as above.  At $N = N_{\min}$ both forces lie on the edge
# of their Coulomb cones (sliding impends at both contacts); $N_{\min}\to\infty$ as
# $\gamma \downarrow \beta$.
#
# **The segment of $I$.**  Three forces in equilibrium (the weight acts at $O$) are
# concurrent, so $I$ is on the vertical through $O$.  The line of $F_0$ leaves
# $P_0 = (-R\cos\beta, R\sin\beta)$ with direction
# $\big((N + \tfrac{mg}{2}\sin\beta)/\cos\beta,\ mg/2\big)$ and reaches $x = 0$ at
# $$y_I(N) = R\sin\beta + R\cos^2\beta\,\frac{mg/2}{N + \tfrac{mg}{2}\sin\beta},$$
# decreasing in $N$.  Its ends:
# * **top**, reached at $N = N_{\min}$: each force makes the angle $\gamma$ with its normal,
#   i.e. rises at $\gamma-\beta$ above the horizontal, so
#   $y_{\rm top} = R\sin\beta + R\cos\beta\tan(\gamma-\beta) = R\,\sin\gamma/\cos(\gamma-\beta)$;
# * **bottom**, $y_{\rm bot} = R\sin\beta$, the height of the chord $P_0P_1$, reached **only in
#   the limit** $N\to\infty$, where the two forces become horizontal and collinear.
#
# So $I$ ranges over $(R\sin\beta,\ R\sin\gamma/\cos(\gamma-\beta)]$, a segment of length
# $R\cos\beta\tan(\gamma-\beta)$ — finite: the two forces are never parallel (a vertical
# force would need $\gamma \ge 90° + \beta$).  Geometrically: the line $P_iI$ makes an angle
# $\varphi$ with the normal line $P_iO$, and Coulomb's law is $\varphi \le \gamma$; moving $I$
# down from $y_{\rm top}$ to the chord, $\varphi$ decreases from $\gamma$ to $\beta$.
#
# `ncd.figures.fig1_wedged.measure.Wedge` implements these formulas; `tests/test_fig1_wedged.py`
# checks them against a linear program on the equilibrium equations
# $H\rho + F = 0$ built by `ncd.core.contacts.h_matrix`.

# %% [markdown]
# ## Differences from the paper
#
# Moreau's figure 1 is a sketch: no dimensions, friction
# coefficient or numerical results are given.  Our geometry is symmetric, so the segment of
# $I$ lies on the vertical through $B$'s centre and the free parameter is the common normal
# force $N$; with an asymmetric placement the segment is still on that vertical (three
# concurrent forces) but its ends change.  The one-step exploration uses random initial
# guesses (section 2's first method).  Its second method, zero guess with random review
# orders, cannot reveal the wedged states here: with $\kappa = 2$ contacts there is
# $(\kappa-1)! = 1$ distinct ordering, and from zero guess it gives free fall.
