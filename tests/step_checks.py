"""Helpers shared by the solver tests: contact velocities and the natural-map residual of a
solved step, recomputed from its end-of-step velocities (independently of the solver's own)."""
import numpy as np

from ncd.core.contacts import local_velocity
from ncd.solver import finish


def contact_velocities(problem, vel, spin):
    """Local velocities ``U = H^T u + bias`` of the step's contacts for body velocities ``vel, spin``."""
    c = problem.contacts
    return local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((c.n, 2))) + problem.bias


def step_residual(problem, impulse, vel, spin):
    """The relative natural-map residual of :mod:`ncd.solver.nlgs` from the end-of-step velocities."""
    rho = 1.0 / problem.W[:, 0, 0]
    q = contact_velocities(problem, problem.free_vel, problem.free_spin)
    return finish.relative_residual(impulse, contact_velocities(problem, vel, spin), problem.contacts.mu, rho,
                                    float(np.sqrt(np.sum((q * rho[:, None]) ** 2))))
