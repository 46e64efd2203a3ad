"""Plots and prose numbers of fig4_history: ground stress, dip, arching.

The figure is drawn for the page's width (11 in, fonts of at least 9 pt, one legend for
both histories below the panels, pile names beside the piles rather than over them);
:func:`summary` gives the numbers of the page's sentences, :func:`outside_band` the dips
lying outside their own bootstrap band (the page says why).
"""
import matplotlib.pyplot as plt
import numpy as np

from ncd.figures.fig4_history.analysis import CERTIFIED_TEXT, exact_summary

COLORS = {"point": "C3", "rain": "C0"}
LABELS = {"point": "point source", "rain": "rain"}


def plot_piles(ax, piles):
    """Final states of one pile per history (grains as discs, offset vertically)."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    d = piles[0].attrs["mean_diameter"]
    off, ticks = 0.0, []
    for ds in piles:
        h = ds.attrs["history"]
        circles = [Circle((x / d, (y + off) / d), r / d) for x, y, r in zip(ds.x.values, ds.y.values,
                                                                           ds.radius.values)]
        ax.add_collection(PatchCollection(circles, facecolor=COLORS[h], edgecolor="none", alpha=0.8))
        ticks.append(((off + 0.5 * ds.y.max().item()) / d, f"{LABELS[h]}\n(pile {ds.attrs['member']})"))
        off += (ds.y.max().item() + 3 * d)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x / d")
    ax.set_yticks([t for t, _ in ticks], [lab for _, lab in ticks], fontsize=9)   # beside the piles
    ax.tick_params(axis="y", length=0)


def plot_stress(ax, an, kernel=None):
    """Mean ground stress against x / L with its bootstrap band over piles, per history."""
    k = an.kernel.values[0] if kernel is None else kernel
    for h in an.history.values:
        s = an.sel(history=h, kernel=k)
        ax.fill_between(an.xi, s.profile_lo, s.profile_hi, color=COLORS[h], alpha=0.25, lw=0)
        ax.plot(an.xi, s.profile_mean, color=COLORS[h])
    ax.axhline(1.0, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("x / L")
    ax.set_ylabel("ground stress / (W / 2L)")
    ax.set_title(f"(b) mean ground stress, kernel {k:g} d", fontsize=10, loc="left")


def plot_dips(ax, an):
    """Dip depth per history and kernel width: piles (dots), mean profile with band (bar)."""
    ks = an.kernel.values
    for i, h in enumerate(an.history.values):
        s = an.sel(history=h)
        for j, k in enumerate(ks):
            x = j + (i - 0.5) * 0.3
            dj = s.dip.sel(kernel=k).values
            ax.plot(np.full(len(dj), x) + 0.04 * np.linspace(-1, 1, len(dj)), dj, ".", color=COLORS[h], ms=3,
                    alpha=0.5)
            lo, hi = float(s.dip_lo.sel(kernel=k)), float(s.dip_hi.sel(kernel=k))
            m = float(s.dip_mean.sel(kernel=k))
            # a bar from lo to hi, not an error bar: the dip of the mean profile (a min/max of
            # a mean) can lie outside its percentile bootstrap band (biased upwards by noise)
            ax.vlines(x, lo, hi, color=COLORS[h], lw=1.2)
            ax.plot(x, m, "o", color=COLORS[h])
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xticks(range(len(ks)), [f"{k:g} d\np = {float(an.dip_diff_p.sel(kernel=k)):.2g}" for k in ks])
    ax.set_xlabel("kernel width (p: point vs rain)")
    ax.set_ylabel("dip depth M − m (units of W / 2L)")
    ax.set_title("(c) dip depth (> 0 a dip, < 0 a hump)", fontsize=10, loc="left")


def plot_arching(ax, an):
    """Median over piles of the cut resultant's deviation from the free-surface slope,
    band: 25-75 % of the piles (shaded) and bootstrap band of the median (bars); thin
    vertical lines: the exact range over A ∩ C of single piles (where computed)."""
    q = an.cut_position.values
    step = np.min(np.diff(q)) if len(q) > 1 else 0.1
    for i, h in enumerate(an.history.values):
        if "exact_computed" in an:
            done = np.nonzero(an.exact_computed.sel(history=h).values)[0]
            for j, m in enumerate(done):
                for f, sign in (("left", -1), ("right", 1)):
                    s = an.sel(history=h, pile=m, flank=f)
                    x = sign * q + (i - 0.5) * 0.35 * step + 0.3 * step * (j + 0.5) / max(len(done), 1) * sign
                    ax.vlines(x, s.exact_deviation_min, s.exact_deviation_max, color=COLORS[h], lw=0.6, alpha=0.6)
        for f, sign in (("left", -1), ("right", 1)):
            s = an.sel(history=h, flank=f)
            x = sign * q
            ax.fill_between(x, s.deviation_q25, s.deviation_q75, color=COLORS[h], alpha=0.15, lw=0)
            ax.vlines(x, s.deviation_median_lo, s.deviation_median_hi, color=COLORS[h], lw=1.0)
            ax.plot(x, s.deviation_median, "o-", ms=3, color=COLORS[h])
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xlabel("cut position x / L")
    ax.set_ylabel("resultant angle − flank slope (°)")
    ax.set_title("(d) arching across vertical cuts", fontsize=10, loc="left")


def figure(an, piles):
    """(a) one pile per history, (b) mean ground stress, (c) dip depths, (d) arching; one
    legend for the histories and the kinds of marks, below the panels."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    with plt.rc_context({"font.size": 9.5}):
        fig = plt.figure(figsize=(11, 8.4), layout="constrained")
        gs = fig.add_gridspec(2, 3, height_ratios=[1, 1.25])
        ax = fig.add_subplot(gs[0, :])
        plot_piles(ax, piles)
        ax.set_title("(a) the final piles, one per history (the same grains)", fontsize=10, loc="left")
        plot_stress(fig.add_subplot(gs[1, 0]), an)
        plot_dips(fig.add_subplot(gs[1, 1]), an)
        plot_arching(fig.add_subplot(gs[1, 2]), an)
        n, level = an.sizes["pile"], int(100 * an.attrs["level"])
        handles = [Line2D([], [], color=COLORS[h], marker="o", ms=4, label=f"{LABELS[h]} ({n} piles)")
                   for h in an.history.values]
        handles += [Patch(color="0.6", alpha=0.35, label=f"(b) {level} % bootstrap band over piles"),
                    Line2D([], [], color="0.3", ls="none", marker=".", label="(c) one pile"),
                    Line2D([], [], color="0.3", marker="o", lw=1.2, label="(c) mean profile, bar: its band"),
                    Line2D([], [], color="0.3", lw=0.6, label="(d) exact range over A ∩ C, one pile")]
        fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    return fig


def outside_band(an):
    """(history, kernel, dip, lo, hi) of every mean-profile dip outside its own basic
    bootstrap band: the band subtracts the upward bias of the resampled dips (a minimum
    against maxima of noisy profiles), which can exceed the band's half-width."""
    out = []
    for h in an.history.values:
        for k in an.kernel.values:
            s = an.sel(history=h, kernel=k)
            m, lo, hi = float(s.dip_mean), float(s.dip_lo), float(s.dip_hi)
            if not lo <= m <= hi:
                out.append((str(h), float(k), m, lo, hi))
    return out


def summary(an):
    """Numbers for the notebook prose, computed from analysis_n<n>.nc."""
    k0 = an.kernel.values[0]
    out = {"kernel": float(k0), "piles": an.sizes["pile"]}
    for h in an.history.values:
        s = an.sel(history=h, kernel=k0)
        out[h] = dict(dip=float(s.dip_mean), lo=float(s.dip_lo), hi=float(s.dip_hi),
                      dips_by_kernel={float(k): float(an.dip_mean.sel(history=h, kernel=k)) for k in an.kernel.values},
                      frac_dip=float((an.dip.sel(history=h, kernel=k0) > 0).mean()),
                      frac_by_kernel={float(k): float((an.dip.sel(history=h, kernel=k) > 0).mean())
                                      for k in an.kernel.values},
                      center=float(s.profile_mean.sel(xi=0.0, method="nearest")),
                      L=float(an.base_half_width.sel(history=h).mean() / an.attrs["mean_diameter"]),
                      fitL=float(an.fit_half_width.sel(history=h).mean() / an.attrs["mean_diameter"]),
                      slope=float(an.surface_angle.sel(history=h).mean()),
                      apex=float(an.apex_height.sel(history=h).mean()),
                      cone=float(an.cone_ratio.sel(history=h).mean()),
                      dev_median=float(an.cut_deviation.sel(history=h).median()),
                      dev_iqr=float(an.cut_deviation.sel(history=h).quantile(0.75)
                                    - an.cut_deviation.sel(history=h).quantile(0.25)),
                      arching=float((an.cut_deviation.sel(history=h) > 0).sum()
                                    / np.isfinite(an.cut_deviation.sel(history=h)).sum()),
                      empty_cuts=int(np.isnan(an.cut_deviation.sel(history=h)).sum()),
                      cuts=int(an.cut_deviation.sel(history=h).size))
    for h in an.history.values:
        out[h].update(grains=float(an.n_grains.sel(history=h).mean()),
                      grains_min=int(an.n_grains.sel(history=h).min()), grains_max=int(an.n_grains.sel(history=h).max()),
                      removed=float(an.n_removed.sel(history=h).mean()))
        out[h].update(exact_summary(an, h) or {})
    out["diff"] = float(an.dip_diff.sel(kernel=k0))
    out["diff_lo"], out["diff_hi"] = float(an.dip_diff_lo.sel(kernel=k0)), float(an.dip_diff_hi.sel(kernel=k0))
    out["p"] = {float(k): float(an.dip_diff_p.sel(kernel=k)) for k in an.kernel.values}
    return out


def outside_text(an):
    """One sentence on the dips of :func:`outside_band` (empty when every dip lies in its band)."""
    out = outside_band(an)
    if not out:
        return ""
    cases = "; ".join(f"{LABELS[h]}, kernel {k:g} d: {m:.3f} against [{lo:.3f}, {hi:.3f}]" for h, k, m, lo, hi in out)
    return (f"A dip of a mean profile lies outside its own band ({cases}): the basic bootstrap band is "
            "2 × dip − the percentiles of the resampled dips, which removes their upward bias (a minimum against "
            "maxima of noisy profiles; largest for the narrowest kernel); where the bias exceeds the band's "
            "half-width the band, the bias-corrected statement, lies below the raw dip.")


def finding(an):
    """The figure's finding in a few sentences (the Snakemake report's caption includes it)."""
    s = summary(an)
    P, R = s["point"], s["rain"]
    return (f"Dip depth M − m of the mean ground-stress profile over {s['piles']} piles per history (units of the "
            f"mean stress W/2L, > 0 a dip, kernel {s['kernel']:g} d): point source {P['dip']:.3f} "
            f"[{P['lo']:.3f}, {P['hi']:.3f}], rain {R['dip']:.3f} [{R['lo']:.3f}, {R['hi']:.3f}] (95 % bootstrap "
            f"bands over piles; difference p = {s['p'][s['kernel']]:.2g}). The cut resultant is steeper than the "
            f"flank at {100 * P['arching']:.0f} % (point source) and {100 * R['arching']:.0f} % (rain) of the cuts.")


# ------------------------------------------------------------------------------ the sentences


def shapes_text(an, cfg):
    """The shapes of the piles of both histories (the rain's deposits against the heaps)."""
    s = summary(an)
    P, R = s["point"], s["rain"]
    return f"""**Shapes.** The point-source piles have a base half-width $L$ of {P['L']:.1f} mean diameters,
an apex {P['apex']:.1f} d above the ground and flanks at {P['slope']:.1f}° on average
(apex / ($L$ tan flank) = {P['cone']:.2f}: 1 for a cone). The rain falls over $|x| \\le L$ onto
the finite base $|x| \\le L$; {R['removed']:.1f} of the {P['grains']:.0f} poured grains roll off
its edges on average, so the rained piles hold {R['grains_min']} to {R['grains_max']} grains
(the point-source piles {P['grains_min']} to {P['grains_max']}; the stresses are normalised by
each pile's own weight). The rained deposits are {R['apex']:.1f} d high with fitted flanks of
{R['slope']:.1f}° (apex / ($L$ tan flank) = {R['cone']:.2f}):
{'a flat layer over the base with steep edges, not a heap with flanks at the angle of repose' if R['slope'] < 0.5 * P['slope'] else 'heaps'}.
The grains are rained gently (perfectly inelastic impacts, drop height
{cfg['source']['drop_height_d']:g} d); the experiments' rain falls from higher, with bouncing
grains. Much faster impacts need a smaller time step here (the grains then overlap by more
than the overlap tolerance within one step); why the gentle rain builds a layer rather than
a heap was not studied.
Both histories are drawn against $x / L$ with the $L$ of the member's point-source pile."""


def stress_text(an):
    """The dip depth of the mean profiles with their bands, per kernel, and the dips outside their band."""
    s = summary(an)
    P, R, k = s["point"], s["rain"], s["kernel"]
    return f"""**Ground stress ({s['piles']} piles per history, kernel {k:g} d).** Dip depth $M - m$ of the
mean profile, in units of the mean stress $W / 2L$ (> 0 a dip): point source {P['dip']:.3f} (95 % basic bootstrap band over piles {P['lo']:.3f} to {P['hi']:.3f}),
rain {R['dip']:.3f} ({R['lo']:.3f} to {R['hi']:.3f}); {100 * P['frac_dip']:.0f} % of the
point-source piles and {100 * R['frac_dip']:.0f} % of the rained piles have a dip of
their own. The difference point − rain is {s['diff']:.3f} (band {s['diff_lo']:.3f} to
{s['diff_hi']:.3f}; permutation p = {s['p'][k]:.3g}). With the other kernel widths the
dips of the mean profiles are
{', '.join(f"{kk:g} d: {P['dips_by_kernel'][kk]:.3f} / {R['dips_by_kernel'][kk]:.3f}" for kk in P['dips_by_kernel'])}
(point / rain), p = {', '.join(f"{s['p'][kk]:.3g}" for kk in s['p'])}.
A single pile's dip is a minimum of a noisy curve against maxima of the same curve, so it
is biased upwards when the kernel is narrow: the fraction of piles with a dip of their own is
{', '.join(f"{kk:g} d: {100 * P['frac_by_kernel'][kk]:.0f} % / {100 * R['frac_by_kernel'][kk]:.0f} %" for kk in P['frac_by_kernel'])}
(point / rain); only the mean profile over piles, with its band, carries a claim.
{outside_text(an)}
Under the apex the mean stress is {P['center']:.2f} (point) and {R['center']:.2f} (rain)
times the mean stress W / 2L."""


def experiments_text(an):
    """The dips against the experiments' dip (point source) and central maximum (rain)."""
    s = summary(an)
    P, R = s["point"], s["rain"]
    return f"""**Against the experiments.** Vanel et al. (1999) and Geng et al. (2001) report a dip
under point-source piles and a central maximum under rained piles. Here the
point-source dip is {'resolved (its band excludes 0)' if P['lo'] > 0 else 'not resolved (its band includes 0 or is negative)'},
and the rained deposit has {'a hump (negative dip, band below 0)' if R['hi'] < 0 else ('a resolved dip (band above 0), the opposite of the central maximum of the experiments' if R['lo'] > 0 else 'neither a resolved hump nor a resolved dip (band includes 0)')}."""


def arching_text(an):
    """The cut resultant against the flank slope over all cuts and piles."""
    s = summary(an)
    P, R = s["point"], s["rain"]
    return f"""**Arching.** Over all cuts and piles the resultant is on median {P['dev_median']:.1f}° (point)
and {R['dev_median']:.1f}° (rain) steeper than the flank (interquartile range
{P['dev_iqr']:.1f}° and {R['dev_iqr']:.1f}°); it is steeper than the free surface at
{100 * P['arching']:.0f} % and {100 * R['arching']:.0f} % of the cuts that cross a contact
({P['empty_cuts']} of {P['cuts']} point-source cuts and {R['empty_cuts']} of {R['cuts']} rain cuts,
near the toes, cross none and have no resultant direction). (Arching here means a
resultant steeper than the flank; the exact test of `fig4_pile` uses a weaker one, a
resultant that pushes the bank downward, $F_y < 0$.)"""


def exact_text(an):
    """The exact ranges over A ∩ C of the cut resultant's angle for the first piles of each history."""
    s = summary(an)
    parts = []
    for h in an.history.values:
        x = s[h]
        if "exact_piles" not in x:
            parts.append(f"{LABELS[h]}: no exact ranges computed.")
            continue
        parts.append(f"{LABELS[h]}, {x['exact_piles']} piles: the admissible angle at a cut spans "
                     f"{x['exact_width_median']:.1f}° on median (at most {x['exact_width_max']:.1f}°); every "
                     f"admissible state is steeper than the flank at {100 * x['exact_all_positive']:.0f} % of the cuts "
                     f"and every one shallower at {100 * x['exact_all_negative']:.0f} %; at "
                     f"{100 * x['exact_undefined']:.0f} % the admissible resultants surround zero (no angle range); the "
                     f"ranges are exact (a linear-fractional program per end, each certified to {CERTIFIED_TEXT}° at "
                     f"{100 * x['exact_confirmed']:.0f} % of the cuts).")
    return (" ".join(parts) + " The arching angle of one force state is thus one choice among many: the spread of "
            "the history angles over piles is to be read against these ranges.")
