"""Ground pressure and arching over ensembles of piles of three histories (Moreau 2005, section 5).

Per pile, from its history forces: the ground stress profile ``p(x / L)`` (kernel
average of the ground contacts, normalised by the mean stress ``W / (2 L)``), the dip
depth ``M - m`` in units of that mean stress (> 0 a dip under the apex; the name, unit and
sign of the single pile's dip in :mod:`ncd.figures.fig4_pile.pressure`) and the angle of the resultant across
vertical cuts at ``x = ± q L`` against the pile's flank slope.  Statistics resample piles,
never runs of one pile.  The dip is a minimum against maxima of a noisier resampled
profile, so its percentile band is biased upwards; the dip and difference bands are
therefore *basic* bootstrap bands (:func:`basic_band`), correct to first order.  The
histories are compared at matched shape by :mod:`ncd.figures.fig4_history.compare`
(:data:`COMPARISONS`: the test and its two controls).
"""
import warnings

import numpy as np
import xarray as xr

from ncd.figures.fig4_history import compare as cmp
from ncd.figures.fig4_history.construct import HISTORIES, ground_forces
from ncd.shared import cuts as cm
from ncd.shared.pile import equilibrium_problem, final_scene
from ncd.shared.sources import mean_diameter

# an exact angle range is certified when its error bound (angle_bound) is below this: the simplex
# route's Dinkelbach bounds are far below it; the interior point's (the piles of 10^4 grains) are
# coarser, its dual residual over the pile's summed forces (docs/solvers.md)
CERTIFIED_DEG = 1e-5
CERTIFIED_TEXT = f"{CERTIFIED_DEG:.0e}".replace("e-0", "e-")   # as the pages write it: 1e-5


def _nan(stat, a, *args, **kw):
    """A nan-aware statistic of ``a`` (cuts crossing no contact are NaN), an all-NaN
    slice giving NaN without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return stat(a, *args, **kw)


def stress_profile(x, fy, weight, L, xi, width):
    """Kernel-averaged ground stress at ``xi`` (units of ``W / (2 L)``); ``width`` in m."""
    s = width / L
    k = np.exp(-0.5 * ((xi[:, None] - x[None, :] / L) / s) ** 2) / (np.sqrt(2 * np.pi) * s)
    return 2.0 * (k @ fy) / weight


def dip_depth(profile, xi, center, flank):
    """The dip depth ``M - m`` along the last axis (the profile's unit, W / 2L; > 0 a dip):
    ``m`` the central minimum (``|xi| <= center``), ``M`` the mean of the largest values on
    either side within ``flank``."""
    P = np.reshape(profile, (-1, len(xi)))
    a = np.abs(xi)
    m = np.min(P[:, a <= center], axis=1)
    sel = (a >= flank[0]) & (a <= flank[1])
    big = 0.5 * (np.max(P[:, sel & (xi < 0)], axis=1) + np.max(P[:, sel & (xi > 0)], axis=1))
    return (big - m).reshape(np.shape(profile)[:-1])


def norm_length(cfg, ds):
    """``L`` of ``xi = x / L``: the pile's own base half-width from its flank fits (point and
    rain heaps), or for a layer the base half-width of the member's point-source pile, the
    half-width of the layer's finite base."""
    key = "point_half_width" if ds.attrs["history"] == "layer" else "base_half_width"
    return float(ds.attrs[key])


def pile_measures(cfg, ds):
    """The measures of one pile file (see the module docstring)."""
    a = cfg["analysis"]
    d = mean_diameter(cfg)
    L = norm_length(cfg, ds)
    W = float(ds.attrs["weight"])
    xi = np.linspace(-a["xi_max"], a["xi_max"], a["n_xi"])
    x, fx, fy = ground_forces(ds)
    prof = np.array([stress_profile(x, fy, W, L, xi, w * d) for w in a["kernel_d"]])
    scene = final_scene(cfg, ds)
    problem = equilibrium_problem(cfg, scene, ds)
    nm = scene.n_mobile
    forces = np.column_stack([ds["force_n"].values, ds["force_t"].values]).ravel()
    q = np.asarray(a["cut_positions"], float)
    specs = [(s * qq * L, s, -np.inf, np.inf) for s in (-1, 1) for qq in q]
    C, counts = cm.cut_matrix(problem.contacts, scene.pos, nm, specs)
    F = (C @ forces).reshape(-1, 2)
    outer = np.repeat([-1, 1], len(q))
    slope = np.where(outer > 0, ds.attrs["right_angle"], ds.attrs["left_angle"])
    phi, dev = cm.flank_angles(F[:, 0], F[:, 1], outer, slope)
    dev = (dev + 180.0) % 360.0 - 180.0              # a deviation in (-180, 180]
    apex = float(np.max(ds["y"].values + ds["radius"].values)) - float(ds.attrs["y_ground"])
    tan = np.tan(np.radians(0.5 * (ds.attrs["left_angle"] + ds.attrs["right_angle"])))
    fitL = float(ds.attrs["base_half_width"])
    return dict(xi=xi, profile=prof, ground_fx=float(fx.sum()), ground_fy=float(fy.sum()), weight=W,
                base_half_width=L, n_ground=len(x), cut_angle=phi.reshape(2, -1), cut_deviation=dev.reshape(2, -1),
                cut_count=np.asarray(counts).reshape(2, -1), surface_angle=slope.reshape(2, -1),
                dip=dip_depth(prof, xi, a["dip_center"], a["dip_flank"]), apex_height=apex / d,
                cone_ratio=apex / (fitL * tan), fit_half_width=float(ds.attrs["base_half_width"]),
                n_grains=nm, n_removed=int(ds.attrs.get("n_removed", 0)))


def basic_band(estimate, boot, lo, hi, axis):
    """Basic (reverse-percentile) bootstrap band ``(2 t - q_hi, 2 t - q_lo)`` of the
    estimate ``t`` from its bootstrap replicates ``boot`` (quantile levels ``lo < hi``)."""
    q_lo, q_hi = np.quantile(boot, lo, axis=axis), np.quantile(boot, hi, axis=axis)
    return 2 * estimate - q_hi, 2 * estimate - q_lo


def bootstrap_index(rng, n_piles, n_boot):
    """``(n_boot, n_piles)`` resampled pile indices."""
    return rng.integers(0, n_piles, size=(n_boot, n_piles))


def permutation_p(dip_a, dip_b, profiles_a, profiles_b, xi, center, flank, rng, n_perm):
    """Two-sided permutation p-value of the difference of the dips of the mean profiles
    (history labels shuffled among the piles)."""
    both = np.concatenate([profiles_a, profiles_b])
    na = len(profiles_a)
    obs = dip_a - dip_b
    count = 0
    for _ in range(n_perm):
        idx = rng.permutation(len(both))
        da = dip_depth(both[idx[:na]].mean(axis=0), xi, center, flank)
        db = dip_depth(both[idx[na:]].mean(axis=0), xi, center, flank)
        count += abs(da - db) >= abs(obs) - 1e-15
    return (count + 1) / (n_perm + 1)


def exact_arrays(exact, hist, n, shape):
    """``(dev_min, dev_max, history_outside, computed, confirmed)`` over (history, pile, flank,
    position) from ``exact = {(history, member): dataset of ncd.figures.fig4_history.exact}``; NaN
    (or 0) where absent."""
    lo, hi, out = (np.full((len(hist), n) + shape, np.nan) for _ in range(3))
    done = np.zeros((len(hist), n), np.int8)
    confirmed = np.zeros((len(hist), n) + shape, np.int8)
    for (h, m), e in (exact or {}).items():
        i = hist.index(h)
        lo[i, m], hi[i, m] = e["exact_deviation_min"].values, e["exact_deviation_max"].values
        out[i, m] = e["history_outside"].values
        bound = e["angle_bound"].values
        confirmed[i, m] = np.isfinite(bound) & (bound <= CERTIFIED_DEG)
        done[i, m] = 1
    return lo, hi, out, done, confirmed


# name: (group A, group B, role, expected); a group is (history, members): None all, "even"/"odd" a half;
# expected: a control's required outcome (True: the groups must differ), None for the test itself
COMPARISONS = {
    "rain": (("point", None), ("rain", None), "test: point source against the rain that builds the same heap", None),
    "layer": (("point", None), ("layer", None), "control: a difference known to exist (heap against layer)", True),
    "same": (("point", "even"), ("point", "odd"), "control: one history, different seeds (even against odd members)",
             False),
}


def _members(n, which):
    return np.arange(n) if which is None else np.arange(0 if which == "even" else 1, n, 2)


def comparisons(cfg, an, hist, rng):
    """The :data:`COMPARISONS` whose histories ``an`` holds, as variables over a ``comparison``
    dimension (:func:`ncd.figures.fig4_history.compare.compare`), added to ``an``."""
    a = cfg["analysis"]
    xi = an.xi.values
    d = an.attrs["mean_diameter"]
    shape = np.stack([an.surface_angle.mean("flank").values, an.apex_height.values,
                      an.fit_half_width.values / d], axis=-1)           # (history, pile, 3)
    dip_fn = lambda prof: dip_depth(prof, xi, a["dip_center"], a["dip_flank"])  # noqa: E731
    names, rows = [], []
    n = an.sizes["pile"]
    for name, (ga, gb, _, _) in COMPARISONS.items():
        if ga[0] not in hist or gb[0] not in hist:
            continue
        groups = []
        for h, which in (ga, gb):
            i, m = hist.index(h), _members(n, which)
            groups.append(dict(shape=shape[i, m], profile=an.profile.values[i, m],
                               deviation=an.cut_deviation.values[i, m]))
        names.append(name)
        rows.append(cmp.compare(*groups, xi, dip_fn, rng, a["permutations"], a["bootstrap"], a["level"]))
    if not names:
        return an
    C, S, K = "comparison", "shape", "kernel"
    stack = lambda key: np.array([r[key] for r in rows])  # noqa: E731
    spec = {
        "shape_diff": ((C, S), "per shape measure", "mean of group B minus mean of group A"),
        "shape_rel": ((C, S), "1", "relative difference of the mean shapes (B - A) / A"),
        "profile_gap": ((C, K), "1", "largest gap between the mean ground stress profiles over |x| <= L (W/2L)"),
        "dip_diff": ((C, K), "1", "dip depth of A's mean profile minus B's (W/2L)"),
        "arching_diff": ((C,), "degree", "pooled median cut deviation of A minus B"),
    }
    keys = {"shape_diff": "shape", "shape_rel": "shape_rel", "profile_gap": "profile_gap", "dip_diff": "dip",
            "arching_diff": "arching"}
    for var, (dims, units, long) in spec.items():
        k = keys[var]
        an[f"cmp_{var}"] = (dims, stack(k), {"units": units, "long_name": long})
        for end in ("lo", "hi"):
            an[f"cmp_{var}_{end}"] = (dims, stack(f"{k}_{end}"), {"units": units, "long_name":
                                      f"basic bootstrap band over piles of cmp_{var}, {'lower' if end == 'lo' else 'upper'}"})
    for var, k, dims in (("shape", "p_shape", (C, S)), ("profile_gap", "p_profile_gap", (C, K)),
                         ("dip", "p_dip", (C, K)), ("arching", "p_arching", (C,))):
        an[f"cmp_p_{var}"] = (dims, stack(k), {"units": "1", "long_name": f"two-sided permutation p-value of the "
                                                f"{var} difference (group labels shuffled over piles)"})
    an["cmp_shape_reference"] = ((C, S), stack("shape_reference"), {"units": "per shape measure",
                                                                  "long_name": "mean shape of group A"})
    an = an.assign_coords({C: names, S: list(cmp.SHAPES)})
    an[C].attrs.update(long_name="comparison: " + "; ".join(f"{k} = {COMPARISONS[k][0]} vs {COMPARISONS[k][1]} "
                                                           f"({COMPARISONS[k][2]})" for k in names))
    an[S].attrs.update(long_name="shape measure: flank slope (degree), apex height (d), base half-width (d)")
    an.attrs.update(shape_tol=cmp.SHAPE_TOL, alpha=cmp.ALPHA)
    return an


def ensemble_dataset(cfg, files, exact=None):
    """analysis.nc from ``files = {history: [pile datasets in member order]}`` and the exact
    angle ranges ``exact = {(history, member): dataset}`` of some piles."""
    a = cfg["analysis"]
    hist = [h for h in HISTORIES if h in files]
    per = {h: [pile_measures(cfg, ds) for ds in files[h]] for h in hist}
    n = min(len(v) for v in per.values())
    if any(len(v) != n for v in per.values()):
        raise ValueError(f"histories have different pile counts: { {h: len(v) for h, v in per.items()} }")
    xi = per[hist[0]][0]["xi"]
    widths = np.asarray(a["kernel_d"], float)
    stack = lambda key: np.array([[m[key] for m in per[h]] for h in hist])  # noqa: E731
    prof = stack("profile")                       # (history, pile, width, xi)
    dips = stack("dip")                           # (history, pile, width)
    rng = np.random.default_rng(a["seed"])
    B, lo, hi = a["bootstrap"], 0.5 * (1 - a["level"]), 0.5 * (1 + a["level"])
    idx = bootstrap_index(rng, n, B)              # the same resamples for both histories
    boot_mean = prof[:, idx].mean(axis=2)         # (history, B, width, xi)
    boot_dip = dip_depth(boot_mean, xi, a["dip_center"], a["dip_flank"])           # (history, B, width)
    mean = prof.mean(axis=1)
    dip_mean = dip_depth(mean, xi, a["dip_center"], a["dip_flank"])                # (history, width)
    dip_lo, dip_hi = basic_band(dip_mean, boot_dip, lo, hi, axis=1)
    dev = stack("cut_deviation")                  # (history, pile, flank, position)
    ang = stack("cut_angle")
    q = np.asarray(a["cut_positions"], float)
    boot_med = _nan(np.nanmedian, dev[:, idx], axis=2)    # (history, B, flank, position)
    ex_lo, ex_hi, ex_out, ex_done, ex_conf = exact_arrays(exact, hist, n, dev.shape[2:])
    one = lambda dims, v, u, ln: (dims, v, {"units": u, "long_name": ln})  # noqa: E731
    H, P, K, X, F, Q = "history", "pile", "kernel", "xi", "flank", "cut_position"
    out = xr.Dataset(
        {
            "profile": one((H, P, K, X), prof, "1", "ground stress / (weight / base width), per pile"),
            "profile_mean": one((H, K, X), mean, "1", "mean ground stress over piles / (weight / base width)"),
            "profile_lo": one((H, K, X), np.quantile(boot_mean, lo, axis=1), "1",
                              "bootstrap band over piles of the mean ground stress, lower end"),
            "profile_hi": one((H, K, X), np.quantile(boot_mean, hi, axis=1), "1",
                              "bootstrap band over piles of the mean ground stress, upper end"),
            "dip": one((H, P, K), dips, "1", "dip depth M - m of one pile's profile (flank maxima minus central minimum), units of the mean ground stress W/2L, > 0 a dip"),
            "dip_mean": one((H, K), dip_mean, "1", "dip depth M - m of the mean profile over piles, units of the mean ground stress W/2L, > 0 a dip"),
            "dip_lo": one((H, K), dip_lo, "1", "basic bootstrap band over piles of dip_mean, lower"),
            "dip_hi": one((H, K), dip_hi, "1", "basic bootstrap band over piles of dip_mean, upper"),
            "cut_deviation": one((H, P, F, Q), dev, "degree", "cut resultant angle minus free-surface slope "
                                 "(NaN: the cut crosses no contact)"),
            "cut_angle": one((H, P, F, Q), ang, "degree", "cut resultant angle below the horizontal, outward"),
            "cut_count": one((H, P, F, Q), stack("cut_count"), "1", "contacts crossing the cut"),
            "deviation_median": one((H, F, Q), _nan(np.nanmedian, dev, axis=1), "degree",
                                    "median over piles of the cut deviation (cuts crossing no contact left out)"),
            "deviation_q25": one((H, F, Q), _nan(np.nanquantile, dev, 0.25, axis=1), "degree",
                                 "25th percentile over piles of the cut deviation"),
            "deviation_q75": one((H, F, Q), _nan(np.nanquantile, dev, 0.75, axis=1), "degree",
                                 "75th percentile over piles of the cut deviation"),
            "deviation_median_lo": one((H, F, Q), _nan(np.nanquantile, boot_med, lo, axis=1), "degree",
                                       "bootstrap band over piles of the median deviation, lower"),
            "deviation_median_hi": one((H, F, Q), _nan(np.nanquantile, boot_med, hi, axis=1), "degree",
                                       "bootstrap band over piles of the median deviation, upper"),
            "surface_angle": one((H, P, F), stack("surface_angle")[..., 0], "degree", "flank slope of the pile"),
            "base_half_width": one((H, P), stack("base_half_width"), "m",
                                   "L of x / L: the pile's own fitted base half-width (a layer: its point pile's)"),
            "fit_half_width": one((H, P), stack("fit_half_width"), "m", "toe-to-toe half-width of the pile's own fit"),
            "weight": one((H, P), stack("weight"), "N", "weight of the pile"),
            "ground_fx": one((H, P), stack("ground_fx"), "N", "horizontal ground reaction"),
            "ground_fy": one((H, P), stack("ground_fy"), "N", "vertical ground reaction"),
            "n_ground": one((H, P), stack("n_ground"), "1", "ground contacts"),
            "apex_height": one((H, P), stack("apex_height"), "1", "highest grain top above the ground, in d"),
            "cone_ratio": one((H, P), stack("cone_ratio"), "1",
                              "apex height / (L tan(mean flank angle)): 1 for a cone, < 1 flat-topped"),
            "n_grains": one((H, P), stack("n_grains"), "1", "grains in the final pile"),
            "n_removed": one((H, P), stack("n_removed"), "1", "poured grains that rolled off the base (removed)"),
            "exact_deviation_min": one((H, P, F, Q), ex_lo, "degree", "exact minimum over A ∩ C of the cut "
                                       "resultant angle minus the flank slope (NaN: not computed)"),
            "exact_deviation_max": one((H, P, F, Q), ex_hi, "degree", "exact maximum over A ∩ C of the cut "
                                       "resultant angle minus the flank slope (NaN: not computed)"),
            "exact_history_outside": one((H, P, F, Q), ex_out, "degree", "angle of the history resultant "
                                         "outside the exact angle range (NaN: not computed)"),
            "exact_computed": one((H, P), ex_done, "1", "exact angle ranges computed for this pile"),
            "exact_confirmed": one((H, P, F, Q), ex_conf, "1", f"exact angle range certified to {CERTIFIED_TEXT} degree (1); "
                                   "0: not computed, or the admissible resultants surround zero (no range)"),
        },
        coords={H: hist, P: np.arange(n), K: widths, X: xi, F: ["left", "right"], Q: q},
        attrs={"level": a["level"], "bootstrap": B, "permutations": a["permutations"],
               "dip_center": a["dip_center"], "dip_flank": list(a["dip_flank"]), "mean_diameter": mean_diameter(cfg)},
    )
    out[K].attrs.update(units="1", long_name="kernel standard deviation in mean grain diameters")
    out[X].attrs.update(units="1", long_name="x / base half-width")
    out[Q].attrs.update(units="1", long_name="cut position |x| / base half-width")
    return comparisons(cfg, out, hist, rng)


def _nanmax(a):
    """Largest finite value of ``a`` (NaN when none, without a warning)."""
    a = np.asarray(a, float)
    return float(np.nanmax(a)) if np.isfinite(a).any() else float("nan")


EXACT_SUMMARY = {
    "exact_piles": ("1", "piles of the history with exact angle ranges"),
    "exact_cuts": ("1", "cuts of those piles with a finite exact angle range"),
    "exact_width_median": ("degree", "median width of the finite exact angle ranges"),
    "exact_width_max": ("degree", "largest width of a finite exact angle range"),
    "exact_all_positive": ("1", "fraction of the cuts where every admissible resultant is steeper than the flank"),
    "exact_all_negative": ("1", "fraction of the cuts where every admissible resultant is shallower than the flank"),
    "exact_undefined": ("1", "fraction of the cuts whose admissible resultants surround zero (no angle range)"),
    "exact_confirmed": ("1", f"fraction of the cuts whose range is certified to {CERTIFIED_TEXT} degree"),
    "exact_outside_max": ("degree", "largest angle of a history resultant outside its exact range"),
}


def exact_summary(an, history):
    """The exact angle ranges of one history's piles in ``an`` (an analysis dataset) in the
    numbers of :data:`EXACT_SUMMARY`, or None when no pile of it has them.  Shared by the
    history page and the size study, so both state the same numbers for the same piles."""
    if "exact_computed" not in an or not int(an.exact_computed.sel(history=history).sum()):
        return None
    e = an.sel(history=history).where(an.exact_computed.sel(history=history) == 1, drop=True)
    width = (e.exact_deviation_max - e.exact_deviation_min).values
    return dict(exact_piles=int(e.sizes["pile"]), exact_cuts=int(np.isfinite(width).sum()),
                exact_width_median=float(np.nanmedian(width)), exact_width_max=float(np.nanmax(width)),
                exact_all_positive=float(np.mean(e.exact_deviation_min.values > 0)),
                exact_all_negative=float(np.mean(e.exact_deviation_max.values < 0)),
                exact_undefined=float(np.mean(np.isnan(width))),
                exact_confirmed=float(np.mean(e.exact_confirmed.values, dtype=float)) if "exact_confirmed" in e else np.nan,
                exact_outside_max=_nanmax(e.exact_history_outside.values))


def comparison_summary(an, name, kernel=None):
    """One comparison of ``an`` (:func:`comparisons`) at one kernel (default the first): the
    shape differences with their bands, the match and its resolution, the p-values by
    measure, the measures that differ (Bonferroni) and the differences with their bands.
    Shared by the history page, its claims and the size study."""
    s = an.sel(comparison=name)
    k = an.kernel.values[0] if kernel is None else kernel
    sk = s.sel(kernel=k)
    rel, rlo, rhi = s.cmp_shape_rel.values, s.cmp_shape_rel_lo.values, s.cmp_shape_rel_hi.values
    tol = float(an.attrs.get("shape_tol", cmp.SHAPE_TOL))
    alpha = float(an.attrs.get("alpha", cmp.ALPHA))
    p = cmp.p_values({"p_shape": s.cmp_p_shape.values, "p_profile_gap": sk.cmp_p_profile_gap.values,
                      "p_dip": sk.cmp_p_dip.values, "p_arching": s.cmp_p_arching.values})
    return dict(name=name, kernel=float(k), tol=tol, alpha=alpha,
                shape={m: dict(rel=float(r), lo=float(lo), hi=float(hi), diff=float(dd), ref=float(ref))
                       for m, r, lo, hi, dd, ref in zip(cmp.SHAPES, rel, rlo, rhi, s.cmp_shape_diff.values,
                                                        s.cmp_shape_reference.values)},
                matched=cmp.shape_matched(rel, tol), resolved=cmp.equivalence_resolved(rlo, rhi, tol),
                p=p, differing=cmp.differing(p, alpha),
                dip=float(sk.cmp_dip_diff), dip_lo=float(sk.cmp_dip_diff_lo), dip_hi=float(sk.cmp_dip_diff_hi),
                gap=float(sk.cmp_profile_gap), gap_lo=float(sk.cmp_profile_gap_lo), gap_hi=float(sk.cmp_profile_gap_hi),
                arching=float(s.cmp_arching_diff), arching_lo=float(s.cmp_arching_diff_lo),
                arching_hi=float(s.cmp_arching_diff_hi))


def control_outcomes(an):
    """``[(name, differs, expected)]`` of the comparisons that control the test (those of
    :data:`COMPARISONS` with a required outcome), the null control (must not differ) first:
    whether the test finds the groups different (None when ``an`` lacks the comparison) and
    whether it must."""
    have = an.comparison.values if "comparison" in an.dims else ()
    rows = [(name, bool(comparison_summary(an, name)["differing"]) if name in have else None, row[3])
            for name, row in COMPARISONS.items() if row[3] is not None]
    return sorted(rows, key=lambda r: r[2])
