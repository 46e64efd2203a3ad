"""Anderson acceleration of NLGS (issue 13, item 2): ``SolverSettings(accel="anderson")``.

NLGS is a fixed-point iteration ``s -> G(s)`` on the impulses: one sweep in the review
order (the body velocities are ``u_free + M^-1 H s``, a function of ``s``).  Anderson's
method, type II ("Anderson mixing", Walker & Ni 2011), keeps the last ``m`` differences
``dF`` of the residuals ``f = G(x) - x`` and ``dG`` of the images ``G(x)``, and extrapolates

    s = proj_C( G(x_k) - dG gamma ),    gamma = argmin |f_k - dF gamma|,

``proj_C`` projecting each contact's impulse on its Coulomb cone (the body velocities
are then recomputed, :func:`ncd.solver.pack.apply_all`).  ``gamma`` solves the ``m x m``
normal equations with a Tikhonov term (:data:`REGULARIZATION` times their largest
diagonal entry) by Cholesky.  Choices by measurement (fig2's step, 545 contacts, 6
review orders; dense packings):

* an Anderson step after every :data:`PERIOD`-th sweep only ("alternating" Anderson,
  Pratapa, Suryanarayana & Pask 2016): an Anderson step with memory 20 costs 1.4 sweeps
  on fig2's step (14 us against 10 us; 31 us before the Gram row's dot products were
  vectorized, :func:`_dots`); to 1e-10 there, one after every sweep took 590-710 sweeps,
  after every 2nd 610-940, every 3rd or 4th up to 2,800 (more stalls);
* safeguard: when ``|f|`` (at the Anderson steps) has not dropped below :data:`STALL_FACTOR` of its last mark
  within ``STALL_SPAN m`` Anderson steps, the history is cleared and ``m 2^(r-1)`` plain
  sweeps follow the ``r``-th restart.  Without it 1 run in 3 to 6 stagnated at residuals
  1e-3 to 1e-5 on fig2's step (status switching defeats the extrapolation); with it all
  6 reached 1e-10.  (Restarting only when ``|f|`` grows did not cure the stagnation.)

Measured to a residual of 1e-10 from the zero guess, memory 20 (NLGS sweeps, plain
NLGS's in brackets): fig2's former step 70 620-900 over 6 review orders (8,720-9,070);
fig2's step 50, where zero-guess runs end on two solutions, 880-1,310 on 3 orders but
8,430, 86,630 and 103,970 on the other 3 (7,620-10,670): the extrapolation mixes iterates
that the status switches send towards different solutions; 10^3-disc
packing 190-210 (3,440-3,790); 10^4-disc packing 1,110 (29,530).  Wall time 5.1-7.5x,
8.8-9.5x and 10.5-11.9x shorter: on fig2's step the sweep count falls 10-14x, and the Anderson
steps take the rest.  The pile's final state (Figure 4) is not helped: NLGS and AA
both stall at residuals ~1e-6 (``finish="active_set"``, :mod:`ncd.solver.finish`, is the route there); AA
without the safeguard, memory 50 or 100, jumped from ~1e-6 to below 1e-10 in 3 of 12
runs (3 review orders) and stalled in the others.

The natural-map residual, the stopping test and the best-iterate record are those of
:mod:`ncd.solver.nlgs`, evaluated on sweep outputs only: the returned impulses and body
velocities are always those of a sweep, consistent with each other.  In chunked runs
(an ``observe`` callable, :mod:`ncd.solver.convergence`) the last sweep of a chunk is not
extrapolated; the history goes on across chunks.
"""
import numpy as np

from ncd.core.jit import njit
from ncd.solver.kernels import check_now, done, relative, remember_best, residual_discs, sweep_discs
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
    """A callable with the signature of :func:`ncd.solver.nlgs.iterate_discs` running the
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
    vectorize the two sums (3x faster than a fixed scalar order; the Gram row was half
    an Anderson step).  The summation order is then fixed by the compiled code: the same
    bits on every run, thread count and shard of a given machine and numba build."""
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
    """The driver of :func:`ncd.solver.nlgs.iterate_discs` with an Anderson step after every
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
        dsum, ssum = sweep_discs(data, order, status)
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
