"""Static packings: the pieces that an equilibrium analysis of any packing needs.

The rest problem is the one-step problem from ``u_i = 0`` with ``theta = 1`` (Moreau
2005, section 2: a single step decides whether a position is an equilibrium); the
external force of the equilibrium equations is :func:`ncd.core.contacts.external_load`.
"""

import numpy as np

from ncd.dynamics.stepper import prepare_step


def rest_problem(scene, h):
    """The core problem of one step from ``u_i = 0`` (the equilibrium test's problem)."""
    return prepare_step(scene, h, 1.0, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin))
