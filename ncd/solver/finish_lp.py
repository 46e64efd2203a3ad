"""The status polyhedron of a Contact Dynamics step, and the nearest point of it (LP, HiGHS).

In 2-D the Coulomb cone is polyhedral, so once every contact's status is fixed the
one-step solutions with those statuses form a polyhedron (Moreau 2005, section 2;
``U = H^T u + b``, ``M (u - u_free) = H s``):

* open: ``s = 0``, ``U_n >= 0``;
* stick: ``U_n = U_t = 0``, ``|s_t| <= mu s_n``;
* slide forward: ``U_n = 0``, ``s_t = -mu s_n``, ``U_t >= 0``;
* slide backward: ``U_n = 0``, ``s_t = +mu s_n``, ``U_t <= 0``;

and ``s_n >= 0`` everywhere.  :func:`project` returns its point nearest to an
iterate ``s0`` in the L1 norm, ``min sum |s - s0|`` (a linear program, solved by
HiGHS: interior point then crossover to a vertex, one thread: deterministic), or reports it empty.  The body
velocities are kept as unknowns in the disc form, so the LP stays as sparse as ``H``;
a problem in local form (``U = W s + q``) uses ``W``.  The impulses are carried in the
Coulomb sector coordinates of :func:`ncd.solver.cone.cone_columns`, so the cone and the
sliding statuses are column bounds, not rows.  Unknowns and rows are scaled
to order one (impulses by ``S``, velocities by ``V``, spins by ``V / r``), and the
primal feasibility tolerance is :data:`FEASIBILITY` of those scales, so the vertex
HiGHS returns satisfies the statuses' equalities to round-off.
"""
import highspy
import numpy as np
import scipy.sparse as sp

from ncd.solver.cone import cone_columns
from ncd.solver.single_contact import NO_CONTACT, SLIDE_BACKWARD, SLIDE_FORWARD, STICK

FEASIBILITY = 1e-9       # HiGHS primal feasibility tolerance, of the scaled rows
# Simplex iterations at most: when the polyhedron of the NLGS statuses is empty the
# interior-point stage does not always say so, and where it stops without progress HiGHS
# runs its dual simplex from scratch, which can go on without an answer, while the
# projections that succeed need few.  A count, not a time limit: the outcome does not
# depend on the machine's load.
SIMPLEX_LIMIT = 2000
OPTIONS = {"threads": 1, "solver": "ipm", "run_crossover": "on", "primal_feasibility_tolerance": FEASIBILITY,
           "dual_feasibility_tolerance": 1e-9, "simplex_iteration_limit": SIMPLEX_LIMIT}
INF = highspy.kHighsInf


class StatusLP:
    """The linear pieces of one step: ``U = B x + b`` for unknowns ``x = (y, s)``,
    ``A x = a`` (the dynamics), ``y`` of scale ``y_scale`` (none in local form)."""

    def __init__(self, B, b, A, a, y_scale, mu, S, V):
        self.B, self.b, self.A, self.a = sp.csr_matrix(B), np.asarray(b, float).ravel(), sp.csr_matrix(A), a
        self.y_scale, self.mu, self.S, self.V = np.asarray(y_scale, float), np.asarray(mu, float), S, V
        self.ny, self.n = len(self.y_scale), len(self.mu)

    @classmethod
    def discs(cls, H, minv, free, bias, mu, radius, S, V):
        """Disc form: ``y = u`` (3 per mobile disc), ``B = [H^T, 0]``, ``u - M^-1 H s = u_free``."""
        nb = H.shape[0]
        B = sp.hstack([H.T, sp.csr_matrix((H.shape[1], H.shape[1]))])
        A = sp.hstack([sp.identity(nb), -(sp.diags(minv) @ H)])
        y_scale = np.column_stack([np.full(len(radius), V), np.full(len(radius), V), V / radius]).ravel()
        return cls(B, bias, A, free, y_scale, mu, S, V)

    @classmethod
    def local(cls, W, q, mu, S, V):
        """Local form: ``U = W s + q``, no other unknown."""
        return cls(W, q, sp.csr_matrix((0, W.shape[1])), np.zeros(0), np.zeros(0), mu, S, V)


def project(lp, s0, status, elastic=0.0, presolve=True):
    """Point of the polyhedron of ``status`` nearest to ``s0`` (n, 2) in the L1 norm.

    Returns ``(s, y, info)``; ``s`` is None when the polyhedron is empty (or HiGHS
    stops otherwise: ``info["status"]`` says why).  ``info``: LP size, simplex
    iterations, ``correction`` = ``sum |s - s0|``.  With ``elastic > 0`` the velocity
    conditions of the statuses may be violated at that cost per unit of ``V`` (an exact
    penalty: always feasible); ``info["slack"]`` (n,) is each contact's violation / ``V``
    (all 0: the point is the projection), which tells the statuses to change.
    ``presolve=False``: HiGHS solves the LP as built, without its presolve
    (:attr:`ncd.solver.settings.SolverSettings.finish_presolve`)."""
    n, ny = lp.n, lp.ny
    st = np.where(status > SLIDE_BACKWARD, STICK, status)
    closed = st != NO_CONTACT
    m = 2 * n
    # impulses in Coulomb sector coordinates s / S = T z (ncd.solver.cone), so the cone and
    # the sliding statuses are column bounds: a quarter fewer rows than cone rows, the same
    # polyhedron, and HiGHS's LPs take about a quarter less time (docs/solvers.md: the
    # outcome of a few of Figure 4's runs changes with the formulation)
    T, upper = cone_columns(lp.mu)
    rough = lp.mu > 0
    z_hi = upper.copy()
    z_hi[0::2][~closed | ((st == SLIDE_FORWARD) & rough)] = 0.0      # mu s_n + s_t = 0
    z_hi[1::2][~closed | ((st == SLIDE_BACKWARD) & rough)] = 0.0     # mu s_n - s_t = 0
    cs = np.concatenate([lp.y_scale, np.full(m, lp.S)])      # column scales
    to_z = sp.block_diag([sp.identity(ny), T], format="csr")
    B = ((lp.B @ sp.diags(cs)) / lp.V @ to_z).tocsr()
    b = lp.b / lp.V
    Bn, Bt = B[0::2], B[1::2]
    bn, bt = b[0::2], b[1::2]
    # velocity rows: U_n >= 0 (open) or = 0 (closed); U_t = 0 (stick), >= 0 (forward), <= 0 (backward)
    lo_n, hi_n = -bn, np.where(closed, -bn, INF)
    lo_t = np.where((st == STICK) | (st == SLIDE_FORWARD), -bt, -INF)[closed]
    hi_t = np.where((st == STICK) | (st == SLIDE_BACKWARD), -bt, INF)[closed]
    rows, lo, hi = [Bn, Bt[closed]], [lo_n, lo_t], [hi_n, hi_t]
    if ny:
        A = sp.diags(1.0 / lp.y_scale) @ lp.A @ sp.diags(cs) @ to_z
        rows.insert(0, A)
        lo.insert(0, lp.a / lp.y_scale)
        hi.insert(0, lp.a / lp.y_scale)
    # L1 distance: T z - d+ + d- = s0 / S, d+, d- >= 0
    E = sp.hstack([sp.csr_matrix((m, ny)), T, -sp.identity(m), sp.identity(m)])
    x0 = np.asarray(s0, float).ravel() / lp.S
    M = sp.vstack([sp.hstack([sp.vstack(rows), sp.csr_matrix((sum(r.shape[0] for r in rows), 2 * m))]), E]).tocsc()
    row_lo, row_hi = np.concatenate(lo + [x0]), np.concatenate(hi + [x0])
    owner = np.concatenate([np.arange(n), np.nonzero(closed)[0]])    # contact of each velocity row
    if elastic > 0:        # slack columns e+ - e- on the velocity rows (after the dynamics rows)
        k = len(owner)
        r = ny + np.arange(k)
        Es = sp.csc_matrix((np.concatenate([np.ones(k), -np.ones(k)]), (np.concatenate([r, r]), np.arange(2 * k))),
                           shape=(M.shape[0], 2 * k))
        M = sp.hstack([M, Es]).tocsc()
    col_lo = np.concatenate([np.full(ny, -INF), np.zeros(m), np.zeros(2 * m)])
    col_hi = np.concatenate([np.full(ny, INF), z_hi, np.full(2 * m, INF)])
    cost = np.concatenate([np.zeros(ny + m), np.ones(2 * m)])
    if elastic > 0:
        col_lo = np.concatenate([col_lo, np.zeros(2 * k)])
        col_hi = np.concatenate([col_hi, np.full(2 * k, INF)])
        cost = np.concatenate([cost, np.full(2 * k, float(elastic))])
    x, info = solve_lp(M, row_lo, row_hi, col_lo, col_hi, cost, presolve)
    if x is None:
        return None, None, info
    s = (T @ x[ny:ny + m]).reshape(n, 2) * lp.S
    info["correction"] = float(np.abs(s - np.asarray(s0).reshape(n, 2)).sum())
    if elastic > 0:
        e = x[ny + 3 * m:]
        info["slack"] = np.bincount(owner, weights=e[:k] + e[k:], minlength=n)
    return s, x[:ny] * lp.y_scale, info


def solve_lp(M, row_lo, row_hi, col_lo, col_hi, cost, presolve=True):
    """``min cost . x`` subject to ``row_lo <= M x <= row_hi``, ``col_lo <= x <= col_hi`` (``M``
    CSC) by HiGHS with :data:`OPTIONS`: ``(x, info)``, ``x`` None unless optimal.

    ``presolve=False`` turns HiGHS's presolve off.  On the walk's projections of Figure 5's
    thin-cone slices, the presolved LP stalled the interior point ("no progress", no
    crossover); HiGHS then ran its dual simplex from scratch, with the pivots and vertex of
    a plain dual simplex, and most of those runs stopped at :data:`SIMPLEX_LIMIT`.  The LP
    as built let the interior point converge and the crossover reach a vertex."""
    h = highspy.Highs()
    h.silent()
    for k, v in OPTIONS.items():
        h.setOptionValue(k, v)
    if not presolve:
        h.setOptionValue("presolve", "off")
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = M.shape[1], M.shape[0]
    lp.col_cost_, lp.col_lower_, lp.col_upper_ = cost, col_lo, col_hi
    lp.row_lower_, lp.row_upper_ = row_lo, row_hi
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = M.indptr, M.indices, M.data
    h.passModel(lp)
    h.run()
    ms = h.getModelStatus()
    info = {"status": h.modelStatusToString(ms), "rows": M.shape[0], "cols": M.shape[1],
            "iterations": int(h.getInfo().simplex_iteration_count), "presolve": _option(h, "presolve")}
    if ms != highspy.HighsModelStatus.kOptimal:
        return None, info
    return np.array(h.getSolution().col_value), info


def _option(h, name):
    """An option's value as HiGHS holds it (``highspy`` returns ``(status, value)`` or the value)."""
    v = h.getOptionValue(name)
    return v[1] if isinstance(v, tuple) else v
