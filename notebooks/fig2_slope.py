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
# # Figure 2 — dispersion of a grain's acceleration in a flow down a slope (Moreau 2005, section 3)
#
# **What the paper says.** $N = 355$ discs flow on a ground under periodic
# lateral conditions, gravity as for a ground sloping down by $24°$, friction
# $0.5$, restitution $0$, "in a phase of overall acceleration". One
# computation step is investigated by repeated nonlinear Gauss–Seidel (NLGS)
# runs from the zero initial guess, each with a random review order of the
# contacts: the acceleration vector of a grain centre is dispersed, and the
# dispersion is a *line*, not an extended cloud. With the contact forces of the
# antecedent step as initial guess, "almost no dispersion is visible". The
# paper leaves open why the dispersion is a line and suggests that "the
# disposition of contact points at which the sliding velocity equals zero may
# be determinant".
#
# **What we compute.** The scene is built, deposited and released by
# `ncd.scenes.slope`: polydisperse discs (diameters uniform, $d_{max}/d_{min}$
# stated below) on a rough ground made of a row of touching *glued discs*
# (fixed obstacle discs) of the mean diameter, periodic along the ground. A
# flat frictional wall was not used: the bottom layer could then roll on a
# smooth surface, while glued discs anchor it and make the flow shear through
# the layer. After the deposit (gravity normal to the ground) gravity is
# tilted to $24°$ and the flow is stepped with warm starts (Moreau–Jean,
# $\theta = 1/2$). At the investigated step, the core problem is solved
# many times: (a) zero guess and (b) previous-step impulses as guess, both with
# a random review order per run (the same orders for (a) and (b)). The paper's
# question hides a numerical one: **is the dispersion a true indeterminacy of
# the step problem, or the iteration error of runs stopped at a finite
# tolerance**, which can also look like a line? Every run is therefore *continued from tolerance to tolerance*
# (relative natural-map residual, decades), so that each run gives its
# acceleration $(u_f - u_i)/h$ at every tolerance: a true indeterminacy keeps a
# fixed non-zero spread as the tolerance tightens, an iteration error shrinks
# with it.

# %%
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from IPython.display import Markdown
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.colors import LogNorm
from matplotlib.patches import Circle

from ncd.figures import census as cs
from ncd.pages.notebook import paths, save
from ncd.scenes import slope_analysis as sa

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig2_slope", ["trajectory", "ensemble", "measures", "census"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config

traj = xr.load_dataset(inp.trajectory)
ens = xr.load_dataset(inp.ensemble)
meas = xr.load_dataset(inp.measures)
sc, fl, ex, an = cfg["scene"], cfg["flow"], cfg["explore"], cfg["analysis"]
g = float(meas.attrs["g"])
h = float(traj.attrs["h"])
grain = int(meas.attrs["grain"])
k_step = int(traj.attrs["investigated_step"])
tols = ens.tol.values
tight = tols.min()
d = sc["diameter"]

# %% [markdown]
# ## The scene, the deposit and the flow

# %%
pen_dep = float(traj.deposit_max_penetration.max()) / d
pen_flow = float(traj.max_penetration.max()) / d
print(f"N = {traj.sizes['disc']} discs, diameters uniform in a ratio {sc['size_ratio']}, mean d = {d} m; "
      f"ground: {traj.sizes['ground']} glued discs, period {traj.attrs['period']:.3g} m "
      f"= {sc['width_diameters']} d; slope {sc['slope_deg']}°, mu = {sc['mu']}, e = {sc['restitution']}")
print(f"deposit: {traj.sizes['deposit_step']} steps of h = {cfg['deposit']['h']} s "
      f"(NLGS tol {cfg['deposit']['solver']['tol']}), largest interpenetration {pen_dep:.2%} of d")
print(f"flow: {traj.sizes['step']} steps of h = {h} s (NLGS tol {fl['solver']['tol']}, warm start); "
      f"{int((traj.converged == 0).sum())} steps stopped at max_sweeps = {fl['solver']['max_sweeps']} "
      f"(sweeps per step: median {int(traj.sweeps.median())}, max {int(traj.sweeps.max())}); "
      f"largest interpenetration {pen_flow:.2%} of d")
i = k_step - 1
mean_acc = float((traj.mean_vx[i] - (traj.mean_vx[i - 1] if i > 0 else 0.0)) / h)
slope_fit = np.polyfit(traj.time.values[max(0, i - 10): i + 11], traj.mean_vx.values[max(0, i - 10): i + 11], 1)[0]
ke_growth = float(traj.kinetic_energy[i] / traj.kinetic_energy[max(0, i - 10)])
print(f"investigated step {k_step}: t = {float(traj.attrs['investigated_time']) * 1e3:.1f} ms after the release, "
      f"{int(traj.n_contacts[i])} contacts, mean velocity {float(traj.mean_vx[i]):.4f} m/s down the slope; "
      f"mean acceleration {slope_fit:.3f} m/s^2 (fit over +-10 steps; {mean_acc:.3f} m/s^2 in the step itself), "
      f"kinetic energy x{ke_growth:.2f} over the 10 steps before: "
      f"{'an accelerating phase' if slope_fit > 0 and ke_growth > 1 else 'NOT accelerating'}")

fig, ax = plt.subplots(1, 3, figsize=(13, 3.2))
ax[0].plot(traj.time * 1e3, traj.mean_vx, label="mean $v_x$ (down the slope)")
ax[0].plot(traj.time * 1e3, traj.mean_vy, label="mean $v_y$")
ax[1].semilogy(traj.time * 1e3, traj.kinetic_energy)
ax[2].semilogy(traj.time * 1e3, traj.sweeps, ".", ms=3)
for a, lab in zip(ax, ("velocity (m/s)", "kinetic energy (J)", "NLGS sweeps per step")):
    a.axvline(float(traj.attrs["investigated_time"]) * 1e3, color="r", lw=0.8)
    a.set_xlabel("time after release (ms)")
    a.set_ylabel(lab)
ax[0].legend(fontsize=8)
fig.tight_layout()

# %% [markdown]
# ## How often is a step indeterminate? (scan of the flow)
#
# Every few flow steps, a few zero-guess and warm-start runs (random orders,
# tight tolerance) are compared: the number of *distinct solutions* they reach
# (whole acceleration fields that differ by more than the stated threshold).
# The paper notes that "in other numerical experiments of the same sort, no
# indetermination was visible"; here it comes and goes from step to step.
# Only converged runs are compared; a step where runs stop at `max_sweeps`
# (plain NLGS cannot reach the tolerance there in that budget) is reported as such.

# %%
scan = traj[[v for v in traj.data_vars if v.startswith("scan_")]].to_dataframe()
print(scan.to_string())
if len(scan):
    for init in ("zero", "warm"):
        sol, conv = traj[f"scan_{init}_solutions"].values, traj[f"scan_{init}_converged"].values
        print(f"{init:5s}: {int((sol > 1).sum())} of {len(sol)} scanned steps with several solutions among the "
              f"converged runs; {int((conv < cfg['scan']['runs']).sum())} steps where some of the "
              f"{cfg['scan']['runs']} runs did not reach tol {cfg['scan']['tol']:.0e} within "
              f"{cfg['scan']['max_sweeps']} sweeps ({int((conv == 0).sum())} where none did)")

# %% [markdown]
# ## The ensembles: convergence, sweeps and wall time
#
# Each run is one NLGS solve continued through the tolerances (each stage
# restarts from the previous impulses with the same review order, so the state
# "at tolerance $\epsilon$" is the run stopped at its first residual check
# below $\epsilon$, give or take `check_every` sweeps). Sweeps and wall times
# are cumulative.

# %%
for init in ens.init.values:
    e = ens.sel(init=init)
    for tol in tols:
        t = e.sel(tol=tol)
        print(f"{init:5s} tol {tol:.0e}: converged {int(t.converged.sum())}/{t.sizes['run']}, "
              f"residual max {float(t.residual.max()):.2e}, sweeps median {int(t.sweeps.median())} "
              f"max {int(t.sweeps.max())}, wall time median {float(t.wall_time.median()) * 1e3:.0f} ms")
fig, ax = plt.subplots(1, 2, figsize=(10, 3.4))
for init, c in zip(ens.init.values, ("C0", "C1")):
    e = ens.sel(init=init)
    ax[0].loglog(e.wall_time.values.T, e.residual.values.T, "-", color=c, alpha=0.05, lw=0.5)
    ax[0].loglog(e.wall_time.median("run"), e.residual.median("run"), "o-", color=c, label=f"{init} (median)")
    ax[1].loglog(tols, e.sweeps.median("run"), "o-", color=c, label=init)
    ax[1].fill_between(tols, e.sweeps.min("run"), e.sweeps.max("run"), color=c, alpha=0.2)
ax[0].set_xlabel("wall time of the run (s)")
ax[0].set_ylabel("relative natural-map residual")
ax[0].legend(fontsize=8)
ax[1].set_xlabel("tolerance")
ax[1].set_ylabel("sweeps (min-median-max)")
ax[1].invert_xaxis()
ax[1].legend(fontsize=8)
fig.tight_layout()

# %%
Markdown(sa.warm_check(ens, cfg["analysis"]["solution_threshold"]) or "The warm runs are plain NLGS.")

# %% [markdown]
# ## True indeterminacy or iteration error? Spread against tolerance
#
# For every grain the cloud of its accelerations over the runs is summarised
# by its covariance: the principal axes (RMS extents along the major and minor
# axes) and the spread $\sqrt{\lambda_1 + \lambda_2}$ (RMS distance to the
# mean). The figure's grain is chosen by the rule in the config
# (`analysis.grain = -1`: the largest zero-guess spread at the tightest
# tolerance). The verdict rule: *indeterminacy* when, over the last
# `analysis.decades` decades of tolerance, the zero-guess spread stays above
# `analysis.floor` $|g|$, does not shrink by more than half per decade, and at
# the tightest tolerance is at least `analysis.warm_ratio` times the
# warm-start spread; *iteration error* when it shrinks tenfold over those
# decades.

# %%
sel = meas.sel(disc=grain)
for init in meas.init.values:
    for tol in tols:
        s = sel.sel(init=init, tol=tol)
        print(f"grain {grain}, {init:5s} tol {tol:.0e}: spread {float(s.spread):.3e} m/s^2 "
              f"({float(s.spread) / g:.2e} g), major {float(s.major):.3e}, minor {float(s.minor):.2e}, "
              f"minor/major {float(s.ratio):.2e}, major axis at {float(s.angle):.1f}°; "
              f"visible grains {float(meas.visible_fraction.sel(init=init, tol=tol)):.1%}")
verdict = meas.attrs["verdict"]
print(f"\nVERDICT: {verdict}.  zero-guess spread: min over the last {an['decades']} decades "
      f"{meas.attrs['verdict_zero_min_in_window']:.3g} m/s^2 (floor {an['floor'] * g:.3g}), "
      f"ratio tightest/loosest of the window {meas.attrs['verdict_zero_shrink']:.3f}, "
      f"zero/warm at {tight:.0e}: {meas.attrs['verdict_zero_over_warm']:.3g}")

# %% [markdown]
# ## Distinct solutions reached by NLGS, and where they differ
#
# At the tightest tolerance the runs of both ensembles are grouped into
# *distinct solutions*: runs whose whole acceleration fields (all grains) agree
# within `analysis.solution_threshold` $|g|$. If the runs reach only a few
# isolated solutions, a grain's cloud consists of a few points (plus the
# iteration error left at the tolerance); with two solutions it is a segment.
# Whether that is what happens here is measured below and by the census.
# The contacts whose status (no contact / stick / slide) differs between the
# two most frequent solutions tell where the alternative is decided, and the
# network of contacts that *stick in both solutions* shows how the difference
# propagates: we measure, for every grain, the number of sticking links to the
# nearest grain with a switching contact.

# %%
counts = meas.solution_count
print(f"{meas.attrs['n_solutions']} distinct solution(s) at tol {tight:.0e}; runs per solution:")
for init in meas.init.values:
    print(f"  {init:5s}: {counts.sel(init=init).values.tolist()}")
print("distance (max |a| difference, m/s^2) of each solution from the trajectory's own step "
      "(warm start, identity order, flow tolerance):", np.round(meas.reference_distance.values, 4).tolist())
vis = meas.spread.sel(init="zero", tol=tight) > an["visible"] * g
ratios = meas.ratio.sel(init="zero", tol=tight).values[vis.values]
if vis.any():
    print(f"{int(vis.sum())} grains ({float(vis.mean()):.1%}) with a visible zero-guess dispersion; "
          f"their minor/major ratios: median {np.median(ratios):.2e}, max {ratios.max():.2e}")
status_names = {0: "no contact", 1: "stick", 2: "slide+", 3: "slide-", 4: "fallback"}
if "switched" in meas:
    runs = [int(np.nonzero(meas.solution_label.values.ravel() == k)[0][0]) for k in (0, 1)]
    st = ens.status.values.reshape(-1, ens.sizes["contact"])
    sw = np.nonzero(meas.switched.values)[0]
    print(f"\nthe two most frequent solutions differ in the status of {len(sw)} of {ens.sizes['contact']} contacts:")
    for c in sw:
        b = int(ens.body_b[c])
        print(f"  grains {int(ens.body_a[c])}-{b if b < traj.sizes['disc'] else 'ground'}: "
              f"{status_names[int(st[runs[0], c])]} -> {status_names[int(st[runs[1], c])]}")
    dist = meas.switch_distance.values
    dmag = np.hypot(meas.delta_x, meas.delta_y).values
    rigid_res = np.hypot(meas.delta_x - meas.rigid_x, meas.delta_y - meas.rigid_y).values / np.maximum(dmag, 1e-300)
    big = dmag > an["visible"] * g
    print(f"\nthe contacts sticking in both solutions join {int(meas.cluster_size.max())} of {len(dmag)} grains "
          f"into one network; the difference is not a rigid motion of it (best rigid fit per network: relative "
          f"residual median {np.median(rigid_res[big]):.2f} over the grains with a visible difference): "
          f"the grains roll on each other")
    print(f"the chosen grain: {int(meas.n_stick_both[grain])} of its {int(meas.n_contacts[grain])} contacts "
          f"stick in both solutions; {dist[grain]} sticking links from a switching contact; "
          f"|difference| {dmag[grain]:.3g} m/s^2 at {np.degrees(np.arctan2(float(meas.delta_y[grain]), float(meas.delta_x[grain]))):.1f}°")
    fig, ax = plt.subplots(figsize=(5, 3.4))
    ok = dist >= 0
    ax.semilogy(dist[ok] + np.random.default_rng(0).uniform(-0.2, 0.2, ok.sum()), dmag[ok] + 1e-6, ".", ms=4)
    if (~ok).any():
        ax.semilogy(np.full((~ok).sum(), -1.0), dmag[~ok] + 1e-6, "x", ms=4, label="not linked by sticking contacts")
        ax.legend(fontsize=8)
    ax.axhline(an["visible"] * g, color="k", lw=0.5)
    ax.set_xlabel("sticking links to the nearest switching contact")
    ax.set_ylabel("|a(solution 1) - a(solution 0)| (m/s$^2$)")
    fig.tight_layout()
    bins = [(-1, -1)] + [(k, k + 2) for k in range(0, dist.max() + 1, 3)]
    for lo, hi in bins:
        m = (dist >= lo) & (dist <= hi)
        if m.any():
            what = "not linked by sticking contacts" if lo < 0 else f"{lo}..{hi} sticking links"
            print(f"  {what:32s}: {m.sum():3d} grains, median |difference| {np.median(dmag[m]):.3g} m/s^2, "
                  f"visible {np.mean(dmag[m] > an['visible'] * g):.0%}")

# %% [markdown]
# ### The chosen grain's runs along the segment joining the two solutions
#
# Each run's acceleration of the chosen grain is written as
# $a = a_0 + t\,(a_1 - a_0) + p\,n$, with $a_0, a_1$ the grain's
# accelerations in the two most frequent solutions and $n$ the unit normal to
# the segment: $t$ is the position along the line (0 and 1 at the
# solutions), $p$ the distance off the line. At loose tolerances this shows
# where the unconverged runs lie.

# %%
if meas.attrs["n_solutions"] >= 2:
    a0 = np.array([float(meas.solution_accel_x[0, grain]), float(meas.solution_accel_y[0, grain])])
    a1 = np.array([float(meas.solution_accel_x[1, grain]), float(meas.solution_accel_y[1, grain])])
    seg = np.linalg.norm(a1 - a0)
    u = (a1 - a0) / seg
    for init in ens.init.values:
        for tol in tols:
            e = ens.sel(init=init, tol=tol, disc=grain)
            p_ = np.column_stack([e.accel_x.values, e.accel_y.values]) - a0
            t_, off = p_ @ u / seg, p_ @ np.array([-u[1], u[0]])
            near = np.minimum(np.abs(t_), np.abs(t_ - 1))
            print(f"{init:5s} tol {tol:.0e}: t in [{t_.min():+.3f}, {t_.max():+.3f}], quartiles "
                  f"{np.round(np.quantile(t_, [0.25, 0.5, 0.75]), 3).tolist()}, runs within 0.05 of an end "
                  f"{np.mean(near < 0.05):.0%}, largest |p| / |a1 - a0| {np.abs(off).max() / seg:.1e}")
    print(f"segment: |a1 - a0| = {seg:.3g} m/s^2 at {np.degrees(np.arctan2(u[1], u[0])):.1f}°")

# %% [markdown]
# ## The figure
#
# (a) the flow at the investigated step, every grain coloured by its
# zero-guess spread at the tightest tolerance, the chosen grain outlined in
# red, the contacts whose status switches between the two solutions in black;
# (b, c) the accelerations of the chosen grain over the zero-guess and the
# warm-start runs, one shade per tolerance (light: loose, dark: the tightest),
# at the same scale, relative to the warm-start mean at the tightest
# tolerance, with the number of runs at each converged point; (d) the spread
# of the chosen grain and the median spread of the visible grains against the
# tolerance.

# %%
fig = plt.figure(figsize=(12, 9), layout="constrained")
gs = fig.add_gridspec(2, 3, height_ratios=[1.0, 1.0])
ax = fig.add_subplot(gs[0, :])
px, py, rad = traj.pos_x.values, traj.pos_y.values, traj.radius.values
period = float(traj.attrs["period"])
spread_t = meas.spread.sel(init="zero", tol=tight).values
norm = LogNorm(vmin=1e-4 * g, vmax=max(spread_t.max(), 1e-3 * g))
patches, colors = [], []
for shift in (-period, 0.0, period):
    for j in range(len(px)):
        if -2 * d < px[j] + shift < period + 2 * d:
            patches.append(Circle((px[j] + shift, py[j]), rad[j]))
            colors.append(max(spread_t[j], norm.vmin))
pc = PatchCollection(patches, cmap="viridis", norm=norm, edgecolor="0.3", linewidth=0.2)
pc.set_array(np.array(colors))
ax.add_collection(pc)
for gx, gy, gr in zip(traj.ground_x.values, traj.ground_y.values, traj.ground_radius.values):
    ax.add_patch(Circle((gx, gy), gr, color="0.6"))
ax.add_patch(Circle((px[grain], py[grain]), rad[grain], fill=False, edgecolor="r", lw=2))
if "switched" in meas:
    segs = []
    for c in np.nonzero(meas.switched.values)[0]:
        a_, b_ = int(ens.body_a[c]), int(ens.body_b[c])
        if b_ < traj.sizes["disc"]:
            xb = px[b_] + period * np.rint((px[a_] - px[b_]) / period)
            segs.append([(px[a_], py[a_]), (xb, py[b_])])
    ax.add_collection(LineCollection(segs, colors="k", linewidths=2.5))
ax.set_xlim(-d, period + d)
ax.set_ylim(-d, py.max() + d)
ax.set_aspect("equal")
ax.set_xlabel("x along the ground (m); gravity tilted by %g° from the normal, the flow goes to the right"
              % sc["slope_deg"])
ax.set_title(f"(a) step {k_step}, {float(traj.attrs['investigated_time']) * 1e3:.1f} ms after the release: "
             f"zero-guess spread of each grain at tol {tight:.0e} (colour, m/s$^2$)\n"
             f"grain {grain} outlined in red; black: contacts whose status differs between the two solutions",
             fontsize=9)
ax.set_anchor("C")
fig.colorbar(pc, cax=ax.inset_axes([1.01, 0.0, 0.015, 1.0]))

centre = np.array([float(ens.accel_x.sel(init="warm", tol=tight, disc=grain).mean()),
                   float(ens.accel_y.sel(init="warm", tol=tight, disc=grain).mean())])
allx = ens.accel_x.sel(disc=grain).values - centre[0]
ally = ens.accel_y.sel(disc=grain).values - centre[1]
xlo, xhi, ylo, yhi = allx.min(), allx.max(), ally.min(), ally.max()
span = max(xhi - xlo, yhi - ylo, 1e-3)
cx, cy = 0.5 * (xlo + xhi), 0.5 * (ylo + yhi)
lims = (cx - 0.6 * span, cx + 0.6 * span), (cy - 0.6 * span, cy + 0.6 * span)
shades = {init: plt.get_cmap(cm)(np.linspace(0.3, 1.0, len(tols))) for init, cm in (("zero", "Blues"), ("warm", "Oranges"))}
for j, init in enumerate(ens.init.values):
    a = fig.add_subplot(gs[1, j])
    e = ens.sel(init=init, disc=grain)
    for k, tol in enumerate(tols):
        last = tol == tight
        a.scatter(e.accel_x.sel(tol=tol) - centre[0], e.accel_y.sel(tol=tol) - centre[1], lw=0,
                  s=25 if last else 6, color=shades[init][k], label=f"tol {tol:.0e}", zorder=3 if last else 2)
    if meas.attrs["n_solutions"] >= 2:
        a.plot(meas.solution_accel_x[:2, grain] - centre[0], meas.solution_accel_y[:2, grain] - centre[1],
               "-", color="0.85", lw=0.8, zorder=1)
    for k in range(int(meas.attrs["n_solutions"])):
        n_k = int(meas.solution_count.sel(init=init)[k])
        if n_k:
            a.annotate(f"{n_k} runs", (float(meas.solution_accel_x[k, grain]) - centre[0],
                                       float(meas.solution_accel_y[k, grain]) - centre[1]),
                       xytext=(4, 6), textcoords="offset points", fontsize=8)
    s_ = meas.sel(init=init, tol=tight, disc=grain)
    a.set_xlim(*lims[0])
    a.set_ylim(*lims[1])
    a.set_aspect("equal")
    a.set_xlabel("$a_x - \\bar a_x$ (m/s$^2$)")
    a.set_ylabel("$a_y - \\bar a_y$ (m/s$^2$)")
    a.set_title(f"({'bc'[j]}) grain {grain}, {init} guess: at {tight:.0e} spread {float(s_.spread):.2g} m/s$^2$,\n"
                f"minor/major {float(s_.ratio):.1e}", fontsize=9)
    a.legend(fontsize=6, loc="best", ncol=2)
a = fig.add_subplot(gs[1, 2])
for init, c in zip(ens.init.values, ("C0", "C1")):
    a.loglog(tols, meas.spread.sel(init=init, disc=grain), "o-", color=c, label=f"{init}, grain {grain}")
    if vis.any():
        a.loglog(tols, meas.spread.sel(init=init).where(vis).median("disc"), "s--", color=c, ms=3,
                 label=f"{init}, median of visible grains")
a.axhline(an["floor"] * g, color="k", lw=0.6, ls=":", label="floor")
a.invert_xaxis()
a.set_xlabel("NLGS tolerance (relative natural-map residual)")
a.set_ylabel("spread (m/s$^2$)")
a.set_title(f"(d) spread against tolerance: {verdict}", fontsize=9)
a.legend(fontsize=7)
save(fig, out, dpi=150)

# %% [markdown]
# ## The census of the step's exact solutions
#
# NLGS end points say which solutions NLGS reaches, not how many the step has.
# `census.nc` gathers exact solutions from the NLGS end points (zero-guess,
# warm-start and random-guess runs), from Lemke's pivoting method on the LCP
# form of the step (size $3\kappa$, several covering vectors) and from
# contact-status patterns that combine the status changes seen between any two
# solutions found (clusters of switching contacts sharing a grain, each taking
# the statuses of one solution or any combination of the statuses seen at its
# contacts), round after round while new solutions appear; each is polished on
# its statuses to a residual of $10^{-12}$, counted by basin (how many runs end
# on it) and restarted from a $10^{-9}$ perturbation to see whether NLGS
# returns to it. The chosen grain's cloud at the tightest tolerance is then
# read through the census: which solutions its runs sit on, and how far from
# them (the iteration error left).

# %%
census = xr.load_dataset(inp.census)
cloud = sa.cloud_against_census(ens, census, grain, "zero")
Markdown(cs.census_text(census) + "\n\n**The chosen grain's cloud, read through the census.** "
         + cs.cloud_text(cloud, grain, tight, an["line_ratio"]))

# %% [markdown]
# ## What we measured, and where the reproduction differs
#
# The text below is written from this run's data when the notebook runs (the paper's
# values: $N = 355$ discs, slope 24°, friction 0.5).

# %%
loose = tols.max()
window = tols[tols <= tight * 10.0 ** an["decades"]]
zs = [float(sel.spread.sel(init="zero", tol=t)) for t in window]
ws = {t: float(sel.spread.sel(init="warm", tol=t)) for t in tols}
et = ens.sel(tol=tight)
conv_t = {init: int(et.sel(init=init).converged.sum()) for init in ens.init.values}
n_runs = {init: et.sel(init=init).sizes["run"] for init in ens.init.values}
sw_med = {init: et.sel(init=init).sweeps.median().item() for init in ens.init.values}
sw_max = {init: et.sel(init=init).sweeps.max().item() for init in ens.init.values}
scan_text = ""
if len(scan):
    none = {init: int((traj[f"scan_{init}_converged"].values == 0).sum()) for init in ("zero", "warm")}
    several = {init: traj[f"scan_{init}_solutions"].values > 1 for init in ("zero", "warm")}
    n_scan = len(traj["scan_zero_solutions"])
    scan_text = (f" In the scan of the flow ({n_scan} steps, {cfg['scan']['runs']} runs each), no zero-guess run "
                 f"converged at {none['zero']} steps and no warm run at {none['warm']}; several solutions appear at "
                 f"{int(several['zero'].sum())} steps from the zero guess and at {int(several['warm'].sum())} from "
                 f"the warm start ({int((several['zero'] | several['warm']).sum())} of {n_scan} in one ensemble or "
                 "the other)" + (": the warm start is not always determinate, and which solution the time stepping "
                                 "follows is decided by the initial guess *and* the review order." if several["warm"].any()
                                 else "; the warm start reached one solution at every scanned step."))
sol_text = ", ".join(f"{init}: {counts.sel(init=init).values[counts.sel(init=init).values > 0].tolist()} runs"
                     for init in meas.init.values)
vis_text = (f"{int(vis.sum())} grains ({float(vis.mean()):.0%}) have a visible zero-guess dispersion, with "
            f"minor/major ratios up to {ratios.max():.1e}" if vis.any() else "no grain has a visible dispersion")
switch_text = ""
if "switched" in meas and len(sw):
    from collections import Counter
    moves = Counter(f"{status_names[int(st[runs[0], c])]} → {status_names[int(st[runs[1], c])]}" for c in sw)
    near_med = [(lo, hi, np.median(dmag[(dist >= lo) & (dist <= hi)])) for lo, hi in bins
                if lo >= 0 and ((dist >= lo) & (dist <= hi)).any()]
    switch_text = (
        f"The two most frequent solutions differ in the status of {len(sw)} of {ens.sizes['contact']} contacts ("
        + ", ".join(f"{n} {m}" for m, n in moves.items()) + "). The difference spreads through the network of "
        f"contacts that stick in both (it joins {int(meas.cluster_size.max())} of {len(dmag)} grains; not a rigid "
        f"motion: relative residual of the best rigid fit {np.median(rigid_res[big]):.2f}) and its median size "
        "goes " + ", ".join(f"{m:.2g} m/s² at {lo}–{hi}" for lo, hi, m in near_med[:1] + near_med[1:2] + near_med[-1:])
        + " sticking links from a switching contact. This supports Moreau's hint that the non-sliding contacts "
        "are determinant: they are where the choice (stick or slip) is made, and they carry it to the grains around.")
zero_l, warm_l = sel.sel(init="zero", tol=loose), sel.sel(init="warm", tol=loose)
seg_angle = (f" against {np.degrees(np.arctan2(u[1], u[0])):.1f}° for the segment joining the two solutions"
             if meas.attrs["n_solutions"] >= 2 else "")
Markdown(f"""
* **Dispersion against tolerance: {verdict}.** The zero-guess spread of the chosen grain (grain {grain}) lies
  in {min(zs):.3g}–{max(zs):.3g} m/s² ({min(zs) / g:.2g}–{max(zs) / g:.2g} $g$) at every tolerance from
  {window.max():.0e} to {tight:.0e}, while the warm-start spread goes from {ws[sorted(tols)[-2]]:.2g} m/s² at
  {sorted(tols)[-2]:.0e} to {ws[tight]:.2g} m/s² at {tight:.0e} (zero/warm {meas.attrs['verdict_zero_over_warm']:.3g}).
  Converged at {tight:.0e}: {', '.join(f'{i} {conv_t[i]}/{n_runs[i]}' for i in conv_t)}; median sweeps
  {', '.join(f'{i} {sw_med[i]:.0f} (max {sw_max[i]:.0f})' for i in sw_med)}. The flow itself stopped
  {int((traj.converged == 0).sum())} of its {traj.sizes['step']} steps at its {fl['solver']['max_sweeps']}-sweep
  budget (tolerance {fl['solver']['tol']:g}).{scan_text}
* **NLGS end points and the census.** At {tight:.0e} the converged runs reach {meas.attrs['n_solutions']}
  distinct solution(s) ({sol_text}); {vis_text}. The step has {census.sizes['solution']} distinct exact
  solutions in the census (NLGS reaches {int((census.n_zero + census.n_warm + census.n_random > 0).sum())} of
  them). {cs.cloud_text(cloud, grain, tight, an['line_ratio'])}
* **Loose tolerances.** At {loose:.0e} the chosen grain's major axes lie at {float(zero_l.angle):.0f}° (zero
  guess) and {float(warm_l.angle):.0f}° (warm start){seg_angle}; minor/major {float(zero_l.ratio):.2g} and
  {float(warm_l.ratio):.2g}; spreads {float(zero_l.spread):.2g} and {float(warm_l.spread):.2g} m/s²; visible
  dispersion in {float(meas.visible_fraction.sel(init='zero', tol=loose)):.0%} and
  {float(meas.visible_fraction.sel(init='warm', tol=loose)):.0%} of the grains.
* **Where the alternative is decided.** {switch_text or 'No pair of solutions to compare at this step.'}
* **Differences from the paper.** The size distribution (ratio {sc['size_ratio']}), the layer
  ({sc['width_diameters']} d wide), the rough ground, the deposit, the time step and the investigated step
  ({float(traj.attrs['investigated_time']) * 1e3:.0f} ms after the release, mean velocity
  {float(traj.mean_vx[k_step - 1]):.2g} m/s, accelerating at {slope_fit:.2g} m/s²) are ours; the paper gives none of
  them. Its figure shows a line of many points; at {tight:.0e} our zero-guess runs sit on
  {len(cloud['visited'])} exact solution(s) of the census, within {cloud['max_offset'] / g:.1e} $g$, and spread
  along a filled cloud only when stopped at a loose tolerance ({float(zero_l.spread) / g:.2g} $g$ at {loose:.0e}):
  at this step, points between the solutions are runs stopped before convergence. One step is one sample; the
  scan above and `fig5_governing` (flows across parameters) count the steps with several solutions.
""")
