"""Finishing stage: the exact solution NLGS converges towards (issue 13, item 2).

NLGS settles the *status* of every contact long before its impulses converge:
open (``s = 0``), stick (``U_n = U_t = 0``), slide forward (``U_n = 0``,
``s_t = -mu s_n``, ``U_t >= 0``) or slide backward (``s_t = +mu s_n``,
``U_t <= 0``).  On fixed statuses the Signorini-Coulomb law is linear in the
impulses, so the finishing stage (a primal-dual active-set / semismooth Newton
method on the natural map):

1. writes the impulses of the statuses as ``s = P x`` (two unknowns per sticking
   contact, ``s_n`` per sliding one, none per open one) and their velocity
   conditions as ``S^T (W P x + q) = 0``, ``W = H^T M^-1 H``;
2. moves the NLGS iterate onto that affine set by the *minimum-norm* correction
   ``x = x_0 + K^+ r`` (``K = S^T W P``; ``W`` is singular wherever the forces
   are indeterminate, and the minimum-norm correction stays on the solution NLGS
   was approaching instead of jumping to another one); ``K^+ r`` is iterated
   Tikhonov on the sparse quasi-definite system ``[[I, K^T], [K, -eps I]]``
   (one sparse LU, :func:`scipy.sparse.linalg.splu`);
3. reads the statuses of the candidate from the regions of the natural map
   ``z = s - rho (U_n + mu |U_t|, U_t)`` (inside the cone: stick; in its polar:
   open; else slide) at the contacts whose natural map exceeds a fraction of the
   tolerance (degenerate contacts, zero force or velocity at round-off, keep their
   status) and repeats until they stop changing; the candidate is
   accepted only if its relative natural-map residual is ``<= finish_tol``
   (:data:`SWITCH_ROUNDS` rounds per attempt, more while fewer contacts switch each round);
4. otherwise returns to NLGS sweeps (chunks growing 4x, within the sweep budget)
   and tries again from the new iterate (accepted as is if it reaches ``finish_tol``).

:func:`check_solution` checks an accepted solution componentwise (cone,
complementarity, sticking and sliding velocities).
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .contacts import h_matrix
from .local_solver import NO_CONTACT, SLIDE_BACKWARD, SLIDE_FORWARD, STICK

SWITCH_ROUNDS = 4        # status switches per attempt before returning to NLGS sweeps
MAX_SWITCH_ROUNDS = 12   # ... or more while the number of switched contacts keeps falling
REFINE = 30              # iterated-Tikhonov refinements of one minimum-norm correction
SWITCH_FRACTION = 1e-2   # a status switches where |F_c| > SWITCH_FRACTION * finish_tol * scale


def global_delassus(scene, contacts):
    """``(W, H, M^-1)``: the sparse Delassus matrix ``W = H^T M^-1 H`` (2n, 2n)."""
    H = h_matrix(scene, contacts).tocsr()
    nm = scene.n_mobile
    minv = np.column_stack([scene.inv_mass[:nm], scene.inv_mass[:nm], scene.inv_inertia[:nm]]).ravel()
    return (H.T @ sp.diags(minv) @ H).tocsr(), H, minv


def natural_map(s, U, mu, rho):
    """Per-contact natural map ``s - proj_K(s - rho U~)`` (n, 2), vectorized
    (:func:`ncd.local_solver.natural_map_sq`), and the regions of ``z``."""
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
    """The relative natural-map residual of :mod:`ncd.nlgs`."""
    F, _ = natural_map(s, U, mu, rho)
    return float(np.sqrt(np.sum(F ** 2)) / max(scale, np.sqrt(np.sum(s ** 2)), 1e-300))


def status_system(mu, status):
    """``(P, S)``: impulses ``s = P x`` and constrained velocity rows ``S^T U`` of the statuses."""
    n = len(status)
    stick = (status == STICK) | (status > SLIDE_BACKWARD)       # FALLBACK reads as stick
    slide = (status == SLIDE_FORWARD) | (status == SLIDE_BACKWARD)
    sign = np.where(status == SLIDE_FORWARD, -1.0, 1.0)
    prow, pcol, pval, srow = [], [], [], []
    col = 0
    for c in range(n):
        if stick[c]:
            prow += [2 * c, 2 * c + 1]
            pcol += [col, col + 1]
            pval += [1.0, 1.0]
            srow += [2 * c, 2 * c + 1]
            col += 2
        elif slide[c]:
            prow += [2 * c, 2 * c + 1]
            pcol += [col, col]
            pval += [1.0, sign[c] * mu[c]]
            srow.append(2 * c)
            col += 1
    P = sp.csr_matrix((pval, (prow, pcol)), shape=(2 * n, col))
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
    A = sp.bmat([[sp.identity(m), K.T], [K, -eps * sp.identity(m)]], format="csc")
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


def project_statuses(W, q, mu, s0, status):
    """The point of the affine set of ``status`` nearest to ``s0`` (in the unknowns ``x``)."""
    P, S = status_system(mu, status)
    K = (S.T @ W @ P).tocsr()
    x0 = (P.T @ s0.ravel()) / np.asarray(P.multiply(P).sum(axis=0)).ravel()   # x0 = P^+ s0
    r = -(S.T @ (W @ (P @ x0) + q))
    return (P @ (x0 + min_norm_solve(K, r))).reshape(-1, 2)


def polish(W, q, mu, rho, scale, s0, status0, tol, more_sweeps=None, max_sweeps=0):
    """Active-set finishing from the NLGS iterate ``s0`` with statuses ``status0``.

    ``more_sweeps(k) -> (s, status)`` continues NLGS by ``k`` sweeps (None: no
    return to sweeps).  Returns ``(s, status, residual, rounds, ok, extra_sweeps)``."""
    s_base, status = s0, np.where(status0 > SLIDE_BACKWARD, STICK, status0).astype(np.int8)
    rounds, extra, chunk = 0, 0, 50
    best = (np.inf, s0, status)
    while True:
        U = (W @ s_base.ravel() + q).reshape(-1, 2)
        res = relative_residual(s_base, U, mu, rho, scale)
        if res < best[0]:
            best = (res, s_base, status)
        if res <= tol:                   # NLGS got there by itself
            return s_base, status, res, rounds, True, extra
        seen, switches, k_round = set(), np.inf, 0
        while k_round < SWITCH_ROUNDS or (k_round < MAX_SWITCH_ROUNDS and shrinking):
            rounds += 1
            k_round += 1
            cand = project_statuses(W, q, mu, s_base, status)
            U = (W @ cand.ravel() + q).reshape(-1, 2)
            F, region = natural_map(cand, U, mu, rho)
            res = float(np.sqrt(np.sum(F ** 2)) / max(scale, np.sqrt(np.sum(cand ** 2)), 1e-300))
            if res < best[0]:
                best = (res, cand, region)
            if res <= tol:
                return cand, region, res, rounds, True, extra
            # switch only where the law is violated by more than a fraction of the tolerance:
            # degenerate contacts (force on a region boundary, velocity at round-off) keep
            # their status, which satisfies both conditions (else the statuses cycle)
            wrong = np.sqrt(np.sum(F ** 2, axis=1)) > SWITCH_FRACTION * tol * max(scale, np.linalg.norm(cand))
            new = np.where(wrong, region, status).astype(np.int8)
            key = new.tobytes()
            if np.array_equal(new, status) or key in seen:
                break
            seen.add(key)
            shrinking = np.count_nonzero(new != status) < switches   # statuses settling: go on
            switches = np.count_nonzero(new != status)
            status = new
        if more_sweeps is None or extra >= max_sweeps:
            return best[1], best[2], best[0], rounds, False, extra
        k = min(chunk, max_sweeps - extra)
        s_base, status = more_sweeps(k)
        status = np.where(status > SLIDE_BACKWARD, STICK, status).astype(np.int8)
        extra += k
        chunk *= 4


def check_solution(impulse, U, mu, tol=1e-8, velocity_scale=None):
    """Componentwise check of the Signorini-Coulomb law; returns a dict of the largest
    violations (impulses over ``max |s|``, velocities over ``velocity_scale``, default
    ``max |U|``; pass the free-velocity scale, e.g. ``|g| h``, at rest) and ``ok``.

    cone: ``s_n >= 0``, ``|s_t| <= mu s_n``; normal complementarity ``U_n >= 0``,
    ``s_n U_n = 0``; sticking contacts (``|s_t| < mu s_n``): ``U_t = 0``; sliding
    ones: ``U_t`` opposite to ``s_t`` (``s_t U_t <= 0``)."""
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
    """The finishing stage of :func:`ncd.nlgs.solve_local` (``data`` its kernel data)."""
    from .nlgs import _iterate_local, _scale
    n = len(mu)
    scale = _scale(q.reshape(n, 2), Wd)
    flat, status = data[6], result.status

    def more(k):
        keep = (np.array([-np.inf, 0.0, 0.0]), np.empty_like(flat), np.empty_like(status), np.empty(0), 0)
        _iterate_local(data, order, status, scale, 0.0, k, 0, k, keep)
        return flat.reshape(n, 2).copy(), status.copy()

    s, st, res, rounds, ok, extra = polish(Wc, q, mu, 1.0 / Wd[:, 0, 0], scale, flat.reshape(n, 2).copy(),
                                           status.copy(), settings.finish_tol, more, settings.max_sweeps)
    return _finished(result, s, st, res, rounds, ok, extra)


def polish_discs(scene, contacts, q_free, Wb, flat, order, result, settings):
    """The finishing stage of :func:`ncd.nlgs.solve_discs`; updates the body velocities."""
    from .nlgs import _iterate_discs, _scale
    n = contacts.n
    W, H, minv = global_delassus(scene, contacts)
    scale = _scale(q_free, Wb)
    body, imp, status = flat[2].reshape(-1, 4), flat[3], result.status
    s_start = imp.reshape(n, 2).copy()

    def more(k):
        keep = (np.array([-np.inf, 0.0, 0.0]), np.empty_like(imp), np.empty_like(status), np.empty_like(flat[2]), 0)
        _iterate_discs(flat, order, status, scale, 0.0, k, 0, k, keep)
        return imp.reshape(n, 2).copy(), status.copy()

    # q of U = W s + q: the free local velocity (bias included) of :func:`solve_discs`
    s, st, res, rounds, ok, extra = polish(W, q_free.ravel(), contacts.mu, 1.0 / Wb[:, 0, 0], scale,
                                           s_start, status.copy(), settings.finish_tol, more,
                                           settings.max_sweeps)
    du = minv * (H @ (s - imp.reshape(n, 2)).ravel())
    nm = scene.n_mobile
    body[:nm, 0] += du[0::3]
    body[:nm, 1] += du[1::3]
    body[:nm, 2] += du[2::3]
    imp[:] = s.ravel()
    return _finished(result, s, st, res, rounds, ok, extra)


def _finished(result, s, status, res, rounds, ok, extra):
    result.impulse = s
    result.status = status
    result.residual = res
    result.converged = bool(ok)
    result.finish_rounds = rounds
    result.sweeps += extra
    result.observable_change = float("nan")   # an exact solution: nothing left to settle
    return result
