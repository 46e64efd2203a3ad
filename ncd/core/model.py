"""The mechanical model: rigid discs, fixed obstacles, gravity, Coulomb friction.

Flat arrays only.  Every disc, mobile or fixed, is a row of the disc arrays:
the ``n_mobile`` mobile discs come first, the fixed obstacle discs after them
(inverse mass and inverse inertia zero).  Straight walls are half-planes
``(x - point) . normal >= 0``.  A slope is a tilted gravity vector.
Mass ``m = density * pi r^2`` (a 2-D density), inertia ``I = m r^2 / 2``.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from ncd.core.errors import InputError, SimulationError
from ncd.core.jit import njit
from ncd.core.validate import F64, all_finite, array, first_bad, integer, is_f64, real, shape_of, show


@dataclass
class Scene:
    """Discs, obstacles, walls and the contact laws of one scene, plus its state.

    Build with :func:`ncd.core.scene.make_scene`; the arrays below are then consistent and
    validated.  ``pos, angle, vel, spin`` are the state of the mobile discs and
    are advanced in place by :func:`ncd.dynamics.stepper.step`.
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
    prev_keys: np.ndarray | None = field(default=None)
    prev_impulse: np.ndarray | None = field(default=None)

    @property
    def n_disc(self) -> int:
        return len(self.radius)

    @property
    def mobile_mass(self) -> np.ndarray:
        return self.mass[: self.n_mobile]

    def copy(self) -> Scene:
        """A deep copy (state included)."""
        kw = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()}
        return Scene(**kw)


# ------------------------------------------------------------ argument checks
MASS_RTOL = 1e-12         # |mass inv_mass - 1| of a mobile disc (make_scene: 1 / mass, a rounding at most)


def check_scene(s: Scene, name: str = "scene", state: bool = False) -> Scene:
    """A :class:`ncd.Scene` whose arrays are consistent: the shapes the kernels
    index, finite radii, masses and laws.  The *state* (``pos``, ``vel``,
    ``spin``, ``angle``) is only shape-checked: a state gone non-finite is a
    :class:`ncd.SimulationError` of the stepper (raised here if ``state``)."""
    if not isinstance(s, Scene):
        raise InputError(f"{name} must be an ncd.Scene (build it with ncd.make_scene); got {type(s).__name__}")
    if not _scene_ok(s):
        _scene_slow(s, name)
    t = s.time
    if isinstance(t, (bool, np.bool_)) or not isinstance(t, numbers.Real) or not np.isfinite(t):
        raise InputError(f"{name}.time = {show(t)} must be a finite real number")
    check_period(f"{name}.period", s.period, float(s.radius.max()))
    if state and not all(np.isfinite(getattr(s, f)).all() for f in ("pos", "vel", "spin", "angle")):
        raise SimulationError(f"{name} state (pos, vel, spin, angle) is non-finite at t = {s.time}")
    return s


def check_period(name: str, value: float, largest_radius: float) -> None:
    """A period along x is 0 (not periodic) or at least three largest diameters (a pair of
    discs then touches across it once at most)."""
    if value > 0 and value < 6 * largest_radius:
        raise InputError(f"{name} = {value} must be at least three largest diameters ({6 * largest_radius})")


def _scene_ok(s):
    """Fast path of :func:`check_scene` (a few microseconds): True if every check passes;
    False sends the scene to the slow path, which names what is wrong."""
    r, nm = s.radius, s.n_mobile
    if type(r) is not np.ndarray or r.ndim != 1 or r.dtype != F64 or type(nm) is not int:
        return False
    nd = r.shape[0]
    v1, v2 = (nd,), (nd, 2)
    wp, wn = s.wall_point, s.wall_normal
    if not (1 <= nm <= nd and is_f64(s.inv_mass, v1) and is_f64(s.inv_inertia, v1) and is_f64(s.mass, v1)
            and is_f64(s.pos, v2) and is_f64(s.vel, v2) and is_f64(s.spin, v1) and is_f64(s.angle, v1)
            and is_f64(s.gravity, (2,)) and type(wp) is np.ndarray and type(wn) is np.ndarray
            and wp.dtype == F64 and wn.dtype == F64 and wp.ndim == 2 and wp.shape == wn.shape
            and wp.shape[1] == 2):
        return False
    for v, hi in ((s.mu, np.inf), (s.mu_obstacle, np.inf), (s.e_n, 1.0), (s.e_t, 1.0),
                  (s.e_n_obstacle, 1.0), (s.e_t_obstacle, 1.0), (s.period, np.inf)):
        if type(v) is not float or not 0.0 <= v <= hi or v == np.inf:
            return False
    if not _scene_values_ok(r, s.inv_mass, s.inv_inertia, s.mass, nm, wp.reshape(-1), wn.reshape(-1), s.gravity):
        return False
    pk = s.prev_keys
    if pk is None:
        return s.prev_impulse is None
    return (type(pk) is np.ndarray and pk.ndim == 1 and pk.dtype.kind in "iu"
            and is_f64(s.prev_impulse, (len(pk), 2)) and s.prev_impulse.flags.c_contiguous
            and all_finite(s.prev_impulse.reshape(-1)) and bool(np.all(pk[1:] > pk[:-1])))


@njit(cache=True)
def _scene_values_ok(r, inv_mass, inv_inertia, mass, nm, wp, wn, g):
    """The value checks of :func:`_scene_ok` in one pass (NaN fails every comparison)."""
    for i in range(r.shape[0]):
        if not (r[i] > 0.0 and r[i] < np.inf and inv_mass[i] >= 0.0 and inv_inertia[i] >= 0.0
                and inv_mass[i] + r[i] * r[i] * inv_inertia[i] <= 1e300):
            return False
        if i < nm and not (inv_mass[i] > 0.0 and mass[i] > 0.0 and mass[i] < np.inf
                           and abs(mass[i] * inv_mass[i] - 1.0) <= MASS_RTOL):
            return False
    return all_finite(wp) and all_finite(wn) and all_finite(g)


def _scene_slow(s, name):
    """The checks of :func:`check_scene` one by one, raising on the first that fails."""
    rshape = shape_of(f"{name}.radius", s.radius)
    nd = rshape[0] if len(rshape) == 1 else -1
    if nd < 1:
        raise InputError(f"{name}.radius has shape {rshape}, expected (n_disc,) with n_disc >= 1")
    integer(f"{name}.n_mobile", s.n_mobile, 1, nd)
    for key, shape, fin in (("radius", (nd,), True), ("inv_mass", (nd,), True), ("inv_inertia", (nd,), True),
                              ("mass", (nd,), False), ("pos", (nd, 2), False), ("vel", (nd, 2), False),
                              ("spin", (nd,), False), ("angle", (nd,), False),
                              ("wall_point", (None, 2), True), ("wall_normal", (None, 2), True),
                              ("gravity", (2,), True)):
        value = getattr(s, key)
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{key} must be a numpy array; got {show(value)}")
        array(f"{name}.{key}", value, shape, finite=fin)
    if np.any(s.radius <= 0):
        first_bad(f"{name}.radius", s.radius, s.radius <= 0, "must be > 0")
    if not np.all(np.isfinite(s.mass[: s.n_mobile]) & (s.mass[: s.n_mobile] > 0)):
        raise InputError(f"{name}.mass of the mobile discs must be finite and > 0")
    if np.any(s.inv_mass[: s.n_mobile] <= 0):
        first_bad(f"{name}.inv_mass", s.inv_mass, s.inv_mass <= 0, "must be > 0 for mobile discs")
    with np.errstate(over="ignore", invalid="ignore"):
        off = ~(np.abs(s.mass[: s.n_mobile] * s.inv_mass[: s.n_mobile] - 1.0) <= MASS_RTOL)
    if np.any(off):
        i = int(np.argmax(off))
        raise InputError(f"{name}.inv_mass[{i}] = {s.inv_mass[i]!r} is not 1 / mass[{i}] = {1.0 / s.mass[i]!r}: "
                         f"the solver uses inv_mass, the energies and weights use mass")
    if np.any(s.inv_mass < 0) or np.any(s.inv_inertia < 0):
        raise InputError(f"{name}.inv_mass and inv_inertia must be >= 0")
    with np.errstate(over="ignore", invalid="ignore"):
        w_tt = s.inv_mass + s.radius ** 2 * s.inv_inertia
    if not np.all(w_tt <= 1e300):
        first_bad(f"{name}.inv_mass + radius^2 inv_inertia", w_tt, ~(w_tt <= 1e300),
                   "(a Delassus diagonal) must be finite and <= 1e300")
    if len(s.wall_point) != len(s.wall_normal):
        raise InputError(f"{name}.wall_point has {len(s.wall_point)} rows, wall_normal {len(s.wall_normal)}")
    for law in ("mu", "mu_obstacle"):
        real(f"{name}.{law}", getattr(s, law), 0.0)
    for law in ("e_n", "e_t", "e_n_obstacle", "e_t_obstacle"):
        real(f"{name}.{law}", getattr(s, law), 0.0, 1.0)
    real(f"{name}.period", s.period, 0.0)
    if (s.prev_keys is None) != (s.prev_impulse is None) or (
            s.prev_keys is not None and (len(shape_of(f"{name}.prev_keys", s.prev_keys)) != 1
                                         or shape_of(f"{name}.prev_impulse", s.prev_impulse)
                                         != (len(s.prev_keys), 2))):
        raise InputError(f"{name}.prev_keys and prev_impulse must be None or of shapes (k,) and (k, 2); "
                         f"got {show(s.prev_keys)} and {show(s.prev_impulse)}")
    if s.prev_keys is not None:
        keys = np.asarray(s.prev_keys)
        if keys.size and keys.dtype.kind not in "iu":
            raise InputError(f"{name}.prev_keys must be integers; got dtype {keys.dtype}")
        if keys.ndim == 1 and np.any(keys[1:] <= keys[:-1]):
            k = int(np.argmax(keys[1:] <= keys[:-1]))
            raise InputError(f"{name}.prev_keys must increase strictly (the warm start searches them); "
                             f"prev_keys[{k}] = {keys[k]}, prev_keys[{k + 1}] = {keys[k + 1]}")
        if not isinstance(s.prev_impulse, np.ndarray):
            raise InputError(f"{name}.prev_impulse must be a numpy array; got {show(s.prev_impulse)}")
        array(f"{name}.prev_impulse", s.prev_impulse, (len(keys), 2))
    return s
