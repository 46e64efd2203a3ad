"""Figure 4, exactly: the set A ∩ C of the pile's final configuration (Moreau 2005, sections 4-5).

Every quantity of the figure is a linear map of the forces ``r`` (cut resultants, ground
forces), so its exact range over ``A ∩ C = {r : H r + F = 0, |r_t| <= mu r_n}`` is given by
LPs on one warm-started HiGHS model (:class:`ncd.exact.exact_set.ExactSet`).
:func:`exact_dataset` writes ``exact.nc``: (a) the exact polygon of the cut resultant, (b)
per cut the range of its angle and of its vertical component (every admissible state
arches iff ``max F_y < 0``), (c) the range of the ground pressure and the dip verdict.
"""
import time

import numpy as np
import xarray as xr

from ncd.exact.exact_set import ExactSet
from ncd.exact.polygon import hull_area, outside_distance, polygon_area
from ncd.figures.fig4_pile import pressure as pm
from ncd.io.netcdf import provenance
from ncd.shared import cuts as cm
from ncd.shared.pile import cut_specs, pile_problem
from ncd.shared.sources import mean_diameter
from ncd.solver.convergence import REST

__all__ = ["ExactSet", "exact_dataset", "pile_problem", "resultant_angle"]


def resultant_angle(vertices, outer):
    """Range of the angle below the horizontal (degrees, pointing outward) of the
    resultants of a convex polygon not containing the origin (nan, nan if it does)."""
    v = np.asarray(vertices, float).reshape(-1, 2)
    if len(v) >= 3 and outside_distance(np.zeros((1, 2)), v)[0] == 0.0:
        return np.nan, np.nan
    phi = np.degrees(np.arctan2(-v[:, 1], outer * v[:, 0]))
    # the polygon subtends less than 180 degrees: unwrap around the mean direction
    ref = np.degrees(np.arctan2(-v[:, 1].mean(), outer * v[:, 0].mean()))
    d = (phi - ref + 180.0) % 360.0 - 180.0
    return float(ref + d.min()), float(ref + d.max())


def _pad(arrays, width):
    """Stack ragged (k, 2) arrays into (n, width, 2) padded with NaN."""
    out = np.full((len(arrays), width, 2), np.nan)
    for i, a in enumerate(arrays):
        out[i, :len(a)] = a
    return out


def exact_dataset(cfg, construction, cuts, log=None):
    """exact.nc: polygons of the default and shifted cuts, the exact angle range and
    arching of every cut, the exact ground-pressure bands and the dip verdict."""
    ex = cfg["exact"]
    scene, c, H, F, mu = pile_problem(cfg, construction)
    nm, d = scene.n_mobile, mean_diameter(cfg)
    weight = float(construction.attrs["weight"])
    history = np.column_stack([construction["force_n"].values, construction["force_t"].values]).ravel()
    t0 = time.perf_counter()
    es = ExactSet(H, F, mu)
    C, _ = cm.cut_matrix(c, scene.pos, nm, cut_specs(cuts))
    kind, outer = cuts["kind"].values, cuts["outer"].values
    hist_F = (C @ history).reshape(-1, 2)
    hist_angle = cm.flank_angles(hist_F[:, 0], hist_F[:, 1], outer, 0.0)[0]     # NaN: a cut crossing no contact
    # (a) the polygons of the default and shifted cuts
    polys, n_lp, exact, walls = [], [], [], []
    for k in np.nonzero(kind != "scan")[0]:
        t1 = time.perf_counter()
        p = es.polygon(C[2 * k: 2 * k + 2], n_dirs=ex["n_dirs"], tol=ex["tol"])
        walls.append(time.perf_counter() - t1)
        polys.append(p["vertices"])
        n_lp.append(p["n_lp"])
        exact.append(p["exact"])
        if k == 0:   # the support points of the first directions, refined to exact vertices
            refined = np.array([es.refine(r) for r in p["points"][:ex["check_vertices"]]])
            eq, co = es.fp.violations(refined)
            vertex_check = (float(eq.max()), float(co.max()))
            vertex_shift = float(np.abs(refined - p["points"][:len(refined)]).max() / es.scale)
        if log is not None:
            log.info("cut %d (%s): %d vertices, %d LPs, %.1f s", k, kind[k], len(p["vertices"]), p["n_lp"],
                     walls[-1])
    n_poly = len(polys)
    # (b) every cut: the exact angle range (linear-fractional LPs) and vertical component
    angle, bound, fy, angle_lp = np.empty((len(kind), 2)), np.empty(len(kind)), np.empty((len(kind), 2)), []
    for k in range(len(kind)):
        n0 = es.n_lp
        rng = es.angle_range(C[2 * k: 2 * k + 2], outer[k], ref=hist_angle[k], tol=ex["angle_tol"])
        angle[k], bound[k] = (rng["lo"], rng["hi"]), rng["bound"]
        fy[k] = es.interval(C[2 * k + 1].toarray().ravel())
        angle_lp.append(es.n_lp - n0)
    fy_min, fy_max = fy[:, 0], fy[:, 1]
    poly_angle = np.array([resultant_angle(v, o) for v, o in zip(polys, outer[:n_poly])]).reshape(-1, 2)
    polygon_angle_gap = float(np.abs(poly_angle - angle[:n_poly]).max()) if n_poly else 0.0
    hist_out = np.full(len(kind), np.nan)
    hist_out[:n_poly] = [outside_distance(hist_F[k:k + 1], polys[k])[0] for k in range(n_poly)]
    hist_angle_out = np.maximum(np.maximum(angle[:, 0] - hist_angle, hist_angle - angle[:, 1]), 0.0)
    # (c) ground pressure: the bins of cuts.nc and a kernel average on a grid
    edges = np.append(cuts["bin_lo"].values, cuts["bin_hi"].values[-1])
    B = pm.bin_matrix(c, nm, edges)
    xg = ex["grid_d"] * d * np.arange(-int(ex["grid_half_d"] / ex["grid_d"]), int(ex["grid_half_d"] / ex["grid_d"]) + 1)
    K = pm.kernel_matrix(c, nm, xg, ex["kernel_d"] * d)
    band_bin = es.intervals(B)
    band_kernel = es.intervals(K)
    # the dip: depth per analysis choice, history values, exact ranges
    labels, D = pm.sensitivity_rows(c, nm, d, ex["dip_offset_d"] * d, ex["kernel_widths_d"],
                                    ex["bin_widths_d"], ex["bin_shifts"])
    # in units of the mean ground stress W / 2L (2L: toe to toe), as the history piles' dip
    mean_stress = weight / (float(cuts.attrs["right_toe"]) - float(cuts.attrs["left_toe"]))
    D = (D / mean_stress).tocsr()
    depth_hist = D @ history
    depth_band = es.intervals(D)
    main = labels.index(f"kernel {ex['kernel_d']:g} d")
    spread = float(depth_hist.max() - depth_hist.min())
    geometry, called = pm.dip_verdict(depth_hist[main], spread, *depth_band[main])
    if log is not None:
        log.info("%d LPs in %.1f s (%.1f s in HiGHS), total %.1f s", es.n_lp, es.lp_time, es.lp_time,
                 time.perf_counter() - t0)
    n_cut = len(kind)
    width = max(len(v) for v in polys)
    V = np.full((n_cut, width, 2), np.nan)
    V[:n_poly] = _pad(polys, width)

    def per_cut(values, fill):
        out = np.full(n_cut, fill, dtype=np.asarray(values).dtype if len(values) else float)
        out[:n_poly] = values
        return out

    ds = xr.Dataset(
        {
            "vertex_fx": (("cut", "vertex"), V[..., 0], {"units": "N", "long_name": "exact polygon of the cut resultant: F_x of its vertices (NaN padding)"}),
            "vertex_fy": (("cut", "vertex"), V[..., 1], {"units": "N", "long_name": "exact polygon of the cut resultant: F_y of its vertices (NaN padding)"}),
            "n_vertices": ("cut", per_cut(np.array([len(v) for v in polys]), 0), {"units": "1", "long_name": "vertices of the exact polygon (0: no polygon, scan cut)"}),
            "polygon_area": ("cut", per_cut(np.array([max(polygon_area(v), 0.0) for v in polys]), np.nan), {"units": "N2", "long_name": "area of the exact polygon (NaN: no polygon)"}),
            "n_lp": ("cut", per_cut(np.array(n_lp), 0), {"units": "1", "long_name": "linear programs solved for the polygon"}),
            "angle_n_lp": ("cut", np.array(angle_lp), {"units": "1", "long_name": "linear programs solved for the angle range and the F_y range"}),
            "angle_bound": ("cut", bound, {"units": "degree", "long_name": "certified bound on the error of the exact angle range (Dinkelbach's last LP value / min of the reference component)"}),
            "exact": ("cut", per_cut(np.array(exact, np.int8), 2).astype(np.int8), {"units": "1", "long_name": "polygon confirmed edge by edge (1), LP budget exhausted (0), or no polygon computed (2: scan cut, angle range only)", "flag_values": np.array([0, 1, 2], np.int8), "flag_meanings": "budget_exhausted confirmed not_computed"}),
            "angle_min": ("cut", angle[:, 0], {"units": "degree", "long_name": "smallest angle below the horizontal (outward) of an admissible resultant"}),
            "angle_max": ("cut", angle[:, 1], {"units": "degree", "long_name": "largest angle below the horizontal (outward) of an admissible resultant"}),
            "fy_min": ("cut", fy_min, {"units": "N", "long_name": "smallest vertical component of an admissible resultant"}),
            "fy_max": ("cut", fy_max, {"units": "N", "long_name": "largest vertical component of an admissible resultant (< 0: every state arches)"}),
            "all_arch": ("cut", (fy_max < 0).astype(np.int8), {"units": "1", "long_name": "every admissible state pushes the bank downward across this cut", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "not_every_state every_state"}),
            "history_outside": ("cut", hist_out, {"units": "N", "long_name": "distance of the history resultant outside the exact polygon (NaN: no polygon)"}),
            "history_angle": ("cut", hist_angle, {"units": "degree", "long_name": "angle below the horizontal (outward) of the history forces' resultant"}),
            "history_angle_outside": ("cut", hist_angle_out, {"units": "degree", "long_name": "angle of the history resultant outside the exact angle range"}),
            "polygon_wall_time": ("cut", per_cut(np.array(walls), np.nan), {"units": "s", "long_name": "measured wall time of the polygon's LPs (a measurement, not reproducible)"}),
            "bin_min": ("bin", band_bin[:, 0] , {"units": "N m-1", "long_name": "exact minimum of the binned ground pressure over A ∩ C"}),
            "bin_max": ("bin", band_bin[:, 1], {"units": "N m-1", "long_name": "exact maximum of the binned ground pressure over A ∩ C"}),
            "kernel_min": ("x_kernel", band_kernel[:, 0], {"units": "N m-1", "long_name": "exact minimum of the kernel ground pressure over A ∩ C"}),
            "kernel_max": ("x_kernel", band_kernel[:, 1], {"units": "N m-1", "long_name": "exact maximum of the kernel ground pressure over A ∩ C"}),
            "kernel_history": ("x_kernel", K @ history, {"units": "N m-1", "long_name": "kernel ground pressure of the history forces"}),
            "choice": ("choice", np.array(labels), {"units": "1", "long_name": "ground-pressure estimate (kernel width, or bin width and shift)"}),
            "dip_history": ("choice", depth_hist, {"units": "1", "long_name": "dip depth (p(-a) + p(a))/2 - p(0) of the history forces, in units of the mean ground stress W/2L (> 0 a dip, < 0 a hump)"}),
            "dip_min": ("choice", depth_band[:, 0], {"units": "1", "long_name": "exact minimum over A ∩ C of the dip depth (units of W/2L, > 0 a dip)"}),
            "dip_max": ("choice", depth_band[:, 1], {"units": "1", "long_name": "exact maximum over A ∩ C of the dip depth (units of W/2L, > 0 a dip)"}),
        },
        coords={"cut": cuts["cut"].values, "vertex": np.arange(width), "bin": cuts["bin"].values,
                "x_kernel": xg},
        attrs=provenance(cfg, weight=weight, n_contacts=c.n, n_grains=nm, mean_diameter=d,
                         vertex_equilibrium=vertex_check[0], vertex_coulomb=vertex_check[1],
                         vertex_refinement=vertex_shift,
                         dip_geometry=geometry, dip_called=called, dip_binning_spread=spread,
                         dip_main_choice=labels[main], dip_offset=ex["dip_offset_d"] * d, dip_unit=mean_stress,
                         kernel_width=ex["kernel_d"] * d, n_lp_total=es.n_lp,
                         polygon_angle_gap=polygon_angle_gap),
    )
    ds["x_kernel"].attrs.update(units="m", long_name="abscissa of the kernel ground pressure")
    ds["vertex"].attrs.update(units="1", long_name="vertex index")
    for k in ("cut", "bin"):
        ds[k].attrs.update({a: cuts[k].attrs[a] for a in ("units", "long_name") if a in cuts[k].attrs})
    return ds


# ---------------------------------------------------------------- reading exact.nc with an ensemble
def polygon_of(exact, k):
    """Vertices (ccw) of the exact polygon of cut ``k``."""
    v = np.column_stack([exact.vertex_fx.values[k], exact.vertex_fy.values[k]])
    return v[np.isfinite(v[:, 0])]


def rest_mask(ens):
    """Runs converged at rest (outcome 1), the only ones drawn in a cloud."""
    return ens["outcome"].values == REST


def cloud_in_polygon(exact, ens, k, mask):
    """Points of cut ``k`` of the runs in ``mask``, their distance outside the exact
    polygon (N) and the coverage (cloud hull area / polygon area)."""
    P = np.column_stack([ens.cut_force_x.values[mask, k], ens.cut_force_y.values[mask, k]])
    poly = polygon_of(exact, k)
    out = outside_distance(P, poly) if len(P) else np.zeros(0)
    area = float(exact.polygon_area.values[k])
    return P, out, (hull_area(P) / area if area > 0 and len(P) >= 3 else 0.0)


def diameter(v):
    """Largest distance between two points of ``v`` (k, 2) in force space (0 for fewer than two):
    the size of a cloud or of an exact polygon."""
    v = np.asarray(v).reshape(-1, 2)
    return float(np.hypot(*(v[:, None] - v[None]).transpose(2, 0, 1)).max()) if len(v) else 0.0
