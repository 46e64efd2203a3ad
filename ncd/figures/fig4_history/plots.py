"""Plots and prose numbers of fig4_history: shape match, ground stress, dip, arching.

The figure is drawn for the page's width (11 in, fonts of at least 9 pt, one legend for
every history below the panels, pile names beside the piles rather than over them);
:func:`summary` gives the numbers of the page's sentences, :func:`outside_band` the dips
lying outside their own bootstrap band (the page says why).  The page states the shape
match first (:func:`shapes_text`), then the differences at that shape and the test's
controls (:func:`comparison_text`).
"""
import matplotlib.pyplot as plt
import numpy as np

from ncd.figures.fig4_history.analysis import CERTIFIED_TEXT, comparison_summary, control_outcomes, exact_summary
from ncd.figures.fig4_history.compare import SHAPES

COLORS = {"point": "C3", "rain": "C0", "layer": "C2"}
LABELS = {"point": "point source", "rain": "rain", "layer": "layer"}
SHAPE_LABELS = {"flank_slope": "flank slope", "apex_height": "apex height", "base_half_width": "base half-width"}
COMPARISON_LABELS = {"rain": "rain − point", "same": "odd − even point piles", "layer": "layer − point"}
CONTROL_PAGE_WORDS = {"same": "two halves of the point-source piles (even against odd members: one history, "
                              "different seeds)",
                      "layer": "the layer against the point-source heap (a difference known to exist)"}


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
    ax.set_title(f"(c) mean ground stress, kernel {k:g} d", fontsize=10, loc="left")


def plot_dips(ax, an):
    """Dip depth per history and kernel width: piles (dots), mean profile with band (bar)."""
    ks = an.kernel.values
    for i, h in enumerate(an.history.values):
        s = an.sel(history=h)
        for j, k in enumerate(ks):
            x = j + (i - 0.5 * (an.sizes["history"] - 1)) * 0.25
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
    if "comparison" in an.dims and "rain" in an.comparison.values:
        ax.set_xticks(range(len(ks)), [f"{k:g} d\np = {float(an.cmp_p_dip.sel(comparison='rain', kernel=k)):.2g}"
                                       for k in ks])
        ax.set_xlabel("kernel width (p: point vs rain)")
    else:
        ax.set_xticks(range(len(ks)), [f"{k:g} d" for k in ks])
        ax.set_xlabel("kernel width")
    ax.set_ylabel("dip depth M − m (units of W / 2L)")
    ax.set_title("(d) dip depth (> 0 a dip, < 0 a hump)", fontsize=10, loc="left")


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
    ax.set_title("(e) arching across vertical cuts", fontsize=10, loc="left")


def plot_shapes(ax, an):
    """Relative difference of the mean shapes from the point source's, per comparison, with
    its bootstrap band; the shaded strip is the tolerance of the match (the layer, far
    outside it, is written, not drawn)."""
    tol = float(an.attrs.get("shape_tol", 0.05))
    ax.axhspan(-100 * tol, 100 * tol, color="0.85", lw=0)
    names = [c for c in ("rain", "same") if "comparison" in an.dims and c in an.comparison.values]
    for i, c in enumerate(names):
        s = an.sel(comparison=c)
        x = np.arange(len(SHAPES)) + (i - 0.5 * (len(names) - 1)) * 0.25
        y = 100 * s.cmp_shape_rel.values
        err = 100 * np.array([s.cmp_shape_rel.values - s.cmp_shape_rel_lo.values,
                              s.cmp_shape_rel_hi.values - s.cmp_shape_rel.values])
        ax.errorbar(x, y, yerr=np.clip(err, 0, None), fmt="o", ms=4, capsize=2,
                    color=COLORS["rain"] if c == "rain" else "0.4", label=COMPARISON_LABELS[c])
    if "comparison" in an.dims and "layer" in an.comparison.values:
        rel = 100 * an.cmp_shape_rel.sel(comparison="layer").values
        ax.text(0.02, 0.98, "layer − point: " + ", ".join(f"{v:+.0f} %" for v in rel), transform=ax.transAxes,
                va="top", fontsize=9, color=COLORS["layer"])
    ax.axhline(0, color="0.5", lw=0.6)
    ax.set_xticks(range(len(SHAPES)), [SHAPE_LABELS[m].replace(" ", "\n", 1) for m in SHAPES])
    ax.set_ylabel("difference of the mean piles (%)")
    ax.legend(fontsize=9, loc="lower right", frameon=False)
    ax.set_title(f"(b) shape match (strip: ±{100 * tol:g} %)", fontsize=10, loc="left")


def figure(an, piles):
    """(a) one pile per history, (b) the shape match, (c) mean ground stress, (d) dip depths,
    (e) arching; one legend for the histories and the kinds of marks, below the panels."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    with plt.rc_context({"font.size": 9.5}):
        fig = plt.figure(figsize=(11, 9.4), layout="constrained")
        gs = fig.add_gridspec(2, 3, height_ratios=[1.15, 1.25])
        ax = fig.add_subplot(gs[0, :2])
        plot_piles(ax, piles)
        ax.set_title("(a) the final piles, one per history (the same grains)", fontsize=10, loc="left")
        plot_shapes(fig.add_subplot(gs[0, 2]), an)
        plot_stress(fig.add_subplot(gs[1, 0]), an)
        plot_dips(fig.add_subplot(gs[1, 1]), an)
        plot_arching(fig.add_subplot(gs[1, 2]), an)
        n, level = an.sizes["pile"], int(100 * an.attrs["level"])
        handles = [Line2D([], [], color=COLORS[h], marker="o", ms=4, label=f"{LABELS[h]} ({n} piles)")
                   for h in an.history.values]
        handles += [Patch(color="0.6", alpha=0.35, label=f"(c) {level} % bootstrap band over piles"),
                    Line2D([], [], color="0.3", ls="none", marker=".", label="(d) one pile"),
                    Line2D([], [], color="0.3", marker="o", lw=1.2, label="(d) mean profile, bar: its band"),
                    Line2D([], [], color="0.3", lw=0.6, label="(e) exact range over A ∩ C, one pile")]
        fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=9, frameon=False)
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
    d = an.attrs["mean_diameter"]
    for h in an.history.values:
        s = an.sel(history=h, kernel=k0)
        dev = an.cut_deviation.sel(history=h)
        out[h] = dict(dip=float(s.dip_mean), lo=float(s.dip_lo), hi=float(s.dip_hi),
                      dips_by_kernel={float(k): float(an.dip_mean.sel(history=h, kernel=k)) for k in an.kernel.values},
                      frac_dip=float((an.dip.sel(history=h, kernel=k0) > 0).mean()),
                      frac_by_kernel={float(k): float((an.dip.sel(history=h, kernel=k) > 0).mean())
                                      for k in an.kernel.values},
                      center=float(s.profile_mean.sel(xi=0.0, method="nearest")),
                      L=float(an.base_half_width.sel(history=h).mean() / d),
                      fitL=float(an.fit_half_width.sel(history=h).mean() / d),
                      slope=float(an.surface_angle.sel(history=h).mean()),
                      apex=float(an.apex_height.sel(history=h).mean()),
                      cone=float(an.cone_ratio.sel(history=h).mean()),
                      dev_median=float(dev.median()), dev_iqr=float(dev.quantile(0.75) - dev.quantile(0.25)),
                      arching=float((dev > 0).sum() / np.isfinite(dev).sum()),
                      empty_cuts=int(np.isnan(dev).sum()), cuts=int(dev.size),
                      grains=float(an.n_grains.sel(history=h).mean()),
                      grains_min=int(an.n_grains.sel(history=h).min()), grains_max=int(an.n_grains.sel(history=h).max()),
                      removed=float(an.n_removed.sel(history=h).mean()))
        out[h].update(exact_summary(an, h) or {})
    out["comparisons"] = {str(c): comparison_summary(an, str(c)) for c in an.comparison.values} \
        if "comparison" in an.dims else {}
    return out


def _p_list(m):
    return ", ".join(f"{k.replace('_', ' ')} {v:.2g}" for k, v in m["p"].items())


def _verdict_words(m):
    return ("different in " + ", ".join(k.replace("_", " ") for k in m["differing"])) if m["differing"] \
        else "not different in any measure"


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
    P = s["point"]
    text = (f"Dip depth M − m of the mean ground-stress profile over {s['piles']} piles per history (units of the "
            f"mean stress W/2L, > 0 a dip, kernel {s['kernel']:g} d): "
            + "; ".join(f"{LABELS[h]} {s[h]['dip']:.3f} [{s[h]['lo']:.3f}, {s[h]['hi']:.3f}]" for h in an.history.values)
            + " (95 % basic bootstrap bands over piles).")
    m = s["comparisons"].get("rain")
    if m:
        text += (f" The rain's mean heap {'matches' if m['matched'] else 'does not match'} the point source's within "
                 f"{100 * m['tol']:g} % (" + ", ".join(f"{SHAPE_LABELS[k]} {100 * v['rel']:+.1f} %" for k, v in m["shape"].items())
                 + f"); at that shape the two histories are {_verdict_words(m)} (permutation tests, Bonferroni over "
                 f"{len(m['p'])} measures at {m['alpha']:g}).")
    for c, what in (("same", "two halves of the point piles"), ("layer", "the layer against the heap")):
        if c in s["comparisons"]:
            text += f" Control, {what}: {_verdict_words(s['comparisons'][c])}."
    text += f" The cut resultant is steeper than the flank at {100 * P['arching']:.0f} % of the point-source cuts."
    return text


# ------------------------------------------------------------------------------ the sentences


def shapes_text(an, cfg):
    """The shape match first: the three histories' mean piles and the rain's difference from
    the point source with its bands, against the stated tolerance."""
    s = summary(an)
    rows = "\n".join(f"| {LABELS[h]} | {s[h]['slope']:.2f}° | {s[h]['apex']:.2f} d | {s[h]['fitL']:.1f} d | "
                     f"{s[h]['cone']:.2f} | {s[h]['grains_min']}–{s[h]['grains_max']} |" for h in an.history.values)
    text = f"""**Shapes first.** Mean over the {s['piles']} piles of each history (flank slope: mean of the two
flank fits; apex: the highest grain top above the ground; base half-width: half the toe-to-toe
distance of the flank fits; cone ratio apex / (half-width × tan flank), 1 for a cone):

| history | flank slope | apex height | base half-width | cone ratio | grains |
|---|---|---|---|---|---|
{rows}
"""
    m = s["comparisons"].get("rain")
    if m:
        diffs = ", ".join(f"{SHAPE_LABELS[k]} {100 * v['rel']:+.1f} % (band {100 * v['lo']:+.1f} to {100 * v['hi']:+.1f} %)"
                          for k, v in m["shape"].items())
        text += f"""
The rain falls through a sieve that spans {100 * cfg['rain']['footprint_fraction']:g} % of the footprint of the heap as
it grows, each grain from {cfg['rain']['drop_height_d']:g} d above the settled surface where it lands (a height
chosen on these piles to match the flank slope; `docs/history.md`), so its grains land on the heap and the heap
grows at its angle of repose. Its mean
heap differs from the point source's by {diffs} ({100 * an.attrs['level']:g} % basic bootstrap
bands over piles). Criterion, stated before the
data: the shapes **match** when each relative difference of the means lies within
±{100 * m['tol']:g} % (a triangular heap {100 * m['tol']:g} % higher on the same base carries
{100 * m['tol']:g} % more pressure under its apex, {2 * m['tol']:.2g} W/2L, small against the
dips compared); the match is **resolved** when each band also lies within it. Here the shapes
**{'match' if m['matched'] else 'do not match'}**, and the match is
{'resolved' if m['resolved'] else 'not resolved at this number of piles (a band reaches beyond the tolerance)'}."""
    y = s.get("layer")
    if y:
        text += f"""

The **layer** (a uniform rain over the point pile's base from the first grain on, onto the
finite base $|x| \\le L$; {y['removed']:.1f} grains roll off its edges on average) is a
flat-topped deposit {y['apex']:.1f} d high with {y['slope']:.1f}° edges: not a heap. It is kept as
the shape that differs, the known difference the comparison must detect."""
    return text


def stress_text(an):
    """The dip depth of the mean profiles with their bands, per kernel, and the dips outside their band."""
    s = summary(an)
    H, k = list(an.history.values), s["kernel"]
    names = " / ".join(LABELS[h] for h in H)
    dips = ", ".join(f"{LABELS[h]} {s[h]['dip']:.3f} ({s[h]['lo']:.3f} to {s[h]['hi']:.3f})" for h in H)
    return f"""**Ground stress ({s['piles']} piles per history, kernel {k:g} d).** Dip depth $M - m$ of the
mean profile, in units of the mean stress $W / 2L$ (> 0 a dip), with its 95 % basic bootstrap band
over piles: {dips}; {', '.join(f"{100 * s[h]['frac_dip']:.0f} %" for h in H)} of the piles ({names})
have a dip of their own. With the other kernel widths the dips of the mean profiles are
{'; '.join(f"{kk:g} d: " + ' / '.join(f"{s[h]['dips_by_kernel'][kk]:.3f}" for h in H) for kk in s[H[0]]['dips_by_kernel'])}
({names}).
A single pile's dip is a minimum of a noisy curve against maxima of the same curve, so it
is biased upwards when the kernel is narrow: the fraction of piles with a dip of their own is
{'; '.join(f"{kk:g} d: " + ' / '.join(f"{100 * s[h]['frac_by_kernel'][kk]:.0f} %" for h in H) for kk in s[H[0]]['frac_by_kernel'])}
({names}); only the mean profile over piles, with its band, carries a claim.
{outside_text(an)}
Under the apex the mean stress is {' / '.join(f"{s[h]['center']:.2f}" for h in H)} ({names})
times the mean stress W / 2L."""


def comparison_text(an):
    """The histories compared at matched shape, then the test's two controls."""
    s = summary(an)
    m = s["comparisons"].get("rain")
    if not m:
        return "**Comparison.** The run holds no rain piles: no comparison at matched shape."
    lvl = 100 * an.attrs["level"]
    text = f"""**Point source against rain, at {'matched' if m['matched'] else 'unmatched'} shape** ({s['piles']} piles
each, two-sided permutation tests of the history labels over piles, {an.attrs['permutations']} permutations;
the histories differ in a measure when its p-value lies below {m['alpha']:g} / {len(m['p'])}, Bonferroni
over the {len(m['p'])} measures): p = {_p_list(m)}. Dip depth point − rain {m['dip']:+.3f} W/2L
({lvl:g} % band {m['dip_lo']:+.3f} to {m['dip_hi']:+.3f}); largest gap between the mean ground
stress profiles over $|x| \\le L$ {m['gap']:.3f} W/2L; pooled median arching deviation point − rain
{m['arching']:+.1f}° ({m['arching_lo']:+.1f}° to {m['arching_hi']:+.1f}°). At this shape the two
histories are **{_verdict_words(m)}**."""
    if not m["matched"]:
        text += " The shapes do not match, so a difference mixes history with shape."
    for c, differs, expected in control_outcomes(an):
        if differs is not None:
            x = s["comparisons"][c]
            outcome = "as required" if differs == expected else \
                "the control FAILS: expected " + ("different" if expected else "not different")
            text += f"\n\n*Control*, {CONTROL_PAGE_WORDS[c]}: p = {_p_list(x)}; **{_verdict_words(x)}** ({outcome})."
    return text


def experiments_text(an):
    """The dips against the experiments' dip (point source) and its absence under a rain."""
    s = summary(an)
    P = s["point"]
    text = f"""**Against the experiments.** Vanel et al. (1999) and Geng et al. (2001) report a dip
under heaps poured from a localized source and none (a central maximum) under heaps of the
same shape built by a rain. Here the point-source dip is
{'resolved (its band excludes 0)' if P['lo'] > 0 else 'not resolved (its band includes 0 or is negative)'}"""
    R = s.get("rain")
    if R:
        text += (f"; the rained heap has {'a hump (negative dip, band below 0)' if R['hi'] < 0 else ('a resolved dip (band above 0)' if R['lo'] > 0 else 'neither a resolved hump nor a resolved dip (band includes 0)')}")
        m = s["comparisons"].get("rain")
        if m:
            text += (f"; the dip difference point − rain is {m['dip']:+.3f} (p = {m['p']['dip']:.2g}), "
                     f"{'significant' if 'dip' in m['differing'] else 'not significant'} at {s['piles']} piles per history")
    return text + "."


def arching_text(an):
    """The cut resultant against the flank slope over all cuts and piles."""
    s = summary(an)
    H = list(an.history.values)
    names = " / ".join(LABELS[h] for h in H)
    return f"""**Arching.** Over all cuts and piles the resultant is on median
{' / '.join(f"{s[h]['dev_median']:.1f}°" for h in H)} ({names}) steeper than the flank
(interquartile range {' / '.join(f"{s[h]['dev_iqr']:.1f}°" for h in H)}); it is steeper than the
free surface at {' / '.join(f"{100 * s[h]['arching']:.0f} %" for h in H)} of the cuts that cross a
contact ({' / '.join(f"{s[h]['empty_cuts']} of {s[h]['cuts']}" for h in H)} cuts, near the toes,
cross none and have no resultant direction). (Arching here means a resultant steeper than the
flank; the exact test of `fig4_pile` uses a weaker one, a resultant that pushes the bank
downward, $F_y < 0$.)"""


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
    text = (" ".join(parts) + " The arching angle of one force state is thus one choice among many: the spread of "
            "the history angles over piles is to be read against these ranges.")
    m = s["comparisons"].get("rain")
    widths = [s[h]["exact_width_median"] for h in ("point", "rain") if "exact_width_median" in s.get(h, {})]
    if m and widths:
        w = min(widths)
        text += (f" The difference of the pooled median arching angles between the histories, {m['arching']:+.1f}°, "
                 f"is {'smaller' if abs(m['arching']) < w else 'larger'} than the median exact range of one cut "
                 f"({w:.1f}°): {'the admissible set of a single pile could hold either history' if abs(m['arching']) < w else 'no single pile could hold both'}"
                 f" (a bound on a single cut, not on the median over piles).")
    return text
