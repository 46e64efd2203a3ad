"""Building a validated :class:`ncd.core.model.Scene` from physical data."""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from numpy.typing import ArrayLike

from ncd.core import validate
from ncd.core.contacts import detect_contacts
from ncd.core.errors import InputError
from ncd.core.model import Scene, check_period, check_scene


def _disc_mass(density: np.ndarray, radius: np.ndarray, label: str) -> np.ndarray:
    """Masses of discs (2-D: ``rho pi r^2``), checked with their inertias ``m r^2 / 2`` to be
    finite, positive and invertible in double precision; ``label`` names a disc in the error."""
    with np.errstate(all="ignore"):
        mass = density * np.pi * radius ** 2
        inertia = 0.5 * mass * radius ** 2
        bad = ~(np.isfinite(mass) & np.isfinite(inertia) & (mass > 0) & (inertia > 0) & np.isfinite(1.0 / inertia))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InputError(f"{label} {i}: mass {mass[i]:.3g} and inertia {inertia[i]:.3g} from density {density[i]} "
                         f"and radius {radius[i]} must be finite and > 0 (double precision)")
    return mass


def make_scene(pos: ArrayLike, radius: ArrayLike, density: ArrayLike = 1.0, *,
               obstacle_pos: ArrayLike | None = None, obstacle_radius: ArrayLike | None = None,
               walls: Iterable[tuple[ArrayLike, ArrayLike]] = (), gravity: ArrayLike = (0.0, -9.81),
               mu: float = 0.5, mu_obstacle: float | None = None, e_n: float = 0.0, e_t: float = 0.0,
               e_n_obstacle: float | None = None, e_t_obstacle: float | None = None, period: float | None = None,
               vel: ArrayLike | None = None, spin: ArrayLike | None = None, angle: ArrayLike | None = None,
               overlap_tolerance: float = 1e-2) -> Scene:
    """Build and validate a scene.

    ``walls`` is a sequence of ``(point, normal)`` pairs; ``period`` (> 0)
    makes the scene periodic along x (positions are wrapped into [0, period)).
    ``overlap_tolerance`` bounds initial interpenetrations, relative to the
    smaller radius of each pair.  Every violation raises :class:`InputError`
    naming the value.
    """
    pos = validate.array("pos", pos, (None, 2))
    n = len(pos)
    if n == 0:
        raise InputError("a scene needs at least one mobile disc (pos is empty)")
    radius = validate.per_item("radius", radius, n, 0.0, lo_open=True)
    density = validate.per_item("density", density, n, 0.0, lo_open=True)
    mu = validate.real("mu", mu, 0.0)
    mu_obstacle = mu if mu_obstacle is None else validate.real("mu_obstacle", mu_obstacle, 0.0)
    e_n = validate.real("e_n", e_n, 0.0, 1.0)
    e_t = validate.real("e_t", e_t, 0.0, 1.0)
    e_n_obstacle = e_n if e_n_obstacle is None else validate.real("e_n_obstacle", e_n_obstacle, 0.0, 1.0)
    e_t_obstacle = e_t if e_t_obstacle is None else validate.real("e_t_obstacle", e_t_obstacle, 0.0, 1.0)
    gravity = validate.array("gravity", gravity, (2,))
    validate.real("overlap_tolerance", overlap_tolerance, 0.0, allow_inf=True)   # inf: no overlap check

    opos = np.zeros((0, 2)) if obstacle_pos is None else validate.array("obstacle_pos", obstacle_pos, (None, 2))
    if len(opos) and obstacle_radius is None:
        raise InputError("obstacle_pos is given without obstacle_radius")
    if not len(opos) and obstacle_radius is not None and np.size(obstacle_radius):
        raise InputError(f"obstacle_radius = {obstacle_radius!r} is given without obstacle_pos")
    orad = np.zeros(0) if not len(opos) else validate.per_item("obstacle_radius", obstacle_radius, len(opos),
                                                             0.0, lo_open=True)
    try:
        walls = [tuple(w) for w in walls]
    except TypeError:
        raise InputError(f"walls = {walls!r} must be a sequence of (point, normal) pairs") from None
    for k, w in enumerate(walls):
        if len(w) != 2:
            raise InputError(f"walls[{k}] = {w!r} must be a (point, normal) pair")
    wp = np.array([validate.array(f"walls[{k}].point", w[0], (2,)) for k, w in enumerate(walls)]).reshape(-1, 2)
    wn = np.array([validate.array(f"walls[{k}].normal", w[1], (2,)) for k, w in enumerate(walls)]).reshape(-1, 2)
    big = np.abs(wn).max(axis=1) if len(wn) else np.zeros(0)
    if np.any(big == 0):
        raise InputError(f"walls[{int(np.argmin(big))}].normal is zero")
    if len(wn):
        with np.errstate(over="ignore", under="ignore"):
            norms = np.linalg.norm(wn, axis=1)
        odd = ~(np.isfinite(norms) & (norms > 0))       # |(1e300, 1e300)| overflows: scale it first
        out = wn / np.where(odd, 1.0, norms)[:, None]
        scaled = wn[odd] / big[odd, None]
        out[odd] = scaled / np.hypot(scaled[:, 0], scaled[:, 1])[:, None]
        wn = out

    period = 0.0 if period is None else validate.real("period", period, 0.0, lo_open=True)
    check_period("period", period, max(radius.max(), orad.max() if len(orad) else 0.0))
    if period > 0:
        pos = pos.copy()
        pos[:, 0] %= period
        opos = opos.copy()
        opos[:, 0] %= period

    mass = _disc_mass(density, radius, "disc")
    extent = np.abs(np.vstack([pos, opos])).max()
    if extent > 1e150 or (len(wp) and np.abs(wp).max() > 1e150):
        raise InputError(f"coordinates must be below 1e150 in magnitude (contact geometry squares them); "
                         f"got {max(extent, np.abs(wp).max() if len(wp) else 0.0):.3g}")
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
            [validate.per_item("angle", angle, n), np.zeros(len(orad))]),
        vel=np.zeros((len(all_rad), 2)) if vel is None else np.vstack(
            [validate.array("vel", vel, (n, 2)), np.zeros((len(orad), 2))]),
        spin=np.zeros(len(all_rad)) if spin is None else np.concatenate(
            [validate.per_item("spin", spin, n), np.zeros(len(orad))]),
    )
    check_overlaps(scene, overlap_tolerance)
    return scene


def add_discs(scene: Scene, pos: ArrayLike, radius: ArrayLike, density: ArrayLike = 1.0, *,
              vel: ArrayLike | None = None, spin: ArrayLike | None = None, angle: ArrayLike | None = None,
              overlap_tolerance: float = 1e-2) -> Scene:
    """``scene`` with mobile discs appended after its own: a new scene, equal to the
    :func:`make_scene` of all the discs (obstacles, walls, laws kept; its time too).

    A pouring adds a few grains to hundreds every few steps: only the new discs are
    validated and given masses (the same formulas, hence the same bits for the old ones,
    whose arrays are taken from ``scene``), while the overlap check covers every disc as
    :func:`make_scene` does.  The warm-start memory is not carried (its keys depend on
    the disc count: :func:`ncd.shared.construction.carry_warm` re-encodes it)."""
    check_scene(scene, state=True)
    pos = validate.array("pos", pos, (None, 2))
    k = len(pos)
    radius = validate.per_item("radius", radius, k, 0.0, lo_open=True)
    density = validate.per_item("density", density, k, 0.0, lo_open=True)
    validate.real("overlap_tolerance", overlap_tolerance, 0.0, allow_inf=True)
    vel = np.zeros((k, 2)) if vel is None else validate.array("vel", vel, (k, 2))
    spin = np.zeros(k) if spin is None else validate.per_item("spin", spin, k)
    angle = np.zeros(k) if angle is None else validate.per_item("angle", angle, k)
    if k and scene.period > 0:
        check_period("scene.period", scene.period, max(float(scene.radius.max()), float(radius.max())))
        pos = pos.copy()
        pos[:, 0] %= scene.period
    mass = _disc_mass(density, radius, "new disc")
    if k and np.abs(pos).max() > 1e150:
        raise InputError(f"coordinates must be below 1e150 in magnitude (contact geometry squares them); "
                         f"got {np.abs(pos).max():.3g}")
    nm = scene.n_mobile

    def insert(old: np.ndarray, new: np.ndarray) -> np.ndarray:
        return np.concatenate([old[:nm], new, old[nm:]])

    out = Scene(
        pos=insert(scene.pos, pos), radius=insert(scene.radius, radius),
        inv_mass=insert(scene.inv_mass, 1.0 / mass), inv_inertia=insert(scene.inv_inertia, 2.0 / (mass * radius ** 2)),
        mass=insert(scene.mass, mass), n_mobile=nm + k, wall_point=scene.wall_point, wall_normal=scene.wall_normal,
        gravity=scene.gravity, mu=scene.mu, mu_obstacle=scene.mu_obstacle, e_n=scene.e_n, e_t=scene.e_t,
        e_n_obstacle=scene.e_n_obstacle, e_t_obstacle=scene.e_t_obstacle, period=scene.period,
        angle=insert(scene.angle, angle), vel=insert(scene.vel, vel), spin=insert(scene.spin, spin),
        time=scene.time)
    check_overlaps(out, overlap_tolerance)
    return out


def check_overlaps(scene: Scene, tolerance: float) -> None:
    """Raise :class:`InputError` if any pair interpenetrates by more than
    ``tolerance`` times the smaller radius."""
    c = detect_contacts(scene, alert=0.0)
    if c.n == 0:
        return
    pair = c.body_b >= 0
    centre = c.gap[pair] + scene.radius[c.body_a[pair]] + scene.radius[c.body_b[pair]]
    if np.any(centre <= 0):                      # no contact normal: refused whatever the tolerance
        k = int(np.nonzero(pair)[0][np.argmin(centre)])
        raise InputError(f"discs {c.body_a[k]} and {c.body_b[k]} have coincident centres (no contact normal)")
    rb = np.where(c.body_b >= 0, scene.radius[np.maximum(c.body_b, 0)], np.inf)
    rmin = np.minimum(scene.radius[c.body_a], rb)
    excess = -c.gap / rmin
    k = int(np.argmax(excess))
    if excess[k] > tolerance:
        other = f"disc {c.body_b[k]}" if c.body_b[k] >= 0 else f"wall {-1 - c.body_b[k]}"
        raise InputError(
            f"initial overlap between disc {c.body_a[k]} and {other} is {-c.gap[k]:.3g} "
            f"({excess[k]:.3g} of the smaller radius), above overlap_tolerance = {tolerance}")
