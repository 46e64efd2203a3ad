"""Building a validated :class:`ncd.model.Scene` from physical data."""
import numpy as np

from .contacts import detect_contacts
from .model import InputError, Scene


def _finite(name, value):
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        where = ", ".join(str(int(i)) for i in bad)
        raise InputError(f"{name} must be finite; {name}[{where}] = {arr[tuple(bad)]}")
    return arr


def _in_range(name, value, lo, hi=np.inf, lo_open=False):
    v = float(value)
    if not np.isfinite(v) or v < lo or v > hi or (lo_open and v == lo):
        span = f"({lo}, {hi}]" if lo_open else f"[{lo}, {hi}]"
        raise InputError(f"{name} = {value!r} is outside {span}")
    return v


def make_scene(pos, radius, density=1.0, *, obstacle_pos=None, obstacle_radius=None,
               walls=(), gravity=(0.0, -9.81), mu=0.5, mu_obstacle=None,
               e_n=0.0, e_t=0.0, e_n_obstacle=None, e_t_obstacle=None, period=None,
               vel=None, spin=None, angle=None, overlap_tolerance=1e-2):
    """Build and validate a scene.

    ``walls`` is a sequence of ``(point, normal)`` pairs; ``period`` (> 0)
    makes the scene periodic along x (positions are wrapped into [0, period)).
    ``overlap_tolerance`` bounds initial interpenetrations, relative to the
    smaller radius of each pair.  Every violation raises :class:`InputError`
    naming the value.
    """
    pos = _finite("pos", pos).reshape(-1, 2)
    n = len(pos)
    if n == 0:
        raise InputError("a scene needs at least one mobile disc (pos is empty)")
    radius = _finite("radius", np.broadcast_to(radius, (n,))).copy()
    if np.any(radius <= 0):
        i = int(np.argmin(radius))
        raise InputError(f"radius must be > 0; radius[{i}] = {radius[i]}")
    density = _finite("density", np.broadcast_to(density, (n,))).copy()
    if np.any(density <= 0):
        i = int(np.argmin(density))
        raise InputError(f"density must be > 0; density[{i}] = {density[i]}")
    mu = _in_range("mu", mu, 0.0)
    mu_obstacle = mu if mu_obstacle is None else _in_range("mu_obstacle", mu_obstacle, 0.0)
    e_n = _in_range("e_n", e_n, 0.0, 1.0)
    e_t = _in_range("e_t", e_t, 0.0, 1.0)
    e_n_obstacle = e_n if e_n_obstacle is None else _in_range("e_n_obstacle", e_n_obstacle, 0.0, 1.0)
    e_t_obstacle = e_t if e_t_obstacle is None else _in_range("e_t_obstacle", e_t_obstacle, 0.0, 1.0)
    gravity = _finite("gravity", gravity).reshape(2)

    opos = np.zeros((0, 2)) if obstacle_pos is None else _finite("obstacle_pos", obstacle_pos).reshape(-1, 2)
    orad = np.zeros(0) if obstacle_radius is None else _finite(
        "obstacle_radius", np.broadcast_to(obstacle_radius, (len(opos),))).copy()
    if np.any(orad <= 0):
        i = int(np.argmin(orad))
        raise InputError(f"obstacle_radius must be > 0; obstacle_radius[{i}] = {orad[i]}")

    wp = np.array([_finite(f"walls[{k}].point", w[0]) for k, w in enumerate(walls)]).reshape(-1, 2)
    wn = np.array([_finite(f"walls[{k}].normal", w[1]) for k, w in enumerate(walls)]).reshape(-1, 2)
    norms = np.linalg.norm(wn, axis=1)
    if np.any(norms == 0):
        raise InputError(f"walls[{int(np.argmin(norms))}].normal is zero")
    wn = wn / norms[:, None] if len(wn) else wn

    period = 0.0 if period is None else _in_range("period", period, 0.0, lo_open=True)
    if period > 0:
        dmax = 2 * max(radius.max(), orad.max() if len(orad) else 0.0)
        if period < 3 * dmax:
            raise InputError(f"period = {period} must be at least three largest diameters ({3 * dmax})")
        pos = pos.copy()
        pos[:, 0] %= period
        opos = opos.copy()
        opos[:, 0] %= period

    mass = density * np.pi * radius ** 2
    all_pos = np.vstack([pos, opos])
    all_rad = np.concatenate([radius, orad])
    scene = Scene(
        pos=all_pos, radius=all_rad,
        inv_mass=np.concatenate([1.0 / mass, np.zeros(len(orad))]),
        inv_inertia=np.concatenate([2.0 / (mass * radius ** 2), np.zeros(len(orad))]),
        mass=np.concatenate([mass, np.full(len(orad), np.inf)]),
        n_mobile=n, wall_point=wp, wall_normal=wn, gravity=gravity,
        mu=mu, mu_obstacle=mu_obstacle, e_n=e_n, e_t=e_t,
        e_n_obstacle=e_n_obstacle, e_t_obstacle=e_t_obstacle, period=period,
        angle=np.zeros(len(all_rad)) if angle is None else np.concatenate(
            [_finite("angle", np.broadcast_to(angle, (n,))), np.zeros(len(orad))]),
        vel=np.zeros((len(all_rad), 2)) if vel is None else np.vstack(
            [_finite("vel", vel).reshape(n, 2), np.zeros((len(orad), 2))]),
        spin=np.zeros(len(all_rad)) if spin is None else np.concatenate(
            [_finite("spin", np.broadcast_to(spin, (n,))), np.zeros(len(orad))]),
    )
    check_overlaps(scene, overlap_tolerance)
    return scene


def check_overlaps(scene, tolerance):
    """Raise :class:`InputError` if any pair interpenetrates by more than
    ``tolerance`` times the smaller radius."""
    c = detect_contacts(scene, alert=0.0)
    if c.n == 0:
        return
    rb = np.where(c.body_b >= 0, scene.radius[np.maximum(c.body_b, 0)], np.inf)
    rmin = np.minimum(scene.radius[c.body_a], rb)
    excess = -c.gap / rmin
    k = int(np.argmax(excess))
    if excess[k] > tolerance:
        other = f"disc {c.body_b[k]}" if c.body_b[k] >= 0 else f"wall {-1 - c.body_b[k]}"
        raise InputError(
            f"initial overlap between disc {c.body_a[k]} and {other} is {-c.gap[k]:.3g} "
            f"({excess[k]:.3g} of the smaller radius), above overlap_tolerance = {tolerance}")
