"""Anderson acceleration of NLGS: ``SolverSettings(accel="anderson")``.

NLGS is a fixed-point iteration ``s -> G(s)`` on the impulses (one sweep in the review
order).  Type-II Anderson mixing (Walker & Ni 2011) keeps the last ``m`` differences
``dF`` of the residuals ``f = G(x) - x`` and ``dG`` of the images, and extrapolates

    s = proj_C( G(x_k) - dG gamma ),    gamma = argmin |f_k - dF gamma|,

``proj_C`` projecting each impulse on its Coulomb cone, the body velocities then
recomputed (:func:`ncd.solver.pack.apply_all`); ``gamma`` solves the normal equations
with a Tikhonov term (:data:`REGULARIZATION`) by Cholesky.  An Anderson step follows
every :data:`PERIOD`-th sweep ("alternating" Anderson, Pratapa, Suryanarayana & Pask
2016).  Status switches defeat the extrapolation, so a safeguard clears the history
when ``|f|`` stops falling (:data:`STALL_FACTOR`, :data:`STALL_SPAN`) and runs
``m 2^(r-1)`` plain sweeps after the ``r``-th restart.  Residual, stopping test and best
iterate are those of :mod:`ncd.solver.kernels`, taken on sweep outputs, and a call's last
sweep is not extrapolated: the returned impulses and velocities are a sweep's, consistent
with each other.  Trade-offs: docs/solvers.md.
"""
import numpy as np

from ncd.core.jit import njit
from ncd.solver.kernels import check_now, done, reads_change, relative, remember_best, residual_discs, sweep_discs
from ncd.solver.pack import C_MU, N_COEF, apply_all
from ncd.solver.single_contact import project_cone

PERIOD = 2                # an Anderson step after every PERIOD-th sweep
REGULARIZATION = 1e-12    # Tikhonov term of the normal equations, relative to their largest diagonal entry
STALL_FACTOR = 0.9        # |f| must drop below this fraction of its mark ...
STALL_SPAN = 2            # ... within STALL_SPAN * m Anderson steps, or the history restarts
# counters of a run (one int64 array): stored columns, next slot, a previous pair (0/1),
# Anderson steps, step of the |f| mark, restarts, sweep phase, plain sweeps to go
N_COUNTERS = 8


def state(flat, memory):
    """Work arrays of an accelerated run on the packed disc problem ``flat`` (before the
    guess is applied: ``flat[2]`` holds the free body velocities):
    ``(m, body_free, x, f_prev, g_prev, dF, dG, gram, counters, mark)``."""
    n2 = flat[3].shape[0]
    m = int(memory)
    return (m, flat[2].copy(), np.empty(n2), np.zeros(n2), np.zeros(n2), np.zeros((m, n2)),
            np.zeros((m, n2)), np.zeros((m, m)), np.zeros(N_COUNTERS, np.int64), np.array([np.inf]))


def driver(flat, memory):
    """A callable with the signature of :func:`ncd.solver.kernels.iterate_discs` running the
    accelerated iteration (its state kept between calls: chunks of
    :func:`ncd.solver.convergence.run_nlgs` continue one history)."""
    aa = state(flat, memory)

    def iterate(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
        return _iterate_anderson(data, order, status, scale, tol, max_sweeps, criterion, check_every, best, aa)
    iterate.state = aa
    iterate.reset = lambda: reset(aa)
    return iterate


def reset(aa):
    """Forget the history and the restarts (after the iterate was changed from outside,
    :mod:`ncd.solver.local_exact`): the next sweeps start a fresh extrapolation."""
    counters, mark = aa[8], aa[9]
    counters[:] = 0
    mark[0] = np.inf


@njit(cache=True, error_model="numpy")
def _solve_spd(A, b, n, reg):
    """``(A + reg max(diag A) I) x = b`` on the leading ``n x n`` block (Cholesky);
    zero when the block vanishes or is not positive definite."""
    d = 0.0
    for i in range(n):
        d = max(d, A[i, i])
    x = np.zeros(n)
    if not d > 0.0:
        return x
    L = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1):
            s = A[i, j] + (reg * d if i == j else 0.0)
            for k in range(j):
                s -= L[i, k] * L[j, k]
            if i == j:
                if not s > 0.0:
                    return np.zeros(n)
                L[i, i] = np.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
    return x


@njit(cache=True, error_model="numpy", fastmath={"reassoc"})
def _dots(a, b, c):
    """``(a . b, a . c)`` in one pass.  ``reassoc`` (and no other fast-math flag) lets LLVM
    vectorize the two sums, the bulk of an Anderson step's Gram row.  The summation order
    is then fixed by the compiled code: the same bits on every run, thread count and shard
    of a given machine and numba build."""
    s = 0.0
    t = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
        t += a[i] * c[i]
    return s, t


@njit(cache=True, error_model="numpy")
def _anderson_step(data, aa):
    """After a sweep (``imp`` = G(x), ``x`` its input): record the differences and put the
    extrapolated, cone-projected iterate in ``imp``, the body velocities recomputed."""
    pair, coef, body, imp = data
    m, body0, x, f_prev, g_prev, dF, dG, gram, counters, mark = aa
    n2 = imp.shape[0]
    counters[3] += 1
    for i in range(n2):
        x[i] = imp[i] - x[i]                  # x <- f = G(x) - x
    fn = np.sqrt(_dots(x, x, x)[0])
    if fn < STALL_FACTOR * mark[0]:
        mark[0] = fn
        counters[4] = counters[3]
    elif counters[3] - counters[4] > STALL_SPAN * m and counters[0] > 0:
        counters[0] = 0                       # restart: forget the history, plain sweeps first
        counters[1] = 0
        counters[2] = 0
        counters[5] += 1
        counters[4] = counters[3]
        counters[7] = m * 2 ** min(counters[5] - 1, 20)
        mark[0] = fn
        return
    h = counters[0]
    j = counters[1]
    if counters[2] == 1:                      # a previous pair (x, G(x)): one more column
        for i in range(n2):
            dF[j, i] = x[i] - f_prev[i]
            dG[j, i] = imp[i] - g_prev[i]
            f_prev[i] = x[i]
            g_prev[i] = imp[i]
        h = min(h + 1, m)
        counters[0] = h
        counters[1] = (j + 1) % m
    else:
        f_prev[:] = x
        g_prev[:] = imp
    counters[2] = 1
    if h == 0:
        return
    rhs = np.zeros(h)
    for slot in range(h):                     # the new column's Gram row and the right-hand side
        gram[j, slot], rhs[slot] = _dots(dF[slot], dF[j], x)
        gram[slot, j] = gram[j, slot]
    gamma = _solve_spd(gram, rhs, h, REGULARIZATION)
    a = 0
    while a + 4 <= h:                        # s -= dG gamma, four columns per pass over s
        g0 = gamma[a]
        g1 = gamma[a + 1]
        g2 = gamma[a + 2]
        g3 = gamma[a + 3]
        for i in range(n2):
            imp[i] -= (g0 * dG[a, i] + g1 * dG[a + 1, i]) + (g2 * dG[a + 2, i] + g3 * dG[a + 3, i])
        a += 4
    while a < h:
        ga = gamma[a]
        for i in range(n2):
            imp[i] -= ga * dG[a, i]
        a += 1
    for c in range(n2 // 2):
        pn, pt = project_cone(imp[2 * c], imp[2 * c + 1], coef[N_COEF * c + C_MU])
        imp[2 * c] = pn
        imp[2 * c + 1] = pt
    body[:] = body0
    apply_all(pair, coef, body, imp)


@njit(cache=True, nogil=True, error_model="numpy")
def _iterate_anderson(data, order, status, scale, tol, max_sweeps, criterion, check_every, best, aa):
    """The driver of :func:`ncd.solver.kernels.iterate_discs` with an Anderson step after every
    :data:`PERIOD`-th sweep (``aa``: :func:`state`); the residual and the best iterate are
    taken on sweep outputs, and the last sweep of a call is not extrapolated."""
    keep, keep_imp, keep_status, keep_body, k0 = best
    x = aa[2]
    counters = aa[8]
    imp = data[3]
    change = np.inf
    res = np.inf
    for k in range(1, max_sweeps + 1):
        x[:] = imp
        measure = reads_change(k, max_sweeps, criterion, check_every)
        dsum, ssum = sweep_discs(data, order, status, measure)
        if measure:
            change = relative(dsum, ssum)
        if check_now(k, change, tol, max_sweeps, criterion, check_every):
            rsq, ssq = residual_discs(data)
            res = np.sqrt(rsq) / max(scale, np.sqrt(ssq), 1e-300)
            if remember_best(keep, res, change, k0 + k, imp, keep_imp, status, keep_status):
                keep_body[:] = data[2]
            if done(res, change, tol, criterion):
                return k, res, change, True
        phase = counters[6]
        counters[6] = (phase + 1) % PERIOD
        if counters[7] > 0:                   # plain sweeps after a restart
            counters[7] -= 1
            counters[6] = 0
        elif k < max_sweeps and phase == PERIOD - 1:
            _anderson_step(data, aa)
    return max_sweeps, res, change, False
