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
# # Beyond the paper: governing parameters of indeterminacy
#
# **What the paper asked.** Section 3 of Moreau (2005) ends: "Further study is thus
# needed to discover the governing parameters and to explain why the dispersion
# produces a line". Every earlier figure rests on one packing, one flow, one step.
#
# **What Unger, Kertész & Wolf found** (PRL 94, 178001, 2005). Packings of 200 rigid
# discs, radii uniform in $[R, 2R]$, periodic sides of width $42R$, no gravity, compressed
# between two plates under a constant force, built by contact dynamics at each $\mu$; a
# middle slice of height $28R$ analysed with the forces across its boundaries held fixed.
# From the force state at jamming they add to every contact force uniform noise in
# $[-\langle F_n\rangle, \langle F_n\rangle]$, relax by Gauss–Seidel with contacts and
# boundary forces fixed, and start the next round from the result: a random walk in the
# solution set. Their measure is $\eta = \langle \delta F\rangle / \langle |F|\rangle$, with
# $\delta F$ the standard deviation of a contact's force vector over the samples. They
# report $\eta \to 0$ as $\mu \to 0$, $\eta \propto \mu$ at small $\mu$ with the
# coordination $z$ still at its frictionless (isostatic) value 4, a maximum near
# $\mu \approx 0.1$, a fall at larger $\mu$; a control series (one packing built without
# friction, friction switched on for the sampling) with $\eta$ rising monotonically; and a
# history force state closer to the centre of the solution set than random samples.
#
# **What we compute.** Their geometry and protocol at their size (sizes below). The top plate is a mobile rigid body of the scene
# (`ncd/figures/fig5_governing/plates.py`): its mass enters the Delassus blocks of its contacts, NLGS moves
# it as it moves a disc, and its vertical equilibrium is a row of $A$. Its contacts are
# frictionless, so that it receives vertical forces only and translates along its normal
# exactly; no solver kernel changes. A packing is at rest when the plate is slow and the
# one-step test from rest gives $u_f = 0$; that test, finished on its contact statuses and
# made exact on its active Coulomb rows, gives the reference forces. The middle slice is then one problem
# $H r + F = 0$, $r \in C$: unknowns the forces between two slice discs, $F$ the
# boundary forces of the reference. On it: the exact range of every force component over
# $A \cap C$ and $\dim(A \cap C)$ by LP (`governing_exact`), with the **exact range ratio**
# (range-box diagonals over box-centre forces: the full extent of the set, not $\eta$);
# **their $\eta_U$ on their random walk** (each relaxed state checked to be a point of
# $A\cap C$); **their $\eta_U$ on a uniform sample** of $A \cap C$ (hit-and-run in its affine
# hull, two chains from dispersed starts whose agreement is the mixing check); the
# coordination $z$ in the slice without rattlers; the distance of the history state to the
# centre of the set.

# %%
from pathlib import Path

import numpy as np
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig5_governing import claims as gc
from ncd.figures.fig5_governing import page as gpage
from ncd.figures.fig5_governing import plots as gp
from ncd.figures.fig5_governing import summary as gs
from ncd.figures.fig5_governing.claims import JUDGES
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, save

_smk = paths("fig5_governing", ["packings", "flows"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config
ds = xr.load_dataset(inp.packings)
flows = xr.load_dataset(inp.flows)
results = Path(inp.packings).parents[1]           # the results folder the claims read

# %% [markdown]
# ## The packings

# %%
plates = ds.kind.values == 0
display(Markdown(gpage.study_summary(ds, cfg)))

# %%
med, worst, n_w = gc.walk_settling(ds)
display(Markdown(
    (f"**Has the walk converged?** Over the {n_w} analyses where the walk moves, η_U over the first half of "
     f"its samples differs from η_U over all of them by a median {med:.0%} (largest {worst:.0%}); panel (d) "
     "shows η_U against the number of samples. " if n_w else "**The walk never moves in this run** (every "
     "slice determinate). ") + "What the verdicts use are means over packings: from half the samples to all "
    f"of them the mean η_U at each μ moves by at most {gc.mean_settling(ds, 0):.1%} in the plates series and "
    f"{gc.mean_settling(ds, 1):.1%} in the control series. Unger et al. drew 100 samples per packing; this run "
    f"drew {cfg['walk']['samples']}."))

# %% [markdown]
# ## The figure

# %%
fig = gp.figure(ds, flows)
save(fig, out, dpi=110)

# %% [markdown]
# ## What we measured against Unger et al.
#
# Each paragraph states one of their findings, our measurement on their statistic and the
# verdict (the same objects the index page prints).

# %%
m_u, lo_u, hi_u = gc.peak(ds, "eta_uniform")
m_x, lo_x, hi_x = gc.peak(ds, "eta_exact")
flat = [m for m in np.unique(ds.mu.values[plates]) if (ds.dim_AC_rank.values[plates & (ds.mu.values == m)] == 0).all()]
spread = (ds.walk_distance / ds.uniform_distance).where((ds.mixed == 1) & (ds.dim_AC_rank > 0)).values
extra = {
    "unger-peak": f"Every slice built at μ = {', '.join(f'{m:.3g}' for m in flat) or 'none'} is determinate (η_U = 0, "
    f"off the log axes of panel a). On the uniform sample the largest η_U is at μ = {m_u:.3g} (band {lo_u:.3g}–{hi_u:.3g}); "
    f"the exact range ratio is largest at μ = {m_x:.3g} (band {lo_x:.3g}–{hi_x:.3g}).",
    "unger-vanishes": f"Slope on the uniform sample {gc.small_mu_slope(ds, 'eta_uniform'):.2f}, of the exact range "
    f"ratio {gc.small_mu_slope(ds, 'eta_exact'):.2f}.",
    "unger-centrality": f"The random-walk samples stay at a median {np.nanmedian(spread):.2f} of the uniform samples' "
    "distance to the centre (indeterminate slices whose chains agree)." if np.isfinite(spread).any() else ""}
display(Markdown(claim_markdown("s4-unger", results, JUDGES)))
for claim_id in gc.UNGER_CLAIMS:
    display(Markdown(claim_markdown(claim_id, results, JUDGES) + "\n" + extra.get(claim_id, "")))

# %%
verdicts = [gc.claim_unger_peak(results), gc.claim_unger_vanishes(results), gc.claim_unger_control(results)]
with open(getattr(out, "caption", Path(inp.packings).with_name("caption.rst")), "w", encoding="utf-8") as caption:
    caption.write(
        "**Beyond the paper: governing parameters of indeterminacy** (Unger, Kertész & Wolf's packings, their "
        f"statistic η_U). {verdicts[0].value} ({verdicts[0].verdict}); {verdicts[1].value} ({verdicts[1].verdict}); "
        f"{verdicts[2].value} ({verdicts[2].verdict}). Details: ``results/html/fig5_governing.html``.\n")

# %% [markdown]
# <a id="unger-causes"></a>
# **Where a difference comes from, one thing at a time.** The same sets measured by another
# statistic (exact range ratio against $\eta_U$, panels a–b), by another sampler (their walk
# against a uniform sample, panel f), and built by another history (the control series:
# one frictionless packing, only the friction of the analysis changes).

# %%
n_c, closer, rank = gc.centrality_summary(ds)
n_k, closer_k, rank_k = gc.centrality_summary(ds, kind=1)
display(Markdown(
    f"Small-μ slope of η_U on the walk: {gc.small_mu_slope(ds):.2f} over new packings at each μ, "
    f"{gc.small_mu_slope(ds, kind=1):.2f} in the control series (same packing, friction changed). "
    f"Determinate slices (dim(A∩C) = 0, η_U = 0) occur in {int(((ds.dim_AC_rank == 0) & plates).sum())} of "
    f"{int(plates.sum())} built-at-μ analyses and enter their means. Centrality in the control series: the "
    f"frictionless history state is closer to the centre than the mean uniform sample in {closer_k} of {n_k} "
    f"analyses (median fraction of uniform samples closer: {rank_k:.2f}), against {closer} of {n_c} for "
    "packings built at μ: what sets the history state's place in the set is the history (a state built "
    "with friction keeps contacts at the Coulomb limit, on the boundary), not the sampler."))

# %% [markdown]
# ## Flows: indeterminate steps against friction, time step and slope

# %%
display(Markdown(gs.flows_overview(flows, cfg["flows"])))

# %%
display(Markdown(gs.factor_text(flows)))
for claim_id in ("s3-other-experiments", "s3-governing-parameters"):
    display(Markdown(claim_markdown(claim_id, results, JUDGES)))

# %% [markdown]
# ## Why a line

# %%
display(Markdown(gs.line_text(flows, cfg["flows"]["line_ratio"])))
display(Markdown(claim_markdown("s3-line", results, JUDGES)))
