"""A ∩ C by an interior point with dual certificates: the angle ranges of a 10^4-grain pile.

The simplex of :class:`ncd.exact.exact_set.ExactSet` pays for every pivot on the
3 10^4 equilibrium rows of a 10^4-grain pile, and the LPs of a central cut, whose optima
rearrange the forces of much of the pile, take many pivots each from the previous basis
(docs/solvers.md).  An interior point (Clarabel, sparse LDL^T of the KKT system) solves
the same LP in a number of iterations that hardly depends on the cost vector, with no
basis to carry.  Its point is not a vertex, so every value is bracketed instead, by weak
duality:

* the primal point, a force state of A ∩ C (equilibrium to round-off, Coulomb exact in
  the sector columns of :func:`ncd.solver.cone.cone_columns`), gives a value attained;
* the dual ``y`` gives a bound on every state: for ``A z = b``, ``z >= 0``,
  ``c . z = y . b + (c - A^T y) . z >= y . b - max(0, -min(c - A^T y)) S`` with ``S`` a
  certified bound on ``sum z`` over A ∩ C (:meth:`InteriorSet.total_bound`, the same
  inequality applied to ``max sum z``).

Where the dual residual times ``S`` (the pile's forces summed: many times the largest grain
weight on a large pile) is too coarse, one more LP bounds ``max residual . z`` over A ∩ C itself
(:meth:`InteriorSet._residual_cost`).

An angle range (Moreau 2005, section 5: the direction of a cut resultant) is a
linear-fractional program; the Charnes-Cooper LP of each end gives its point and, by its
dual, its bound, so a cut costs three LPs (``min p`` and the two ends), and one more per end
whose bound exceeds :data:`BOUND_DEG`.  A reference direction that does not separate the image from the origin
(``p_min <= 0`` not excluded) goes to the simplex route, whose exact polygon decides.
"""
import math
import time

import clarabel
import numpy as np
import scipy.sparse as sp

from ncd.core import validate
from ncd.exact.exact_set import ExactSet, min_norm_correction
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.solver.cone import cone_columns

GAP_TOL = 1e-13          # Clarabel's absolute and relative duality gap: the dual residual, times the
                         # bound on the forces, is what a certified end loses, hence a tight gap
BOUND_DEG = 1e-6         # an end whose bound (max residual times S) is larger pays one more LP for a tighter one
FEAS_TOL = 1e-10         # Clarabel's feasibility tolerance (the primal point is corrected to round-off)
UNIT = np.finfo(float).eps / 2     # unit round-off: the first-order error bounds of A^T y and y . b
SOLVED = ("Solved", "AlmostSolved")
STATIC_REG = 1e-20       # Clarabel's proportional static regularisation (default eps^2): reaches "Solved" here
RETRY = {"max_step_fraction": 0.9}   # a second attempt at an end whose first bound is loose (a stalled solve)


class InteriorSet:
    """A ∩ C of ``H r + F = 0`` with Coulomb cones (as :class:`ExactSet`), solved by
    Clarabel's interior point; :meth:`minimize` and :meth:`angle_range` return points of
    A ∩ C together with a certified bound on what no admissible state exceeds."""

    def __init__(self, H, F, mu, gap_tol=GAP_TOL):
        self.fp = fp = ForcePolytope(H, F, mu)
        self.scale, self.n = fp.scale, 2 * fp.n_contacts
        T, upper = cone_columns(fp.mu)
        free = np.flatnonzero(upper > 0)            # a frictionless contact's second column is fixed at 0
        if np.any(np.isfinite(upper[free])):
            raise ValueError("sector columns are either fixed at 0 or unbounded above")
        self.T = T[:, free].tocsr()
        self._Tt = self.T.T.tocsr()
        self.A = (fp.A_eq @ self.T).tocsc()
        self.b = np.asarray(fp.b_eq, float)
        self.gap_tol = float(validate.real("gap_tol", gap_tol, 1e-16, 1e-4))
        self.n_lp, self.lp_time = 0, 0.0
        self._total, self._simplex = None, None
        self._H, self._F, self._mu = H, F, mu

    # ------------------------------------------------------------------ one LP
    def _clarabel(self, cost, A, b, options=None):
        """Clarabel on ``min cost . x``, ``A x = b``, ``x >= 0`` (``options`` override the
        settings): ``(x, y, support)`` with ``y`` the duals of the equations (``cost - A^T y
        >= 0`` up to the solver's tolerance) and ``support`` the columns off their bound."""
        m, n = A.shape
        K = sp.vstack([A, -sp.identity(n, format="csc")]).tocsc()
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.tol_gap_abs = settings.tol_gap_rel = self.gap_tol
        settings.tol_feas = FEAS_TOL
        settings.static_regularization_proportional = STATIC_REG
        settings.direct_solve_method, settings.max_threads = "faer", 1     # one thread: the same point every run
        for key, value in (options or {}).items():
            setattr(settings, key, value)
        t0 = time.perf_counter()
        sol = clarabel.DefaultSolver(sp.csc_matrix((n, n)), np.asarray(cost, float), K,
                                     np.concatenate([b, np.zeros(n)]),
                                     [clarabel.ZeroConeT(m), clarabel.NonnegativeConeT(n)], settings).solve()
        self.n_lp += 1
        self.lp_time += time.perf_counter() - t0
        status = str(sol.status)
        if status == "PrimalInfeasible":
            raise PolytopeError("A ∩ C is empty: no contact forces balance the weights")
        if status not in SOLVED:
            raise PolytopeError(f"LP not solved: Clarabel status {status}")
        z = np.asarray(sol.z)                        # Clarabel: c + A^T z[:m] - z[m:] = 0
        x = np.maximum(np.asarray(sol.x), 0.0)
        return x, -z[:m], x > z[m:]                  # the columns off their bound: x_j above its reduced cost

    @staticmethod
    def _dual_residual(cost, A, y):
        """Per column, ``max(0, -(c - A^T y)_j)`` plus the round-off of that reduced cost
        (a column of ``A`` has at most seven entries: ``8 u (|c| + |A|^T |y|)_j``): what a
        unit of ``x_j`` can take off the dual value."""
        return np.maximum(A.T @ y - cost, 0.0) + 8 * UNIT * (abs(A).T @ np.abs(y) + np.abs(cost))

    @staticmethod
    def _dual_value(y, b):
        """``y . b`` less its round-off (summed exactly rounded, :func:`math.fsum`)."""
        yb = y * b
        return math.fsum(yb) - 2 * UNIT * float(np.abs(yb).sum())

    def _dual_bound(self, cost, A, b, y, total):
        """``y . b - max_j(residual_j) total`` (:meth:`_dual_residual`): a lower bound on
        ``cost . x`` for every ``x >= 0`` with ``A x = b`` and ``sum x <= total``."""
        return self._dual_value(y, b) - float(self._dual_residual(cost, A, y).max()) * total

    def _residual_cost(self, weights):
        """A certified bound on ``max weights . z`` over A ∩ C (one more LP): what the dual
        residual ``weights`` (:meth:`_dual_residual`) can cost at most, far below
        ``max(weights) S`` when the residual sits on a few columns."""
        top = float(weights.max())
        if not top > 0:
            return 0.0
        w = weights / top
        _, y, _ = self._clarabel(-w, self.A, self.b)
        return top * min(-self._dual_bound(-w, self.A, self.b, y, self.total_bound()), self.total_bound())

    def total_bound(self):
        """``S >= sum z`` over A ∩ C, certified and computed once: with ``y`` the dual of
        ``min -sum z``, ``-sum z >= y . b - w sum z`` (``w`` the dual residual and the
        round-off, :meth:`_dual_residual`), so ``S = -y . b / (1 - w)``."""
        if self._total is None:
            ones = -np.ones(self.A.shape[1])
            _, y, _ = self._clarabel(ones, self.A, self.b)
            w = float(self._dual_residual(ones, self.A, y).max())
            lead = -self._dual_value(y, self.b)
            if not w < 0.5 or not lead > 0:
                raise PolytopeError("no certified bound on the forces of A ∩ C (unbounded or ill-posed)")
            self._total = lead / (1.0 - w)
        return self._total

    def admissible(self, x, support):
        """The sector columns ``x >= 0`` of an interior point made to balance the weights to
        round-off: the minimum-norm correction of ``A x = b`` on the columns off their bound
        (:func:`ncd.exact.exact_set.min_norm_correction`); the interior point's own residual
        (the solver's feasibility tolerance) would otherwise be the error of every value
        "attained"."""
        keep = np.flatnonzero(support)
        out = x.copy()
        out[keep] += min_norm_correction(self.A[:, keep].tocsc(), self.b - self.A @ x)
        return np.maximum(out, 0.0)

    def bounds(self, c):
        """``(lower, value, r)`` for ``min c . r`` over A ∩ C (``c``, ``r`` in force units):
        ``r`` the interior point's forces, ``value = c . r`` attained, ``lower`` certified."""
        c = validate.array("c", c, (self.n,))
        cost = self._Tt @ c * self.scale
        norm = max(float(np.abs(cost).max()), 1e-300)          # a cost of unit size: the gap tolerance is relative
        x, y, support = self._clarabel(cost / norm, self.A, self.b)
        lower = self._dual_bound(cost / norm, self.A, self.b, y, self.total_bound()) * norm
        r = self.T @ self.admissible(x, support) * self.scale
        return lower, float(np.dot(c, r)), r

    def minimize(self, c):
        """``(min c . r, r)`` over A ∩ C, as :meth:`ExactSet.minimize`: the value attained
        at the interior point, within the certified gap of :meth:`bounds`."""
        _, value, r = self.bounds(c)
        return value, r

    def simplex_set(self):
        """The simplex route (:class:`ExactSet`, built on first use) for the cases the dual
        bounds cannot settle."""
        if self._simplex is None:
            self._simplex = ExactSet(self._H, self._F, self._mu)
        return self._simplex

    def angle_range(self, L, outer=1.0, ref=None, tol=1e-12, max_lp=60, retry=True):
        """Range of ``phi = atan2(-g_y, outer g_x)`` over ``g = L r``, r in A ∩ C (degrees),
        as :meth:`ExactSet.angle_range` returns it: ``lo``, ``hi`` attained by the forces
        ``points``, ``bound`` the certified distance (degrees) to the true ends, ``p_min``,
        ``n_lp``.

        With ``p = a . u``, ``q = b . u`` around ``ref`` (``u = (outer g_x, -g_y)``):
        ``min p`` gives ``p_lo > 0``, a certified lower bound; each end ``max +-q / p`` is
        the Charnes-Cooper LP ``max +-b' zeta`` over ``A zeta = b t``, ``a' zeta = 1``,
        ``zeta, t >= 0``, whose point gives the end attained and whose dual bounds it
        (``sum zeta + t <= (S + 1) / p_lo``).  ``tol`` and ``max_lp`` are the simplex
        route's, used when ``p_lo`` is not positive."""
        L = validate.matrix("L", L, (2, self.n))
        M = sp.diags([float(outer), -1.0]) @ L
        Mt = M.T.tocsr()
        n0 = self.n_lp
        if ref is None or not np.isfinite(ref):
            u = M @ self.minimize(np.zeros(self.n))[1]
            ref = np.degrees(np.arctan2(u[1], u[0]))
        t = np.radians(ref)
        a, b = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
        alpha, beta = self._Tt @ (Mt @ a) * self.scale, self._Tt @ (Mt @ b) * self.scale
        norm = float(np.abs(alpha).max()) if np.any(alpha) else 0.0
        p_lo = -np.inf
        if norm > 0:
            alpha, beta = alpha / norm, beta / norm
            x, y, support = self._clarabel(alpha, self.A, self.b)
            p_min = float(alpha @ x)
            value, res = self._dual_value(y, self.b), self._dual_residual(alpha, self.A, y)
            p_lo = value - float(res.max()) * self.total_bound()
            if p_lo < 0.99 * p_min:                 # the residual times S costs over a hundredth: bound it by an LP
                p_lo = max(p_lo, value - self._residual_cost(res))
            p_min *= norm
        if not p_lo * norm > 1e-9 * self.scale:
            # the reference does not separate the image from the origin: the simplex route
            # (its exact polygon decides the direction, or that the image contains 0)
            es = self.simplex_set()
            m0, s0 = es.n_lp, es.lp_time
            out = es.angle_range(L, outer, ref=ref, tol=tol, max_lp=max_lp, retry=retry)
            self.n_lp, self.lp_time = self.n_lp + es.n_lp - m0, self.lp_time + es.lp_time - s0
            out["n_lp"] = self.n_lp - n0
            return out
        m, n = self.A.shape
        A_cc = sp.vstack([sp.hstack([self.A, -self.b[:, None]]), sp.csr_matrix(np.append(alpha, 0.0)[None, :])]).tocsc()
        b_cc = np.append(np.zeros(m), 1.0)
        total = (self.total_bound() + 1.0) / p_lo
        ends, bounds, points = [0.0, 0.0], [], np.zeros((2, L.shape[1]))
        for j, sign in ((1, 1.0), (0, -1.0)):
            cost = np.append(-sign * beta, 0.0)
            lam, upper = -np.inf, np.inf
            for options in (None, RETRY):
                # the larger attained end and the smaller certified bound, whichever solve gave
                # them (the first solve's always set them: a NaN from it then stays visible)
                x, y, support = self._clarabel(cost, A_cc, b_cc, options)
                r_k = self.T @ self.admissible(x[:n] / x[n], support[:n]) * self.scale
                u = M @ r_k
                lam_k = sign * (b @ u) / (a @ u)
                if options is None or lam_k > lam:
                    lam, r = lam_k, r_k
                value_k, res_k = self._dual_value(y, b_cc), self._dual_residual(cost, A_cc, y)
                upper_k = -(value_k - float(res_k.max()) * total)       # max of sign q / p, certified
                if options is None or upper_k < upper:
                    upper, value, res = upper_k, value_k, res_k
                bound = np.degrees(np.arctan(max(upper, lam)) - np.arctan(lam))
                if bound <= BOUND_DEG:
                    break
            if bound > BOUND_DEG:
                # the residual's cost over A ∩ C itself: sum_j res_j zeta_j + res_t t
                # = (res_z . z + res_t) / p <= (max res_z . z + res_t) / p_lo
                upper = min(upper, -(value - (self._residual_cost(res[:n]) + res[n]) / p_lo))
                bound = np.degrees(np.arctan(max(upper, lam)) - np.arctan(lam))
            ends[j] = ref + sign * np.degrees(np.arctan(lam))
            bounds.append(bound)
            points[j] = r
        return {"p_min": p_min, "lo": float(ends[0]), "hi": float(ends[1]), "bound": float(max(bounds)),
                "points": points, "n_lp": self.n_lp - n0}
