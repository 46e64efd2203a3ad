"""Exact measures of ``A ∩ C`` for the packings of Figure 5 (Moreau 2005, section 4).

Per packing (``H r + F = 0``, Coulomb sectors, scaled as in
:class:`ncd.exact.polytope.ForcePolytope`): ``rank H`` and ``dim A``; the exact range of
every force component over ``A ∩ C`` by HiGHS LPs on one model (:func:`force_ranges`);
the implicit equalities and ``dim (A ∩ C)`` by a rank count, checked against the affine
rank of LP points (:func:`lp_dimension`); the contacts fixed by statics; boundedness (a
self-stress inside ``C`` gives infinite ranges, reported as NaN); and the exact
range ratio ``eta_exact`` (range-box diagonals over the forces at the box centres: the full extent
of the set along each contact, not Unger et al.'s eta_U, a standard deviation).
"""
import highspy
import numpy as np

from ncd.exact.exact_set import sector_model
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.solver.cone import cone_columns


class _Model:
    """One HiGHS model of the scaled ``A ∩ C``, Coulomb sectors as column bounds
    (:func:`ncd.solver.cone.cone_columns`), so its only rows are the equilibrium equations.

    Queries take and return scaled forces ``x``; only the objective changes between solves,
    and :meth:`minimize` can restart from a stored basis: bounds instead of rows, and a
    restart from the best known point, make the range LPs much cheaper."""

    def __init__(self, P, feas_tol=1e-10):
        self.P = P
        n = 2 * P.n_contacts
        self.T, upper = cone_columns(P.mu)
        self._Tt = self.T.T.tocsr()
        self.h = sector_model(P.A_eq, P.b_eq, self.T, upper, primal_feasibility_tolerance=feas_tol,
                              dual_feasibility_tolerance=feas_tol, threads=1, random_seed=0, presolve="off",
                              solver="simplex", simplex_strategy=4)    # primal: a stored basis stays feasible
        self.n, self.m_eq = n, P.A_eq.shape[0]
        self._cols = np.arange(n, dtype=np.int32)
        self.n_lp = 0

    def minimize(self, c, start=None):
        """``argmin c . x`` (scaled), or None if infeasible; restarted from the basis
        ``start`` (:meth:`basis`) when given, else from the last one.  When ``c . x`` is
        unbounded below, returns a point far along a ray (:meth:`ray_point`) and sets
        ``self.unbounded``; raises on any other failure."""
        c = np.asarray(c, float)
        self.h.changeColsCost(self.n, self._cols, self._Tt @ c)
        if start is not None:
            self.h.setBasis(start)
        self.h.run()
        self.n_lp += 1
        status = self.h.getModelStatus()
        self.unbounded = status == highspy.HighsModelStatus.kUnbounded
        if status == highspy.HighsModelStatus.kInfeasible:
            return None
        if self.unbounded:
            return self.ray_point(c)
        if status != highspy.HighsModelStatus.kOptimal:
            raise PolytopeError(f"LP failed: {self.h.modelStatusToString(status)}")
        return self.T @ np.maximum(np.asarray(self.h.getSolution().col_value), 0.0)

    def basis(self):
        """The current optimal basis (a copy), to restart a later solve from."""
        return self.h.getBasis()

    def ray_point(self, c):
        """A point of ``A ∩ C`` far along an unbounded ray of decreasing ``c . x``
        (base point + unit ray): the set is unbounded along ``c``."""
        _, has_ray, ray = self.h.getPrimalRay()
        ray = self.T @ np.asarray(ray, float)
        if not has_ray or not (c @ ray < 0):
            raise PolytopeError("HiGHS reported an unbounded LP without a primal ray")
        return self.base + ray / np.abs(ray).max()


def force_ranges(P, model, zero_tol=1e-10):
    """Exact ``[min, max]`` of ``r_n`` and ``r_t`` of every contact (scaled units) and the
    LP points found (rows of ``points``).

    Two shortcuts, both exact: ``min r_n = 0`` needs no LP once an LP point has
    ``r_n <= zero_tol`` there (``r_n >= 0`` holds on ``C``); a frictionless contact has
    ``r_t = 0`` on ``C``.  The minima of ``r_n`` are solved last, when most points are known."""
    k = P.n_contacts
    lo, hi = np.zeros((k, 2)), np.zeros((k, 2))
    points = []
    seen_min = np.full(k, np.inf)
    c = np.zeros(2 * k)
    mu = P.mu
    jobs = [(a, comp, sign) for a in range(k) for comp, sign in ((0, -1.0), (1, 1.0), (1, -1.0))]
    jobs += [(a, 0, 1.0) for a in range(k)]
    bases = []
    best_value = np.array([np.full(2 * k, -np.inf), np.full(2 * k, np.inf)])   # largest, least x seen
    best_at = np.full((2, 2 * k), -1)
    for a, comp, sign in jobs:
        j = 2 * a + comp
        if comp == 1 and mu[a] == 0.0:
            continue                                   # r_t = 0: lo = hi = 0
        if comp == 0 and sign > 0 and seen_min[a] <= zero_tol:
            continue                                   # min r_n = 0, attained at a known point
        c[:] = 0.0
        c[j] = sign
        best = int(best_at[int(sign > 0), j])          # restart from the best known point
        x = model.minimize(c, bases[best] if 0 <= best != len(points) - 1 else None)
        if x is None:
            raise PolytopeError("A ∩ C is empty")
        points.append(x)
        bases.append(model.basis() if not model.unbounded else None)
        if not model.unbounded:
            for row, better in ((0, x > best_value[0]), (1, x < best_value[1])):
                best_value[row, better], best_at[row, better] = x[better], len(points) - 1
        if not model.unbounded:
            np.minimum(seen_min, x[0::2], out=seen_min)
        value = -sign * np.inf if model.unbounded else x[j]
        if sign > 0:
            lo[a, comp] = value
        else:
            hi[a, comp] = value
    return lo, hi, np.array(points)


def implicit_rows(P, model, points, tol):
    """Coulomb rows tight at every point of ``A ∩ C``: candidates are the rows tight at
    every LP point found; each is confirmed by maximizing its slack."""
    G = P.G.toarray()
    slack = -(points @ G.T)                    # (points, rows) >= 0
    candidate = np.nonzero(slack.max(axis=0) <= tol)[0]
    implicit = np.zeros(G.shape[0], bool)
    extra = []
    for i in candidate:
        x = model.minimize(G[i])               # maximize the slack -G_i x
        extra.append(x)
        implicit[i] = not model.unbounded and -(G[i] @ x) <= tol
    return implicit, (np.array(extra) if extra else np.zeros((0, P.G.shape[1])))


def _rank(M, rel=1e-9):
    if M.shape[0] == 0:
        return 0
    s = np.linalg.svd(M, compute_uv=False)
    return int(np.sum(s > rel * max(s[0], 1e-300)))


def lp_dimension(model, points, basis, tol, max_rounds=200):
    """Affine rank of LP points of ``A ∩ C``, completed along the unspanned directions of
    ``basis`` (orthonormal columns spanning the linear space of the affine hull found by the
    rank count): each direction is maximized and minimized; a width ``<= tol`` marks it flat.
    Returns ``(dimension, flat_directions)``."""
    d = basis.shape[1]
    pts = [p for p in points]
    flat = 0
    for _ in range(max_rounds):
        X = np.array(pts) @ basis                  # coordinates in the hull's space
        D = X - X.mean(axis=0)
        if D.shape[0] > 1:
            _, s, vt = np.linalg.svd(D, full_matrices=D.shape[0] < d)   # every row of vt, no big U
            r = int(np.sum(s > 1e-9 * max(s[0], 1e-300) + tol)) if len(s) else 0
        else:
            vt, r = np.eye(d), 0
        if r + flat >= d:
            return r, flat
        v = vt[r + flat] if r + flat < vt.shape[0] else vt[-1]
        u = basis @ v
        x1 = model.minimize(u)
        ub = model.unbounded
        x2 = model.minimize(-u)
        if not (ub or model.unbounded) and abs(u @ (x2 - x1)) <= tol:
            flat += 1
        pts += [x1, x2]
    return r, flat


def exact_measures(H, F, mu, width_tol=1e-7, slack_tol=1e-9, feas_tol=1e-10):
    """Every exact measure of one packing -> dict (forces in force units); ``feas_tol``:
    HiGHS's relative feasibility tolerance.  ``lp_points``: the LP points found (rows, forces),
    vertices whose spread spans the set's widths (the uniform sampler's first rounding)."""
    P = ForcePolytope(H, F, mu, feas_tol)
    k = P.n_contacts
    Hd = P.A_eq.toarray()
    rank_h = _rank(Hd)
    model = _Model(P, feas_tol)
    out = {"n_contacts": k, "rank_H": rank_h, "dim_A": 2 * k - rank_h, "n_equations": Hd.shape[0],
           "scale": P.scale}
    model.base = model.minimize(np.zeros(2 * k))
    if model.base is None:
        raise PolytopeError("A ∩ C is empty: the packing is not in equilibrium")
    out["bounded"] = P.is_bounded()       # False: a self-stress inside C, some ranges infinite
    lo, hi, points = force_ranges(P, model)
    implicit, extra = implicit_rows(P, model, points, slack_tol)
    E = np.vstack([Hd, P.G.toarray()[implicit]])
    _, s, vt = np.linalg.svd(E, full_matrices=E.shape[0] < E.shape[1])
    rank_e = int(np.sum(s > 1e-9 * s[0]))
    basis = vt[rank_e:].T
    out["dim_AC_rank"] = 2 * k - rank_e
    out["dim_AC_lp"], out["flat_directions"] = lp_dimension(model, np.vstack([points, extra]), basis,
                                                            tol=width_tol)
    width = hi - lo
    with np.errstate(invalid="ignore"):
        mid = 0.5 * (hi + lo)
    fixed = (width <= width_tol).all(axis=1)
    finite = out["bounded"]
    out.update(
        force_min=lo * P.scale, force_max=hi * P.scale, fixed=fixed, n_fixed=int(fixed.sum()),
        implicit=implicit, implicit_zero=implicit[2 * k:], implicit_sliding=implicit[:k] | implicit[k:2 * k],
        eta_exact=float(np.hypot(width[:, 0], width[:, 1]).sum() / np.hypot(mid[:, 0], mid[:, 1]).sum())
        if finite else np.nan,
        eta_normal=float(width[:, 0].sum() / np.abs(mid[:, 0]).sum()) if finite else np.nan,
        n_lp=model.n_lp + P.n_lp, lp_points=np.vstack([points, extra]) * P.scale)
    return out
