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
# **What the paper says** (Moreau 2005, section 1).  A circular rigid body $B$ lies in
# contact with two fixed circular obstacles and is released at rest under gravity, with
# Coulomb friction at both contacts.  A possible evolution is that $B$ loses contact and
# falls freely; but if the friction angle $\gamma$ is large enough, $B$ may also remain
# *wedged*, and then the contact forces are undetermined: "any position of $I$ [the
# intersection of their lines of action] on some vertical segment corresponds to contact
# forces values balancing gravity and compatible with Coulomb friction" (caption of
# figure 1).  Which evolution happens is not decided by positions and velocities: the
# contact forces at $t_0$ ("the intensity of wedging") are the missing state data.
# Section 2 turns this into a computational statement: in Contact Dynamics the one-step
# problem from rest is solved by nonlinear Gauss–Seidel (NLGS) from some initial guess;
# from zero guess one gets one solution, from random guesses "any solution has a chance
# to be approached", and with the previous step's forces as the guess (warm start) the
# forces behave as state variables.
#
# **What we do.**  The paper gives no dimensions, so we choose a symmetric geometry
# (`config.yaml`, section `fig1_wedged`), derive the set of wedged force states in closed
# form, and compare with (i) an ensemble of one-step NLGS runs from random and zero
# initial guesses, (ii) two evolutions from the same initial state that differ only by the
# initial guess of the first step, (iii) a sweep of the friction angle.

# %%
import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
import yaml
from IPython.display import Image, Markdown, display

from ncd.figures.wedged import Wedge
from ncd.pages.notebook import paths as notebook_paths
from ncd.pages.notebook import save

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = notebook_paths("fig1_wedged", ["ensemble", "evolutions", "sweep"], globals().get("snakemake"))
paths = {k: Path(str(getattr(_smk.input, k))) for k in ("ensemble", "evolutions", "sweep")}
out_png, out_pdf = Path(_smk.output.png), Path(_smk.output.pdf)
ens = xr.load_dataset(paths["ensemble"])
evo = xr.load_dataset(paths["evolutions"])
swp = xr.load_dataset(paths["sweep"])
cfg = yaml.safe_load(ens.attrs["config_yaml"])
wedge = Wedge.from_config(cfg)
R, mg, beta, gamma = wedge.radius, wedge.weight, np.degrees(wedge.beta), np.degrees(wedge.gamma)
y_bot, y_top = wedge.segment
print(f"B: radius R = {R} m, mass m = {wedge.mass:.4g} kg (weight mg = {mg:.4g} N); "
      f"obstacles: radius {wedge.obstacle_radius} m")
print(f"contact normals {beta:.2f} deg below the horizontal; mu = {wedge.mu} "
      f"(friction angle gamma = {gamma:.2f} deg); h = {ens.attrs['h']} s")

# %% [markdown]
# ## Closed form: the admissible contact forces and the segment of $I$
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
# `ncd.figures.wedged.Wedge` implements these formulas; `tests/test_fig1_wedged.py`
# checks them against a linear program on the equilibrium equations
# $H\rho + F = 0$ built by `ncd.core.contacts.h_matrix`.

# %%
print(f"threshold: gamma > beta = {beta:.2f} deg; here gamma = {gamma:.2f} deg -> wedging "
      f"{'possible' if wedge.wedging_possible else 'impossible'}")
print(f"N_min = {wedge.n_min / mg:.4f} mg;  T(N_min)/N_min = {wedge.forces(wedge.n_min)[1][0] / wedge.n_min:.4f} = mu")
print(f"segment of I: y_bot = R sin(beta) = {y_bot / R:.4f} R (limit N -> inf, not reached), "
      f"y_top = {y_top / R:.4f} R (reached at N_min); length {(y_top - y_bot) / R:.4f} R")

# %% [markdown]
# ## The exploration ensemble: one step from rest
#
# One Moreau–Jean step ($u_i = 0$) is prepared once; each run solves it by NLGS from its own
# initial guess and review order, drawn from `numpy.random.default_rng((run, root_seed))`:
# * **random guesses** (`zero_guess = 0`): at each contact a normal force log-uniform over
#   `[force_min, force_max]` weights and a tangential force uniform in the Coulomb cone
#   (log-uniform because the "intensity of wedging" has no natural scale: wedged states
#   exist for every $N \ge N_{\min}$);
# * **zero guesses** (`zero_guess = 1`).
#
# The review order of the two contacts is random.  A converged run is classified as
# *falls* (impulses zero and $u_f = hg$) or *wedged* ($u_f = 0$), each within
# `velocity_tol` $\cdot\,gh$; anything else, or a run that did not converge, gets outcome $-1$
# and is reported, not plotted.  For a wedged run we store both contact forces
# (impulse$/h$) and the intersection $I$ of their lines of action.

# %%
conv = ens.converged.values == 1
zero = ens.zero_guess.values == 1
outcome = ens.outcome.values
n_run = ens.sizes["run"]
print(f"{n_run} runs ({int((~zero).sum())} random guesses, {int(zero.sum())} zero guesses); "
      f"converged: {int(conv.sum())}/{n_run} (natural-map tolerance {ens.attrs['solver_tol']:g})")
for label, sel in (("random guess", ~zero), ("zero guess", zero)):
    c = conv & sel
    print(f"  {label}: falls {int((outcome[c] == 0).sum())}, wedged {int((outcome[c] == 1).sum())}, "
          f"unclassified {int((outcome[c] == -1).sum())}, not converged {int((sel & ~conv).sum())}")
wed = conv & (outcome == 1)
Fn, Ft = ens.force_n.values[wed], ens.force_t.values[wed]
Iy = ens.I_y.values[wed]
N = Fn.mean(axis=1)
if not wed.any():  # e.g. a solver budget too small for any run to converge
    print(f"no converged wedged run ({int(conv.sum())} of {len(conv)} runs converged): "
          "nothing to compare with the closed-form segment")
else:
    eq = np.abs((Fn[:, :, None] * wedge.normals + Ft[:, :, None] * wedge.tangents).sum(1) + [0, -mg]).max() / mg
    print(f"wedged runs: N from {N.min() / mg:.4f} to {N.max() / mg:.1f} mg; largest force-balance defect "
          f"{eq:.1e} mg; largest |T|/(mu N) = {np.abs(Ft / Fn).max() / wedge.mu:.6f}; "
          f"largest |I_x| = {np.nanmax(np.abs(ens.I_x.values[wed])) / R:.1e} R")
    print(f"I_y from {Iy.min() / R:.4f} R to {Iy.max() / R:.4f} R: the dots span "
          f"{100 * (Iy.max() - Iy.min()) / (y_top - y_bot):.1f} % of the closed-form segment; "
          f"largest distance to y_I(N): {np.abs(Iy - wedge.y_of_n(N)).max() / R:.1e} R")

# %% [markdown]
# ## The two evolutions
#
# Both start from the same positions at rest, with the same step $h$ and the same
# Moreau–Jean scheme; they differ only in the initial guess of the NLGS:
# (a) zero at every step; (b) at the first step the closed-form wedged state with
# $N = $ `wedge_factor` $N_{\min}$, afterwards the previous step's impulses (warm start).

# %%
t = evo.time.values
for name in evo.evolution.values:
    e = evo.sel(evolution=name)
    print(f"{name}: y(T) = {e.y.values[-1]:.6g} m after T = {t[-1]:.3g} s (free fall: {-0.5 * wedge.g * t[-1] ** 2:.6g}); "
          f"max |y| over the run {np.abs(e.y.values).max():.3g} m; contacts at the last step {int(e.n_contacts.values[-1])}; "
          f"all steps converged: {bool(e.converged.values[1:].all())}, max sweeps {int(e.sweeps.values.max())}")

# %% [markdown]
# ## Threshold sweep
#
# The same random-guess exploration (`sweep.runs` runs per angle) for a range of friction
# angles $\gamma$; the closed form says no wedged state exists for $\gamma \le \beta$.

# %%
frac = swp.wedged_fraction.values
gam = swp.gamma.values
below, above = gam < beta, gam > beta
print(f"not converged in the sweep: {int((swp.converged.values == 0).sum())} of {swp.converged.size}")
print(f"wedged fraction for gamma < beta: max {np.nanmax(frac[below]) if below.any() else np.nan}; "
      f"first angle above beta: {gam[above][0] if above.any() else np.nan} deg, fraction {frac[above][0] if above.any() else np.nan}")

# %% [markdown]
# ## The figure

# %%
def circle(ax, c, r, **kw):
    ax.add_patch(plt.Circle(c, r, **kw))


fig = plt.figure(figsize=(13, 8.4), constrained_layout=True)
top = fig.add_gridspec(2, 1)[0].subgridspec(1, 3, width_ratios=[1.75, 0.75, 1.0])
gs = fig.add_gridspec(2, 1)[1].subgridspec(1, 3)
opos, ro = wedge.obstacle_pos, wedge.obstacle_radius
P = wedge.contact_points
picks = np.argsort(Iy)[np.linspace(0, len(Iy) - 1, 6).round().astype(int)] if len(Iy) else []
seg_kw = dict(color="C3", lw=4, alpha=0.35, solid_capstyle="butt")


def scene_axes(ax, zoom):
    for c in opos:
        circle(ax, c, ro, fc="0.82", ec="0.3", lw=1)
    circle(ax, (0, 0), R, fc="#dbe8f6", ec="C0", lw=1.5)
    for i in range(2):  # Coulomb cones at each contact: directions of F_i on B
        a0 = np.degrees(np.arctan2(wedge.normals[i, 1], wedge.normals[i, 0]))
        ax.add_patch(matplotlib.patches.Wedge(P[i], 0.45 * R, a0 - gamma, a0 + gamma, fc="C1", alpha=0.25, lw=0))
    for k, j in enumerate(picks):
        for i in range(2):
            ax.plot([P[i, 0], 0], [P[i, 1], Iy[j]], color=plt.cm.viridis(k / 5), lw=1)
    ax.plot([0, 0], [y_bot, y_top], **seg_kw)
    ax.plot(0, y_top, "o", color="C3", ms=6)
    ax.plot(0, y_bot, "o", mfc="white", mec="C3", ms=6)
    ax.plot(*P.T, "k.", ms=6)
    ax.set_aspect("equal")
    ax.set_xticks([]), ax.set_yticks([])


ax = fig.add_subplot(top[0])
scene_axes(ax, False)
ax.text(0, -0.45 * R, "$B$", ha="center", fontsize=13)
ax.annotate("", xy=(0, -0.95 * R), xytext=(0, -0.6 * R), arrowprops=dict(arrowstyle="->", color="k"))
ax.text(0.05 * R, -0.85 * R, "$mg$")
ax.add_patch(plt.Rectangle((-0.22 * R, 0.3 * R), 0.44 * R, 0.37 * R, fill=False, ec="k", lw=0.6, ls="--"))
ax.set_xlim(opos[0, 0] - 1.05 * ro, opos[1, 0] + 1.05 * ro)
ax.set_ylim(-1.08 * R, opos[0, 1] + 1.05 * ro)
ax.set_title(f"(a) $B$ between two fixed discs: $\\beta$ = {beta:.0f}°, $\\mu$ = {wedge.mu} "
             f"($\\gamma$ = {gamma:.1f}°)\nCoulomb cones (orange), lines of action of 6 wedged runs", fontsize=10)

ax = fig.add_subplot(top[1])
scene_axes(ax, True)
ax.plot(np.zeros(len(Iy)), Iy, "k.", ms=3, alpha=0.25)
ax.text(0.01 * R, y_top, " $N = N_{\\min}$\n (reached)", fontsize=8, va="bottom")
ax.text(0.01 * R, y_bot, " $N \\to \\infty$\n (limit)", fontsize=8, va="top")
ax.set_xlim(-0.22 * R, 0.22 * R)
ax.set_ylim(0.3 * R, 0.67 * R)
ax.set_title(f"(b) zoom: $I$ of the {len(Iy)} wedged runs (dots)\non the closed-form segment (red)", fontsize=10)

ax = fig.add_subplot(top[2])
Ns = np.geomspace(wedge.n_min, max(N.max() if len(N) else 10 * wedge.n_min, 10 * wedge.n_min) * 1.5, 300)
ax.semilogx(Ns / mg, wedge.y_of_n(Ns) / R, color="C3", lw=2, label="closed form $y_I(N)$")
ax.semilogx(N / mg, Iy / R, "k.", ms=2.5, alpha=0.5, label="wedged runs")
ax.axhline(y_top / R, color="C3", ls="--", lw=0.8)
ax.axhline(y_bot / R, color="C3", ls=":", lw=0.8)
ax.axvline(wedge.n_min / mg, color="0.5", lw=0.8)
ax.text(wedge.n_min / mg * 1.1, y_top / R, "$N_{\\min}$: cone edges", fontsize=8, va="top")
ax.text(Ns[-1] / mg, y_bot / R, "$R\\sin\\beta$ (limit)", fontsize=8, va="top", ha="right")
ax.set_ylim(y_bot / R - 0.03, y_top / R + 0.02)
ax.set_xlabel("normal force $N / mg$ (both contacts)")
ax.set_ylabel("height of $I$, $y_I / R$")
ax.set_title("(c) $I$ against the wedging intensity\n" + (f"dots span {100 * (Iy.max() - Iy.min()) / (y_top - y_bot):.1f} % "
             "of the segment" if len(Iy) else "no converged wedged run"), fontsize=10)
ax.legend(fontsize=8, loc="center right")

ax = fig.add_subplot(gs[0])
labels = {"zero_guess": "(a) zero guess at every step", "wedged_warm": "(b) wedged first guess, then warm"}
for k, name in enumerate(evo.evolution.values):
    ax.plot(t, evo.sel(evolution=name).y.values / R, color=f"C{k}", label=labels.get(name, name))
ax.plot(t, -0.5 * wedge.g * t ** 2 / R, "k:", lw=1, label="free fall $-gt^2/2$")
ax.set_xlabel("time (s)")
ax.set_ylabel("height of $B$'s centre, $y / R$")
ax.set_yscale("symlog", linthresh=1e-3)
ax.set_title("(d) two evolutions from the same state", fontsize=10)
ax.legend(fontsize=8, loc="lower left")

ax = fig.add_subplot(gs[1])
for k, name in enumerate(evo.evolution.values):
    e = evo.sel(evolution=name)
    for i, ls in enumerate(("-", "--")):
        ax.plot(t[1:], e.force_n.values[1:, i] / mg, color=f"C{k}", ls=ls, lw=1.5 if i == 0 else 1)
        ax.plot(t[1:], e.force_t.values[1:, i] / mg, color=f"C{k}", ls=ls, lw=0.8, alpha=0.6)
ax.plot([], [], "k-", label="left contact")
ax.plot([], [], "k--", label="right contact")
ax.text(t[-1], evo.force_n.values[-1, -1, 0] / mg, "$N$", va="bottom", ha="right")
ax.text(t[-1], evo.force_t.values[-1, -1, 0] / mg, "$T$", va="bottom", ha="right")
ax.set_xlabel("time (s)")
ax.set_ylabel("contact force / $mg$")
ax.set_title("(e) contact forces $N$ (thick), $T$ (thin) of (a) and (b)", fontsize=10)
ax.legend(fontsize=8)

ax = fig.add_subplot(gs[2])
ax.plot(gam, frac, "o-", color="C2", ms=4, label=f"{swp.sizes['run']} random guesses per angle")
ax.axvline(beta, color="C3", lw=1.5, label=f"closed form: wedging iff $\\gamma > \\beta$ = {beta:.0f}°")
ax.axvspan(gam.min() - 1, beta, color="0.92")
ax.set_xlim(gam.min() - 1, gam.max() + 1)
ax.set_xlabel("friction angle $\\gamma$ = atan $\\mu$ (degrees)")
ax.set_ylabel("fraction of wedged outcomes")
ax.set_title("(f) threshold sweep", fontsize=10)
ax.legend(fontsize=8, loc="upper left")
out_png.parent.mkdir(parents=True, exist_ok=True)
save(fig, _smk.output, dpi=130)
plt.close(fig)
display(Image(filename=str(out_png)))

# %% [markdown]
# ## Solver diagnostics of the ensemble
#
# Per run: the natural-map residual at the end (relative), against wall time and sweeps,
# and the final wedging intensity against the initial guess.  Within a sweep the contact
# reviewed first is solved with the other contact's guessed impulse frozen, so its own
# guess is overwritten at once: the outcome is set by the guess at the contact reviewed
# second.  Wall time is a measurement on a shared machine (other jobs share its two
# cores); the sweep count is the reproducible cost.

# %%
fig, axs = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
res = np.maximum(ens.residual.values, 1e-18)
colors = {0: "C0", 1: "C1", -1: "C3"}
names = {0: "falls", 1: "wedged", -1: "unclassified"}
for o in (0, 1, -1):
    sel = conv & (outcome == o)
    if sel.any():
        axs[0].loglog(ens.wall_time.values[sel], res[sel], ".", ms=3, color=colors[o], label=names[o])
        axs[1].semilogy(ens.sweeps.values[sel], res[sel], ".", ms=3, color=colors[o], label=names[o])
if (~conv).any():
    axs[0].loglog(ens.wall_time.values[~conv], res[~conv], "x", color="k", label="not converged")
for a in axs[:2]:
    a.axhline(ens.attrs["solver_tol"], color="0.5", ls="--", lw=0.8)
    a.set_ylabel("natural-map residual (relative; 0 at 1e-18)")
    a.legend(fontsize=8)
axs[0].set_xlabel("wall time per run (s)")
axs[1].set_xlabel("NLGS sweeps")
second = 1 - ens.first_reviewed.values
gN = ens.guess_force_n.values[np.arange(n_run), second]
rnd = conv & ~zero
axs[2].loglog(gN[rnd & (outcome == 1)] / mg, ens.force_n.values[rnd & (outcome == 1), 0] / mg, ".", ms=3,
              color="C1", label="wedged: final $N$")
axs[2].loglog(gN[rnd & (outcome == 0)] / mg, np.full((rnd & (outcome == 0)).sum(), wedge.n_min / mg / 3), "|",
              ms=4, color="C0", label="falls (drawn at $N_{\\min}/3$)")
axs[2].axhline(wedge.n_min / mg, color="C3", lw=0.8, label="$N_{\\min}$")
axs[2].set_xlabel("guessed $N$ at the contact reviewed second / $mg$")
axs[2].set_ylabel("final $N / mg$")
axs[2].legend(fontsize=8)
buf = io.BytesIO()
fig.savefig(buf, format="png", dpi=110)
plt.close(fig)
display(Image(data=buf.getvalue()))
wt = ens.wall_time.values
print(f"wall time per run: median {np.median(wt) * 1e6:.0f} us, max {wt.max() * 1e3:.2f} ms; "
      f"sweeps: median {np.median(ens.sweeps.values):.0f}, max {ens.sweeps.values.max()}; "
      f"residual: max over converged runs {ens.residual.values[conv].max() if conv.any() else float('nan'):.1e}")

# %% [markdown]
# ## What we measured, and where the reproduction differs
#
# The first three points are written from this run's data when the notebook runs.

# %%
fmax = cfg["ensemble"]["force_max"]
onset = np.degrees(np.arcsin(np.cos(wedge.beta) / (2 * fmax)))   # sin(gamma - beta) = cos(gamma) / (2 force_max) at gamma ~ beta
step_deg = float(np.diff(gam).min()) if len(gam) > 1 else np.nan
zero_conv = conv & zero
warm = evo.sel(evolution="wedged_warm")
threshold = ("zero at every angle below $\\beta$" if not below.any() or np.nanmax(frac[below]) == 0
             else f"up to {np.nanmax(frac[below]):.2g} below $\\beta$ (against the closed form)")
first = (f"{frac[above][0]:.2g} at the first angle above ({gam[above][0]:.3g}°)" if above.any() else "no angle above")
segment = (f"satisfies equilibrium to {eq:.0e} $mg$ and Coulomb's law to |T|/(μN) ≤ {np.abs(Ft / Fn).max() / wedge.mu:.6f}, "
           f"and its $I$ lies within {np.abs(Iy - wedge.y_of_n(N)).max() / R:.0e} R of the curve $y_I(N)$ (panels b, c); "
           f"the dots span {100 * (Iy.max() - Iy.min()) / (y_top - y_bot):.0f} % of the closed-form segment" if wed.any()
           else "— none converged wedged in this run")
Markdown(f"""
* **The threshold.**  The closed form allows wedged states only for $\\gamma > \\beta$ = {np.degrees(wedge.beta):g}°
  (config); the sweep (panel f) is {threshold} and {first}. How fast the fraction rises above $\\beta$ is *not* a
  property of the mechanics but of the guess distribution: near the threshold $N_{{\\min}}\\propto 1/\\sin(\\gamma-\\beta)$
  diverges and only guesses of comparable intensity end wedged: the apparent onset is where $N_{{\\min}}(\\gamma)$
  falls below the largest guessed forces (`force_max` = {fmax:g} weights, config), i.e.
  $\\sin(\\gamma-\\beta) \\gtrsim \\cos\\gamma / (2\\,$`force_max`$)$, about {onset:.2g}° above $\\beta$, against a
  sweep step of {step_deg:.2g}°.
* **The segment.**  Every converged wedged run ({int(wed.sum())} runs) {segment}. The top end ($N = N_{{\\min}}$,
  both contacts at the edge of their cones) is approached closely; the bottom end $R\\sin\\beta$ only as $N$ grows
  without bound, as the closed form says. The density of dots along the segment reflects our guess distribution,
  not a property of the solution set (the paper shows no distribution).
* **Zero guess vs history.**  Of the {int(zero_conv.sum())} converged zero-guess runs, {int((outcome[zero_conv] == 0).sum())}
  fall; evolution (a) ends at y = {float(evo.sel(evolution='zero_guess').y.values[-1]):.6g} m against free fall
  {-0.5 * wedge.g * t[-1] ** 2:.6g} m. Evolution (b), started from a wedged force state and warm-started, keeps $B$
  within {np.abs(warm.y.values).max():.1e} m of rest over {t[-1]:g} s (at most {int(warm.sweeps.values[1:].max())}
  NLGS sweeps per step after the first): the forces act as state variables, as section 2 proposes.
""")

# %% [markdown]
# * **Differences from the paper.**  Moreau's figure 1 is a sketch: no dimensions, friction
#   coefficient or numerical results are given.  Our geometry is symmetric, so the segment of
#   $I$ lies on the vertical through $B$'s centre and the free parameter is the common normal
#   force $N$; with an asymmetric placement the segment is still on that vertical (three
#   concurrent forces) but its ends change.  The one-step exploration uses random initial
#   guesses (section 2's first method).  Its second method, zero guess with random review
#   orders, cannot reveal the wedged states here: with $\kappa = 2$ contacts there is
#   $(\kappa-1)! = 1$ distinct ordering, and from zero guess it gives free fall.
