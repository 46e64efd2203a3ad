"""Linear complementarity problems solved exactly by Lemke's complementary pivoting.

An LCP(M, q) asks for ``z >= 0`` with ``w = M z + q >= 0`` and ``w . z = 0``.
:func:`lemke` is Lemke's method (Lemke 1965; Cottle, Pang & Stone, *The Linear
Complementarity Problem*, section 4.4): an artificial variable ``z0`` with
covering vector ``d = 1`` makes ``w = M z + d z0 + q`` feasible, then
complementary pivots on a dense tableau move along an almost-complementary
path until ``z0`` leaves the basis (a solution) or a column has no positive
entry (a secondary ray: the method gives no answer, which for a non-copositive
``M`` does not prove that no solution exists).  Ties in the ratio test, which
degenerate problems (a singular Delassus matrix) produce at every pivot, are
broken lexicographically, so the path never cycles.  The solution read from the
final basis is recomputed from ``M, q`` by one linear solve of the basic columns.

:func:`frictional_lcp` writes the 2-D Signorini-Coulomb problem ``U = W s + q``
as an LCP of size ``3 kappa`` (per contact ``s_n``, ``sigma = s_t + mu s_n`` and
the backward sliding speed ``v``):

    U_n >= 0 _|_ s_n >= 0,   U_t + v >= 0 _|_ sigma >= 0,   2 mu s_n - sigma >= 0 _|_ v >= 0,

so ``sigma = 0`` is forward sliding (``s_t = -mu s_n``, ``U_t >= 0``), ``0 < sigma
< 2 mu s_n`` sticking (``U_t = 0``) and ``sigma = 2 mu s_n`` backward sliding
(``U_t = -v <= 0``), the law of :mod:`ncd.solver.single_contact`.
"""
import numpy as np

from ncd.core import validate
from ncd.core.errors import InputError
from ncd.core.jit import njit

LEMKE_STATUS = {0: "solution", 1: "secondary ray", 2: "pivot budget exhausted"}
# ("inaccurate": the final basis's z has a complementarity residual above ACCEPT max(1, |q|))
ACCEPT = 1e-6
MAX_ENTRY = 1e150              # |M|, |q| at most: products of two entries stay finite
MAX_COVERING_RATIO = 1e12      # largest / smallest covering entry


@njit(cache=True, nogil=True)    # no GIL: several runs side by side on threads (ncd.figures.fig2_slope.census)
def _lemke(M, q, d, max_pivots, tol):
    """Lemke's method on the tableau ``[I, -M, -d | q]``; returns ``(basis, status, pivots)``.

    ``basis[i]`` is the variable basic in row ``i``: ``0..n-1`` are ``w``,
    ``n..2n-1`` are ``z``, ``2n`` is ``z0``.  The tableau is kept in compact form:
    only the ``n + 1`` nonbasic columns and ``q`` (a basic variable's column is a unit
    vector), the leaving variable taking the entering one's place.  That halves the
    memory each pivot streams through, and every stored entry is computed by the same
    operations as in the full tableau, so the path and the basis are the same bit for bit."""
    n = q.shape[0]
    m1 = n + 1                      # nonbasic variables; column m1 holds q
    T = np.zeros((n, n + 2))
    for i in range(n):
        for j in range(n):
            T[i, j] = -M[i, j]
        T[i, n] = -d[i]
        T[i, m1] = q[i]
    basis = np.arange(n)
    col_of = np.empty(2 * n + 1, np.int64)      # compact column of a nonbasic variable, -1 if basic
    row_of = np.empty(2 * n + 1, np.int64)      # row of a basic variable
    for v in range(n):
        col_of[v] = -1
        row_of[v] = v
    for k in range(m1):
        col_of[n + k] = k
    # first pivot: z0 enters, the row of the most negative q / d leaves
    row = 0
    best = np.inf
    for i in range(n):
        r = q[i] / d[i]
        if r < best:
            best = r
            row = i
    entering = 2 * n
    cand = np.empty(n, np.int64)
    for it in range(max_pivots):
        # pivot on (row, entering): the leaving variable's unit column becomes column c
        c = col_of[entering]
        piv = T[row, c]
        inv = 1.0 / piv
        for j in range(n + 2):
            T[row, j] /= piv
        T[row, c] = inv
        for i in range(n):
            if i != row:
                f = T[i, c]
                if f != 0.0:
                    for j in range(n + 2):
                        T[i, j] -= f * T[row, j]
                    T[i, c] = 0.0 - f * inv
                else:
                    T[i, c] = 0.0
        leaving = basis[row]
        basis[row] = entering
        row_of[entering] = row
        col_of[entering] = -1
        col_of[leaving] = c
        if leaving == 2 * n:
            return basis, 0, it + 1
        # the complement of the leaving variable enters
        entering = leaving + n if leaving < n else leaving - n
        e = col_of[entering]
        # lexicographic minimum ratio test over rows with a positive pivot entry
        m = 0
        for i in range(n):
            if T[i, e] > tol:
                cand[m] = i
                m += 1
        if m == 0:
            return basis, 1, it + 1
        z0_row = -1
        for col in range(-1, n):
            # the ratio column: q, then the columns of w_0.. (a basic w's is a unit vector)
            cc = m1 if col < 0 else col_of[col]
            unit = -1 if cc >= 0 else row_of[col]
            lo = np.inf
            for k in range(m):
                i = cand[k]
                num = T[i, cc] if cc >= 0 else (1.0 if i == unit else 0.0)
                r = num / T[i, e]
                if r < lo:
                    lo = r
            keep = 0
            for k in range(m):
                i = cand[k]
                num = T[i, cc] if cc >= 0 else (1.0 if i == unit else 0.0)
                r = num / T[i, e]
                if r <= lo + tol * (1.0 + abs(lo)):
                    cand[keep] = cand[k]
                    keep += 1
            m = keep
            z0_row = -1
            for k in range(m):
                if basis[cand[k]] == 2 * n:
                    z0_row = cand[k]
            if z0_row >= 0 or m == 1:
                break
        row = z0_row if z0_row >= 0 else cand[0]
    return basis, 2, max_pivots


def lemke(M, q, max_pivots=None, tol=1e-12, covering=None):
    """Solve LCP(M, q) by Lemke's method (covering vector ``covering``, default all ones).

    Returns ``(z, info)``: ``z`` (None unless ``info["status"] == "solution"``)
    recomputed from the final complementary basis by a linear solve, and
    ``info`` with ``status`` (one of :data:`LEMKE_STATUS`), ``pivots`` and the
    complementarity residual ``max |min(z, w)|`` of ``z``.
    """
    q = validate.array("q", np.ravel(q) if np.ndim(q) > 1 else q, (None,))
    n = len(q)
    M = validate.array("M", M, (n, n))
    for name, a in (("M", M), ("q", q)):
        if a.size and np.abs(a).max() > MAX_ENTRY:
            raise InputError(f"{name} has an entry of size {np.abs(a).max():.3g} > {MAX_ENTRY:g}: "
                             "pivoting would overflow; rescale the problem")
    tol = validate.real("tol", tol, 0.0, lo_open=True)
    d = np.ones(n) if covering is None else validate.array("covering", np.ravel(covering), (n,))
    if n and not (d.min() >= 1e-150 and d.max() <= MAX_COVERING_RATIO * d.min()):
        raise InputError(f"covering must be {n} positive numbers >= 1e-150 within a ratio of "
                         f"{MAX_COVERING_RATIO:g}; got [{d.min():.3g}, {d.max():.3g}]")
    max_pivots = 50 * n + 100 if max_pivots is None else validate.integer("max_pivots", max_pivots, 1, 10 ** 9)
    if n == 0 or np.all(q >= 0):
        z = np.zeros(n)
        return z, {"status": "solution", "pivots": 0, "residual": lcp_residual(M, q, z)}
    basis, status, pivots = _lemke(M, q, d, max_pivots, tol)
    info = {"status": LEMKE_STATUS[int(status)], "pivots": int(pivots)}
    if status != 0:
        info["residual"] = np.nan
        return None, info
    z = basis_solution(M, q, basis)
    info["residual"] = lcp_residual(M, q, z)
    if not info["residual"] <= ACCEPT * max(1.0, float(np.abs(q).max())):   # a basis that does not solve
        info["status"] = "inaccurate"
        return None, info
    return z, info


def basis_solution(M, q, basis):
    """``z`` of the complementary basis ``basis`` (variables ``0..n-1`` = w, ``n..2n-1`` = z):
    the basic columns of ``[I, -M]`` solved against ``q`` (least squares if singular)."""
    n = len(q)
    basis = np.asarray(basis)
    if np.any(basis >= 2 * n) or len(basis) != n:
        raise InputError("basis must hold n indices of w (0..n-1) or z (n..2n-1)")
    B = np.where(basis[None, :] < n, np.eye(n)[:, np.minimum(basis, n - 1)],
                 -M[:, np.clip(basis - n, 0, n - 1)])
    try:
        x = np.linalg.solve(B, q)
    except np.linalg.LinAlgError:
        x = np.linalg.lstsq(B, q, rcond=None)[0]
    z = np.zeros(n)
    zb = basis >= n
    z[basis[zb] - n] = x[zb]
    return np.maximum(z, 0.0)


def lcp_residual(M, q, z):
    """``max_i |min(z_i, w_i)|`` with ``w = M z + q`` (0 exactly at a solution)."""
    w = M @ z + q
    return float(np.abs(np.minimum(z, w)).max()) if len(q) else 0.0


def frictional_lcp(W, q, mu):
    """The LCP ``(A, b)`` of size ``3 kappa`` of the 2-D frictional problem ``U = W s + q``.

    ``W`` (2 kappa, 2 kappa) ordered ``(n, t)`` per contact, ``q`` (kappa, 2) or
    (2 kappa,), ``mu`` (kappa,).  Unknowns per contact ``(s_n, sigma, v)`` with
    ``s_t = sigma - mu s_n`` (see the module docstring); :func:`impulse_of_lcp`
    maps a solution back to ``s``.
    """
    W = np.asarray(W, dtype=float)
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    k = len(q)
    mu = validate.per_item("mu", mu, k, 0.0)
    if W.shape != (2 * k, 2 * k):
        raise InputError(f"W has shape {W.shape}: expected ({2 * k}, {2 * k}) for {k} contacts")
    # s = P x with x = (s_n, sigma, v) per contact: s_n = s_n, s_t = sigma - mu s_n
    P = np.zeros((2 * k, 3 * k))
    i = np.arange(k)
    P[2 * i, 3 * i] = 1.0
    P[2 * i + 1, 3 * i] = -mu
    P[2 * i + 1, 3 * i + 1] = 1.0
    WP = W @ P
    A = np.zeros((3 * k, 3 * k))
    b = np.zeros(3 * k)
    A[3 * i] = WP[2 * i]                     # U_n
    b[3 * i] = q[:, 0]
    A[3 * i + 1] = WP[2 * i + 1]             # U_t + v
    A[3 * i + 1, 3 * i + 2] += 1.0
    b[3 * i + 1] = q[:, 1]
    A[3 * i + 2, 3 * i] = 2 * mu             # 2 mu s_n - sigma
    A[3 * i + 2, 3 * i + 1] = -1.0
    return A, b


def impulse_of_lcp(x, mu):
    """Impulses ``(kappa, 2)`` of a solution ``x`` of :func:`frictional_lcp`."""
    x = np.asarray(x, dtype=float).reshape(-1, 3)
    return np.column_stack([x[:, 0], x[:, 1] - np.asarray(mu) * x[:, 0]])
