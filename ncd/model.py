"""The mechanical model: rigid discs, fixed obstacles, gravity, Coulomb friction.

Flat arrays only.  Every disc, mobile or fixed, is a row of the disc arrays:
the ``n_mobile`` mobile discs come first, the fixed obstacle discs after them
(inverse mass and inverse inertia zero).  Straight walls are half-planes
``(x - point) . normal >= 0``.  A slope is a tilted gravity vector.
Mass ``m = density * pi r^2`` (a 2-D density), inertia ``I = m r^2 / 2``.
"""
from dataclasses import dataclass, field

import numpy as np


class InputError(ValueError):
    """A scene, a parameter or a configuration that is physically invalid."""


class SimulationError(RuntimeError):
    """A state that went non-finite or diverged during stepping."""


@dataclass
class Scene:
    """Discs, obstacles, walls and the contact laws of one scene, plus its state.

    Build with :func:`make_scene`; the arrays below are then consistent and
    validated.  ``pos, angle, vel, spin`` are the state of the mobile discs and
    are advanced in place by :func:`ncd.stepper.step`.
    """
    pos: np.ndarray              # (n_disc, 2) centres, mobile first
    radius: np.ndarray           # (n_disc,)
    inv_mass: np.ndarray         # (n_disc,) 0 for fixed discs
    inv_inertia: np.ndarray      # (n_disc,)
    mass: np.ndarray             # (n_disc,) inf for fixed discs
    n_mobile: int
    wall_point: np.ndarray       # (n_wall, 2)
    wall_normal: np.ndarray      # (n_wall, 2) unit, pointing into the domain
    gravity: np.ndarray          # (2,)
    mu: float                    # disc-disc friction
    mu_obstacle: float           # disc-obstacle friction (fixed discs and walls)
    e_n: float
    e_t: float
    e_n_obstacle: float
    e_t_obstacle: float
    period: float = 0.0          # > 0: periodic along x with this period
    angle: np.ndarray = field(default=None)
    vel: np.ndarray = field(default=None)
    spin: np.ndarray = field(default=None)
    time: float = 0.0
    # warm-start memory: the previous step's contacts (keys) and impulses
    prev_keys: np.ndarray = field(default=None)
    prev_impulse: np.ndarray = field(default=None)

    @property
    def n_disc(self):
        return len(self.radius)

    @property
    def mobile_mass(self):
        return self.mass[: self.n_mobile]

    def copy(self):
        """A deep copy (state included)."""
        kw = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()}
        return Scene(**kw)
