"""Exact angle ranges at the arching cuts of a pile of fig4_history (issue 16, item 3).

For one pile file, the set A ∩ C of its final configuration (every force state that
balances the weights within the Coulomb cones, :class:`ncd.figures.pile_exact.ExactSet`,
HiGHS LPs) is projected onto the resultant across each arching cut of
:func:`ncd.figures.history_analysis.pile_measures` (``x = ± q L``, whole column): the
exact polygon of admissible resultants, hence the exact range of the resultant's angle
below the horizontal and of its deviation from the pile's flank slope.  The history
forces' angle lies in that range (checked: ``history_outside``).
"""
import time

import numpy as np
import xarray as xr

from . import cuts as cm
from .history_analysis import norm_length
from .pile_exact import ExactSet, pile_problem, resultant_angle


def cut_specs(cfg, ds):
    """``(specs, outer, slope)`` of the arching cuts of a pile (as in ``pile_measures``)."""
    q = np.asarray(cfg["analysis"]["cut_positions"], float)
    L = norm_length(cfg, ds)
    specs = [(s * qq * L, s, -np.inf, np.inf) for s in (-1, 1) for qq in q]
    outer = np.repeat([-1, 1], len(q))
    slope = np.where(outer > 0, ds.attrs["right_angle"], ds.attrs["left_angle"])
    return specs, outer, slope


def exact_ranges(cfg, ds, log=None):
    """Dataset of one pile: per flank and cut position the exact angle range over A ∩ C,
    the history angle and whether the polygon was confirmed edge by edge."""
    e = cfg["exact"]
    t0 = time.perf_counter()
    scene, c, H, F, mu = pile_problem(cfg, ds)
    nm = scene.n_mobile
    es = ExactSet(H, F, mu)
    specs, outer, slope = cut_specs(cfg, ds)
    C, _ = cm.cut_matrix(c, scene.pos, nm, specs)
    hist = (C @ np.column_stack([ds["force_n"].values, ds["force_t"].values]).ravel()).reshape(-1, 2)
    phi_hist = np.degrees(np.arctan2(-hist[:, 1], outer * hist[:, 0]))
    amin, amax, exact, n_lp, fy_max = [], [], [], [], []
    from ..polytope import outside_distance
    inside = []
    for k in range(len(specs)):
        p = es.polygon(C[2 * k: 2 * k + 2], n_dirs=e["n_dirs"], tol=e["tol"], max_lp=e["max_lp"])
        lo, hi = resultant_angle(p["vertices"], outer[k])
        amin.append(lo)
        amax.append(hi)
        exact.append(p["exact"])
        n_lp.append(p["n_lp"])
        fy_max.append(p["vertices"][:, 1].max())
        inside.append(outside_distance(hist[k:k + 1], p["vertices"])[0])
    if log is not None:
        log.info("%s pile %d: %d cuts, %d LPs, %.1f s", ds.attrs["history"], ds.attrs["member"], len(specs),
                 es.n_lp, time.perf_counter() - t0)
    shape = (2, -1)
    fq = ("flank", "cut_position")
    # deviations from the flank slope, the lower end wrapped to (-180, 180] as the analysis' deviations
    dev_lo = (np.asarray(amin) - slope + 180.0) % 360.0 - 180.0
    dev_hi = dev_lo + (np.asarray(amax) - np.asarray(amin))
    q = np.asarray(cfg["analysis"]["cut_positions"], float)
    out = xr.Dataset(
        {
            "exact_angle_min": (fq, np.reshape(amin, shape), {"units": "degree", "long_name":
                                "smallest angle below the horizontal (outward) of an admissible cut resultant"}),
            "exact_angle_max": (fq, np.reshape(amax, shape), {"units": "degree", "long_name":
                                "largest angle below the horizontal (outward) of an admissible cut resultant"}),
            "exact_deviation_min": (fq, dev_lo.reshape(shape), {"units": "degree",
                                    "long_name": "smallest admissible angle minus the flank slope"}),
            "exact_deviation_max": (fq, dev_hi.reshape(shape), {"units": "degree",
                                    "long_name": "largest admissible angle minus the flank slope"}),
            "history_angle": (fq, phi_hist.reshape(shape), {"units": "degree", "long_name":
                              "angle of the history forces' cut resultant"}),
            "history_outside": (fq, np.reshape(inside, shape), {"units": "N", "long_name":
                                "distance of the history resultant outside the exact polygon"}),
            "exact_fy_max": (fq, np.reshape(fy_max, shape), {"units": "N", "long_name":
                             "largest vertical component of an admissible resultant (< 0: every state arches)"}),
            "polygon_exact": (fq, np.reshape(exact, shape).astype(np.int8), {
                "units": "1", "long_name": "polygon confirmed edge by edge (1) or LP budget exhausted (0)",
                "flag_values": np.array([0, 1], np.int8), "flag_meanings": "budget_exhausted confirmed"}),
            "n_lp": (fq, np.reshape(n_lp, shape), {"units": "1", "long_name": "linear programs of the polygon"}),
        },
        coords={"flank": ["left", "right"], "cut_position": q},
        attrs={"history": ds.attrs["history"], "member": int(ds.attrs["member"]), "n_contacts": int(c.n),
               "lp_wall_time": float(es.lp_time)},
    )
    out["cut_position"].attrs.update(units="1", long_name="cut position |x| / base half-width")
    return out
