"""Ground pressure and arching over ensembles of piles of two histories (Moreau 2005, section 5).

Per pile, from its history forces: the ground stress profile ``p(x / L)`` (kernel
average of the ground contacts, normalised by the mean stress ``W / (2 L)``), the dip
depth ``M - m`` in units of that mean stress (> 0 a dip under the apex; the name, unit and
sign of the single pile's dip in :mod:`ncd.figures.fig4_pile.pressure`) and the angle of the resultant across
vertical cuts at ``x = ± q L`` against the pile's flank slope.  Statistics resample piles,
never runs of one pile.  The dip is a minimum against maxima of a noisier resampled
profile, so its percentile band is biased upwards; the dip and difference bands are
therefore *basic* bootstrap bands (:func:`basic_band`), correct to first order.
"""
import warnings

import numpy as np
import xarray as xr

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
    """``L`` of ``xi = x / L``: the base half-width of the member's point-source pile (for a
    rain pile, the half-width of its finite base), so that both piles of a member share
    the abscissa."""
    return float(ds.attrs["point_half_width"])


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
    idx2 = bootstrap_index(rng, n, B)             # independent resamples of the second history
    diff_boot = boot_dip[0] - dip_depth(prof[-1][idx2].mean(axis=1), xi, a["dip_center"], a["dip_flank"])
    dip_lo, dip_hi = basic_band(dip_mean, boot_dip, lo, hi, axis=1)
    diff_lo, diff_hi = basic_band(dip_mean[0] - dip_mean[-1], diff_boot, lo, hi, axis=0)
    p_value = np.array([permutation_p(dip_mean[0, j], dip_mean[-1, j], prof[0, :, j], prof[-1, :, j], xi,
                                      a["dip_center"], a["dip_flank"], rng, a["permutations"]) for j in range(len(widths))])
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
            "dip_diff": one((K,), dip_mean[0] - dip_mean[-1], "1", f"dip_mean {hist[0]} minus {hist[-1]}"),
            "dip_diff_lo": one((K,), diff_lo, "1", "basic bootstrap band of dip_diff, lower"),
            "dip_diff_hi": one((K,), diff_hi, "1", "basic bootstrap band of dip_diff, upper"),
            "dip_diff_p": one((K,), p_value, "1", "two-sided permutation p-value of dip_diff (labels over piles)"),
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
                                   "L: base half-width of the member's point-source pile"),
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
    return out


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
