"""How the piles of fig4_history change with size.

The analyses of several pile sizes (``analysis_n<n>.nc`` of
:mod:`ncd.figures.fig4_history.analysis`) side by side, per history: the dip depth and the
median cut deviation with bootstrap bands over piles, and their change from the
smallest size with a permutation p-value
(:func:`ncd.figures.fig4_history.analysis.permutation_p`).  The abscissae are in units of the
base half-width, so profiles of every size compare directly.
"""
import numpy as np
import xarray as xr

from ncd.figures.fig4_history.analysis import CERTIFIED_TEXT, bootstrap_index, permutation_p
from ncd.figures.fig4_history.plots import COLORS, EXACT_SUMMARY, exact_summary


def _pile_arching(an):
    """(history, pile): median over flanks and cut positions of the cut deviation (degree)."""
    dev = an.cut_deviation.values
    return np.nanmedian(dev.reshape(dev.shape[0], dev.shape[1], -1), axis=2)


def _perm_mean(a, b, rng, n_perm):
    """Two-sided permutation p-value of ``mean(b) - mean(a)`` (labels shuffled)."""
    both = np.concatenate([a, b])
    obs = abs(b.mean() - a.mean())
    count = 0
    for _ in range(n_perm):
        idx = rng.permutation(len(both))
        count += abs(both[idx[len(a):]].mean() - both[idx[:len(a)]].mean()) >= obs - 1e-12
    return (count + 1) / (n_perm + 1)


def size_dataset(analyses, seed=16):
    """size.nc from ``analyses`` (analysis datasets of distinct grain counts, any order).
    Every analysis must share the histories, kernels, abscissae and cut positions."""
    if len(analyses) < 2:
        raise ValueError(f"a size comparison needs at least 2 analyses, got {len(analyses)}")
    grains = [int(round(float(an.n_grains.mean()))) for an in analyses]
    order = np.argsort(grains)
    ans = [analyses[i] for i in order]
    ref = ans[0]
    for an in ans[1:]:
        for c in ("history", "kernel", "xi", "cut_position", "flank"):
            if not np.array_equal(an[c].values, ref[c].values):
                raise ValueError(f"analyses differ in coordinate {c!r}: {an[c].values} vs {ref[c].values}")
    hist, K = list(ref.history.values), ref.kernel.values
    S, H = len(ans), len(hist)
    a = ref.attrs
    lo_q, hi_q = 0.5 * (1 - a["level"]), 0.5 * (1 + a["level"])
    rng = np.random.default_rng([seed, 4])
    n_max = max(an.sizes["pile"] for an in ans)
    arch = np.full((S, H, n_max), np.nan)
    arch_mean, arch_lo, arch_hi = (np.full((S, H), np.nan) for _ in range(3))
    arch_p, dip_p = np.full((S, H), np.nan), np.full((S, H, len(K)), np.nan)
    for s, an in enumerate(ans):
        per = _pile_arching(an)
        n = per.shape[1]
        arch[s, :, :n] = per
        idx = bootstrap_index(rng, n, int(a["bootstrap"]))
        boot = per[:, idx].mean(axis=2)                       # (history, B)
        arch_mean[s] = per.mean(axis=1)
        arch_lo[s], arch_hi[s] = np.quantile(boot, lo_q, axis=1), np.quantile(boot, hi_q, axis=1)
        if s == 0:
            continue
        for i in range(H):
            arch_p[s, i] = _perm_mean(arch[0, i, :ref.sizes["pile"]], per[i], rng, int(a["permutations"]))
            for j, k in enumerate(K):
                pa = ref.profile.values[i, :, j]
                pb = an.profile.values[i, :, j]
                dip_p[s, i, j] = permutation_p(float(ref.dip_mean.values[i, j]), float(an.dip_mean.values[i, j]),
                                               pa, pb, ref.xi.values, a["dip_center"], np.asarray(a["dip_flank"]),
                                               rng, int(a["permutations"]))
    # the exact angle ranges of each size's first piles (history_plots.exact_summary; NaN: none)
    exact = {k: np.full((S, H), np.nan) for k in EXACT_SUMMARY}
    for s, an in enumerate(ans):
        for i, h in enumerate(hist):
            for k, v in (exact_summary(an, h) or {"exact_piles": 0}).items():
                exact[k][s, i] = v
    stack = lambda v: np.array([an[v].values for an in ans])            # noqa: E731
    mean_over = lambda v: np.array([an[v].mean("pile").values for an in ans])   # noqa: E731
    d = ref.attrs["mean_diameter"]
    one = lambda dims, v, u, ln: (dims, v, {"units": u, "long_name": ln})  # noqa: E731
    Z, Hd, P, Kd, F, Q = "size", "history", "pile", "kernel", "flank", "cut_position"
    dip_mean = stack("dip_mean")
    out = xr.Dataset(
        {
            "grains": one(Z, np.array(grains)[order], "1", "grains per pile (mean over piles, rounded)"),
            "piles": one(Z, np.array([an.sizes["pile"] for an in ans]), "1", "piles per history"),
            "n_grains_mean": one((Z, Hd), mean_over("n_grains"), "1", "grains in the final pile, mean over piles"),
            "dip_mean": one((Z, Hd, Kd), dip_mean, "1", "dip depth M - m of the mean profile over piles, units of the mean ground stress W/2L, > 0 a dip"),
            "dip_lo": one((Z, Hd, Kd), stack("dip_lo"), "1", "bootstrap band over piles of dip_mean, lower"),
            "dip_hi": one((Z, Hd, Kd), stack("dip_hi"), "1", "bootstrap band over piles of dip_mean, upper"),
            "dip_size_diff": one((Z, Hd, Kd), dip_mean - dip_mean[:1], "1",
                                 "dip_mean minus that of the smallest size"),
            "dip_size_p": one((Z, Hd, Kd), dip_p, "1", "two-sided permutation p-value of dip_size_diff "
                                                       "(size labels over piles; NaN: smallest size)"),
            "arching_pile": one((Z, Hd, P), arch, "degree", "median over flanks and cut positions of one "
                                                            "pile's cut deviation (NaN: padding)"),
            "arching_mean": one((Z, Hd), arch_mean, "degree", "mean over piles of arching_pile"),
            "arching_lo": one((Z, Hd), arch_lo, "degree", "bootstrap band over piles of arching_mean, lower"),
            "arching_hi": one((Z, Hd), arch_hi, "degree", "bootstrap band over piles of arching_mean, upper"),
            "arching_size_diff": one((Z, Hd), arch_mean - arch_mean[:1], "degree",
                                     "arching_mean minus that of the smallest size"),
            "arching_size_p": one((Z, Hd), arch_p, "1", "two-sided permutation p-value of arching_size_diff "
                                                        "(size labels over piles; NaN: smallest size)"),
            "deviation_median": one((Z, Hd, F, Q), stack("deviation_median"), "degree",
                                    "median over piles of the cut deviation"),
            "deviation_median_lo": one((Z, Hd, F, Q), stack("deviation_median_lo"), "degree",
                                       "bootstrap band over piles of the median deviation, lower"),
            "deviation_median_hi": one((Z, Hd, F, Q), stack("deviation_median_hi"), "degree",
                                       "bootstrap band over piles of the median deviation, upper"),
            "surface_angle": one((Z, Hd), np.array([an.surface_angle.mean(("pile", "flank")).values for an in ans]),
                                 "degree", "flank slope, mean over piles and flanks"),
            "apex_height": one((Z, Hd), mean_over("apex_height"), "1", "apex height in d, mean over piles"),
            "half_width": one((Z, Hd), mean_over("fit_half_width") / d, "1",
                              "toe-to-toe half-width of the pile's own fit in d, mean over piles"),
            "cone_ratio": one((Z, Hd), mean_over("cone_ratio"), "1", "cone ratio, mean over piles"),
            **{k: one((Z, Hd), exact[k], u, ln) for k, (u, ln) in EXACT_SUMMARY.items()},
        },
        coords={Z: np.arange(S), Hd: hist, P: np.arange(n_max), Kd: K, F: ref.flank.values,
                Q: ref.cut_position.values},
        attrs={"level": a["level"], "bootstrap": a["bootstrap"], "permutations": a["permutations"],
               "dip_center": a["dip_center"], "dip_flank": list(a["dip_flank"])},
    )
    out[Z].attrs.update(units="1", long_name="size index (grain counts ascending)")
    out[Kd].attrs.update(units="1", long_name="kernel standard deviation in mean grain diameters")
    out[Q].attrs.update(units="1", long_name="cut position |x| / base half-width")
    return out


def figure(sz):
    """(a) dip depth of the mean profile, (b) arching deviation, (c) flank slope, against grains
    per pile, per history with bands over piles; (d) median deviation against cut position per
    size.  Drawn for the page's width (11 in, fonts of at least 9 pt, legends below the panels)."""
    import matplotlib.pyplot as plt

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


__all__ = ["size_dataset", "figure", "summary", "exact_text"]

def finding(sz):
    """The figure's finding in a few sentences (the Snakemake report's caption includes it)."""
    s = summary(sz)
    g = s["grains"]
    return " ".join(
        f"{h}: from {g[0]} to {g[-1]} grains the dip depth of the mean profile (units of W/2L, > 0 a dip) changes "
        f"by {s[h]['dip_change']:+.3f} (permutation p = {s[h]['dip_p']:.2f}) and the arching deviation by "
        f"{s[h]['arching_change']:+.1f}° (p = {s[h]['arching_p']:.2f})." for h in ("point", "rain"))
