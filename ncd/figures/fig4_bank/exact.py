"""Exact ranges over A ∩ C at the surface-parallel cuts of a pile (Moreau 2005, sections 4-5).

Is the vertical force across a cut parallel to the free surface forced by the geometry of
the pile (every force state of ``A ∩ C = {r : H r + F = 0, |r_t| <= mu r_n}`` gives it), or
a property of the history forces only?  Per cut of :func:`ncd.figures.fig4_bank.measure.bank_cuts`, the
exact range of the resultant's angle to the vertical (a linear-fractional program, solved
by Dinkelbach's iteration with a certified bound, :meth:`ExactSet.angle_range`) and of its
vertical component (two LPs).  At the LP points that realise the extreme angles, the
Love-Weber stress of the cut's window is evaluated too: every state of A ∩ C balances the
moments of every grain, so its stress is symmetric and the reciprocity formula holds for
every admissible state, not only for the history forces.
"""
import time

import numpy as np
import xarray as xr

from ncd.exact.exact_set import ExactSet
from ncd.figures.fig4_bank import stress as st
from ncd.figures.fig4_bank.measure import FLANKS, bank_cuts, pile_geometry
from ncd.shared.pile import pile_problem


def exact_ranges(cfg, pile_cfg, ds, name, cuts=None, log=None):
    """Dataset of one pile over ``(flank, position, depth)``: exact angle range to the vertical
    and F_y range of each valid surface-parallel cut, the history angle, and the largest
    stress asymmetry of the window at the extreme LP points (``cfg``: the fig4_bank section;
    ``pile_cfg``: the section that built the pile, for its equilibrium problem; ``name``: the
    pile's name in measures.nc)."""
    t0 = time.perf_counter()
    scene, c, H, F, mu = pile_problem(pile_cfg, ds)
    nm = scene.n_mobile
    es = ExactSet(H, F, mu)
    geom = pile_geometry(ds, cuts)
    geo, segs, wins, _ = bank_cuts(cfg, geom, scene.pos[:nm], scene.radius[:nm])
    shape = geo["valid"].shape
    valid = geo["valid"].ravel()
    M, counts = st.segment_matrix(c, scene.pos, nm, segs)
    S, _ = st.stress_matrix(c, scene.pos, nm, wins)
    history = np.column_stack([ds["force_n"].values, ds["force_t"].values]).ravel()
    Fh = (M @ history).reshape(-1, 2)
    outer = np.repeat([o for _, o in FLANKS], shape[1] * shape[2])
    slope = np.repeat([geom["fits"][f]["angle"] for f, _ in FLANKS], shape[1] * shape[2])
    psi_hist = st.angle_to_vertical(Fh[:, 0], Fh[:, 1], outer)
    res = {k: np.full(len(segs), np.nan) for k in ("angle_min", "angle_max", "angle_bound", "fy_min", "fy_max",
                                                   "vertex_asymmetry")}
    res["n_lp"] = np.zeros(len(segs))
    for k in np.nonzero(valid & (counts > 0))[0]:
        n0 = es.n_lp
        rng = es.angle_range(st.to_vertical_rows(M[2 * k: 2 * k + 2], outer[k]), 1.0, ref=psi_hist[k],
                             tol=cfg["exact"]["angle_tol"])
        res["angle_min"][k], res["angle_max"][k], res["angle_bound"][k] = rng["lo"], rng["hi"], rng["bound"]
        res["fy_min"][k], res["fy_max"][k] = es.interval(M[2 * k + 1].toarray().ravel())
        if np.isfinite(rng["lo"]):
            res["vertex_asymmetry"][k] = np.abs(st.asymmetry((S[4 * k: 4 * k + 4] @ rng["points"].T).T)).max()
        res["n_lp"][k] = es.n_lp - n0
        if log is not None:
            log.info("cut %d: angle to the vertical in [%.2f, %.2f] deg (history %.2f), %d LPs, %.0f s so far", k,
                     res["angle_min"][k], res["angle_max"][k], psi_hist[k], res["n_lp"][k], time.perf_counter() - t0)
    outside = np.maximum(np.maximum(res["angle_min"] - psi_hist, psi_hist - res["angle_max"]), 0.0)
    # tau / sigma_n of the resultant on the cut's plane is tan(flank + angle to the vertical): monotone
    with np.errstate(invalid="ignore"):
        fail = np.tan(np.radians(slope[:, None] + np.column_stack([res["angle_min"], res["angle_max"]])))
    dims = ("flank", "position", "depth")
    one = lambda v, u, ln: (dims, np.where(valid, v, np.nan).reshape(shape), {"units": u, "long_name": ln})  # noqa: E731
    out = xr.Dataset(
        {
            "angle_min": one(res["angle_min"], "degree", "smallest angle to the vertical (positive outward) of an "
                             "admissible resultant across the surface-parallel cut"),
            "angle_max": one(res["angle_max"], "degree", "largest angle to the vertical of an admissible resultant"),
            "angle_bound": one(res["angle_bound"], "degree", "certified bound on the error of the exact angle "
                               "range (NaN: the admissible resultants surround zero)"),
            "history_angle": one(psi_hist, "degree", "angle to the vertical of the history forces' resultant"),
            "history_outside": one(outside, "degree", "angle of the history resultant outside the exact range"),
            "fy_min": one(res["fy_min"], "N", "smallest F_y of an admissible resultant"),
            "fy_max": one(res["fy_max"], "N", "largest F_y of an admissible resultant"),
            "mobilized_min": one(fail[:, 0], "1", "smallest tau / sigma_n of an admissible resultant on the cut"),
            "mobilized_max": one(fail[:, 1], "1", "largest tau / sigma_n of an admissible resultant on the cut"),
            "vertex_asymmetry": one(res["vertex_asymmetry"], "1", "largest |sigma_xy - sigma_yx| / p of the "
                                    "window at the two LP points of the extreme angles"),
            "n_lp": one(res["n_lp"], "1", "linear programs of the cut"),
        },
        coords={"flank": [f for f, _ in FLANKS], "position": np.asarray(cfg["positions"], float),
                "depth": np.asarray(cfg["depths_d"], float)},
        attrs={"pile": name,
               "n_contacts": int(c.n), "n_lp_total": int(es.n_lp), "lp_wall_time": float(es.lp_time),
               "left_angle": geom["fits"]["left"]["angle"], "right_angle": geom["fits"]["right"]["angle"]},
    )
    out["position"].attrs.update(units="1", long_name="cut centre |x| / L")
    out["depth"].attrs.update(units="1", long_name="depth of the cut below the free surface (normal), mean diameters")
    if log is not None:
        log.info("%d cuts, %d LPs, %.1f s", int(valid.sum()), es.n_lp, time.perf_counter() - t0)
    return out
