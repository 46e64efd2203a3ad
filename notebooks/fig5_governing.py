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
# # Figure 5 — what governs indeterminacy: friction, measured exactly over many packings
#
# **What the paper asked.** Section 3 of Moreau (2005) ends: "Further study is thus
# needed to discover the governing parameters and to explain why the dispersion
# produces a line". Every earlier figure rests on one packing, one flow, one step.
#
# **What Unger, Kertész & Wolf found** (PRL 94, 178001, 2005). Packings of 200 rigid
# discs, radii uniform in $[R, 2R]$, compressed between two plates with periodic sides
# (width $42R$), built by contact dynamics. They sampled the solution set by adding
# noise to every contact force and relaxing by Gauss–Seidel, and measured
# $\eta = \langle|\delta F|\rangle / \langle|F|\rangle$: $\eta \to 0$ as $\mu \to 0$,
# $\eta \propto \mu$ at small $\mu$, a peak near $\mu \approx 0.1$, then a fall as the
# coordination number drops.
#
# **What we compute.** Packings built at each $\mu$ (log-spaced), in Unger et al.'s
# geometry (bottom plate, periodic sides $42R$, compression by a body force toward the
# plate, no lid — see `ncd/figures/governing.py` for why) and under gravity in a box.
# On each: $\kappa$, the rank of the equilibrium equations, $\dim A$, $\dim(A\cap C)$
# twice (rank count with the implicit equalities found by LP, and affine rank of LP
# points), the exact range of every contact's normal and tangential force over
# $A \cap C$ ($4\kappa$ LPs, HiGHS), the contacts fixed by statics, the exact ratio
# $\eta_\mathrm{exact} = \sum_\alpha |\Delta r_\alpha| / \sum_\alpha |\bar r_\alpha|$
# ($\Delta r$: widths of the two ranges, $\bar r$: centre of the range box), and
# Unger et al.'s $\eta$ measured their way (uniform noise of amplitude
# $a\langle|r|\rangle$, NLGS relaxation to a natural-map residual $\le 10^{-8}$ and
# $u_f = 0$, a few rounds; $\eta_U = \langle|F_k - F_0|\rangle/\langle|F_0|\rangle$).
# The two are different statistics of the same set: $\eta_\mathrm{exact}$ is its full
# extent along each contact, $\eta_U$ the distance a short random walk travels in it.
#
# **Flows across parameters.** Figure 2's flow (the discs of
# `fig2_slope.scene` on its rough periodic ground) is released at several friction
# coefficients, time steps and slope angles, one factor at a time around Figure 2's
# setting, several flows (seeds) per setting. Every setting of a seed is released from the
# same deposit, built under gravity normal to the ground at the base's $\mu$: a setting
# changes its one parameter at the release and nothing else. At fixed times after release each flow's next step is scanned as
# Figure 2's scan does: zero-guess and warm-start NLGS runs with random review orders to a
# natural-map residual $\le 10^{-8}$ with the grain accelerations settled (unconverged runs
# are counted and left out: the first steps after release, grains nearly at rest under heavy
# forces, often exhaust the sweep budget). Distinct end points (accelerations further apart
# than a threshold) are then polished on their contact statuses to a residual $\le 10^{-10}$:
# a step is *indeterminate* when two exact solutions or more remain distinct, *determinate*
# when every end point polishes to one solution, *unknown* otherwise. At every indeterminate
# step we record the contacts whose status differs, the grains whose acceleration differs and
# the connected clusters they form, the number of independent directions the solutions span
# over the whole field and over the cluster of the grain of largest spread, the rank of that
# grain's acceleration cloud, and the dimension of the set of impulses (and of grain
# velocities) keeping the statuses of the most frequent solution (the null space of its
# sticking and sliding equations).

# %%
import numpy as np
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures import governing as fg
from ncd.figures import governing_plot as gp
from ncd.figures import governing_summary as gs
from ncd.pages.notebook import paths, save

_smk = paths("fig5_governing", ["packings", "flows"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config
ds = xr.load_dataset(inp.packings)
flows = xr.load_dataset(inp.flows)
kinds = sorted(set(ds.kind.values.tolist()))

# %% [markdown]
# ## The packings

# %%
p = cfg["packings"]
n_mu = len(np.unique(ds.mu.values))
lines = [f"{ds.sizes['packing']} packings of N = {ds.sizes['disc']} discs at {n_mu} values of μ "
         f"from {ds.mu.values.min():.3g} to {ds.mu.values.max():.3g}; "
         + ", ".join(f"{int((ds.kind.values == k).sum())} {fg.KINDS[k]}" for k in kinds) + ". ",
         f"Built in {int(ds.build_steps.min())}–{int(ds.build_steps.max())} steps of h = {p['h']:g} s; "
         f"largest interpenetration {float(ds.max_penetration.max()):.3f} R; every packing passed the "
         f"equilibrium test (largest |u_f| = {float(ds.rest_velocity.max()):.1e} |g| h). ",
         f"A ∩ C is unbounded (a self-stress inside C) in {int((ds.bounded == 0).sum())} packings "
         f"({', '.join(f'{fg.KINDS[int(a)]} μ = {b:.3g}' for a, b in zip(ds.kind.values[ds.bounded == 0], ds.mu.values[ds.bounded == 0]))}): "
         f"there some ranges are infinite, η_exact is undefined and left out of the bands. "
         f"Exact measures: {int(ds.n_lp.sum())} LPs in all. dim(A∩C) by rank count and by LP agree on "
         f"{int((ds.dim_AC_rank == ds.dim_AC_lp).sum())} of {ds.sizes['packing']} packings."]
display(Markdown("".join(lines)))

# %% [markdown]
# ## The figure

# %%
fig = gp.figure(ds, flows)
save(fig, out, dpi=120)

# %% [markdown]
# ## What we measured, and where it differs from Unger et al.

# %%
text = []
for k in kinds:
    name = fg.KINDS[k]
    te, tu = fg.eta_table(ds, "eta_exact", k), fg.eta_table(ds, "eta_unger", k)
    pe, se = fg.peak_and_slope(te)
    pu, su = fg.peak_and_slope(tu)
    z = fg.eta_table(ds, "coordination", k)
    dr = fg.eta_table(ds, "dim_ratio", k)
    ff = fg.eta_table(ds, "fixed_fraction", k)
    text.append(
        f"**{name}** ({int(te[:, 3].min())}–{int(te[:, 3].max())} packings per μ with a bounded A ∩ C). "
        f"Exact η: {te[0, 1]:.3g} at μ = {te[0, 0]:.3g}, largest mean "
        f"{np.nanmax(te[:, 1]):.3g} at μ = {pe:.3g} (Unger et al.: peak near 0.1) and is {te[-1, 1]:.3g} at "
        f"μ = {te[-1, 0]:.3g}; log-log slope over the two smallest μ: {se:.2f} (Unger et al.: 1). "
        f"Unger et al.'s η measured their way: {tu[0, 1]:.3g} at the smallest μ, largest {np.nanmax(tu[:, 1]):.3g} at μ = {pu:.3g}, "
        f"slope {su:.2f}; it is {np.nanmedian(ds.eta_unger.values[ds.kind.values == k] / ds.eta_exact.values[ds.kind.values == k]):.2f} "
        f"times the exact η (median over packings). "
        f"Coordination 2κ/N falls from {z[0, 1]:.2f} to {z[-1, 1]:.2f}; dim(A∩C)/2κ goes from "
        f"{dr[0, 1]:.3f} to {dr[-1, 1]:.3f} (largest {np.nanmax(dr[:, 1]):.3f} at μ = {dr[np.nanargmax(dr[:, 1]), 0]:.3g}); "
        f"the fraction of contacts fixed by statics from {ff[0, 1]:.3f} to {ff[-1, 1]:.3f}.")
display(Markdown("\n\n".join(text)))

# %%
k0 = kinds[0]
te, tu = fg.eta_table(ds, "eta_exact", k0), fg.eta_table(ds, "eta_unger", k0)
(pe, se), (pu, su) = fg.peak_and_slope(te), fg.peak_and_slope(tu)
grid = np.unique(ds.mu.values)
nearest = grid[np.argmin(np.abs(np.log(grid / gp.UNGER_PEAK_MU)))]   # the grid point nearest mu = 0.1


def where(m):
    if m == grid.max():
        return "the largest μ of the grid: no peak inside the range studied"
    return "the grid point nearest Unger et al.'s 0.1" if m == nearest else f"not the grid point nearest 0.1 ({nearest:.3g})"


display(Markdown(
    f"**Where we agree and differ ({fg.KINDS[k0]}).** Largest mean exact η at μ = {pe:.3g}: {where(pe)}; "
    f"largest mean η measured their way at μ = {pu:.3g}: {where(pu)}. Small-μ log-log "
    f"slope: exact {se:.2f}, their way {su:.2f}, against their η ∝ μ (slope 1). "
    f"The exact η is the full extent of the solution set along each contact (an upper envelope of any sampling); "
    f"{cfg['unger']['rounds']} noise-and-relax rounds travel only part of it (median ratio printed above). "
    f"Built-in differences: a body-force load (stress growing with depth) instead of a lid, the whole "
    f"packing instead of a bulk slice with fixed boundary forces, and {int(te[:, 3].min())}–{int(te[:, 3].max())} "
    f"packings per μ in this run"
    + ("; with fewer than 3 packings at some μ the location of the largest mean is not resolved "
       "(the seed bands of the figure)." if int(te[:, 3].min()) < 3 else ".")))

# %% [markdown]
# ## Flows: indeterminate steps against friction, time step and slope

# %%
fc = cfg["flows"]
fm = gs.flow_measures(flows)
n_set = len(np.unique(flows.setting.values))
runs = fc["scan"]["runs"]
n_scan = flows.sizes["scan"]
ind = flows.indeterminate.values
conv = (flows.converged_zero.values + flows.converged_warm.values).sum()
display(Markdown(
    f"{flows.sizes['flow']} flows: {n_set} settings × {fc['seeds']} seeds, one factor at a time around "
    f"μ = {fc['base']['mu']}, h = {fc['base']['h']:g} s, slope {fc['base']['slope_deg']:g}°. "
    f"Each flow is scanned {n_scan} times, every {fc['scan_every'] * 1e3:g} ms up to "
    f"{fc['duration'] * 1e3:g} ms after release, with {runs} zero-guess and {runs} warm-start runs: "
    f"{conv} of {2 * runs * ind.size} runs converged. Of the {ind.size} scanned steps, "
    f"{int((ind == 1).sum())} are indeterminate (two exact solutions or more), {int((ind == 0).sum())} "
    f"determinate and {int((ind == -1).sum())} unknown (no converged run, or end points that did not "
    f"polish to exact solutions: {int(((ind == -1) & (flows.n_solutions.values == 0)).sum())} without a "
    f"converged run). With {runs} + {runs} runs per step a solution reached rarely can be missed: the "
    f"fractions below are lower bounds of the fraction of steps with several solutions."))

# %%
rows = []
for factor, name, unit in (("mu", "μ", ""), ("h", "h", " s"), ("slope", "slope", "°")):
    ti, ts = gs.factor_table(flows, factor, "indeterminate"), gs.factor_table(flows, factor, "spread")
    tu = gs.factor_table(flows, factor, "unknown")
    cells = "; ".join(f"{name} = {v:g}{unit}: {m:.2f} ± {np.nan_to_num(b):.2f} (spread {s:.2g} |g|, "
                      f"unknown {u:.2f}, {int(n)} flows)"
                      for (v, m, b, n), (_, s, _, _), (_, u, _, _) in zip(ti, ts, tu))
    rows.append(f"**Against {name}** — fraction of indeterminate steps (mean ± 95 % band over seeds): {cells}.")
display(Markdown("\n\n".join(rows)))

# %% [markdown]
# ## Why a line

# %%
c = gs.line_counts(flows)
ratio = flows.cloud_minor.values / flows.cloud_major.values
lr = fc["line_ratio"]
visual = int(((flows.indeterminate.values == 1) & (ratio <= lr)).sum())
display(Markdown(
    f"At the {c['steps']} indeterminate steps: {c['solutions'][0]} have two exact solutions, "
    f"{c['solutions'][1]} three and {c['solutions'][2]} more; a median of {c['switched_median']:.0f} "
    f"contacts change status and {c['moving_median']:.0f} grains accelerate differently between them "
    f"(one connected cluster at {c['one_cluster']} steps). The cloud of the grain of largest spread is a "
    f"point at {c['rank'][0]}, a line (rank 1, minor extent below the solution threshold) at {c['rank'][1]} "
    f"and spans an area at {c['rank'][2]} steps; by Figure 2's visual criterion (minor/major ≤ {lr}) it "
    f"is a line at {visual}. The grain's cluster has one degree of freedom (the solutions restricted to "
    f"it span one direction) at {c['predicted']} steps; the hypothesis — a line exactly when one isolated "
    f"one-degree-of-freedom cluster decides between the solutions — holds at {c['holds']} of "
    f"{c['steps']} steps ({c['line_and_predicted']} lines predicted, {c['line_not_predicted']} lines "
    f"not predicted). Two solutions always span one direction: with two exact solutions the line is "
    f"unavoidable, and the test has content only at the {c['tested']['steps']} steps with three or more. "
    f"There it holds at {c['tested']['holds']}: {c['tested']['line_and_predicted']} predicted lines and "
    f"{c['tested']['neither']} steps with neither a line nor a prediction; it fails at "
    f"{c['tested']['line_not_predicted']} lines not predicted and {c['tested']['predicted_not_line']} "
    f"predicted lines that are not. Keeping the statuses "
    f"of the most frequent solution leaves grain velocities free (a continuum of solutions) at "
    f"{c['continuum']} steps; elsewhere the solutions are isolated points and the impulses alone are "
    f"indeterminate (median dimension {np.nanmedian(flows.null_impulse.values[flows.indeterminate.values == 1]) if c['steps'] else np.nan:.0f})."))
