"""Local exact solves where NLGS stalls: ``SolverSettings(local_exact=True)``.

Warm-started NLGS (plain or Anderson) can sit on a residual plateau: a few contacts
drift by a small constant amount per sweep along a direction the sweeps barely move.
A local exact solve goes there at once.  The run is made in chunks of :data:`CHUNK`
sweeps; when the residual has not fallen below :data:`STALL_FACTOR` of its value
:data:`STALL_WINDOW` chunks earlier, a *region* is formed (:func:`region`): the
:data:`SEED` contacts whose impulses moved most over the last chunk (the drift, not the
largest residuals, which can point at the stalled iterate itself), grown by the other
contacts of their mobile grains, :data:`MAX_REGION` at most.  With every other impulse
frozen, the region's problem is the LCP of :func:`ncd.solver.lcp.frictional_lcp`, solved
by Lemke's method; its solution replaces the region's impulses, the body velocities are
recomputed and Anderson's history cleared.  The stopping test and best-iterate record
stay those of :mod:`ncd.solver.kernels`.  Trade-offs: docs/solvers.md.
"""
import numpy as np

from ncd.solver.finish import global_delassus
from ncd.solver.lcp import frictional_lcp, impulse_of_lcp, lemke

CHUNK = 100          # sweeps between stall tests
STALL_WINDOW = 5     # chunks over which the residual must fall ...
STALL_FACTOR = 0.5   # ... below this fraction of its value, or the region is solved exactly
SEED = 12            # contacts that moved most over the last chunk
MAX_REGION = 60      # contacts of a region at most (Lemke's tableau is dense: 3 MAX_REGION rows, twice as many columns)


def solve_region(W, q, mu, s, idx):
    """Impulses ``(len(idx), 2)`` of the contacts ``idx`` solving ``U = W s + q`` with the
    Coulomb law there, every other impulse of ``s`` (flat, ``2 kappa``) frozen: the LCP of
    :func:`ncd.solver.lcp.frictional_lcp` on ``W_RR`` and ``q_R = q_R + W_R,other s_other``,
    by Lemke's method, in units where ``q_R`` and the diagonal of ``W_RR`` are of order one
    (the law is invariant under a scaling of impulses and of velocities).  None when Lemke
    gives no solution (or ``q_R`` is not finite)."""
    dof = np.column_stack([2 * idx, 2 * idx + 1]).ravel()
    rows = W[dof]
    Wrr = rows[:, dof].toarray()
    q_r = (rows @ s + q[dof]) - Wrr @ s[dof]
    V = float(np.abs(q_r).max())
    if not np.isfinite(V):
        return None
    if V == 0.0:
        return np.zeros((len(idx), 2))
    S = V / float(Wrr.diagonal().max())
    A, b = frictional_lcp(Wrr * (S / V), q_r / V, mu[idx])
    z, _ = lemke(A, b)
    return None if z is None else S * impulse_of_lcp(z, mu[idx])


def region(moved, body_a, body_b, n_mobile):
    """Contacts of a region: the :data:`SEED` contacts of largest ``moved`` and the other
    contacts of their mobile grains (at most :data:`MAX_REGION`, those of largest ``moved``)."""
    seed = np.argsort(-moved, kind="stable")[:SEED]
    grains = np.concatenate([body_a[seed], body_b[seed]])
    grains = grains[grains < n_mobile]
    near = np.flatnonzero(np.isin(body_a, grains) | np.isin(body_b, grains))
    near = near[np.argsort(-moved[near], kind="stable")][:MAX_REGION]
    return np.union1d(seed, near)


class LocalExact:
    """The stall test and the local exact solves of one disc-form run."""

    def __init__(self, scene, contacts, free, q_free, flat, reset=None, delassus=None):
        # delassus: global_delassus of the problem, when the caller built it once for many runs
        self.W, self.H, self.minv = global_delassus(scene, contacts) if delassus is None else delassus
        self.W = self.W.tocsr()
        self.q = np.asarray(q_free, float).ravel()
        self.mu = contacts.mu
        self.a, self.b = contacts.body_a, contacts.body_b
        self.nm = scene.n_mobile
        self.body = flat[2].reshape(-1, 4)
        self.imp = flat[3]
        self.free = free                                        # u_free of the mobile grains (3 nm,)
        self.reset = reset
        self.solves = 0

    def solve(self, moved):
        """Solve the region of ``moved`` exactly, the other impulses frozen (nothing when
        Lemke gives no solution)."""
        idx = region(moved, self.a, self.b, self.nm)
        s_region = solve_region(self.W, self.q, self.mu, self.imp, idx)
        if s_region is None:
            return
        self.solves += 1
        s = self.imp
        s.reshape(-1, 2)[idx] = s_region
        self.body[:self.nm, :3] = (self.free + self.minv * (self.H @ s)).reshape(self.nm, 3)
        if self.reset is not None:
            self.reset()

    def driver(self, iterate):
        """A callable with the signature of :func:`ncd.solver.kernels.iterate_discs`: ``iterate``
        in chunks of :data:`CHUNK` sweeps (counted across calls, which the chunked runs of
        :mod:`ncd.solver.convergence` make ``check_every`` sweeps at a time), each chunk's
        residual the one ``iterate`` returns (it checks at its last sweep).  A stall's solve
        is made before the next sweeps, never as a call's last act: the iterate a call
        returns is always a sweep's output."""
        history = []
        period = {"start": None, "since": 0, "pending": None}

        def run(data, order, status, scale, tol, max_sweeps, criterion, check_every, best):
            done = 0
            res, change, ok = np.inf, np.inf, False
            while done < max_sweeps and not ok:
                if period["pending"] is not None:
                    self.solve(period["pending"])
                    period["pending"] = None
                if period["start"] is None:
                    period["start"] = self.imp.copy()
                k, res, change, ok = iterate(data, order, status, scale, tol,
                                             min(CHUNK - period["since"], max_sweeps - done), criterion,
                                             check_every, best[:4] + (best[4] + done,))
                done += int(k)
                period["since"] += int(k)
                if ok or period["since"] < CHUNK:
                    continue
                history.append(res)
                if len(history) > STALL_WINDOW and history[-1] > STALL_FACTOR * history[-1 - STALL_WINDOW]:
                    period["pending"] = np.abs(self.imp - period["start"]).reshape(-1, 2).sum(axis=1)
                    history.clear()
                period["start"], period["since"] = None, 0
            return done, res, change, ok
        return run
