"""Exact angle ranges at the arching cuts of a pile of fig4_history (Moreau 2005, sections 4-5).

Over ``A ∩ C`` of one pile's final configuration (:class:`ncd.exact.exact_set.ExactSet`),
the exact range of the angle of the resultant across each cut of
:func:`ncd.figures.fig4_history.analysis.pile_measures`: a linear-fractional program, solved
by the Charnes-Cooper LP with a certified error bound.  ``exact.solver`` picks the route: vertices
by simplex restarts (:class:`ExactSet`, HiGHS or CLP; the bound from a Dinkelbach LP) or an
interior point with bounds from the dual (:class:`InteriorSet`, Clarabel: the piles of 10^4
grains).  The history forces' angle must lie in that range (``history_outside`` counts the
exceptions).
"""
import time

import numpy as np
import xarray as xr

from ncd.exact.exact_set import ExactSet
from ncd.exact.interior_set import InteriorSet
from ncd.figures.fig4_history.analysis import norm_length
from ncd.shared import cuts as cm
from ncd.shared.pile import pile_problem


def cut_specs(cfg, ds):
    """``(specs, outer, slope)`` of the arching cuts of a pile (as in ``pile_measures``)."""
    q = np.asarray(cfg["analysis"]["cut_positions"], float)
    L = norm_length(cfg, ds)
    specs = [(s * qq * L, s, -np.inf, np.inf) for s in (-1, 1) for qq in q]
    outer = np.repeat([-1, 1], len(q))
    slope = np.where(outer > 0, ds.attrs["right_angle"], ds.attrs["left_angle"])
    return specs, outer, slope


def exact_ranges(cfg, ds, log=None):
    """Dataset of one pile: per flank and cut position the exact angle range over A ∩ C
    (certified, :meth:`ExactSet.angle_range`), the exact range of the vertical component
    and the history angle."""
    e = cfg["exact"]
    t0 = time.perf_counter()
    scene, c, H, F, mu = pile_problem(cfg, ds)
    nm = scene.n_mobile
    es = InteriorSet(H, F, mu) if e["solver"] == "clarabel" else ExactSet(H, F, mu, simplex=e["solver"])
    specs, outer, slope = cut_specs(cfg, ds)
    C, _ = cm.cut_matrix(c, scene.pos, nm, specs)
    hist = (C @ np.column_stack([ds["force_n"].values, ds["force_t"].values]).ravel()).reshape(-1, 2)
    phi_hist = cm.flank_angles(hist[:, 0], hist[:, 1], outer, 0.0)[0]     # NaN: a cut crossing no contact
    amin, amax, bound, n_lp, fy_max = [], [], [], [], []
    for k in range(len(specs)):
        n0 = es.n_lp
        rng = es.angle_range(C[2 * k: 2 * k + 2], outer[k], ref=phi_hist[k], tol=e["angle_tol"])
        amin.append(rng["lo"])
        amax.append(rng["hi"])
        bound.append(rng["bound"])
        fy_max.append(-es.minimize(-C[2 * k + 1].toarray().ravel())[0])     # max only: one LP
        n_lp.append(es.n_lp - n0)
        if log is not None:     # a 10^4-grain pile takes minutes per cut: show the progress
            log.info("cut %d of %d: angle range [%.3f, %.3f] deg, %d LPs, %.0f s so far", k + 1, len(specs),
                     amin[-1], amax[-1], n_lp[-1], time.perf_counter() - t0)
    amin, amax = np.asarray(amin), np.asarray(amax)
    outside = np.maximum(np.maximum(amin - phi_hist, phi_hist - amax), 0.0)
    if log is not None:
        log.info("%s pile %d: %d cuts, %d LPs, %.1f s", ds.attrs["history"], ds.attrs["member"], len(specs),
                 es.n_lp, time.perf_counter() - t0)
    shape = (2, -1)
    fq = ("flank", "cut_position")
    # deviations from the flank slope, the lower end wrapped to (-180, 180] as the analysis' deviations
    dev_lo = (amin - slope + 180.0) % 360.0 - 180.0
    dev_hi = dev_lo + (amax - amin)
    q = np.asarray(cfg["analysis"]["cut_positions"], float)
    out = xr.Dataset(
        {
            "exact_angle_min": (fq, amin.reshape(shape), {"units": "degree", "long_name":
                                "smallest angle below the horizontal (outward) of an admissible cut resultant"}),
            "exact_angle_max": (fq, amax.reshape(shape), {"units": "degree", "long_name":
                                "largest angle below the horizontal (outward) of an admissible cut resultant"}),
            "exact_deviation_min": (fq, dev_lo.reshape(shape), {"units": "degree",
                                    "long_name": "smallest admissible angle minus the flank slope"}),
            "exact_deviation_max": (fq, dev_hi.reshape(shape), {"units": "degree",
                                    "long_name": "largest admissible angle minus the flank slope"}),
            "history_angle": (fq, phi_hist.reshape(shape), {"units": "degree", "long_name":
                              "angle of the history forces' cut resultant"}),
            "history_outside": (fq, outside.reshape(shape), {"units": "degree", "long_name":
                                "angle of the history resultant outside the exact angle range"}),
            "exact_fy_max": (fq, np.reshape(fy_max, shape), {"units": "N", "long_name":
                             "largest vertical component of an admissible resultant (< 0: every state arches)"}),
            "angle_bound": (fq, np.reshape(bound, shape), {"units": "degree", "long_name":
                            "certified bound on the error of the exact angle range (NaN: the image contains 0)"}),
            "n_lp": (fq, np.reshape(n_lp, shape), {"units": "1", "long_name": "linear programs of the cut"}),
        },
        coords={"flank": ["left", "right"], "cut_position": q},
        attrs={"history": ds.attrs["history"], "member": int(ds.attrs["member"]), "n_contacts": int(c.n),
               "lp_wall_time": float(es.lp_time)},
    )
    out["cut_position"].attrs.update(units="1", long_name="cut position |x| / base half-width")
    return out
