"""Nonlinear Gauss-Seidel (NLGS) for the core problem of a Contact Dynamics step.

Contacts are reviewed one at a time in a given ``review_order``; each is
solved exactly (:func:`ncd.local_solver.solve_single_contact`) with the other
impulses frozen, and the result is propagated at once (Moreau 2005, section 2).
Two forms of the same problem share the iteration driver:

* disc form: body velocities ``u`` are updated incrementally,
  ``u += M^-1 H_alpha (s_new - s_old)``, so a sweep costs O(contacts);
* local form: ``U = W s + q`` with a Delassus matrix ``W`` given dense or
  sparse, as NSCD codes (LMGC90, Siconos) export 2-D frictional problems.

Each run reports its sweeps, the relative impulse change of the last sweep,
the relative natural-map residual (:func:`ncd.local_solver.natural_map_sq`,
``rho_alpha = 1 / W_alpha,nn``, divided by the largest of ``|s|`` and
``|rho q_free|``) and a converged flag.  The stopping criterion is either the
residual (default) or the change; non-convergence at ``max_sweeps`` is flagged,
and the iterate returned is then the one of smallest residual seen (``keep_best``).
With ``finish="active_set"`` the NLGS iterate is finished to ``finish_tol`` by
:mod:`ncd.finish` (projection on the polyhedron of its contact statuses, an LP); with an ``observe`` callable the run is made in chunks of
``check_every`` sweeps and stops only when the observable has settled too
(:mod:`ncd.convergence`).
"""
from dataclasses import dataclass, asdict

import numpy as np
import scipy.sparse as sp

from . import checks
from ._cache import njit
from .contacts import delassus_blocks, local_velocity
from .local_solver import natural_map_sq, solve_single_contact
from .nlgs_pack import (C_BN, C_BT, C_MU, C_WNN, C_WTT, N_COEF, _add_impulse, _apply_all,  # noqa: F401
                        _relative_velocity, pack_problem)

CRITERIA = {"residual": 0, "change": 1}
FINISHES = ("none", "active_set")
ACCELS = ("none", "anderson")    # the iteration itself: plain NLGS or Anderson-accelerated (ncd.anderson)


@dataclass(frozen=True)
class SolverSettings:
    """NLGS settings: tolerance on the chosen criterion, sweep budget, finishing stage.

    ``finish``: "none" (plain NLGS) or "active_set" (:func:`ncd.finish.polish`: where
    NLGS's rate is slow, its iterate projected (L1, LP) on the solutions with the contact
    statuses it has settled, the active set, until the natural-map residual is <= ``finish_tol``).
    ``observable_tol``: largest relative change of an observed quantity over the
    last residual checks for a run to count as converged (:mod:`ncd.convergence`).
    ``keep_best``: at ``max_sweeps`` return the iterate of smallest residual seen
    (``False``: the last sweep's, as LMGC90 and Siconos do; the stability study's
    setting, since time steps going on from the best iterate made its 10^6 stack gain energy).
    ``accel``: "none" (plain NLGS) or "anderson" (:mod:`ncd.anderson`: Anderson
    acceleration of the sweeps with ``accel_memory`` stored differences, disc form only;
    memory 0 is plain NLGS).
    ``local_exact``: where the residual stalls, the contacts drifting most and their
    grains' other contacts solved exactly by Lemke's method, the other impulses frozen
    (:mod:`ncd.local_exact`; disc form only).
    """
    tol: float = 1e-8
    max_sweeps: int = 20000
    criterion: str = "residual"   # "residual" (natural map) or "change"
    check_every: int = 1          # sweeps between residual evaluations
    finish: str = "none"          # "none" or "active_set"
    finish_tol: float = 1e-10
    observable_tol: float = 1e-6
    keep_best: bool = True
    accel: str = "none"           # "none" or "anderson"
    accel_memory: int = 20
    local_exact: bool = False

    def __post_init__(self):
        checks.solver_settings(self)    # InputError naming the field (issue 14)
        if not (np.isfinite(self.tol) and self.tol > 0):
            raise ValueError(f"tol = {self.tol!r} must be > 0")
        if self.max_sweeps < 1 or self.check_every < 1:
            raise ValueError(f"max_sweeps = {self.max_sweeps}, check_every = {self.check_every} must be >= 1")
        if self.criterion not in CRITERIA:
            raise ValueError(f"criterion = {self.criterion!r} must be one of {sorted(CRITERIA)}")
        if self.finish not in FINISHES:
            raise ValueError(f"finish = {self.finish!r} must be one of {FINISHES}")
        for name in ("finish_tol", "observable_tol"):
            if not (np.isfinite(getattr(self, name)) and getattr(self, name) > 0):
                raise ValueError(f"{name} = {getattr(self, name)!r} must be > 0")
        if not isinstance(self.accel, str) or self.accel not in ACCELS:
            raise checks.InputError(f"settings.accel = {self.accel!r} must be one of {ACCELS}")
        object.__setattr__(self, "accel_memory", checks.integer("settings.accel_memory", self.accel_memory, 0, 100))

    def as_attrs(self):
        return {f"solver_{k}": int(v) if isinstance(v, bool) else v for k, v in asdict(self).items()}


@dataclass
class NLGSResult:
    """Impulses ``(n, 2)`` (normal, tangential), final status per contact and diagnostics."""
    impulse: np.ndarray
    status: np.ndarray
    sweeps: int
    residual: float
    change: float
    converged: bool
    finish_rounds: int = 0                  # LP projections of the finishing stage (0: none)
    finish_correction: float = 0.0          # relative L1 size of the accepted projection (0: none)
    observable_change: float = float("nan")  # relative change of the observable (nan: not observed)
    best_sweep: int = 0                     # sweep of the returned iterate (keep_best), 0: the last
    local_solves: int = 0                   # local exact solves (ncd.local_exact; 0: none)

    @property
    def impulse_n(self):
        return self.impulse[:, 0]

    @property
    def impulse_t(self):
        return self.impulse[:, 1]


# The drivers below are written once per form on purpose: passing the sweep and
# residual functions as arguments to one cached driver keys numba's on-disk cache
# on the dispatcher objects of the current process, so every process recompiled
# the driver, appended one more entry to the cache index, and eventually failed
# to pickle the index ("underlying object has vanished").
@njit(cache=True, inline="always")
def _check_now(k, change, tol, max_sweeps, criterion, check_every):
    return k % check_every == 0 or k == max_sweeps or (criterion == 1 and change <= tol)


@njit(cache=True, inline="always")
def _relative(dsum, ssum):
    return dsum / max(ssum, 1e-300) if ssum > 0.0 else 0.0


@njit(cache=True, inline="always")
def _done(res, change, tol, criterion):
    return (criterion == 0 and res <= tol) or (criterion == 1 and change <= tol)


@njit(cache=True, inline="always")
def _keep(keep, res, change, k, imp, keep_imp, status, keep_status):
    """Record the iterate if its residual is the smallest seen: ``keep = [res, change, sweep]``."""
    if res < keep[0]:
        keep[0] = res
        keep[1] = change
        keep[2] = k
        keep_imp[:] = imp
        keep_status[:] = status
        return True
    return False


# ---------------------------------------------------------------- disc form
# The packed arrays and their per-contact kernels: :mod:`ncd.nlgs_pack`.


@njit(cache=True, error_model="numpy")
def _sweep_discs(data, order, status):
    pair, coef, body, imp = data
    dsum = 0.0
    ssum = 0.0
    for k in range(order.shape[0]):
        c = order[k]
        un, ut = _relative_velocity(pair, coef, body, c)
        j = N_COEF * c
        wnn = coef[j + C_WNN]
        wtt = coef[j + C_WTT]
        sn = imp[2 * c]
        st = imp[2 * c + 1]
        qn = un - wnn * sn + coef[j + C_BN]
        qt = ut - wtt * st + coef[j + C_BT]
        rn, rt, st_ = solve_single_contact(wnn, 0.0, 0.0, wtt, qn, qt, coef[j + C_MU])
        status[c] = st_
        dn = rn - sn
        dt = rt - st
        imp[2 * c] = rn
        imp[2 * c + 1] = rt
        _add_impulse(pair, coef, body, c, dn, dt)
        dsum += abs(dn) + abs(dt)
        ssum += abs(rn) + abs(rt)
    return dsum, ssum


@njit(cache=True, error_model="numpy")
def _residual_discs(data):
    pair, coef, body, imp = data
    rsq = 0.0
    ssq = 0.0
    for c in range(imp.shape[0] // 2):
        un, ut = _relative_velocity(pair, coef, body, c)
        j = N_COEF * c
        rsq += natural_map_sq(imp[2 * c], imp[2 * c + 1], un + coef[j + C_BN], ut + coef[j + C_BT],
                              coef[j + C_MU], 1.0 / coef[j + C_WNN])
        ssq += imp[2 * c] ** 2 + imp[2 * c + 1] ** 2
    return rsq, ssq


@njit(cache=True, nogil=True, error_model="numpy")
def _iterate_discs(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
    """The NLGS driver (disc form): sweeps until the criterion holds or ``max_sweeps``;
    ``best = (keep, keep_imp, keep_status, keep_body, k0)`` records the iterate of
    smallest residual (sweeps counted from ``k0``) when ``keep[0]`` starts finite or inf."""
    keep, keep_imp, keep_status, keep_body, k0 = best
    change = np.inf
    res = np.inf
    for k in range(1, max_sweeps + 1):
        dsum, ssum = _sweep_discs(data, order, status)
        change = _relative(dsum, ssum)
        if _check_now(k, change, tol, max_sweeps, criterion, check_every):
            rsq, ssq = _residual_discs(data)
            res = np.sqrt(rsq) / max(scale, np.sqrt(ssq), 1e-300)
            if _keep(keep, res, change, k0 + k, data[3], keep_imp, status, keep_status):
                keep_body[:] = data[2]
            if _done(res, change, tol, criterion):
                return k, res, change, True
    return max_sweeps, res, change, False


def _scale(q, W):
    """``|rho q|`` with ``rho_alpha = 1 / W_alpha,nn``: the impulse scale of the problem."""
    return float(np.sqrt(np.sum((q / W[:, 0, 0][:, None]) ** 2)))


def restitution_bias(contacts, U_initial):
    """``e * U_i`` per component, for approaching contacts only (``U_i,n < 0``).

    The law is imposed on Moreau's weighted mean ``(U_f + e U_i) / (1 + e)``;
    since the Coulomb law is invariant under positive scaling of each velocity
    component, this is the law on ``U_f + e U_i``.
    """
    return _restitution_bias(contacts.e_n, contacts.e_t, U_initial)


@njit(cache=True)
def _restitution_bias(e_n, e_t, U_initial):
    """The loop of :func:`restitution_bias`."""
    bias = np.zeros_like(U_initial)
    for c in range(U_initial.shape[0]):
        if U_initial[c, 0] < 0.0:
            bias[c, 0] = e_n[c] * U_initial[c, 0]
            bias[c, 1] = e_t[c] * U_initial[c, 1]
    return bias


@checks.finite_output
def solve_discs(scene, contacts, vel, spin, guess=None, review_order=None,
                settings=SolverSettings(), bias=None, W=None, observe=None):
    """Solve the core problem of one step by NLGS in disc form.

    ``vel, spin`` hold the free velocities on entry and the end-of-step
    velocities ``u_f`` on return (modified in place).  ``guess`` is the initial
    impulse array (n, 2) (zero if None); ``review_order`` a permutation of the
    contacts (identity if None); ``bias`` the restitution term ``e U_i``;
    ``observe(impulse, vel, spin)``: see :func:`ncd.convergence.run_nlgs`.
    """
    guess, review_order, bias, W = checks.disc_problem(scene, contacts, vel, spin, guess, review_order,
                                                       settings, bias, W)
    if observe is not None and not callable(observe):
        raise checks.InputError(f"observe = {observe!r} must be None or a callable (impulse, vel, spin) -> array")
    n = contacts.n
    impulse = np.zeros((n, 2)) if guess is None else np.array(guess, dtype=float).reshape(n, 2)
    status = np.zeros(n, np.int8)
    if n == 0:
        return NLGSResult(impulse, status, 0, 0.0, 0.0, True)
    order = np.arange(n) if review_order is None else np.asarray(review_order, dtype=np.int64)
    bias = np.zeros((n, 2)) if bias is None else bias
    c = contacts
    W = delassus_blocks(c.body_a, c.body_b, c.arm_a, c.arm_b, scene.inv_mass, scene.inv_inertia) if W is None else W
    q_free = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((n, 2))) + bias
    pair, coef, body = pack_problem(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, W, c.mu, bias,
                                    scene.inv_mass, scene.inv_inertia, vel, spin)
    flat = (pair.ravel(), coef.ravel(), body.ravel(), impulse.ravel())
    iterate = _iterate_discs
    if settings.accel == "anderson" and settings.accel_memory > 0:
        from .anderson import driver
        iterate = driver(flat, settings.accel_memory)      # before the guess: it keeps the free velocities
    _apply_all(*flat)
    from .convergence import run_nlgs
    look = None if observe is None else (lambda: observe(impulse, body[:-1, :2], body[:-1, 2]))
    local = None
    if settings.local_exact:
        from .local_exact import LocalExact
        nm = scene.n_mobile
        local = LocalExact(scene, contacts, np.column_stack([vel[:nm], spin[:nm]]).ravel(), q_free, flat,
                           getattr(iterate, "reset", None))
        iterate = local.driver(iterate)
    result = run_nlgs(iterate, flat, order, status, _scale(q_free, W), settings, look)
    result.impulse = impulse
    result.local_solves = 0 if local is None else local.solves
    if settings.finish != "none":
        from .finish import polish_discs
        result = polish_discs(scene, contacts, vel, spin, bias, q_free, W, flat, order, result, settings)
    vel[:] = body[:-1, :2]
    spin[:] = body[:-1, 2]
    return result


# ---------------------------------------------------------------- local form
@njit(cache=True, error_model="numpy")
def _local_U(indptr, indices, values, q, flat, row):
    u = q[row]
    for j in range(indptr[row], indptr[row + 1]):
        u += values[j] * flat[indices[j]]
    return u


@njit(cache=True, error_model="numpy")
def _sweep_local(data, order, status):
    indptr, indices, values, q, Wd, mu, flat = data
    dsum = 0.0
    ssum = 0.0
    for k in range(order.shape[0]):
        c = order[k]
        sn = flat[2 * c]
        st = flat[2 * c + 1]
        qn = _local_U(indptr, indices, values, q, flat, 2 * c) - Wd[c, 0, 0] * sn - Wd[c, 0, 1] * st
        qt = _local_U(indptr, indices, values, q, flat, 2 * c + 1) - Wd[c, 1, 0] * sn - Wd[c, 1, 1] * st
        rn, rt, st_ = solve_single_contact(Wd[c, 0, 0], Wd[c, 0, 1], Wd[c, 1, 0], Wd[c, 1, 1], qn, qt, mu[c])
        status[c] = st_
        flat[2 * c] = rn
        flat[2 * c + 1] = rt
        dsum += abs(rn - sn) + abs(rt - st)
        ssum += abs(rn) + abs(rt)
    return dsum, ssum


@njit(cache=True, error_model="numpy")
def _residual_local(data):
    indptr, indices, values, q, Wd, mu, flat = data
    rsq = 0.0
    ssq = 0.0
    for c in range(Wd.shape[0]):
        un = _local_U(indptr, indices, values, q, flat, 2 * c)
        ut = _local_U(indptr, indices, values, q, flat, 2 * c + 1)
        rsq += natural_map_sq(flat[2 * c], flat[2 * c + 1], un, ut, mu[c], 1.0 / Wd[c, 0, 0])
        ssq += flat[2 * c] ** 2 + flat[2 * c + 1] ** 2
    return rsq, ssq


@njit(cache=True, nogil=True, error_model="numpy")
def _iterate_local(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
    """The NLGS driver (local form): as :func:`_iterate_discs` (``keep_body`` unused)."""
    keep, keep_imp, keep_status, keep_body, k0 = best
    change = np.inf
    res = np.inf
    for k in range(1, max_sweeps + 1):
        dsum, ssum = _sweep_local(data, order, status)
        change = _relative(dsum, ssum)
        if _check_now(k, change, tol, max_sweeps, criterion, check_every):
            rsq, ssq = _residual_local(data)
            res = np.sqrt(rsq) / max(scale, np.sqrt(ssq), 1e-300)
            _keep(keep, res, change, k0 + k, data[6], keep_imp, status, keep_status)
            if _done(res, change, tol, criterion):
                return k, res, change, True
    return max_sweeps, res, change, False


@checks.finite_output
def solve_local(W, q, mu, guess=None, review_order=None, settings=SolverSettings()):
    """NLGS on a 2-D frictional contact problem in local form.

    Find ``s`` (n, 2) with ``U = W s + q`` and the Coulomb law at each contact.
    ``W`` is (2n, 2n), dense or scipy.sparse, rows ordered (n_1, t_1, n_2, ...);
    ``q`` (2n,); ``mu`` scalar or (n,).  Checks: :func:`ncd.checks.local_problem`.
    """
    W, q, mu, guess, review_order = checks.local_problem(W, q, mu, guess, review_order, settings)
    if settings.accel != "none":
        raise checks.InputError(f"settings.accel = {settings.accel!r}: acceleration is implemented "
                                "for the disc form (solve_discs, solve_problem) only")
    if settings.local_exact:
        raise checks.InputError("settings.local_exact = True: local exact solves are implemented "
                                "for the disc form (solve_discs, solve_problem) only")
    if len(q) == 0:
        return NLGSResult(np.zeros((0, 2)), np.zeros(0, np.int8), 0, 0.0, 0.0, True)
    Wc = sp.csr_matrix(W, dtype=float)
    q = np.asarray(q, dtype=float).ravel()
    n = len(q) // 2
    if Wc.shape != (2 * n, 2 * n) or len(q) != 2 * n:
        raise ValueError(f"W has shape {Wc.shape}, q has length {len(q)}: expected (2n, 2n) and 2n")
    mu = np.broadcast_to(np.asarray(mu, dtype=float), (n,)).copy()
    if np.any(mu < 0):
        raise ValueError(f"mu must be >= 0; got min {mu.min()}")
    Wd = np.empty((n, 2, 2))
    for i, j in ((0, 0), (0, 1), (1, 0), (1, 1)):
        Wd[:, i, j] = Wc[np.arange(n) * 2 + i, np.arange(n) * 2 + j].A1
    if np.any(Wd[:, 0, 0] <= 0) or np.any(Wd[:, 0, 0] * Wd[:, 1, 1] - Wd[:, 0, 1] * Wd[:, 1, 0] <= 0):
        raise ValueError("the diagonal 2x2 blocks of W must be positive definite")
    flat = np.zeros(2 * n) if guess is None else np.array(guess, dtype=float).ravel().copy()
    order = np.arange(n) if review_order is None else np.asarray(review_order, dtype=np.int64)
    status = np.zeros(n, np.int8)
    data = (Wc.indptr.astype(np.int64), Wc.indices.astype(np.int64), Wc.data, q, Wd, mu, flat)
    from .convergence import run_nlgs
    result = run_nlgs(_iterate_local, data, order, status, _scale(q.reshape(n, 2), Wd), settings)
    result.impulse = flat.reshape(n, 2)
    if settings.finish != "none":
        from .finish import polish_local
        result = polish_local(Wc, q, mu, Wd, data, order, result, settings)
    return result
