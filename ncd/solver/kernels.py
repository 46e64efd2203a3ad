"""The NLGS kernels (numba): one sweep, the residual, and the iteration loop, in disc
form and in local form.

A sweep reviews the contacts in ``review_order`` and solves each exactly with the
others frozen (:func:`ncd.solver.single_contact.solve_single_contact`; in disc form its
diagonal-block case :func:`~ncd.solver.single_contact.solve_disc_contact`, the same bit for
bit), propagating at once (Moreau 2005, section 2). In disc form the body velocities are updated
incrementally, ``u += M^-1 H_alpha (s_new - s_old)`` (packed arrays of
:mod:`ncd.solver.pack`), so a sweep costs O(contacts); in local form ``U = W s + q``
with ``W`` in CSR. The residual is the natural map, ``rho_alpha = 1 / W_alpha,nn``,
relative to the largest of ``|s|`` and ``|rho q_free|`` (:func:`problem_scale`).
They are shared by plain NLGS, Anderson acceleration, local exact solves and the
finishing stage.
"""

import numpy as np

from ncd.core.jit import njit
from ncd.solver.pack import C_BN, C_BT, C_MU, C_WNN, C_WTT, N_COEF, add_impulse, relative_velocity
from ncd.solver.single_contact import natural_map_sq, solve_disc_contact, solve_single_contact


# The drivers below are written once per form on purpose: passing the sweep and
# residual functions as arguments to one cached driver would key numba's on-disk
# cache on the dispatcher objects of the current process, so every process would
# recompile the driver, add an entry to the cache index, and eventually fail to
# pickle the index ("underlying object has vanished").
@njit(cache=True, inline="always")
def scheduled_check(k, max_sweeps, check_every):
    """Sweep ``k`` is one of the scheduled residual checks (every ``check_every``-th, and the last)."""
    return k % check_every == 0 or k == max_sweeps


@njit(cache=True, inline="always")
def check_now(k, change, tol, max_sweeps, criterion, check_every):
    return scheduled_check(k, max_sweeps, check_every) or (criterion == 1 and change <= tol)


@njit(cache=True, inline="always")
def reads_change(k, max_sweeps, criterion, check_every):
    """Whether a driver reads sweep ``k``'s change: at the scheduled checks, and at every
    sweep under the change criterion (:func:`sweep_discs`' ``measure``)."""
    return criterion == 1 or scheduled_check(k, max_sweeps, check_every)


@njit(cache=True, inline="always")
def relative(dsum, ssum):
    return dsum / max(ssum, 1e-300) if ssum > 0.0 else 0.0


@njit(cache=True, inline="always")
def done(res, change, tol, criterion):
    return (criterion == 0 and res <= tol) or (criterion == 1 and change <= tol)


@njit(cache=True, inline="always")
def remember_best(keep, res, change, k, imp, keep_imp, status, keep_status):
    """Record the iterate if its residual is the smallest seen: ``keep = [res, change, sweep]``."""
    if res < keep[0]:
        keep[0] = res
        keep[1] = change
        keep[2] = k
        keep_imp[:] = imp
        keep_status[:] = status
        return True
    return False


@njit(cache=True, error_model="numpy")
def sweep_discs(data, order, status, measure=True):
    """One sweep in disc form; ``(sum |ds|, sum |s|)`` of its impulse changes and impulses
    when ``measure`` (the sweeps at which the driver reads the change), else ``(0, 0)``:
    the sums are a serial chain of additions per contact, skipped where nothing reads them."""
    pair, coef, body, imp = data
    dsum = 0.0
    ssum = 0.0
    for k in range(order.shape[0]):
        c = order[k]
        un, ut = relative_velocity(pair, coef, body, c)
        j = N_COEF * c
        wnn = coef[j + C_WNN]
        wtt = coef[j + C_WTT]
        sn = imp[2 * c]
        st = imp[2 * c + 1]
        qn = un - wnn * sn + coef[j + C_BN]
        qt = ut - wtt * st + coef[j + C_BT]
        rn, rt, st_ = solve_disc_contact(wnn, wtt, qn, qt, coef[j + C_MU])
        status[c] = st_
        dn = rn - sn
        dt = rt - st
        imp[2 * c] = rn
        imp[2 * c + 1] = rt
        add_impulse(pair, coef, body, c, dn, dt)
        if measure:
            dsum += abs(dn) + abs(dt)
            ssum += abs(rn) + abs(rt)
    return dsum, ssum


@njit(cache=True, error_model="numpy")
def residual_discs(data):
    pair, coef, body, imp = data
    rsq = 0.0
    ssq = 0.0
    for c in range(imp.shape[0] // 2):
        un, ut = relative_velocity(pair, coef, body, c)
        j = N_COEF * c
        rsq += natural_map_sq(imp[2 * c], imp[2 * c + 1], un + coef[j + C_BN], ut + coef[j + C_BT],
                              coef[j + C_MU], 1.0 / coef[j + C_WNN])
        ssq += imp[2 * c] ** 2 + imp[2 * c + 1] ** 2
    return rsq, ssq


@njit(cache=True, nogil=True, error_model="numpy")
def iterate_discs(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
    """The NLGS driver (disc form): sweeps until the criterion holds or ``max_sweeps``;
    ``best = (keep, keep_imp, keep_status, keep_body, k0)`` records the iterate of
    smallest residual (sweeps counted from ``k0``) when ``keep[0]`` starts finite or inf."""
    keep, keep_imp, keep_status, keep_body, k0 = best
    change = np.inf
    res = np.inf
    for k in range(1, max_sweeps + 1):
        measure = reads_change(k, max_sweeps, criterion, check_every)
        dsum, ssum = sweep_discs(data, order, status, measure)
        if measure:
            change = relative(dsum, ssum)
        if check_now(k, change, tol, max_sweeps, criterion, check_every):
            rsq, ssq = residual_discs(data)
            res = np.sqrt(rsq) / max(scale, np.sqrt(ssq), 1e-300)
            if remember_best(keep, res, change, k0 + k, data[3], keep_imp, status, keep_status):
                keep_body[:] = data[2]
            if done(res, change, tol, criterion):
                return k, res, change, True
    return max_sweeps, res, change, False


def problem_scale(q, W):
    """``|rho q|`` with ``rho_alpha = 1 / W_alpha,nn``: the impulse scale of the problem."""
    return float(np.sqrt(np.sum((q / W[:, 0, 0][:, None]) ** 2)))


# ---------------------------------------------------------------- local form
@njit(cache=True, error_model="numpy")
def row_velocity(indptr, indices, values, q, flat, row):
    u = q[row]
    for j in range(indptr[row], indptr[row + 1]):
        u += values[j] * flat[indices[j]]
    return u


@njit(cache=True, error_model="numpy")
def sweep_local(data, order, status):
    indptr, indices, values, q, Wd, mu, flat = data
    dsum = 0.0
    ssum = 0.0
    for k in range(order.shape[0]):
        c = order[k]
        sn = flat[2 * c]
        st = flat[2 * c + 1]
        qn = row_velocity(indptr, indices, values, q, flat, 2 * c) - Wd[c, 0, 0] * sn - Wd[c, 0, 1] * st
        qt = row_velocity(indptr, indices, values, q, flat, 2 * c + 1) - Wd[c, 1, 0] * sn - Wd[c, 1, 1] * st
        rn, rt, st_ = solve_single_contact(Wd[c, 0, 0], Wd[c, 0, 1], Wd[c, 1, 0], Wd[c, 1, 1], qn, qt, mu[c])
        status[c] = st_
        flat[2 * c] = rn
        flat[2 * c + 1] = rt
        dsum += abs(rn - sn) + abs(rt - st)
        ssum += abs(rn) + abs(rt)
    return dsum, ssum


@njit(cache=True, error_model="numpy")
def residual_local(data):
    indptr, indices, values, q, Wd, mu, flat = data
    rsq = 0.0
    ssq = 0.0
    for c in range(Wd.shape[0]):
        un = row_velocity(indptr, indices, values, q, flat, 2 * c)
        ut = row_velocity(indptr, indices, values, q, flat, 2 * c + 1)
        rsq += natural_map_sq(flat[2 * c], flat[2 * c + 1], un, ut, mu[c], 1.0 / Wd[c, 0, 0])
        ssq += flat[2 * c] ** 2 + flat[2 * c + 1] ** 2
    return rsq, ssq


@njit(cache=True, nogil=True, error_model="numpy")
def iterate_local(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
    """The NLGS driver (local form): as :func:`iterate_discs` (``keep_body`` unused)."""
    keep, keep_imp, keep_status, keep_body, k0 = best
    change = np.inf
    res = np.inf
    for k in range(1, max_sweeps + 1):
        dsum, ssum = sweep_local(data, order, status)
        change = relative(dsum, ssum)
        if check_now(k, change, tol, max_sweeps, criterion, check_every):
            rsq, ssq = residual_local(data)
            res = np.sqrt(rsq) / max(scale, np.sqrt(ssq), 1e-300)
            remember_best(keep, res, change, k0 + k, data[6], keep_imp, status, keep_status)
            if done(res, change, tol, criterion):
                return k, res, change, True
    return max_sweeps, res, change, False
