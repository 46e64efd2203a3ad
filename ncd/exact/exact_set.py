"""A ∩ C as one sparse HiGHS model: exact ranges, polygons and angle ranges (Moreau 2005, section 4).

The equilibrium forces of a packing form the polytope
``A ∩ C = {r : H r + F = 0, |r_t| <= mu r_n}`` (:class:`ncd.exact.polytope.ForcePolytope`
builds its scaled equations).  :class:`ExactSet` keeps one HiGHS model (``highspy``)
whose only rows are the equilibrium equations -- the Coulomb sectors are column
bounds (:func:`ncd.solver.cone.cone_columns`) -- and changes only its objective between queries, so
that each LP restarts (primal simplex) from the previous optimal basis:

* :meth:`ExactSet.interval`: exact min and max of a linear functional;
* :meth:`ExactSet.polygon`: the exact image of A ∩ C under a 2-row map (a cut
  resultant), support directions then every hull edge confirmed;
* :meth:`ExactSet.angle_range`: the exact range of the direction of such an image,
  a linear-fractional program: one LP per end on a second, homogenised (Charnes-Cooper)
  model of A ∩ C, whose basis is handed back to the first for a certifying Dinkelbach LP.

``simplex="clp"`` keeps HiGHS for the first LP only and restarts every later LP with CLP
(:mod:`ncd.exact.clp_model`): on a 10^4-grain pile its primal simplex takes fewer iterations
from the previous basis (docs/solvers.md; the LP time of every pile: the bench page).
"""
import time

import highspy
import numpy as np
import scipy.sparse as sp

from ncd.core import validate
from ncd.core.errors import InputError
from ncd.exact.clp_model import BASIC, LOWER, UPPER, ClpModel
from ncd.exact.polygon import outside_distance, support_polygon
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.solver.cone import cone_columns

FEAS_TOL = 1e-10
SIMPLEX = ("highs", "clp")


class ExactSet:
    """A ∩ C of ``H r + F = 0`` (r: 2 kappa forces) with Coulomb cones, as one HiGHS model
    (and, with ``simplex="clp"``, a CLP model restarted from the first LP's basis)."""

    def __init__(self, H, F, mu, simplex="highs"):
        if simplex not in SIMPLEX:
            raise InputError(f"simplex = {simplex!r} must be one of {SIMPLEX}")
        self.fp = fp = ForcePolytope(H, F, mu)
        self.scale, self.n = fp.scale, 2 * fp.n_contacts
        self.T, upper = cone_columns(fp.mu)
        self._Tt = self.T.T.tocsr()
        self._options = dict(primal_feasibility_tolerance=FEAS_TOL, dual_feasibility_tolerance=FEAS_TOL,
                             threads=1, random_seed=0, simplex_strategy=4)
        h = sector_model(fp.A_eq, fp.b_eq, self.T, upper, **self._options)
        self.highs, self.n_lp, self.lp_time = h, 0, 0.0
        self._cols = np.arange(self.n, dtype=np.int32)
        self._upper, self._cc, self._cc_support, self._last = upper, None, np.zeros(0, dtype=np.int64), None
        self.simplex, self._clp = simplex, None

    def minimize(self, c):
        """``(min c . r, r)`` over A ∩ C (``c`` in force units, ``r`` forces)."""
        c = validate.array("c", c, (self.n,))
        t0 = time.perf_counter()
        if self._clp is not None:
            return self._minimize_clp(c, t0)
        self.highs.changeColsCost(self.n, self._cols, self._Tt @ c * self.scale)
        if self._last is None:
            # no basis yet: interior point and crossover to a vertex (on a large pile, primal
            # simplex from the slack basis would pivot far longer to its first vertex), then
            # primal simplex from that basis for every later LP
            self.highs.setOptionValue("solver", "ipm")
            self.highs.run()
            self.highs.setOptionValue("solver", "simplex")
        else:
            self.highs.run()
        status = self.highs.getModelStatus()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        self._last = "lp"
        if status == highspy.HighsModelStatus.kInfeasible:
            raise PolytopeError("A ∩ C is empty: no contact forces balance the weights")
        if status != highspy.HighsModelStatus.kOptimal:
            raise PolytopeError(f"LP not solved: {self.highs.modelStatusToString(status)}")
        if self.simplex == "clp":
            # the first LP's vertex becomes CLP's starting basis for every later LP
            fp = self.fp
            self._clp = ClpModel(fp.A_eq @ self.T, fp.b_eq, fp.b_eq, np.zeros(self.n), self._upper, FEAS_TOL)
            self._clp.set_basis(*_basis_arrays(self.highs))
        r = self.T @ np.maximum(np.asarray(self.highs.getSolution().col_value), 0.0) * self.scale
        return float(np.dot(c, r)), r

    def _minimize_clp(self, c, t0):
        """:meth:`minimize` on CLP's model of A ∩ C, from its current basis."""
        self._clp.set_cost(self._Tt @ c * self.scale)
        status = self._clp.run()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        self._last = "lp"
        if status == "primal infeasible":
            raise PolytopeError("A ∩ C is empty: no contact forces balance the weights")
        if status != "optimal":
            raise PolytopeError(f"LP not solved: CLP status {status!r}")
        r = self.T @ np.maximum(self._clp.solution(), 0.0) * self.scale
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
        sparse LU), which removes the residue that the LP's feasibility tolerance leaves
        on the equations."""
        x = np.asarray(r, float) / self.scale
        G, A = self.fp.G, self.fp.A_eq
        act = (G @ x) >= -active_tol
        K = sp.vstack([A, G[np.nonzero(act)[0]]]).tocsr()
        rhs = np.concatenate([self.fp.b_eq, np.zeros(int(act.sum()))])
        return (x + min_norm_correction(K, rhs - K @ x)) * self.scale

    def intervals(self, rows):
        """Exact ``(min, max)`` of each row of a sparse matrix over A ∩ C, shape (m, 2).

        All minima first, then all maxima, in row order: neighbouring rows (a
        pressure profile) have neighbouring optima, so each LP restarts close by."""
        rows = validate.matrix("rows", rows, (None, self.n))
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
        L = validate.matrix("L", L, (2, self.n))
        n_dirs = validate.integer("n_dirs", n_dirs, 3, 10 ** 6)
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

    def angle_range(self, L, outer=1.0, ref=None, tol=1e-12, max_lp=60, retry=True):
        """Exact range of ``phi = atan2(-g_y, outer g_x)`` over ``g = L r``, r in A ∩ C
        (degrees): the angle below the horizontal, pointing outward, of a cut resultant.

        Around a reference direction ``phi0`` (``ref``; default, or NaN: an LP point), with
        ``p = a . u``, ``q = b . u`` (``u = (outer g_x, -g_y)``, ``a`` along ``phi0``, ``b``
        normal to it), ``tan(phi - phi0) = q / p``.  The Charnes-Cooper model
        (:meth:`_fractional`, ``y = r / p``, ``t = 1 / p``) gives ``min p`` (``p_min``: ``p > 0``
        on all of A ∩ C, so the image lies in an open half-plane and its angles span less
        than 180°) and each end of ``q / p`` in one LP apiece.  Each end is then certified by
        Dinkelbach's iteration on A ∩ C started there: with ``lam = q / p`` at the current
        point, ``max (q - lam p)`` is 0 at the optimum, and otherwise its maximiser has a
        larger ratio (the first such LP starts from the end's basis and usually pivots
        nowhere).  The final LP value ``v`` bounds the error of the ratio by ``v / p_min``
        (``bound``, radians, reported).  Returns a dict: ``lo``, ``hi`` (degrees), ``bound``
        (the larger of the two certificates, degrees), ``p_min`` (N), ``n_lp``, ``points``
        (forces at the two extremes); ``lo = hi = nan`` and ``p_min <= 0`` when the image
        contains the origin.  If ``ref`` does not separate the image from the origin, the
        exact polygon (:meth:`polygon`) gives a direction that does, and the range is
        computed again around it (``retry``).
        """
        L = validate.matrix("L", L, (2, self.n))
        M = sp.diags([float(outer), -1.0]) @ L          # r -> u = (outer g_x, -g_y)
        Mt = M.T.tocsr()
        n0 = self.n_lp
        if ref is None or not np.isfinite(ref):
            u = M @ self.minimize(np.zeros(L.shape[1]))[1]
            ref = np.degrees(np.arctan2(u[1], u[0]))
        t = np.radians(ref)
        a, b = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
        ca, cb = Mt @ a, Mt @ b
        start = self._fractional(ca, cb)
        if start is None:                                # p > 0 not certified: min p on A ∩ C itself
            p_min, r = self.minimize(ca)
        else:
            p_min, r = start[0], start[1]
        out = {"p_min": p_min, "lo": np.nan, "hi": np.nan, "bound": np.nan, "points": np.zeros((2, L.shape[1]))}
        if not p_min > 1e-9 * self.scale:
            # the reference direction does not separate the image from the origin: the
            # exact polygon decides (its angle range, or NaN if it contains the origin)
            poly = self.polygon(L, n_dirs=12)
            v = (M @ np.asarray(poly["points"]).T).T
            if len(poly["vertices"]) < 3 or outside_distance(np.zeros((1, 2)), poly["vertices"])[0] > 0.0:
                phi = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
                d = (phi - ref + 180.0) % 360.0 - 180.0
                mid = ref + 0.5 * (d.min() + d.max())
                if d.max() - d.min() < 180.0 and retry:
                    out = self.angle_range(L, outer, ref=mid, tol=tol, max_lp=max_lp, retry=False)
                    out["n_lp"] = self.n_lp - n0
                    return out
            out["n_lp"] = self.n_lp - n0
            return out
        ends, bounds = [0.0, 0.0], []
        # max, then min of q / p: the model of A ∩ C is left at the smaller angle's end, near
        # the next query of the cut in history_exact (the largest vertical component)
        for j, sign in ((1, 1.0), (0, -1.0)):
            if start is not None:
                r = self._fractional_end(-sign * cb)     # max of sign q / p
            u = M @ r
            lam = sign * (b @ u) / (a @ u)
            for _ in range(max_lp):
                v, r_new = self.minimize(-(Mt @ (sign * b - lam * a)))
                v = -v                                   # max of sign q - lam p
                u_new = M @ r_new
                lam_new = sign * (b @ u_new) / (a @ u_new)
                if v <= tol * self.scale or lam_new <= lam:
                    break
                lam, r = lam_new, r_new
            ends[j] = ref + sign * np.degrees(np.arctan(lam))
            bounds.append(max(v, 0.0) / p_min)
            out["points"][j] = r
        out.update(lo=float(ends[0]), hi=float(ends[1]), bound=float(np.degrees(max(bounds))),
                   n_lp=self.n_lp - n0)
        return out

    def _fractional(self, ca, cb):
        """``(p_min, r)``: ``min p = ca . r`` over A ∩ C by the Charnes-Cooper model, or
        None if that model cannot certify ``p > 0`` (then :meth:`angle_range` falls back
        to the LP over A ∩ C and the exact polygon).

        The homogenised model ``H y + F t = 0``, ``y`` in the Coulomb sectors, ``t >= 0``,
        ``ca . y = 1`` is built once (:meth:`_homogenised`); a cut changes only its
        normalisation row (``ca`` is sparse: the contacts the cut crosses).  ``max t``
        is ``1 / min p`` when ``p > 0`` on A ∩ C (``r = y / t``), and unbounded or
        infeasible otherwise.  A basis of A ∩ C with ``t`` added as basic is a basis of
        the homogenised model, feasible where ``p > 0`` at its vertex, so the model
        restarts from the last LP of either model."""
        if self.simplex == "clp":
            return self._fractional_clp(ca)
        h = self._homogenised()
        w = self._Tt @ ca                               # ca . r = scale (w . z), r = scale T z
        idx = np.nonzero(w)[0]
        row = h.getNumRow() - 1
        for j in np.setdiff1d(self._cc_support, idx):
            h.changeCoeff(row, int(j), 0.0)
        for j in idx:
            h.changeCoeff(row, int(j), float(w[j]))
        self._cc_support = idx
        if len(idx) == 0:
            return None
        if self._last is None:                           # no basis yet: A ∩ C's own LP starts faster
            self.minimize(ca)
        if self._last == "lp":
            self._carry_basis(self.highs, h, add_t=True)
        cost = np.zeros(self.n + 1)
        cost[-1] = -1.0
        status, x = self._cc_run(cost)
        if status != highspy.HighsModelStatus.kOptimal or not x[-1] > 0.0:
            return None
        return self.scale / x[-1], self.T @ np.maximum(x[:-1], 0.0) / x[-1] * self.scale

    def _fractional_clp(self, ca):
        """:meth:`_fractional` on CLP's models (``simplex="clp"``): the homogenised model is
        built with the first cut's normalisation row, later cuts replace that row."""
        w = self._Tt @ ca
        if not np.any(w):
            return None
        if self._last is None:                           # the first LP (HiGHS) starts CLP's model of A ∩ C
            self.minimize(ca)
        row = np.append(w, 0.0)
        if self._cc is None:
            fp = self.fp
            m = fp.A_eq.shape[0]
            A = sp.vstack([sp.hstack([fp.A_eq @ self.T, -fp.b_eq[:, None]]), sp.csr_matrix(row[None, :])])
            rhs = np.append(np.zeros(m), 1.0)
            self._cc = ClpModel(A, rhs, rhs, np.zeros(self.n + 1), np.append(self._upper, np.inf), FEAS_TOL)
        else:
            self._cc.set_last_row(row, 1.0, 1.0)
        if self._last == "lp":
            col, rows = self._clp.basis()
            self._cc.set_basis(np.append(col, BASIC), np.append(rows, LOWER))
        cost = np.zeros(self.n + 1)
        cost[-1] = -1.0
        status, x = self._cc_run_clp(cost)
        if status != "optimal" or not x[-1] > 0.0:
            return None
        return self.scale / x[-1], self.T @ np.maximum(x[:-1], 0.0) / x[-1] * self.scale

    def _cc_run_clp(self, cost):
        t0 = time.perf_counter()
        self._cc.set_cost(cost)
        status = self._cc.run()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        self._last = "cc"
        return status, self._cc.solution()

    def _fractional_end(self, c):
        """Forces ``r`` minimising ``c . r / p`` (the normalisation row set by
        :meth:`_fractional`) by one LP of the homogenised model, with its basis handed to
        the model of A ∩ C (``t`` dropped) for the certifying LP."""
        if self.simplex == "clp":
            status, x = self._cc_run_clp(np.append(self._Tt @ c, 0.0))
            if status != "optimal" or not x[-1] > 0.0:
                raise PolytopeError(f"LP not solved: CLP status {status!r}")
            col, rows = self._cc.basis()
            if col[-1] == BASIC and rows[-1] != BASIC:
                self._clp.set_basis(col[:-1], rows[:-1])
            return self.T @ np.maximum(x[:-1], 0.0) / x[-1] * self.scale
        status, x = self._cc_run(np.append(self._Tt @ c, 0.0))
        if status != highspy.HighsModelStatus.kOptimal or not x[-1] > 0.0:
            raise PolytopeError(f"LP not solved: {self._cc.modelStatusToString(status)}")
        self._carry_basis(self._cc, self.highs, add_t=False)
        return self.T @ np.maximum(x[:-1], 0.0) / x[-1] * self.scale

    def _homogenised(self):
        """The Charnes-Cooper model of A ∩ C: columns ``(z, t)`` (``z`` the sector columns
        of :func:`ncd.solver.cone.cone_columns`), rows ``A_eq T z - b_eq t = 0`` and a normalisation row
        (empty until :meth:`_fractional` fills it), built on first use."""
        if self._cc is None:
            fp = self.fp
            m = fp.A_eq.shape[0]
            A = sp.vstack([sp.hstack([fp.A_eq @ self.T, -fp.b_eq[:, None]]), sp.csr_matrix((1, self.n + 1))])
            rhs = np.zeros(m + 1)
            rhs[-1] = 1.0
            self._cc = sector_model(A, rhs, sp.identity(self.n + 1, format="csr"),
                                    np.append(self._upper, highspy.kHighsInf), **self._options)
        return self._cc

    def _cc_run(self, cost):
        t0 = time.perf_counter()
        h = self._cc
        h.changeColsCost(self.n + 1, np.arange(self.n + 1, dtype=np.int32), cost)
        h.run()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        self._last = "cc"
        return h.getModelStatus(), np.asarray(h.getSolution().col_value)

    @staticmethod
    def _carry_basis(src, dst, add_t):
        """Hand the optimal basis of one model to the other: ``t`` basic and the
        normalisation row nonbasic added (``add_t``) or dropped; nothing if ``src`` has
        no valid basis or ``t`` is not basic in it."""
        basis = src.getBasis()
        if not basis.valid:
            return
        cols, rows = list(basis.col_status), list(basis.row_status)
        if add_t:
            cols.append(highspy.HighsBasisStatus.kBasic)
            rows.append(highspy.HighsBasisStatus.kLower)
        elif cols[-1] == highspy.HighsBasisStatus.kBasic and rows[-1] != highspy.HighsBasisStatus.kBasic:
            cols, rows = cols[:-1], rows[:-1]
        else:
            return
        new = highspy.HighsBasis()
        new.col_status, new.row_status = cols, rows
        dst.setBasis(new)


def _basis_arrays(highs):
    """HiGHS's current basis as ``(col, row)`` arrays of :mod:`ncd.exact.clp_model`'s codes."""
    code = {highspy.HighsBasisStatus.kBasic: BASIC, highspy.HighsBasisStatus.kUpper: UPPER}
    basis = highs.getBasis()
    return tuple(np.array([code.get(v, LOWER) for v in statuses], dtype=np.int8)
                 for statuses in (basis.col_status, basis.row_status))


def sector_model(A_eq, b_eq, T, upper, **options):
    """A HiGHS model of ``A_eq T y = b_eq``, ``0 <= y <= upper`` (the Coulomb sectors as
    column bounds, :func:`ncd.solver.cone.cone_columns`), zero cost, silent, with the given options."""
    A = (A_eq @ T).tocsc()
    n = A.shape[1]
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, A.shape[0]
    lp.col_cost_ = np.zeros(n)
    lp.col_lower_ = np.zeros(n)
    lp.col_upper_ = upper
    lp.row_lower_ = b_eq
    lp.row_upper_ = b_eq
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = A.indptr
    lp.a_matrix_.index_ = A.indices
    lp.a_matrix_.value_ = A.data
    h = highspy.Highs()
    h.silent()
    for k, v in options.items():
        h.setOptionValue(k, v)
    h.passModel(lp)
    return h


def min_norm_correction(K, r, eps=1e-12, refine=20):
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
