"""Figure 4, exactly: the set A ∩ C of the pile's final configuration (Moreau 2005, sections 4-5).

The equilibrium forces of the final arrangement form the polytope
``A ∩ C = {r : H r + F = 0, |r_t| <= mu r_n}`` (:class:`ncd.polytope.ForcePolytope`
builds its scaled equations and Coulomb rows).  Every quantity of the figure is a
linear map of ``r`` (cut resultants, ground forces), so its exact range over
A ∩ C is given by linear programs.  :class:`ExactSet` keeps one sparse HiGHS
model (``highspy``) whose only rows are the equilibrium equations (the Coulomb
sectors are column bounds, :func:`cone_columns`) and changes only its objective
between queries, so that each LP restarts (primal simplex) from the previous
optimal basis:

* :meth:`ExactSet.polygon`: the exact projection of A ∩ C under a 2-row map
  (a cut resultant) -- ``n_dirs`` support directions evenly spread, then every
  hull edge tested along its outer normal until inner and outer polygons agree;
* :meth:`ExactSet.interval`: the exact min and max of one linear functional
  (a ground-pressure value, a dip depth, the vertical component of a resultant).

:func:`exact_dataset` applies them to the pile (``exact.nc``): the polygons of
the default cut and of the cuts moved by ``± shift_d``, per cut of both flanks
the exact range of the resultant's angle below the horizontal and of its
vertical component (a state *arches* across a cut when the inner side pushes the
bank downward, ``F_y < 0``: every admissible state arches iff ``max F_y < 0``),
and the exact range of the ground pressure (:mod:`ncd.figures.pressure`).
"""
import time

import highspy
import numpy as np
import scipy.sparse as sp
import xarray as xr

from ..contacts import h_matrix
from ..io import provenance
from ..polygon import hull_area, outside_distance, polygon_area, support_polygon
from ..polytope import ForcePolytope, PolytopeError
from . import cuts as cm

FEAS_TOL = 1e-10


class ExactSet:
    """A ∩ C of ``H r + F = 0`` (r: 2 kappa forces) with Coulomb cones, as one HiGHS model."""

    def __init__(self, H, F, mu):
        self.fp = fp = ForcePolytope(H, F, mu)
        self.scale, self.n = fp.scale, 2 * fp.n_contacts
        self.T, upper = cone_columns(fp.mu)
        self._Tt = self.T.T.tocsr()
        A = (fp.A_eq @ self.T).tocsc()
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = self.n, A.shape[0]
        lp.col_cost_ = np.zeros(self.n)
        lp.col_lower_ = np.zeros(self.n)
        lp.col_upper_ = upper
        lp.row_lower_ = fp.b_eq
        lp.row_upper_ = fp.b_eq
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_ = A.indptr
        lp.a_matrix_.index_ = A.indices
        lp.a_matrix_.value_ = A.data
        h = highspy.Highs()
        h.silent()
        for k, v in (("primal_feasibility_tolerance", FEAS_TOL), ("dual_feasibility_tolerance", FEAS_TOL),
                     ("threads", 1), ("random_seed", 0), ("simplex_strategy", 4)):
            h.setOptionValue(k, v)
        h.passModel(lp)
        self.highs, self.n_lp, self.lp_time = h, 0, 0.0
        self._cols = np.arange(self.n, dtype=np.int32)

    def minimize(self, c):
        """``(min c . r, r)`` over A ∩ C (``c`` in force units, ``r`` forces)."""
        t0 = time.perf_counter()
        self.highs.changeColsCost(self.n, self._cols, self._Tt @ np.asarray(c, dtype=float) * self.scale)
        self.highs.run()
        status = self.highs.getModelStatus()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        if status == highspy.HighsModelStatus.kInfeasible:
            raise PolytopeError("A ∩ C is empty: no contact forces balance the weights")
        if status != highspy.HighsModelStatus.kOptimal:
            raise PolytopeError(f"LP not solved: {self.highs.modelStatusToString(status)}")
        r = self.T @ np.maximum(np.asarray(self.highs.getSolution().col_value), 0.0) * self.scale
        return float(np.dot(c, r)), r

    def interval(self, c):
        """Exact ``(min, max)`` of ``c . r`` over A ∩ C."""
        lo = self.minimize(c)[0]
        hi = -self.minimize(-np.asarray(c, dtype=float))[0]
        return lo, hi

    def refine(self, r, active_tol=1e-7):
        """An LP vertex ``r`` (forces) made exact: the Coulomb rows it meets within
        ``active_tol`` (scaled) and the equilibrium equations solved together by the
        minimum-norm correction (iterated Tikhonov on ``[[I, K^T], [K, -eps I]]``, one
        sparse LU), which removes the LP's feasibility-tolerance residue (HiGHS: ~1e-8
        of the force scale)."""
        x = np.asarray(r, float) / self.scale
        G, A = self.fp.G, self.fp.A_eq
        act = (G @ x) >= -active_tol
        K = sp.vstack([A, G[np.nonzero(act)[0]]]).tocsr()
        rhs = np.concatenate([self.fp.b_eq, np.zeros(int(act.sum()))])
        return (x + _min_norm(K, rhs - K @ x)) * self.scale

    def intervals(self, rows):
        """Exact ``(min, max)`` of each row of a sparse matrix over A ∩ C, shape (m, 2).

        All minima first, then all maxima, in row order: neighbouring rows (a
        pressure profile) have neighbouring optima, so each LP restarts close by."""
        rows = sp.csr_matrix(rows)
        out = np.empty((rows.shape[0], 2))
        for j, sign in ((0, 1.0), (1, -1.0)):
            for i in range(rows.shape[0]):
                out[i, j] = sign * self.minimize(sign * rows[i].toarray().ravel())[0]
        return out

    def polygon(self, L, n_dirs=180, tol=1e-9, max_lp=4000):
        """Exact image of A ∩ C under the (2, 2 kappa) map ``L``: a convex polygon.

        Support points in ``n_dirs`` evenly spread directions, then each edge of
        their hull tested along its outer normal (a point beyond it by more than
        ``tol`` times the force scale is added) until every edge is confirmed.
        Returns ``vertices`` (ccw), ``inner_area``, ``outer_area`` (the polygon
        of all supporting half-planes), ``n_lp``, ``exact`` and ``points`` (the
        support points' full force vectors, one per LP).
        """
        L = sp.csr_matrix(L)
        Lt = L.T.tocsr()
        full = []

        def query(u):
            _, r = self.minimize(-(Lt @ u))
            full.append(r)
            return L @ r

        dirs = [np.array([np.cos(a), np.sin(a)]) for a in 2 * np.pi * np.arange(n_dirs) / n_dirs]
        out = support_polygon(query, dirs, tol * self.scale, max_lp, self.scale)
        out["points"] = np.array(full)
        return out


def cone_columns(mu):
    """The Coulomb sectors as bounds: ``r = T y`` with ``y >= 0`` (``y <= upper``).

    Per contact ``y = (a, b) = (mu r_n + r_t, mu r_n - r_t)``, so that ``|r_t| <= mu r_n``
    is ``a, b >= 0`` (``r_n = (a + b) / (2 mu)``, ``r_t = (a - b) / 2``); a frictionless
    contact has ``r_n = a``, ``r_t = 0`` (``b`` fixed at 0).  The LP then has only the
    equilibrium rows, and every LP point satisfies Coulomb's law to round-off."""
    mu = np.asarray(mu, dtype=float)
    k = len(mu)
    i = np.arange(k)
    rough = mu > 0
    inv = np.where(rough, 0.5 / np.where(rough, mu, 1.0), 1.0)
    rows = np.concatenate([2 * i, 2 * i, 2 * i + 1, 2 * i + 1])
    cols = np.concatenate([2 * i, 2 * i + 1, 2 * i, 2 * i + 1])
    vals = np.concatenate([inv, np.where(rough, inv, 0.0), np.where(rough, 0.5, 0.0), np.where(rough, -0.5, 0.0)])
    T = sp.csr_matrix((vals, (rows, cols)), shape=(2 * k, 2 * k))
    T.eliminate_zeros()
    upper = np.full(2 * k, highspy.kHighsInf)
    upper[2 * i[~rough] + 1] = 0.0
    return T, upper


def _min_norm(K, r, eps=1e-12, refine=20):
    """Minimum-norm ``d`` with ``K d = r`` (K: p x n sparse, consistent)."""
    from scipy.sparse.linalg import splu
    p, n = K.shape
    lu = splu(sp.bmat([[sp.identity(n), K.T], [K, -eps * sp.identity(p)]], format="csc"))
    d = np.zeros(n)
    for _ in range(refine):
        e = r - K @ d
        if np.abs(e).max(initial=0.0) <= 1e-16 * max(np.abs(r).max(initial=0.0), 1e-300):
            break
        d += lu.solve(np.concatenate([np.zeros(n), e]))[:n]
    return d


def pile_problem(cfg, construction):
    """``(scene, contacts, H, F, mu)`` of the final configuration: ``H r + F = 0`` (forces)."""
    from .pile import equilibrium_problem, final_scene
    scene = final_scene(cfg, construction)
    c = equilibrium_problem(cfg, scene, construction).contacts
    nm = scene.n_mobile
    F = np.zeros((nm, 3))
    F[:, :2] = scene.mass[:nm, None] * scene.gravity[None, :]
    return scene, c, h_matrix(scene, c), F.ravel(), c.mu


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
    from . import pressure as pm
    from .pile import _cut_specs, mean_diameter
    ex = cfg["exact"]
    scene, c, H, F, mu = pile_problem(cfg, construction)
    nm, d = scene.n_mobile, mean_diameter(cfg)
    weight = float(construction.attrs["weight"])
    history = np.column_stack([construction["force_n"].values, construction["force_t"].values]).ravel()
    t0 = time.perf_counter()
    es = ExactSet(H, F, mu)
    C, _ = cm.cut_matrix(c, scene.pos, nm, _cut_specs(cuts))
    kind, outer = cuts["kind"].values, cuts["outer"].values
    # (a) the polygons of the default and shifted cuts, (b) every cut's exact polygon
    polys, n_lp, exact, walls = [], [], [], []
    for k in range(len(kind)):
        n_dirs = ex["n_dirs"] if kind[k] != "scan" else ex["scan_dirs"]
        t1 = time.perf_counter()
        p = es.polygon(C[2 * k: 2 * k + 2], n_dirs=n_dirs, tol=ex["tol"])
        walls.append(time.perf_counter() - t1)
        polys.append(p["vertices"])
        n_lp.append(p["n_lp"])
        exact.append(p["exact"])
        if k == 0:   # the support points of the first directions, refined to exact vertices
            refined = np.array([es.refine(r) for r in p["points"][:ex["check_vertices"]]])
            eq, co = es.fp.violations(refined)
            vertex_check = (float(eq.max()), float(co.max()))
            vertex_shift = float(np.abs(refined - p["points"][:len(refined)]).max() / es.scale)
        if log is not None and kind[k] != "scan":
            log.info("cut %d (%s): %d vertices, %d LPs, %.1f s", k, kind[k], len(p["vertices"]), p["n_lp"],
                     walls[-1])
    angle = np.array([resultant_angle(v, o) for v, o in zip(polys, outer)])
    fy_max = np.array([v[:, 1].max() for v in polys])
    fy_min = np.array([v[:, 1].min() for v in polys])
    hist_F = (C @ history).reshape(-1, 2)
    hist_out = np.array([outside_distance(hist_F[k:k + 1], polys[k])[0] for k in range(len(kind))])
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
    depth_hist = D @ history
    depth_band = es.intervals(D)
    main = labels.index(f"kernel {ex['kernel_d']:g} d")
    spread = float(depth_hist.max() - depth_hist.min())
    geometry, called = pm.dip_verdict(depth_hist[main], spread, *depth_band[main])
    if log is not None:
        log.info("%d LPs in %.1f s (%.1f s in HiGHS), total %.1f s", es.n_lp, es.lp_time, es.lp_time,
                 time.perf_counter() - t0)
    width = max(len(v) for v in polys)
    V = _pad(polys, width)
    ds = xr.Dataset(
        {
            "vertex_fx": (("cut", "vertex"), V[..., 0], {"units": "N", "long_name": "exact polygon of the cut resultant: F_x of its vertices (NaN padding)"}),
            "vertex_fy": (("cut", "vertex"), V[..., 1], {"units": "N", "long_name": "exact polygon of the cut resultant: F_y of its vertices (NaN padding)"}),
            "n_vertices": ("cut", np.array([len(v) for v in polys]), {"units": "1", "long_name": "vertices of the exact polygon"}),
            "polygon_area": ("cut", np.array([max(polygon_area(v), 0.0) for v in polys]), {"units": "N2", "long_name": "area of the exact polygon"}),
            "n_lp": ("cut", np.array(n_lp), {"units": "1", "long_name": "linear programs solved for the polygon"}),
            "exact": ("cut", np.array(exact, np.int8), {"units": "1", "long_name": "polygon confirmed edge by edge (1) or LP budget exhausted (0)", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "budget_exhausted confirmed"}),
            "angle_min": ("cut", angle[:, 0], {"units": "degree", "long_name": "smallest angle below the horizontal (outward) of an admissible resultant"}),
            "angle_max": ("cut", angle[:, 1], {"units": "degree", "long_name": "largest angle below the horizontal (outward) of an admissible resultant"}),
            "fy_min": ("cut", fy_min, {"units": "N", "long_name": "smallest vertical component of an admissible resultant"}),
            "fy_max": ("cut", fy_max, {"units": "N", "long_name": "largest vertical component of an admissible resultant (< 0: every state arches)"}),
            "all_arch": ("cut", (fy_max < 0).astype(np.int8), {"units": "1", "long_name": "every admissible state pushes the bank downward across this cut", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "not_every_state every_state"}),
            "history_outside": ("cut", hist_out, {"units": "N", "long_name": "distance of the history resultant outside the exact polygon"}),
            "polygon_wall_time": ("cut", np.array(walls), {"units": "s", "long_name": "measured wall time of the polygon's LPs (a measurement, not reproducible)"}),
            "bin_min": ("bin", band_bin[:, 0] , {"units": "N m-1", "long_name": "exact minimum of the binned ground pressure over A ∩ C"}),
            "bin_max": ("bin", band_bin[:, 1], {"units": "N m-1", "long_name": "exact maximum of the binned ground pressure over A ∩ C"}),
            "kernel_min": ("x_kernel", band_kernel[:, 0], {"units": "N m-1", "long_name": "exact minimum of the kernel ground pressure over A ∩ C"}),
            "kernel_max": ("x_kernel", band_kernel[:, 1], {"units": "N m-1", "long_name": "exact maximum of the kernel ground pressure over A ∩ C"}),
            "kernel_history": ("x_kernel", K @ history, {"units": "N m-1", "long_name": "kernel ground pressure of the history forces"}),
            "choice": ("choice", np.array(labels), {"units": "1", "long_name": "ground-pressure estimate (kernel width, or bin width and shift)"}),
            "depth_history": ("choice", depth_hist, {"units": "N m-1", "long_name": "dip depth p(0) - (p(-a) + p(a))/2 of the history forces"}),
            "depth_min": ("choice", depth_band[:, 0], {"units": "N m-1", "long_name": "exact minimum of the dip depth over A ∩ C"}),
            "depth_max": ("choice", depth_band[:, 1], {"units": "N m-1", "long_name": "exact maximum of the dip depth over A ∩ C"}),
        },
        coords={"cut": cuts["cut"].values, "vertex": np.arange(width), "bin": cuts["bin"].values,
                "x_kernel": xg},
        attrs=provenance(cfg, weight=weight, n_contacts=c.n, n_grains=nm, mean_diameter=d,
                         vertex_equilibrium=vertex_check[0], vertex_coulomb=vertex_check[1],
                         vertex_refinement=vertex_shift,
                         dip_geometry=geometry, dip_called=called, dip_binning_spread=spread,
                         dip_main_choice=labels[main], dip_offset=ex["dip_offset_d"] * d,
                         kernel_width=ex["kernel_d"] * d, n_lp_total=es.n_lp),
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
    from ..convergence import REST
    return ens["outcome"].values == REST


def cloud_in_polygon(exact, ens, k, mask):
    """Points of cut ``k`` of the runs in ``mask``, their distance outside the exact
    polygon (N) and the coverage (cloud hull area / polygon area)."""
    P = np.column_stack([ens.cut_force_x.values[mask, k], ens.cut_force_y.values[mask, k]])
    poly = polygon_of(exact, k)
    out = outside_distance(P, poly) if len(P) else np.zeros(0)
    area = float(exact.polygon_area.values[k])
    return P, out, (hull_area(P) / area if area > 0 and len(P) >= 3 else 0.0)


def draw_cloud(ax, exact, ens, k, mask, color="C0", label=None):
    """The exact polygon of cut ``k`` (shaded) and the converged rest runs (dots)."""
    poly = polygon_of(exact, k)
    ax.fill(*np.vstack([poly, poly[:1]]).T, color="0.85", lw=0.8, ec="0.4", label="exact projection of A ∩ C")
    P, _, _ = cloud_in_polygon(exact, ens, k, mask)
    ax.plot(P[:, 0], P[:, 1], ".", ms=2, color=color, label=label)
    ax.set(xlabel="$F_x$ (N)", ylabel="$F_y$ (N)")
    ax.set_aspect("equal", adjustable="datalim")


def exact_text(exact, ens, cuts):
    """Markdown from exact.nc and the ensemble: outcomes, polygons and coverage of the
    default and shifted cuts, arching over all cuts, the ground-pressure dip verdict."""
    from ..convergence import OUTCOMES
    a, W = exact.attrs, float(exact.attrs["weight"])
    oc = ens["outcome"].values
    counts = {OUTCOMES[k]: int((oc == k).sum()) for k in sorted(OUTCOMES)}
    mask = oc == 1
    lines = [f"Of the {len(oc)} zero-guess runs, {counts['rest']} converged at rest, {counts['motion']} converged "
             f"on a motion solution (grains moving faster than the rest bound) and {counts['unconverged']} did "
             f"not converge; only the {counts['rest']} rest states are drawn."]
    for k, name in ((0, "default"), (1, "moved by -1 d"), (2, "moved by +1 d")):
        P, out, cov = cloud_in_polygon(exact, ens, k, mask)
        lines.append(f"Cut {name}: exact polygon of {int(exact.n_vertices[k])} vertices ({int(exact.n_lp[k])} LPs), "
                     f"diameter {_diameter(polygon_of(exact, k)):.4f} N; the rest runs cover "
                     f"{100 * cov:.2g} % of its area and lie inside it to "
                     f"{(out.max() if len(out) else 0.0) / W:.1e} of the weight.")
    arch = exact.all_arch.values.astype(bool)
    lines.append(f"Every admissible force state arches (pushes the bank downward) across {arch.sum()} of the "
                 f"{len(arch)} cuts; the exact angle of the resultant below the horizontal spans "
                 f"{np.nanmin(exact.angle_max.values - exact.angle_min.values):.1f}° to "
                 f"{np.nanmax(exact.angle_max.values - exact.angle_min.values):.1f}° (median "
                 f"{np.nanmedian(exact.angle_max.values - exact.angle_min.values):.1f}°) across a cut.")
    m = list(exact.choice.values).index(a["dip_main_choice"])
    lines.append(f"Ground pressure ({a['dip_main_choice']} kernel): dip depth p(0) - (p(-a)+p(a))/2 with "
                 f"a = {a['dip_offset'] * 1e3:.1f} mm is {float(exact.depth_history[m]):.1f} N/m for the history "
                 f"forces; over the analysis choices it spans {a['dip_binning_spread']:.1f} N/m; over A ∩ C it "
                 f"ranges exactly from {float(exact.depth_min[m]):.1f} to {float(exact.depth_max[m]):.1f} N/m: a dip "
                 f"is **{a['dip_geometry']}** by the geometry, and "
                 f"{'a dip is called' if a['dip_called'] else 'no dip is called'}.")
    return "\n\n".join(lines)


def _diameter(v):
    v = np.asarray(v).reshape(-1, 2)
    return float(np.hypot(*(v[:, None] - v[None]).transpose(2, 0, 1)).max()) if len(v) else 0.0
