"""The size study's page: the analyses of every pile size side by side (figure, summary,
sentences), read from ``size.nc`` (:mod:`ncd.figures.fig4_history.size`)."""
import matplotlib.pyplot as plt
import numpy as np

from ncd.figures.fig4_history.analysis import CERTIFIED_TEXT, EXACT_SUMMARY
from ncd.figures.fig4_history.plots import COLORS


def figure(sz):
    """(a) dip depth of the mean profile, (b) arching deviation, (c) flank slope, against grains
    per pile, per history with bands over piles; (d) median deviation against cut position per
    size.  Drawn for the page's width (11 in, fonts of at least 9 pt, legends below the panels)."""

    with plt.rc_context({"font.size": 9.5}):
        fig, axes = plt.subplots(2, 2, figsize=(11, 7.4), layout="constrained")
        axes = axes.ravel()
        n = sz.grains.values
        k0 = sz.kernel.values[0]
        for j, h in enumerate(sz.history.values):
            s = sz.sel(history=h)
            off = n * (1 + 0.04 * (2 * j - 1))
            dm, dl, dh = (s[v].sel(kernel=k0).values for v in ("dip_mean", "dip_lo", "dip_hi"))
            axes[0].errorbar(off, dm, yerr=[dm - dl, dh - dm], fmt="o-", color=COLORS.get(h), capsize=3, label=h)
            am, al, ah = s.arching_mean.values, s.arching_lo.values, s.arching_hi.values
            axes[1].errorbar(off, am, yerr=[am - al, ah - am], fmt="o-", color=COLORS.get(h), capsize=3, label=h)
            axes[2].plot(n, s.surface_angle.values, "o-", color=COLORS.get(h), label=h)
            for z in sz["size"].values:
                med = s.deviation_median.sel(size=z).median("flank").values
                axes[3].plot(sz.cut_position.values, med, "-" if z == sz["size"].values[-1] else "--",
                             color=COLORS.get(h), alpha=0.5 + 0.5 * z / max(1, sz.sizes["size"] - 1),
                             label=f"{h}, {int(n[z])} grains")
        axes[0].axhline(0, color="k", lw=0.5)
        axes[0].set_ylabel("dip depth M − m (units of W / 2L)")
        axes[0].set_title(f"(a) dip depth of the mean profile (kernel {k0:g} d; > 0 a dip)", loc="left", fontsize=10)
        axes[1].axhline(0, color="k", lw=0.5)
        axes[1].set_ylabel("median cut deviation (°)")
        axes[1].set_title("(b) arching: resultant − flank slope", loc="left", fontsize=10)
        axes[2].set_ylabel("flank slope (°)")
        axes[2].set_title("(c) flank slope", loc="left", fontsize=10)
        axes[3].axhline(0, color="k", lw=0.5)
        axes[3].set_xlabel("cut position |x| / L")
        axes[3].set_ylabel("median deviation over piles (°)")
        axes[3].set_title("(d) deviation against the cut position", loc="left", fontsize=10)
        for ax in axes[:3]:
            ax.set_xscale("log")
            ax.set_xlabel("grains per pile")
        axes[2].legend(fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.2), ncol=2, frameon=False,
                       title="(a)–(c), bars: 95 % bootstrap bands over piles", title_fontsize=9)
        axes[3].legend(fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.2), ncol=2, frameon=False)
    return fig


def summary(sz):
    """Numbers for the prose: per history, the smallest and largest sizes and their change."""
    k0 = sz.kernel.values[0]
    last = sz.sizes["size"] - 1
    out = {"grains": [int(g) for g in sz.grains.values], "piles": [int(p) for p in sz.piles.values], "kernel": float(k0)}
    for h in sz.history.values:
        s = sz.sel(history=h)
        out[h] = {q: [float(v) for v in s[q].sel(kernel=k0).values] for q in ("dip_mean", "dip_lo", "dip_hi")}
        out[h].update({q: [float(v) for v in s[q].values] for q in
                       ("arching_mean", "arching_lo", "arching_hi", "surface_angle", "apex_height", "half_width",
                        "cone_ratio")})
        out[h]["dip_p"] = float(s.dip_size_p.sel(kernel=k0, size=last))
        out[h]["dip_p_kernels"] = {float(k): float(s.dip_size_p.sel(kernel=k, size=last)) for k in sz.kernel.values}
        out[h]["arching_p"] = float(s.arching_size_p.sel(size=last))
        out[h]["arching_change"] = float(s.arching_size_diff.sel(size=last))
        out[h]["dip_change"] = float(s.dip_size_diff.sel(kernel=k0, size=last))
        out[h].update({q: [float(v) for v in s[q].values] for q in EXACT_SUMMARY if q in s})
    return out


def exact_text(sz):
    """The exact angle ranges over A ∩ C at every size, in a sentence per size and history."""
    s = summary(sz)
    per_pile = sz.sizes["flank"] * sz.sizes["cut_position"]
    parts = []
    for z, n in enumerate(s["grains"]):
        for h in sz.history.values:
            x = {k: v[z] for k, v in s[h].items() if k in EXACT_SUMMARY}
            if not x.get("exact_piles"):
                parts.append(f"{n} grains, {h}: no exact ranges computed.")
                continue
            total = int(x["exact_piles"]) * per_pile
            none = total - int(x["exact_cuts"])
            parts.append(
                f"{n} grains, {h}, {x['exact_piles']:.0f} pile(s): {x['exact_cuts']:.0f} of {total} cuts have an "
                "angle range" + (f" (the other {none} have none: the admissible resultants surround zero, or the cut crosses no "
                                 "contact)" if none else "") + ", "
                f"{x['exact_confirmed'] * total:.0f} certified to {CERTIFIED_TEXT}°; a range spans {x['exact_width_median']:.1f}° "
                f"on median (at most {x['exact_width_max']:.1f}°); every admissible state is steeper than the flank at "
                f"{100 * x['exact_all_positive']:.0f} % of the cuts and shallower at {100 * x['exact_all_negative']:.0f} "
                f"%; the history resultant lies outside its range by at most {x['exact_outside_max']:.1e}°.")
    return " ".join(parts)


def finding(sz):
    """The figure's finding in a few sentences (the Snakemake report's caption includes it)."""
    s = summary(sz)
    g = s["grains"]
    return " ".join(
        f"{h}: from {g[0]} to {g[-1]} grains the dip depth of the mean profile (units of W/2L, > 0 a dip) changes "
        f"by {s[h]['dip_change']:+.3f} (permutation p = {s[h]['dip_p']:.2f}) and the arching deviation by "
        f"{s[h]['arching_change']:+.1f}° (p = {s[h]['arching_p']:.2f})." for h in sz.history.values) \
        + " " + shape_text(sz)


def shape_text(sz):
    """The rain's heap against the point source's at every size: relative differences of the
    mean piles with their bands, matched or not within the analysis' tolerance."""
    if "shape_rel" not in sz:
        return ""
    tol = float(sz.attrs.get("shape_tol", 0.05))
    parts = []
    for z, n in enumerate(sz.grains.values):
        rel = sz.shape_rel.isel(size=z)
        if not np.isfinite(rel.values).all():
            parts.append(f"{int(n)} grains: no rain piles.")
            continue
        lo, hi = sz.shape_rel_lo.isel(size=z).values, sz.shape_rel_hi.isel(size=z).values
        ok = bool(np.all(np.abs(rel.values) <= tol))
        parts.append(f"{int(n)} grains ({int(sz.piles.values[z])} piles per history): the rain's mean heap "
                     + ("matches" if ok else "does not match") + f" the point source's within {100 * tol:g} % ("
                     + ", ".join(f"{str(k).replace('_', ' ')} {100 * v:+.1f} % [{100 * a:+.1f}, {100 * b:+.1f}]"
                                 for k, v, a, b in zip(sz.shape.values, rel.values, lo, hi)) + ").")
    return " ".join(parts)
