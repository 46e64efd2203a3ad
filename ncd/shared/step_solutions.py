"""The core problem of one step in local form, for exact work on its solution set.

``U = W s + q`` with the Delassus matrix ``W = H^T M^-1 H``: residuals, contact
statuses, grain accelerations of an impulse ``s``, and its polish on the affine set of
its statuses. Shared by the census of Figure 2 and the slope flows of Figure 5.
"""

import numpy as np

from ncd.solver.finish import natural_map, project_statuses, relative_residual
from ncd.solver.single_contact import SLIDE_BACKWARD, STICK


class StepSolutions:
    """The core problem of one step in local form ``U = W s + q`` with its disc velocities."""

    def __init__(self, scene, problem):
        c = problem.contacts
        self.scene, self.problem, self.h, self.nm = scene, problem, problem.h, scene.n_mobile
        self.W, self.H, self.minv = problem.delassus(scene)     # shared with the problem's NLGS runs
        nm = self.nm
        self.free = np.column_stack([problem.free_vel[:nm], problem.free_spin[:nm]]).ravel()
        self.q = (self.H.T @ self.free).reshape(-1, 2) + problem.bias
        self.mu = c.mu
        self.rho = 1.0 / self.W.diagonal()[0::2]
        self.scale = float(np.sqrt(np.sum((self.q * self.rho[:, None]) ** 2)))
        self.g = float(np.linalg.norm(scene.gravity))

    def U(self, s):
        return (self.W @ np.asarray(s).ravel()).reshape(-1, 2) + self.q

    def residual(self, s):
        return relative_residual(np.asarray(s).reshape(-1, 2), self.U(s), self.mu, self.rho, self.scale)

    def status(self, s):
        return natural_map(np.asarray(s).reshape(-1, 2), self.U(s), self.mu, self.rho)[1]

    def accel(self, s):
        """Accelerations (nm, 2) of the grains: ``(u_f - u_i) / h``."""
        u = (self.free + self.minv * (self.H @ np.asarray(s).ravel())).reshape(-1, 3)
        return (u[:, :2] - self.problem.vel_initial[:self.nm]) / self.h

    def polish(self, s, status=None, tol=1e-12, rounds=12):
        """Project ``s`` on the affine set of its statuses, re-read them, repeat:
        ``(s, residual)`` of the best iterate (residual ``<= tol`` when it succeeded)."""
        s = np.asarray(s, float).reshape(-1, 2)
        status = self.status(s) if status is None else np.where(status > SLIDE_BACKWARD, STICK, status)
        best = (self.residual(s), s)
        for _ in range(rounds):
            s = project_statuses(self.W, self.q.ravel(), self.mu, s, status.astype(np.int8))
            res = self.residual(s)
            if res < best[0]:
                best = (res, s)
            if res <= tol:
                break
            new = self.status(s)
            if np.array_equal(new, status):
                break
            status = new
        return best[1], best[0]
