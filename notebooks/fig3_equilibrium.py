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
# # Figure 3 — indetermination clouds of 28 discs at rest (Moreau 2005, section 4)
#
# **What the paper says.** A collection of $N = 28$ frictional discs is in
# equilibrium under gravity. With $\kappa$ contacts, the contact forces form a
# vector $\rho \in \mathbf{R}^{2\kappa}$; the $3N$ equilibrium equations restrict
# it to an affine subspace $A$ of dimension $2\kappa - 3N$, Coulomb's law to the
# product $C$ of the friction sectors $C_\alpha$, so the set of equilibrium
# forces is the convex polyhedron $A \cap C$ and the possible values of one
# contact force form the projection of $A \cap C$ on that contact's plane.
# Repeated NLGS runs of one step from $u_i = 0$, each with a random review
# order, draw a dot per solution; the clouds "provide outlines of the
# projections", and show "ghost images of edges and vertices" of the
# high-dimensional polyhedron: the points are "a little denser in the vicinity
# of the boundary of $A \cap C$". Section 2 names the other exploration
# (random initial guesses from a plausible range) and notes that warm-started
# runs (the antecedent step's impulses as guess) show very little indeterminacy.
#
# %%
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig3_equilibrium import plots as ep
from ncd.figures.fig3_equilibrium.claims import JUDGES
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save, write_finding

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig3_equilibrium", ["state", "ensemble", "projection", "uniform"], globals().get("snakemake"))
inp, out, results = _smk.input, _smk.output, results_dir(_smk)
r = ep.Fig3Run(*(xr.load_dataset(getattr(inp, n)) for n in ("state", "ensemble", "projection", "uniform")))
save(ep.figure(r), out, dpi=130, show=True)
write_finding(out, ep.finding(r))

# %% [markdown]
# **(a)** The packing (line widths: normal forces at rest) with the two displayed
# contacts. **(b)** The dimension of the face of $A \cap C$ that holds each solution,
# per exploration (a uniform point is interior, of dimension $\dim A \cap C$, with
# probability one). **(c)–(j)** Each displayed contact's force plane in local
# coordinates (tangential $r_t$ across, normal $r_n$ up; the force on disc $a$ is
# $r_n n + r_t t$), with the Coulomb sector $C_\alpha$ (grey), the exact projection of
# $A \cap C$ (shaded) and one dot per converged solution; column (c, g) is the paper's
# figure (zero guess, random review orders); insets magnify clouds too small to see
# at the polygon's scale.
#
# ## What we compute
#
# A packing of 28 polydisperse discs deposited in a box
# (floor and two walls, all frictional with $\mu = 0.5$; the wall contacts are
# contacts of $A \cap C$ like the others) until the warm equilibrium test of
# section 2 gives $u_f = 0$; on its contacts, three ensembles of NLGS runs
# converged to a natural-map residual $\le 10^{-8}$ (relative): zero guess with
# random review orders (the paper's figure), random guesses with a fixed order,
# warm guess with random orders. Unlike the paper we also compute $A \cap C$
# exactly: its dimension, its boundedness and the exact projection on every
# contact's force plane by linear programming (HiGHS), and a sample drawn
# *uniformly* from $A \cap C$ (hit-and-run), the neutral reference against which
# the density of the NLGS clouds is judged.

# %% [markdown]
# ## The packing and the polyhedron $A \cap C$
#
# When $\operatorname{rank} H < 3N$ (a disc whose equations are dependent) the
# dimension of $A$ exceeds Moreau's count $2\kappa - 3N$; we report both. $A \cap C$
# is bounded when the LP "maximize $\sum r_n$ over self-stresses in $C$" has optimum 0:
# with gravity and a floor, no nonzero set of contact forces in the Coulomb sectors
# balances itself.

# %%
display(Markdown(ep.packing_text(r)))

# %%
display(Markdown(claim_markdown("s4-dimension-A", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s4-force-set", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s2-equilibrium-test", results, JUDGES)))

# %% [markdown]
# ## Every converged run lies in $A \cap C$

# %%
display(Markdown(ep.convergence_text(r)))

# %%
display(Markdown(claim_markdown("s4-in-cones", results, JUDGES)))

# %% [markdown]
# ## Coverage, spread and density of the clouds
#
# Per displayed contact and exploration: *coverage* = area of the convex hull of the
# cloud / area of the exact polygon; *spread* = RMS distance of the points to their
# mean; *near the boundary* = fraction of points within $0.05\sqrt{\text{area}}$ of
# the polygon's boundary, against the uniform sample of $A \cap C$.

# %%
display(Markdown(ep.measures_table(r) + "\n\n" + ep.findings_text(r)))

# %%
display(Markdown(claim_markdown("s4-outlines", results, JUDGES)))
display(Markdown(claim_markdown("s2-review-orders", results, JUDGES)))
display(Markdown(claim_markdown("s2-limit-depends-on-order", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s2-warm-accelerates", results, JUDGES)))

# %% [markdown]
# ## Ghost images: where the solutions lie in $\mathbf{R}^{2\kappa}$
#
# The 2-D projection hides where a point lies in $\mathbf{R}^{2\kappa}$. The dimension
# of the face of $A \cap C$ that carries each solution (from the Coulomb conditions it
# meets with equality: a contact without force, a sliding contact) tells directly
# whether NLGS lands on the boundary (panel b). The lines inside the random-guess
# clouds are projections of faces, as Moreau suggests; in the force plane the contrast
# is less simple, because a projection mixes faces and interior.

# %%
display(Markdown(ep.faces_text(r)))

# %%
display(Markdown(claim_markdown("s4-ghost-images", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s4-denser-boundary", results, JUDGES)))

# %% [markdown]
# ## Where the reproduction differs
#
# The paper gives neither its packing nor its friction coefficient, time step or
# tolerance; ours are stated in `config.yaml` ($\mu = 0.5$ as in section 3 for discs
# and walls). Its packing is not ours, so $\kappa$, $\dim A$ and the shapes of the
# clouds differ. The two displayed contacts are our choice: the largest exact
# polygons between two mobile discs not sharing a disc. We draw each force in its
# contact's local frame $(r_t, r_n)$; the paper draws "a dot at the extremity" of each
# force, presumably as a vector in the plane of the packing.
