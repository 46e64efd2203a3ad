"""Active-set finishing stage: the exact solution NLGS is converging towards.

NLGS settles every contact's *status* (open, stick, slide forward or backward) long
before its impulses converge.  In 2-D the Coulomb cone is polyhedral, so the one-step
solutions sharing a status pattern form a polyhedron (:mod:`ncd.solver.finish_lp`).
:func:`polish` lets NLGS go on while its own rate predicts ``finish_tol`` within
:data:`LP_SWEEPS` sweeps; otherwise it projects the iterate on the polyhedron of its
statuses (nearest point in L1, an LP) and accepts the projection only if its residual
is ``<= finish_tol`` and it moves the impulses by at most :data:`MAX_CORRECTION`, so
that it stays on the solution NLGS approaches instead of jumping to another one of an
indeterminate problem.  An empty polyhedron near a solution falls back on the states
at rest (:func:`rest_status`).  :func:`check_solution` checks a solution
componentwise; :func:`project_statuses` (minimum-norm point of a status pattern's
affine set) serves the census of :mod:`ncd.figures.fig2_slope.census`.  Trade-offs: docs/solvers.md.
"""
import logging

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ncd.core.contacts import h_matrix
from ncd.solver.finish_lp import StatusLP, project
from ncd.solver.kernels import iterate_discs, iterate_local, problem_scale
from ncd.solver.single_contact import NO_CONTACT, SLIDE_BACKWARD, SLIDE_FORWARD, STICK

FIRST_CHUNK = 50         # NLGS sweeps (at least; a quarter of those made) that measure NLGS's rate
LP_SWEEPS = 50000        # NLGS goes on while its rate predicts finish_tol within this many sweeps
MAX_ATTEMPTS = 3         # failed projections (an empty polyhedron is a long LP) before NLGS alone
REST_GATE = 1e-5         # the rest polyhedron is tried from iterates this close only (far ones: long LPs, rejected)
MAX_CORRECTION = 0.05    # a projection moving the impulses by more (relative L1) is a jump: rejected
JUMP_MARGIN = 1e-6       # relative L1: a projection skipped as a jump only when its bound clears MAX_CORRECTION by this
LOG = logging.getLogger(__name__)
REFINE = 30              # iterated-Tikhonov refinements of one minimum-norm correction (census)


def global_delassus(scene, contacts):
    """``(W, H, M^-1)``: the sparse Delassus matrix ``W = H^T M^-1 H`` (2n, 2n)."""
    H = h_matrix(scene, contacts).tocsr()
    nm = scene.n_mobile
    minv = np.column_stack([scene.inv_mass[:nm], scene.inv_mass[:nm], scene.inv_inertia[:nm]]).ravel()
    return (H.T @ sp.diags(minv) @ H).tocsr(), H, minv


def natural_map(s, U, mu, rho):
    """Per-contact natural map ``s - proj_K(s - rho U~)`` (n, 2), vectorized
    (:func:`ncd.solver.single_contact.natural_map_sq`), and the regions of ``z``."""
    zn = s[:, 0] - rho * (U[:, 0] + mu * np.abs(U[:, 1]))
    zt = s[:, 1] - rho * U[:, 1]
    inside = (zn >= 0) & (np.abs(zt) <= mu * zn)
    polar = ~inside & (mu * np.abs(zt) <= -zn)
    pn = np.where(inside, zn, np.where(polar, 0.0, (zn + mu * np.abs(zt)) / (1 + mu * mu)))
    pt = np.where(inside, zt, np.where(polar, 0.0, np.sign(zt) * mu * pn))
    status = np.where(inside, STICK, np.where(polar, NO_CONTACT,
                                              np.where(zt > 0, SLIDE_BACKWARD, SLIDE_FORWARD)))
    return np.column_stack([s[:, 0] - pn, s[:, 1] - pt]), status.astype(np.int8)


def relative_residual(s, U, mu, rho, scale):
    """The relative natural-map residual of the NLGS kernels (:mod:`ncd.solver.kernels`)."""
    F, _ = natural_map(s, U, mu, rho)
    return float(np.sqrt(np.sum(F ** 2)) / max(scale, np.sqrt(np.sum(s ** 2)), 1e-300))


def status_system(mu, status):
    """``(P, S)``: impulses ``s = P x`` and constrained velocity rows ``S^T U`` of the statuses.

    A sticking contact has two unknowns ``(s_n, s_t)`` and two rows ``U_n = U_t = 0``, a
    sliding one one unknown ``s_n`` (``s_t = -+mu s_n``) and the row ``U_n = 0``, an open one
    none; unknowns in contact order."""
    status, mu = np.asarray(status), np.asarray(mu, float)
    n = len(status)
    stick = (status == STICK) | (status > SLIDE_BACKWARD)       # FALLBACK reads as stick
    slide = (status == SLIDE_FORWARD) | (status == SLIDE_BACKWARD)
    sign = np.where(status == SLIDE_FORWARD, -1.0, 1.0)
    width = np.where(stick, 2, np.where(slide, 1, 0))
    first = np.cumsum(width) - width                             # first unknown of each contact
    col = int(width.sum())
    # per closed contact c at column k: P[2c, k] = 1 and P[2c+1, k+1] = 1 (stick) or P[2c+1, k] = sign mu (slide)
    c = np.nonzero(width)[0]
    rows = np.column_stack([2 * c, 2 * c + 1]).ravel()
    cols = np.column_stack([first[c], first[c] + width[c] - 1]).ravel()
    vals = np.column_stack([np.ones(len(c)), np.where(stick[c], 1.0, sign[c] * mu[c])]).ravel()
    P = sp.csr_matrix((vals, (rows, cols)), shape=(2 * n, col))
    srow = np.empty(col, np.int64)
    srow[first[c]] = 2 * c
    c_st = np.nonzero(stick)[0]
    srow[first[c_st] + 1] = 2 * c_st + 1
    S = sp.csr_matrix((np.ones(col), (srow, np.arange(col))), shape=(2 * n, col))
    return P, S


def min_norm_solve(K, r, eps_rel=1e-10):
    """Minimum-norm solution of the consistent system ``K d = r`` (iterated Tikhonov on
    ``[[I, K^T], [K, -eps I]]``, one sparse LU, refined while each step at least halves
    the residual); a truncated least-squares one otherwise."""
    m = K.shape[0]
    if m == 0:
        return np.zeros(0)
    eps = eps_rel * max(abs(K).sum(axis=1).max(), 1e-300) ** 2
    A = _kkt(K, eps)
    lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options={"SymmetricMode": True})
    d = np.zeros(m)
    rnorm, prev = np.linalg.norm(r), np.inf
    for _ in range(REFINE):
        e = r - K @ d
        enorm = np.linalg.norm(e)
        # stop at round-off, or when a refinement no longer halves the residual (the
        # rest lies along nearly singular modes: a truncated minimum-norm correction)
        if enorm <= 1e-15 * max(rnorm, 1e-300) or enorm > 0.5 * prev:
            break
        prev = enorm
        d += lu.solve(np.concatenate([np.zeros(m), e]))[:m]
    return d


def _kkt(K, eps):
    """``[[I, K^T], [K, -eps I]]`` (CSC) of the square ``K``, entries in the order of
    ``scipy.sparse.bmat`` (blocks row by row, each in COO order), so the LU is the same,
    without bmat's per-block conversions (on the census, 14 s of its 81 s of minimum-norm
    solves)."""
    m = K.shape[0]
    Kc = K.tocoo()
    d = np.arange(m)
    e = d if eps != 0 else d[:0]          # bmat drops a zero diagonal block's entries
    row = np.concatenate([d, Kc.col, Kc.row + m, e + m])
    col = np.concatenate([d, Kc.row + m, Kc.col, e + m])
    data = np.concatenate([np.ones(m), Kc.data, Kc.data, np.full(len(e), -eps)])
    return sp.coo_matrix((data, (row, col)), shape=(2 * m, 2 * m)).tocsc()


def project_statuses(W, q, mu, s0, status):
    """The point of the affine set of ``status`` nearest to ``s0`` (in the unknowns ``x``)."""
    P, S = status_system(mu, status)
    K = (S.T @ W @ P).tocsr()
    x0 = (P.T @ s0.ravel()) / np.asarray(P.multiply(P).sum(axis=0)).ravel()   # x0 = P^+ s0
    r = -(S.T @ (W @ (P @ x0) + q))
    return (P @ (x0 + min_norm_solve(K, r))).reshape(-1, 2)


def polish(make_lp, W, q, mu, rho, scale, s0, status0, tol, more_sweeps, max_sweeps, sweeps0, presolve=True):
    """Finishing stage (module docstring) from the NLGS iterate ``s0`` (``status0``, after
    ``sweeps0`` sweeps); ``more_sweeps(k) -> (s, status)`` runs NLGS on.  ``make_lp()``
    builds the :class:`StatusLP`, at the first projection only: most runs of an ensemble
    reach ``tol`` by NLGS alone, and the LP's matrices cost more than their sweeps.  Failed projections
    are retried after chunks growing 4x, :data:`MAX_ATTEMPTS` times at most.  Returns ``(s,
    status, residual, lp_solves, ok, extra_sweeps, correction)``, the best iterate when the
    budget runs out; ``correction`` is ``|s - s_k|_1 / |s_k|_1`` of the accepted projection
    (0 when NLGS got there).  ``presolve``: HiGHS's presolve on the projections
    (:func:`ncd.solver.finish_lp.project`)."""
    def residual(s):
        return relative_residual(s, (W @ s.ravel() + q).reshape(-1, 2), mu, rho, scale)

    s, status = s0, np.where(status0 > SLIDE_BACKWARD, STICK, status0).astype(np.int8)
    res = residual(s)
    best = (res, s, status)
    solves, attempts, extra, chunk, rate = 0, 0, 0, max(FIRST_CHUNK, sweeps0 // 4, 1), None
    lp = None
    seen = {}       # polyhedron (its statuses' bytes) -> (iterate, L1 distance) of its last projection
    while True:
        if res <= tol:
            return s, status, res, solves, True, extra, 0.0
        ahead = np.inf if rate is None or rate <= 0 else np.log(res / tol) / rate
        if rate is None and FIRST_CHUNK > 0:
            k = min(chunk, max_sweeps - extra)                                # NLGS's rate first
        elif ahead <= LP_SWEEPS:
            k = int(min(np.ceil(1.2 * ahead) + 10, max_sweeps - extra))     # NLGS converges: let it
        elif attempts >= MAX_ATTEMPTS:
            k = min(chunk, max_sweeps - extra)
            chunk *= 4
        else:
            attempts += 1
            solves += 1
            lp = make_lp() if lp is None else lp
            cand, info = project_unless_jump(lp, s, status, presolve, seen)
            if cand is None and not info["jump"] and res <= REST_GATE:   # no solution with its statuses: the nearest at rest
                cand, info = project_unless_jump(lp, s, rest_status(lp), presolve, seen)
                LOG.debug("rest polyhedron: %s", info["status"])
            r = np.inf if cand is None else residual(cand)
            LOG.debug("sweeps %d residual %.2e: LP (%s, %d iterations) -> %.2e",
                      sweeps0 + extra, res, info["status"], info["iterations"], r)
            if cand is not None:
                region = natural_map(cand, (W @ cand.ravel() + q).reshape(-1, 2), mu, rho)[1]
                corr = info["correction"] / max(np.abs(s).sum(), 1e-300)
                if r < best[0] and info["correction"] <= MAX_CORRECTION * np.abs(s).sum():
                    best = (r, cand, region)
                if r <= tol and corr <= MAX_CORRECTION:
                    return cand, region, r, solves, True, extra, corr
                # else: an empty polyhedron, a residual above tol, or a jump to another
                # solution far from the iterate: more sweeps first
            k = min(chunk, max_sweeps - extra)
            chunk *= 4
        if k <= 0:
            return best[1], best[2], best[0], solves, False, extra, float("nan")
        s_new, status = more_sweeps(k)
        status = np.where(status > SLIDE_BACKWARD, STICK, status).astype(np.int8)
        extra += k
        res_new = residual(s_new)
        rate = np.log(res / res_new) / k if res_new > 0 else np.inf
        s, res = s_new, res_new
        if res < best[0]:
            best = (res, s, status)


def project_unless_jump(lp, s, status, presolve, seen):
    """:func:`ncd.solver.finish_lp.project` of ``s`` on the polyhedron of ``status``, skipped
    when its answer can only be a jump: the L1 distance to a set is 1-Lipschitz in the L1
    norm, so an iterate ``s`` at most ``|s - s'|_1`` nearer than an earlier iterate ``s'``
    projected on the same polyhedron (``seen``) lies at least ``d(s') - |s - s'|_1`` from it.
    Where that bound exceeds :data:`MAX_CORRECTION` (plus :data:`JUMP_MARGIN`, far above the
    LP's tolerances), the projection would be rejected whatever vertex the LP returned, so
    :func:`polish` goes on exactly as after it (a rejected candidate, so no rest polyhedron
    after a skipped status projection): the same sweeps, projections and result.  Returns
    ``(candidate or None, info)``, ``info["jump"]`` True where the projection was skipped."""
    key = status.tobytes()
    size = np.abs(s).sum()
    if key in seen:
        s_prev, d_prev = seen[key]
        if d_prev - np.abs(s - s_prev).sum() > (MAX_CORRECTION + JUMP_MARGIN) * size:
            return None, {"status": "skipped: a jump by the distance of an earlier iterate", "iterations": 0,
                          "jump": True}
    cand, _, info = project(lp, s, status, presolve=presolve)
    info["jump"] = False
    if cand is not None:
        seen[key] = (s.copy(), info["correction"])
    return cand, info


def rest_status(lp):
    """Every contact sticking (``U = 0``) except those whose gap velocity is positive with
    the bodies at rest (``b_n > 0``: open).  Its polyhedron is the set of one-step
    solutions at rest: the equilibrium forces A ∩ C (times ``h``) where the free motion
    is the weight's."""
    return np.where(lp.b[0::2] > 0, NO_CONTACT, STICK).astype(np.int8)


def check_solution(impulse, U, mu, tol=1e-8, velocity_scale=None):
    """Componentwise check of the Signorini-Coulomb law: a dict of the largest violations
    and ``ok``.  Cone ``s_n >= 0``, ``|s_t| <= mu s_n``; ``U_n >= 0``, ``s_n U_n = 0``;
    sticking (``|s_t| < mu s_n``): ``U_t = 0``; sliding: ``s_t U_t <= 0``.  Impulses are
    scaled by ``max |s|``, velocities by ``velocity_scale`` (default ``max |U|``; pass the
    free-velocity scale, e.g. ``|g| h``, for a state at rest)."""
    s = np.asarray(impulse, float).reshape(-1, 2)
    U = np.asarray(U, float).reshape(-1, 2)
    S = max(float(np.abs(s).max(initial=0.0)), 1e-300)
    V = float(np.abs(U).max(initial=0.0)) if velocity_scale is None else float(velocity_scale)
    V = V if V > 0 else 1.0
    sn, st = s[:, 0] / S, s[:, 1] / S
    un, ut = U[:, 0] / V, U[:, 1] / V
    inner = np.abs(st) < mu * sn - tol
    out = {
        "cone_normal": float(max(0.0, -sn.min(initial=0.0))),
        "cone_tangential": float(max(0.0, (np.abs(st) - mu * sn).max(initial=0.0))),
        "gap_velocity": float(max(0.0, -un.min(initial=0.0))),
        "complementarity": float(np.abs(sn * un).max(initial=0.0)),
        "sticking_velocity": float(np.abs(ut[inner]).max(initial=0.0)),
        "sliding_direction": float(max(0.0, (st * ut)[~inner].max(initial=0.0))),
    }
    out["ok"] = all(v <= tol for v in out.values())
    return out


def polish_local(Wc, q, mu, Wd, data, order, result, settings):
    """The finishing stage of :func:`ncd.solver.nlgs.solve_local` (``data`` its kernel data)."""
    n = len(mu)
    scale = problem_scale(q.reshape(n, 2), Wd)
    flat, status = data[6], result.status

    def more(k):
        keep = (np.array([-np.inf, 0.0, 0.0]), np.empty_like(flat), np.empty_like(status), np.empty(0), 0)
        iterate_local(data, order, status, scale, 0.0, k, 0, k, keep)
        return flat.reshape(n, 2).copy(), status.copy()

    s0 = flat.reshape(n, 2).copy()

    def make_lp():
        return StatusLP.local(Wc, q, mu, max(float(np.abs(s0).max(initial=0.0)), scale / np.sqrt(n)),
                              max(float(np.abs(q).max()), 1e-300))
    out = polish(make_lp, Wc, q, mu, 1.0 / Wd[:, 0, 0], scale, s0, status.copy(), settings.finish_tol, more,
                 settings.max_sweeps, result.sweeps, settings.finish_presolve)
    flat[:] = out[0].ravel()
    return _finished(result, *out)


def polish_discs(scene, contacts, vel, spin, bias, q_free, Wb, flat, order, result, settings, delassus=None):
    """The finishing stage of :func:`ncd.solver.nlgs.solve_discs`; updates the body velocities.
    ``delassus``: :func:`global_delassus` of the problem, built once by the caller for the
    many runs of an ensemble (None: built here)."""
    n = contacts.n
    W, H, minv = global_delassus(scene, contacts) if delassus is None else delassus
    scale = problem_scale(q_free, Wb)
    body, imp, status = flat[2].reshape(-1, 4), flat[3], result.status
    s_start = imp.reshape(n, 2).copy()

    def more(k):
        keep = (np.array([-np.inf, 0.0, 0.0]), np.empty_like(imp), np.empty_like(status), np.empty_like(flat[2]), 0)
        iterate_discs(flat, order, status, scale, 0.0, k, 0, k, keep)
        return imp.reshape(n, 2).copy(), status.copy()

    # q of U = W s + q: the free local velocity (bias included) of :func:`ncd.solver.nlgs.solve_discs`
    nm = scene.n_mobile
    free = np.column_stack([vel[:nm], spin[:nm]]).ravel()       # u_free (vel, spin untouched so far)

    def make_lp():
        return StatusLP.discs(H, minv, free, bias, contacts.mu, scene.radius[:nm],
                              max(float(np.abs(s_start).max(initial=0.0)), scale / np.sqrt(n)),
                              max(float(np.abs(q_free).max()), 1e-300))
    out = polish(make_lp, W, q_free.ravel(), contacts.mu, 1.0 / Wb[:, 0, 0], scale, s_start, status.copy(),
                 settings.finish_tol, more, settings.max_sweeps, result.sweeps, settings.finish_presolve)
    s = out[0]
    if not np.array_equal(s, imp.reshape(n, 2)):       # a projection: u_f = u_free + M^{-1} H s
        body[:nm, :3] = (free + minv * (H @ s.ravel())).reshape(nm, 3)
        imp[:] = s.ravel()
    return _finished(result, *out)


def _finished(result, s, status, res, solves, ok, extra, correction):
    result.impulse = s
    result.status = status
    result.residual = res
    result.converged = bool(ok)
    result.finish_rounds = solves
    result.finish_correction = correction
    result.sweeps += extra
    result.observable_change = float("nan")   # an exact solution: nothing left to settle
    return result
