"""How the piles of fig4_history change with size.

The analyses of several pile sizes (``analysis_n<n>.nc`` of
:mod:`ncd.figures.fig4_history.analysis`) side by side, per history: the dip depth and the
median cut deviation with bootstrap bands over piles, and their change from the
smallest size with a permutation p-value
(:func:`ncd.figures.fig4_history.analysis.permutation_p`), and at each size the shape match
of the rain's heap to the point source's (:mod:`ncd.figures.fig4_history.compare`).  The abscissae are in units of the
base half-width, so profiles of every size compare directly.
"""
import numpy as np
import xarray as xr

from ncd.figures.fig4_history.analysis import (
    EXACT_SUMMARY,
    bootstrap_index,
    comparison_summary,
    exact_summary,
    permutation_p,
)
from ncd.figures.fig4_history.compare import SHAPES


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
    # the shape match of the rain to the point source at each size (NaN: no rain piles)
    match = {k: np.full((S, len(SHAPES)), np.nan) for k in ("rel", "lo", "hi")}
    match_p = np.full((S, len(SHAPES)), np.nan)
    for z, an in enumerate(ans):
        if "comparison" in an.dims and "rain" in an.comparison.values:
            m = comparison_summary(an, "rain")
            for j, key in enumerate(SHAPES):
                for q in ("rel", "lo", "hi"):
                    match[q][z, j] = m["shape"][key][q]
                match_p[z, j] = m["p"][key]
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
            "shape_rel": one((Z, "shape"), match["rel"], "1", "rain minus point source, relative difference of the "
                             "mean piles (NaN: no rain piles)"),
            "shape_rel_lo": one((Z, "shape"), match["lo"], "1", "basic bootstrap band of shape_rel, lower"),
            "shape_rel_hi": one((Z, "shape"), match["hi"], "1", "basic bootstrap band of shape_rel, upper"),
            "shape_p": one((Z, "shape"), match_p, "1", "two-sided permutation p-value of the shape difference"),
        },
        coords={Z: np.arange(S), Hd: hist, P: np.arange(n_max), Kd: K, F: ref.flank.values,
                Q: ref.cut_position.values, "shape": list(SHAPES)},
        attrs={"level": a["level"], "bootstrap": a["bootstrap"], "permutations": a["permutations"],
               "dip_center": a["dip_center"], "dip_flank": list(a["dip_flank"]),
               "shape_tol": float(a.get("shape_tol", np.nan))},
    )
    out[Z].attrs.update(units="1", long_name="size index (grain counts ascending)")
    out[Kd].attrs.update(units="1", long_name="kernel standard deviation in mean grain diameters")
    out[Q].attrs.update(units="1", long_name="cut position |x| / base half-width")
    out["shape"].attrs.update(long_name="shape measure: flank slope (degree), apex height (d), base half-width (d)")
    return out
