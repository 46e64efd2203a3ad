"""Figure 2's page: the figure, the sentences of what was measured and the short tables,
from ``fig2_slope/trajectory.nc``, ``ensemble.nc``, ``measures.nc`` (and the census text
of :mod:`ncd.figures.fig2_slope.census`).

A grain's *spread* is the RMS distance of its accelerations to their mean over the runs
(:func:`ncd.shared.slope_analysis.cloud_stats`); sentences say which runs they count
(converged ones, at which tolerance) and which steps they leave out.
"""
from collections import Counter

import numpy as np

STATUS = {0: "no contact", 1: "stick", 2: "slide+", 3: "slide-", 4: "fallback"}


def _fit_acceleration(traj, k_step, half=10):
    """Mean acceleration down the slope at the investigated step: a linear fit of the mean
    velocity over ``±half`` steps, and the kinetic energy's growth over the ``half`` before."""
    i = k_step - 1
    lo, hi = max(0, i - half), i + half + 1
    slope = np.polyfit(traj.time.values[lo:hi], traj.mean_vx.values[lo:hi], 1)[0]
    growth = float(traj.kinetic_energy[i] / traj.kinetic_energy[max(0, i - half)])
    return float(slope), growth


def flow_sentence(traj, cfg):
    """The scene, the deposit, the flow and the state at the investigated step."""
    sc, fl = cfg["scene"], cfg["flow"]
    d = sc["diameter"]
    k = int(traj.attrs["investigated_step"])
    acc, growth = _fit_acceleration(traj, k)
    return (
        f"{traj.sizes['disc']} discs (diameters uniform in a ratio {sc['size_ratio']}, mean $d$ = {d} m) on "
        f"{traj.sizes['ground']} glued ground discs, period {float(traj.attrs['period']):.3g} m; slope "
        f"{sc['slope_deg']}°, μ = {sc['mu']}, e = {sc['restitution']}.  The deposit took "
        f"{traj.sizes['deposit_step']} steps (largest interpenetration "
        f"{float(traj.deposit_max_penetration.max()) / d:.2%} of $d$); the flow took {traj.sizes['step']} steps of "
        f"$h$ = {float(traj.attrs['h']):g} s with warm starts, of which {int((traj.converged == 0).sum())} stopped "
        f"at the {fl['solver']['max_sweeps']}-sweep budget before the tolerance {fl['solver']['tol']:g} (largest "
        f"interpenetration {float(traj.max_penetration.max()) / d:.2%} of $d$).  At the investigated step "
        f"{k}, {float(traj.attrs['investigated_time']) * 1e3:.1f} ms after the release, {int(traj.n_contacts[k - 1])} "
        f"contacts are active, the mean velocity is {float(traj.mean_vx[k - 1]):.3f} m/s down the slope and grows "
        f"at {acc:.3f} m/s² (fit over ±10 steps), the kinetic energy by ×{growth:.2f} over the 10 steps before: "
        + ("a phase of overall acceleration, as in the paper." if acc > 0 and growth > 1
           else "**not** a phase of overall acceleration, unlike the paper's."))


def tolerance_table(ens, meas):
    """Per guess and tolerance: runs converged, sweeps, residual, the chosen grain's spread."""
    import pandas as pd

    grain = int(meas.attrs["grain"])
    rows = []
    for init in ens.init.values:
        for tol in ens.tol.values:
            e = ens.sel(init=init, tol=tol)
            rows.append({"guess": str(init), "tolerance": f"{tol:.0e}",
                         "converged": f"{int(e.converged.sum())} / {e.sizes['run']}",
                         "sweeps (median, max)": f"{int(e.sweeps.median())}, {int(e.sweeps.max())}",
                         "largest residual": f"{float(e.residual.max()):.1e}",
                         f"spread of grain {grain} (m/s²)": f"{float(meas.spread.sel(init=init, tol=tol, disc=grain)):.2g}",
                         "minor / major": f"{float(meas.ratio.sel(init=init, tol=tol, disc=grain)):.1e}"})
    return pd.DataFrame(rows)


def spread_sentence(ens, meas, cfg):
    """The chosen grain's spread against the tolerance, zero guess against warm start."""
    an = cfg["analysis"]
    g = float(meas.attrs["g"])
    grain = int(meas.attrs["grain"])
    tols = np.sort(ens.tol.values)[::-1]
    tight = tols[-1]
    window = tols[tols <= tight * 10.0 ** an["decades"]]
    sel = meas.sel(disc=grain)
    zs = [float(sel.spread.sel(init="zero", tol=t)) for t in window]
    ws = [float(sel.spread.sel(init="warm", tol=t)) for t in tols]
    conv = {str(i): int(ens.sel(init=i, tol=tight).converged.sum()) for i in ens.init.values}
    return (
        f"The grain of largest zero-guess spread at the tightest tolerance is grain {grain}.  Its zero-guess "
        f"spread (RMS distance of its acceleration to the mean over the runs) stays within {min(zs):.3g}–"
        f"{max(zs):.3g} m/s² ({min(zs) / g:.2g}–{max(zs) / g:.2g} $g$) from tolerance {window.max():.0e} to "
        f"{tight:.0e}; its warm-start spread goes from {ws[0]:.2g} m/s² at {tols[0]:.0e} to {ws[-1]:.2g} m/s² "
        f"at {tight:.0e} (zero / warm = {float(meas.attrs['verdict_zero_over_warm']):.3g}).  Verdict of the "
        f"rule below: **{meas.attrs['verdict']}**.  Spreads count the converged runs at each tolerance (at "
        f"{tight:.0e}: " + ", ".join(f"{i} {c} of {ens.sizes['run']}" for i, c in conv.items()) + ").")


def solutions_sentence(meas, cfg):
    """Distinct solutions at the tightest tolerance, and how many grains show a dispersion."""
    an = cfg["analysis"]
    g = float(meas.attrs["g"])
    tight = float(meas.tol.min())
    counts = meas.solution_count
    per_init = "; ".join(f"{i}: " + ", ".join(str(int(c)) for c in counts.sel(init=i).values if c > 0) + " runs"
                         for i in meas.init.values)
    vis = (meas.spread.sel(init="zero", tol=tight) > an["visible"] * g).values
    ratios = meas.ratio.sel(init="zero", tol=tight).values[vis]
    grains = (f"{int(vis.sum())} of {len(vis)} grains ({vis.mean():.0%}) have a zero-guess spread above "
              f"{an['visible']:g} $g$, with minor/major ratios of their clouds from {ratios.min():.1e} to "
              f"{ratios.max():.1e} (median {np.median(ratios):.1e})" if vis.any()
              else f"no grain has a zero-guess spread above {an['visible']:g} $g$")
    return (f"At {tight:.0e} the runs of both guesses reach {int(meas.attrs['n_solutions'])} distinct "
            f"solution(s) (whole acceleration fields agreeing within {an['solution_threshold']:g} $g$): "
            f"{per_init}.  {grains}.")


def switch_bins(meas):
    """Grains grouped by the number of sticking links to the nearest switching contact
    (−1: not linked): ``[(label, mask of grains, median |a₁ − a₀| in m/s²)]``."""
    dist = meas.switch_distance.values
    dmag = np.hypot(meas.delta_x, meas.delta_y).values
    bins = [(-1, -1)] + [(k, k + 2) for k in range(0, int(dist.max()) + 1, 3)]
    out = []
    for lo, hi in bins:
        m = (dist >= lo) & (dist <= hi)
        if m.any():
            out.append(("not linked by sticking contacts" if lo < 0 else f"{lo}–{hi}", m, float(np.median(dmag[m]))))
    return out


def switch_table(meas, cfg):
    """The binned table of :func:`switch_bins`, with the share of grains of visible difference."""
    import pandas as pd

    g = float(meas.attrs["g"])
    dmag = np.hypot(meas.delta_x, meas.delta_y).values
    return pd.DataFrame([{"sticking links to a switching contact": label, "grains": int(m.sum()),
                          "median |a₁ − a₀| (m/s²)": f"{med:.2g}",
                          "visible": f"{np.mean(dmag[m] > cfg['analysis']['visible'] * g):.0%}"}
                         for label, m, med in switch_bins(meas)])


def switch_sentence(meas, ens):
    """Where the two most frequent solutions differ: contacts that switch status, and how the
    difference spreads through the contacts that stick in both."""
    if "switched" not in meas or int(meas.attrs["n_solutions"]) < 2:
        return "The runs reach one solution: there is no pair of solutions to compare at this step."
    labels = meas.solution_label.values.ravel()
    runs = [int(np.nonzero(labels == k)[0][0]) for k in (0, 1)]
    st = ens.status.isel(tol=-1).values.reshape(-1, ens.sizes["contact"]) if "tol" in ens.status.dims \
        else ens.status.values.reshape(-1, ens.sizes["contact"])
    sw = np.nonzero(meas.switched.values)[0]
    moves = Counter(f"{STATUS[int(st[runs[0], c])]} → {STATUS[int(st[runs[1], c])]}" for c in sw)
    dmag = np.hypot(meas.delta_x, meas.delta_y).values
    big = dmag > 1e-3 * float(meas.attrs["g"])
    rigid = (np.hypot(meas.delta_x - meas.rigid_x, meas.delta_y - meas.rigid_y).values
             / np.maximum(dmag, 1e-300))
    near = [b for b in switch_bins(meas) if not b[0].startswith("not")]
    grain = int(meas.attrs["grain"])
    return (
        f"The two most frequent solutions differ in the status of {len(sw)} of {ens.sizes['contact']} contacts ("
        + ", ".join(f"{n} {m}" for m, n in moves.items()) + ").  The difference spreads through the network of "
        f"contacts that stick in both solutions (it joins {int(meas.cluster_size.max())} of {len(dmag)} grains), "
        f"not as a rigid motion of it (relative residual of the best rigid fit: median "
        f"{np.median(rigid[big]) if big.any() else float('nan'):.2f}): the grains roll on each other.  Its median "
        f"size falls from {near[0][2]:.2g} m/s² at {near[0][0]} sticking links from a switching contact to "
        f"{near[-1][2]:.2g} m/s² at {near[-1][0]}.  The chosen grain {grain}: {int(meas.n_stick_both[grain])} of "
        f"its {int(meas.n_contacts[grain])} contacts stick in both solutions, {int(meas.switch_distance[grain])} "
        f"sticking links from a switching contact.")


def scan_table(traj):
    """The scan of the flow: per scanned step, distinct solutions and converged runs per guess."""
    import pandas as pd

    rows = []
    for k, step in enumerate(traj.scan_step.values):
        row = {"step": int(step)}
        for init in ("zero", "warm"):
            n_ok = int(traj[f"scan_{init}_converged"].values[k])
            row[f"{init}: converged runs"] = n_ok
            row[f"{init}: solutions"] = int(traj[f"scan_{init}_solutions"].values[k]) if n_ok else "—"
            row[f"{init}: largest spread (m/s²)"] = (f"{float(traj[f'scan_{init}_max_spread'].values[k]):.2g}"
                                                     if n_ok else "—")
        rows.append(row)
    return pd.DataFrame(rows)


def scan_sentence(traj, cfg):
    """How often a step of the flow has several solutions, and the steps the count leaves out."""
    if "scan_step" not in traj.dims or traj.sizes["scan_step"] == 0:
        return "The flow was not scanned in this run."
    sc = cfg["scan"]
    n = traj.sizes["scan_step"]
    none = {i: int((traj[f"scan_{i}_converged"].values == 0).sum()) for i in ("zero", "warm")}
    some = {i: int((traj[f"scan_{i}_converged"].values < sc["runs"]).sum()) for i in ("zero", "warm")}
    several = {i: traj[f"scan_{i}_solutions"].values > 1 for i in ("zero", "warm")}
    return (
        f"Every {sc['every']} steps of the flow ({n} scanned steps), {sc['runs']} zero-guess and {sc['runs']} warm-start runs "
        f"with random review orders, tolerance {sc['tol']:.0e}, at most {sc['max_sweeps']} sweeps.  Several distinct "
        f"solutions among the converged runs: at {int(several['zero'].sum())} steps from the zero guess and at "
        f"{int(several['warm'].sum())} from the warm start ({int((several['zero'] | several['warm']).sum())} of {n} "
        f"in one or the other).  Left out of these counts: the runs that did not converge — some runs at "
        f"{some['zero']} (zero) and {some['warm']} (warm) steps, every run at {none['zero']} and {none['warm']}."
        + (" The warm start is not always determinate: which solution the time stepping follows depends on the "
           "initial guess and on the review order." if several["warm"].any() else ""))


def differences_sentence(traj, ens, meas, cloud, cfg):
    """What is ours and not the paper's, and what the line of many points is here."""
    sc = cfg["scene"]
    g = float(meas.attrs["g"])
    k = int(traj.attrs["investigated_step"])
    tight, loose = float(ens.tol.min()), float(ens.tol.max())
    grain = int(meas.attrs["grain"])
    acc, _ = _fit_acceleration(traj, k)
    return (
        f"The size distribution (ratio {sc['size_ratio']}), the layer ({sc['width_diameters']} $d$ wide, "
        f"{traj.sizes['disc']} discs), the rough ground, the deposit, the step and the investigated step "
        f"({float(traj.attrs['investigated_time']) * 1e3:.0f} ms after the release, mean velocity "
        f"{float(traj.mean_vx[k - 1]):.2g} m/s, accelerating at {acc:.2g} m/s²) are ours; the paper gives none of "
        f"them.  Its figure shows a line of many points; at {tight:.0e} our zero-guess runs sit on "
        f"{len(cloud['visited'])} exact solution(s) of the census, within {cloud['max_offset'] / g:.1e} $g$, and "
        f"fill the segment between them only when stopped at a loose tolerance (spread "
        f"{float(meas.spread.sel(init='zero', tol=loose, disc=grain)) / g:.2g} $g$ at {loose:.0e}): at this step, "
        f"points between the solutions are runs stopped before convergence.")


def plot(traj, ens, meas, cfg):
    """(a) the flow at the investigated step coloured by each grain's zero-guess spread;
    (b, c) the chosen grain's accelerations over the zero-guess and warm-start runs, one
    shade per tolerance; (d) the spread against the tolerance.  Returns the figure."""
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.colors import LogNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle

    plt.rcParams.update({"font.size": 9.5})
    an, d = cfg["analysis"], cfg["scene"]["diameter"]
    g = float(meas.attrs["g"])
    grain = int(meas.attrs["grain"])
    tols = ens.tol.values
    tight = float(tols.min())
    fig = plt.figure(figsize=(10, 8.2), layout="constrained")
    gs = fig.add_gridspec(2, 3, height_ratios=[1.0, 1.1])

    ax = fig.add_subplot(gs[0, :])
    px, py, rad = traj.pos_x.values, traj.pos_y.values, traj.radius.values
    period = float(traj.attrs["period"])
    spread = meas.spread.sel(init="zero", tol=tight).values
    norm = LogNorm(vmin=1e-4 * g, vmax=max(spread.max(), 1e-3 * g))
    patches, colours = [], []
    for shift in (-period, 0.0, period):
        for j in range(len(px)):
            if -2 * d < px[j] + shift < period + 2 * d:
                patches.append(Circle((px[j] + shift, py[j]), rad[j]))
                colours.append(max(spread[j], norm.vmin))
    pc = PatchCollection(patches, cmap="viridis", norm=norm, edgecolor="0.3", linewidth=0.2)
    pc.set_array(np.array(colours))
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
    ax.set_xlabel("x along the ground (m); the flow goes to the right")
    ax.set_title(f"(a) step {int(traj.attrs['investigated_step'])}: zero-guess spread of each grain at tol "
                 f"{tight:.0e}\ngrain {grain} in red; black: contacts that switch status", fontsize=10)
    ax.set_anchor("C")
    fig.colorbar(pc, cax=ax.inset_axes([1.02, 0.06, 0.02, 0.88]), label="spread (m/s²)")

    wx = float(ens.accel_x.sel(init="warm", tol=tight, disc=grain).mean())
    wy = float(ens.accel_y.sel(init="warm", tol=tight, disc=grain).mean())
    allx = ens.accel_x.sel(disc=grain).values - wx
    ally = ens.accel_y.sel(disc=grain).values - wy
    span = max(np.nanmax(allx) - np.nanmin(allx), np.nanmax(ally) - np.nanmin(ally), 1e-3)
    cx, cy = 0.5 * (np.nanmax(allx) + np.nanmin(allx)), 0.5 * (np.nanmax(ally) + np.nanmin(ally))
    shades = {"zero": plt.get_cmap("Blues")(np.linspace(0.3, 1.0, len(tols))),
              "warm": plt.get_cmap("Oranges")(np.linspace(0.3, 1.0, len(tols)))}
    order = np.argsort(-tols)                         # loose first, the tightest drawn last
    n_sol = int(meas.attrs["n_solutions"])
    for j, init in enumerate(("zero", "warm")):
        a = fig.add_subplot(gs[1, j])
        e = ens.sel(init=init, disc=grain)
        for rank, k in enumerate(order):
            last = tols[k] == tight
            a.scatter(e.accel_x.isel(tol=k) - wx, e.accel_y.isel(tol=k) - wy, lw=0, s=25 if last else 6,
                      color=shades[init][rank], zorder=3 if last else 2)
        if n_sol >= 2:
            a.plot(meas.solution_accel_x[:2, grain] - wx, meas.solution_accel_y[:2, grain] - wy, "-", color="0.8",
                   lw=0.8, zorder=1)
        for s in range(n_sol):
            n_k = int(meas.solution_count.sel(init=init)[s])
            if n_k:
                a.annotate(f"{n_k} runs", (float(meas.solution_accel_x[s, grain]) - wx,
                                           float(meas.solution_accel_y[s, grain]) - wy),
                           xytext=(5, 5), textcoords="offset points", fontsize=9.5, zorder=4)
        a.set_xlim(cx - 0.6 * span, cx + 0.6 * span)
        a.set_ylim(cy - 0.6 * span, cy + 0.6 * span)
        a.set_aspect("equal")
        a.set_xlabel("$a_x - \\bar a_x$ (m/s²)")
        a.set_ylabel("$a_y - \\bar a_y$ (m/s²)")
        a.set_title(f"({'bc'[j]}) grain {grain}, {init} guess", fontsize=10)

    a = fig.add_subplot(gs[1, 2])
    vis = meas.spread.sel(init="zero", tol=tight) > an["visible"] * g
    for init, c in (("zero", "C0"), ("warm", "C1")):
        a.loglog(tols, meas.spread.sel(init=init, disc=grain), "o-", color=c)
        if vis.any():
            a.loglog(tols, meas.spread.sel(init=init).where(vis).median("disc"), "s--", color=c, ms=3)
    a.axhline(an["floor"] * g, color="k", lw=0.6, ls=":")
    a.invert_xaxis()
    a.set_xlabel("NLGS tolerance")
    a.set_ylabel("spread (m/s²)")
    a.set_title(f"(d) spread against tolerance:\n{meas.attrs['verdict']}", fontsize=10)
    handles = [Line2D([], [], color="C0", marker="o", label="zero guess"),
               Line2D([], [], color="C1", marker="o", label="warm start"),
               Line2D([], [], color="0.4", marker="o", label=f"(d) grain {grain}"),
               Line2D([], [], color="0.4", ls="--", marker="s", ms=3, label="(d) median of visible grains"),
               Line2D([], [], color="k", ls=":", label="(d) floor of the verdict rule"),
               Line2D([], [], ls="", marker="o", color="0.75", label=f"(b, c) light: tol {tols.max():.0e}"),
               Line2D([], [], ls="", marker="o", color="0.1", label=f"(b, c) dark: tol {tight:.0e}")]
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=9, frameon=False)
    return fig


def caption(ens, meas):
    """The Snakemake report's caption (reStructuredText): the figure's finding, from the data."""
    grain = int(meas.attrs["grain"])
    tols = np.sort(ens.tol.values)
    tight, loose = tols[0], tols[-1]
    sp = meas.spread.sel(disc=grain)
    return (f"**Figure 2 (section 3): dispersion of a grain's acceleration in a flow down a slope.** At the "
            f"investigated step the runs (both guesses) reach {int(meas.attrs['n_solutions'])} distinct solution(s); the "
            f"RMS spread of grain {grain}'s acceleration is {float(sp.sel(init='zero', tol=loose)):.2g} m/s2 at "
            f"tolerance {loose:.0e} and {float(sp.sel(init='zero', tol=tight)):.2g} m/s2 at {tight:.0e} from the "
            f"zero guess, {float(sp.sel(init='warm', tol=tight)):.2g} m/s2 from the warm start: "
            f"{meas.attrs['verdict']}. Details: ``results/html/fig2_slope.html``.\n")
