"""Nonlinear Gauss-Seidel (NLGS): the front door of the solver layer.

Contacts are reviewed one at a time in a ``review_order``; each is solved exactly
with the other impulses frozen and the result propagated at once (Moreau 2005,
section 2).  Two forms of one problem share the drivers of :mod:`ncd.solver.kernels`:
:func:`solve_discs` (body velocities updated incrementally, packed by
:mod:`ncd.solver.pack`: a sweep costs O(contacts)) and :func:`solve_local`
(``U = W s + q`` with ``W`` dense or sparse, as LMGC90 and Siconos export 2-D
problems).  This module composes the variants chosen by
:class:`ncd.solver.settings.SolverSettings`: Anderson acceleration, local exact solves,
chunked runs with an observable (:mod:`ncd.solver.convergence`) and the active-set
finishing stage (:mod:`ncd.solver.finish`); none of them imports it back.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ncd.core import validate
from ncd.core.contacts import Contacts, check_contacts, check_disc_blocks, delassus_blocks, local_velocity
from ncd.core.errors import InputError
from ncd.core.jit import njit
from ncd.core.model import Scene, check_scene
from ncd.core.validate import array, impulse_guess, per_item, permutation, shape_of, show, sparse_matrix
from ncd.solver.anderson import driver
from ncd.solver.convergence import run_nlgs
from ncd.solver.finish import polish_discs, polish_local
from ncd.solver.kernels import iterate_discs, iterate_local, problem_scale
from ncd.solver.local_exact import LocalExact
from ncd.solver.pack import apply_all, pack_problem
from ncd.solver.settings import NLGSResult, SolverSettings, check_settings_arg

# ``observe(impulse, vel, spin) -> 1-D array``: a figure's observable (:mod:`ncd.solver.convergence`)
Observer = Callable[[np.ndarray, np.ndarray, np.ndarray], ArrayLike]
# ``(W, H, M^-1)`` of :func:`ncd.solver.finish.global_delassus`
Delassus = tuple[sp.spmatrix, sp.spmatrix, np.ndarray]

# ------------------------------------------------------------ entry points


def restitution_bias(contacts: Contacts, U_initial: np.ndarray) -> np.ndarray:
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


@validate.finite_output
def solve_discs(scene: Scene, contacts: Contacts, vel: np.ndarray, spin: np.ndarray,
                guess: ArrayLike | None = None, review_order: ArrayLike | None = None,
                settings: SolverSettings = SolverSettings(), bias: ArrayLike | None = None,
                W: np.ndarray | None = None, observe: Observer | None = None, check: bool = True,
                delassus: Delassus | None = None) -> NLGSResult:
    """Solve the core problem of one step by NLGS in disc form.

    ``vel, spin`` hold the free velocities on entry and the end-of-step
    velocities ``u_f`` on return (modified in place).  ``guess`` is the initial
    impulse array (n, 2) (zero if None); ``review_order`` a permutation of the
    contacts (identity if None); ``bias`` the restitution term ``e U_i``;
    ``observe(impulse, vel, spin)``: see :func:`ncd.solver.convergence.run_nlgs`.
    ``check=False``: the caller has checked the arguments (:func:`ncd.step` does).
    ``delassus``: ``(W, H, M^-1)`` of :func:`ncd.solver.finish.global_delassus` for these
    contacts, which the finishing stage and local exact solves need; an ensemble of runs
    on one problem builds it once (None: built here when needed).
    """
    if check:
        guess, review_order, bias, W = check_disc_problem(scene, contacts, vel, spin, guess, review_order,
                                                           settings, bias, W)
        check_delassus(delassus, contacts.n, scene.n_mobile)
    if observe is not None and not callable(observe):
        raise InputError(f"observe = {observe!r} must be None or a callable (impulse, vel, spin) -> array")
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
    iterate = iterate_discs
    if settings.accel == "anderson" and settings.accel_memory > 0:
        iterate = driver(flat, settings.accel_memory)      # before the guess: it keeps the free velocities
    apply_all(*flat)
    look = None if observe is None else (lambda: observe(impulse, body[:-1, :2], body[:-1, 2]))
    local = None
    if settings.local_exact:
        nm = scene.n_mobile
        local = LocalExact(scene, contacts, np.column_stack([vel[:nm], spin[:nm]]).ravel(), q_free, flat,
                           getattr(iterate, "reset", None), delassus)
        iterate = local.driver(iterate)
    result = run_nlgs(iterate, flat, order, status, problem_scale(q_free, W), settings, look)
    result.impulse = impulse
    result.local_solves = 0 if local is None else local.solves
    if settings.finish != "none":
        result = polish_discs(scene, contacts, vel, spin, bias, q_free, W, flat, order, result, settings,
                              delassus)
    vel[:] = body[:-1, :2]
    spin[:] = body[:-1, 2]
    return result


@validate.finite_output
def solve_local(W: ArrayLike | sp.spmatrix, q: ArrayLike, mu: float | ArrayLike, guess: ArrayLike | None = None,
                review_order: ArrayLike | None = None, settings: SolverSettings = SolverSettings()) -> NLGSResult:
    """NLGS on a 2-D frictional contact problem in local form.

    Find ``s`` (n, 2) with ``U = W s + q`` and the Coulomb law at each contact.
    ``W`` is (2n, 2n), dense or scipy.sparse, rows ordered (n_1, t_1, n_2, ...);
    ``q`` (2n,); ``mu`` scalar or (n,).  Checks: :func:`check_local_problem`.
    """
    # checked once, returned in the form the kernel reads: Wc CSR, q flat, mu (n,), guess (n, 2), order int64
    Wc, q, mu, guess, order = check_local_problem(W, q, mu, guess, review_order, settings)
    if settings.accel != "none":
        raise InputError(f"settings.accel = {settings.accel!r}: acceleration is implemented "
                         "for the disc form (solve_discs, solve_problem) only")
    if settings.local_exact:
        raise InputError("settings.local_exact = True: local exact solves are implemented "
                         "for the disc form (solve_discs, solve_problem) only")
    if len(q) == 0:
        return NLGSResult(np.zeros((0, 2)), np.zeros(0, np.int8), 0, 0.0, 0.0, True)
    n = len(q) // 2
    Wd = np.empty((n, 2, 2))                  # the diagonal blocks (positive definite: checked)
    for i, j in ((0, 0), (0, 1), (1, 0), (1, 1)):
        Wd[:, i, j] = Wc[np.arange(n) * 2 + i, np.arange(n) * 2 + j].A1
    flat = guess.reshape(-1).copy()
    status = np.zeros(n, np.int8)
    data = (Wc.indptr.astype(np.int64), Wc.indices.astype(np.int64), Wc.data, q, Wd, mu, flat)
    result = run_nlgs(iterate_local, data, order, status, problem_scale(q.reshape(n, 2), Wd), settings)
    result.impulse = flat.reshape(n, 2)
    if settings.finish != "none":
        result = polish_local(Wc, q, mu, Wd, data, order, result, settings)
    return result


# ------------------------------------------------------------ argument checks
def check_local_problem(W, q, mu, guess, review_order, settings):
    """All arguments of :func:`ncd.solve_local`; returns ``(Wc, q, mu, guess, order)``, ``Wc`` CSR.

    ``W`` is square ``2 n`` and finite; each diagonal 2x2 block ``B`` must be positive
    definite as ``x . B x > 0`` (its symmetric part is), which makes it invertible and
    admits the non-symmetric blocks the single-contact solver handles.  The coupling
    blocks are not checked: an NLGS diverging on them ends in :class:`ncd.SimulationError`."""
    q = array("q", q, (None,))
    if len(q) % 2:
        raise InputError(f"q has length {len(q)}, expected 2 n (rows n_1, t_1, n_2, ...)")
    n = len(q) // 2
    Wc = sparse_matrix("W", W) if sp.issparse(W) else None
    shape = shape_of("W", W) if Wc is None else Wc.shape
    if shape != (2 * n, 2 * n):
        raise InputError(f"W has shape {shape}, q has length {len(q)}: expected (2n, 2n) and 2n")
    if Wc is None:
        Wc = sp.csr_matrix(array("W", W, shape))
    mu = per_item("mu", mu, n, 0.0)
    if n:
        rows = np.arange(n) * 2
        nn, nt = Wc[rows, rows].A1, Wc[rows, rows + 1].A1
        tn, tt = Wc[rows + 1, rows].A1, Wc[rows + 1, rows + 1].A1
        bad = ~((nn > 0) & (tt > 0) & (nn * tt > (0.5 * (nt + tn)) ** 2))
        if np.any(bad):
            k = int(np.argmax(bad))
            raise InputError(f"the diagonal 2x2 blocks of W must be positive definite (x.Bx > 0); block {k} "
                             f"= {[[float(nn[k]), float(nt[k])], [float(tn[k]), float(tt[k])]]} is not")
    check_settings_arg(settings)
    return Wc, q, mu, impulse_guess("guess", guess, n), permutation("review_order", review_order, n)


def check_delassus(delassus, n, n_mobile):
    """``delassus`` of :func:`solve_discs`: None, or ``(W, H, minv)`` with ``W`` sparse
    (2n, 2n), ``H`` sparse (3 n_mobile, 2n) and ``minv`` (3 n_mobile,), all finite (a NaN
    would reach the Lemke kernel of the local exact solves)."""
    if delassus is None:
        return
    shapes = ((2 * n, 2 * n), (3 * n_mobile, 2 * n), (3 * n_mobile,))
    if not (isinstance(delassus, tuple) and len(delassus) == 3 and sp.issparse(delassus[0])
            and sp.issparse(delassus[1]) and all(np.shape(x) == sh for x, sh in zip(delassus, shapes))):
        raise InputError(f"delassus must be None or (W, H, minv) of global_delassus with shapes {shapes}; "
                         f"got {show(delassus)}")
    W, H, minv = delassus
    if not (np.isfinite(W.data).all() and np.isfinite(H.data).all() and np.isfinite(minv).all()):
        raise InputError("delassus (W, H, minv) must be finite; it holds NaN or inf")


def check_disc_problem(s, c, vel, spin, guess, review_order, settings, bias, W):
    """All arguments of :func:`ncd.solve_discs`; returns ``(guess, order, bias, W)``."""
    check_scene(s)
    check_contacts(s, c)
    n, nd = c.n, s.n_disc
    for nm_, value, shape in (("vel", vel, (nd, 2)), ("spin", spin, (nd,))):
        if not (isinstance(value, np.ndarray) and value.dtype == np.float64 and value.flags.writeable):
            raise InputError(f"{nm_} must be a writeable float64 numpy array of shape {shape} (modified in place); "
                             f"got {show(value)}")
        array(nm_, value, shape)
    check_settings_arg(settings)
    W = None if W is None else check_disc_blocks(W, n)
    bias = np.zeros((n, 2)) if bias is None else array("bias", bias, (n, 2))
    return impulse_guess("guess", guess, n), permutation("review_order", review_order, n), bias, W
