"""Discs between two plates, the top one mobile under a prescribed force; a slice of them.

Unger, Kertész & Wolf (PRL 94, 178001, 2005) compress discs, without gravity and with
periodic sides, between two plates under a constant force, and analyse a middle slice
with the forces across its boundaries held fixed.  The solver knows fixed walls only,
so the top plate is handled here, at the scene level, with no change to the kernels:
it is one more mobile body of the scene (index ``n``, after the discs), with its mass,
no rotation, and contacts built here rather than by the disc grid (normal ``(0, -1)``,
no arm).  Its contacts are frictionless: the plate then receives vertical forces only
and translates along its normal exactly, as a plate guided by rails would.  NLGS sees
its mass in the Delassus blocks (``1/m_a + 1/M``) and moves it as it moves a disc; its
equilibrium rows (the last three rows of ``H``; only the vertical one is not zero) are
in ``A``.  The bottom plate is a fixed wall ``y = 0`` with the discs' friction.

A *slice* (:func:`slice_problem`) keeps the discs whose centres lie in a horizontal
band; the contacts between two of them are the unknowns, every other contact of a slice
disc is a boundary load fixed at a reference solution of the whole packing.  NLGS on the
slice is the one-step problem from rest whose free velocities carry those loads
(``u_free = h M^-1 F``), so that ``u_f = 0`` is exactly ``H r + F = 0`` in ``C``.
"""
from dataclasses import dataclass

import numpy as np

from ncd.core.contacts import Contacts, delassus_blocks, detect_contacts, h_matrix, local_velocity, pair_key
from ncd.core.errors import InputError
from ncd.core.model import Scene, check_scene
from ncd.dynamics.stepper import StepProblem, solve_problem
from ncd.solver.nlgs import restitution_bias

PLATE_NORMAL = (0.0, -1.0)       # from the top plate into the packing


@dataclass
class Cell:
    """A periodic cell: ``scene`` holds the ``n`` discs and, as mobile body ``n``, the top
    plate (``pos[n, 1]`` its height); ``force`` pushes the plate down (N)."""
    scene: Scene
    force: float

    @property
    def n(self):
        return self.scene.n_mobile - 1

    @property
    def plate_y(self):
        return float(self.scene.pos[self.n, 1])


def make_cell(disc_scene, plate_y, plate_mass, force):
    """The cell of ``disc_scene`` (periodic, no gravity, bottom wall, no obstacles) and a top
    plate at height ``plate_y`` of mass ``plate_mass`` under ``force`` (N, downward)."""
    s = check_scene(disc_scene, "disc_scene")
    if s.n_disc != s.n_mobile or s.period <= 0 or np.any(s.gravity != 0):
        raise InputError("disc_scene must hold mobile discs only, be periodic and have no gravity")
    for name, v in (("plate_mass", plate_mass), ("force", force)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be finite and > 0")
    n = s.n_mobile
    r_plate = float(s.radius.max())         # a placeholder: the plate has no arm and no rotation

    def add(a, v):
        return np.concatenate([a, [v]]) if a.ndim == 1 else np.vstack([a, [v]])

    scene = Scene(pos=add(s.pos, (0.5 * s.period, float(plate_y))), radius=add(s.radius, r_plate),
                  inv_mass=add(s.inv_mass, 1.0 / plate_mass), inv_inertia=add(s.inv_inertia, 0.0),
                  mass=add(s.mass, float(plate_mass)), n_mobile=n + 1, wall_point=s.wall_point,
                  wall_normal=s.wall_normal, gravity=s.gravity, mu=s.mu, mu_obstacle=s.mu_obstacle,
                  e_n=s.e_n, e_t=s.e_t, e_n_obstacle=s.e_n_obstacle, e_t_obstacle=s.e_t_obstacle,
                  period=s.period, angle=add(s.angle, 0.0), vel=add(s.vel, (0.0, 0.0)), spin=add(s.spin, 0.0))
    return Cell(check_scene(scene, "cell"), float(force))


def cell_contacts(cell, pos, alert, check=True):
    """Contacts of the cell at positions ``pos``: the disc grid's (discs, bottom wall) and the
    top plate's (frictionless, body ``n``), sorted by the cell's pair keys.  ``check=False``:
    the caller has checked the cell (:func:`step` does at its first call of a build)."""
    s, n = cell.scene, cell.n
    discs = Scene(**{**s.__dict__, "pos": pos[:n], "radius": s.radius[:n], "inv_mass": s.inv_mass[:n],
                     "inv_inertia": s.inv_inertia[:n], "mass": s.mass[:n], "n_mobile": n,
                     "angle": s.angle[:n], "vel": s.vel[:n], "spin": s.spin[:n],
                     "prev_keys": None, "prev_impulse": None})
    c = detect_contacts(discs, alert=alert, pos=pos[:n], check=check)
    gap = pos[n, 1] - pos[:n, 1] - s.radius[:n]
    top = np.nonzero(gap <= alert)[0].astype(np.int64)
    k = len(top)
    body_b = np.where(c.body_b >= 0, c.body_b, c.body_b)          # walls keep -1 - index
    point = np.column_stack([pos[top, 0], pos[top, 1] + s.radius[top] + 0.5 * gap[top]])
    fields = {"body_a": np.concatenate([c.body_a, top]), "body_b": np.concatenate([body_b, np.full(k, n)]),
              "normal": np.vstack([c.normal, np.tile(PLATE_NORMAL, (k, 1))]),
              "point": np.vstack([c.point, point]), "gap": np.concatenate([c.gap, gap[top]]),
              "arm_a": np.concatenate([c.arm_a, s.radius[top]]), "arm_b": np.concatenate([c.arm_b, np.zeros(k)]),
              "shift_b": np.concatenate([c.shift_b, np.zeros(k)]), "mu": np.concatenate([c.mu, np.zeros(k)]),
              "e_n": np.concatenate([c.e_n, np.full(k, s.e_n_obstacle)]),
              "e_t": np.concatenate([c.e_t, np.full(k, s.e_t_obstacle)])}
    fields["key"] = pair_key(fields["body_a"], fields["body_b"], s.n_disc)
    order = np.argsort(fields["key"], kind="mergesort")
    return Contacts(**{f: v[order] for f, v in fields.items()})


def prepare(cell, h, theta=0.5, vel=None, spin=None, check=True):
    """The core problem of one Moreau-Jean step of the cell (the plate pushed by ``force``)."""
    s, n = cell.scene, cell.n
    vel = s.vel if vel is None else vel
    spin = s.spin if spin is None else spin
    pos_mid = s.pos + (1.0 - theta) * h * vel
    angle_mid = s.angle + (1.0 - theta) * h * spin
    c = cell_contacts(cell, pos_mid, 1e-9 * s.radius.min(), check)
    W = delassus_blocks(c.body_a, c.body_b, c.arm_a, c.arm_b, s.inv_mass, s.inv_inertia)
    U_i = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((c.n, 2)))
    free_vel = vel.copy()
    free_vel[n, 1] -= h * cell.force * s.inv_mass[n]
    return StepProblem(h, theta, c, W, free_vel, spin.copy(), restitution_bias(c, U_i), pos_mid, angle_mid,
                       vel.copy(), spin.copy())


def step(cell, h, settings, theta=0.5, check=True):
    """One Moreau-Jean step of the cell in place (warm start by pair key); the NLGS result.

    ``check=False``: the cell and settings were checked at an earlier step of the same
    build (the checks of every step cost more than its sweeps on a 60-disc cell); the
    solver still refuses a non-finite result."""
    s = cell.scene
    p = prepare(cell, h, theta, check=check)
    guess = _warm(p.contacts, s.prev_keys, s.prev_impulse)
    res, vel, spin = solve_problem(s, p, guess, None, settings, check=check)
    vel[cell.n, 0] = 0.0
    pos = p.pos_mid + theta * h * vel
    pos[:, 0] %= s.period
    s.pos, s.angle, s.vel, s.spin = pos, p.angle_mid + theta * h * spin, vel, spin
    s.time += h
    s.prev_keys, s.prev_impulse = p.contacts.key, res.impulse
    return res, p


def _warm(c, keys, impulse):
    if keys is None or len(keys) == 0:
        return None
    j = np.searchsorted(keys, c.key)
    j = np.minimum(j, len(keys) - 1)
    hit = keys[j] == c.key
    return np.where(hit[:, None], impulse[j], 0.0)


def rest_state(cell, h, settings, guess=None, check=True):
    """The one-step problem from rest (the equilibrium test): ``(forces, max |u_f|, problem,
    result)``, forces ``r = s / h`` of every contact, ``|u_f|`` over discs and plate.
    ``check``: as in :func:`step`."""
    s = cell.scene
    p = prepare(cell, h, 1.0, vel=np.zeros_like(s.vel), spin=np.zeros_like(s.spin), check=check)
    if guess is None:
        guess = _warm(p.contacts, s.prev_keys, s.prev_impulse)
    res, vel, spin = solve_problem(s, p, guess, None, settings, check=check)
    umax = max(np.abs(vel).max(), np.abs(spin * s.radius).max())
    return res.impulse / h, float(umax), p, res


def plate_load(cell):
    """The forces applied to the cell's mobile bodies, shape (n + 1, 2): the plate's load
    only, downwards (the cell has no gravity); the equilibrium's external force is
    ``external_load(cell.scene, plate_load(cell))``."""
    applied = np.zeros((cell.n + 1, 2))
    applied[cell.n, 1] = -cell.force
    return applied


@dataclass
class Slice:
    """The unknowns and loads of a slice: ``H r + F = 0`` with ``r`` the forces of the
    ``contacts`` between two slice discs, ``F`` the boundary loads; ``scene`` and ``problem``
    the slice as a one-step problem from rest (NLGS); ``reference`` the slice forces of the
    reference solution; ``discs`` the cell's indices of the slice discs."""
    H: object
    F: np.ndarray
    mu: np.ndarray
    reference: np.ndarray
    discs: np.ndarray
    inner: np.ndarray        # indices of the unknown contacts among the cell's contacts
    scene: Scene
    problem: StepProblem


def slice_problem(cell, contacts, forces, y_lo, y_hi, h, balance=False):
    """The slice ``y_lo <= y < y_hi`` (disc centres) with every other contact fixed at ``forces``
    (an equilibrium of the whole cell, one row per contact of ``contacts``).

    ``balance``: the loads are ``-H r`` of the slice's own ``forces`` instead of the boundary
    forces' (they differ by the cell's equilibrium residual on the slice's rows).  For forces
    balanced only to ~1e-10: the right-hand side of dependent equations is then consistent,
    without which the slice's LP is infeasible at any tolerance."""
    s, n = cell.scene, cell.n
    inside = np.zeros(s.n_disc, bool)
    inside[:n] = (s.pos[:n, 1] >= y_lo) & (s.pos[:n, 1] < y_hi)
    a, b = contacts.body_a, contacts.body_b
    in_a = inside[a]
    in_b = np.where(b >= 0, inside[np.maximum(b, 0)], False)
    inner = np.nonzero(in_a & in_b)[0]
    touch = np.nonzero(in_a ^ in_b)[0]
    H = h_matrix(s, contacts).tocsc()
    discs = np.nonzero(inside)[0]
    rows = (3 * discs[:, None] + np.arange(3)).ravel()
    bcols = (2 * touch[:, None] + np.arange(2)).ravel()
    cols = (2 * inner[:, None] + np.arange(2)).ravel()
    Hs = H[rows][:, cols].tocsr()
    F = -(Hs @ forces[inner].ravel()) if balance else (H[:, bcols] @ forces[touch].ravel())[rows]
    Hs.eliminate_zeros()
    index = np.full(s.n_disc, -1, np.int64)
    index[discs] = np.arange(len(discs))
    sub = contacts.subset(inner)
    sub.body_a, sub.body_b = index[sub.body_a], index[sub.body_b]
    sub.key = pair_key(sub.body_a, sub.body_b, len(discs))
    keep = ("pos", "radius", "inv_mass", "inv_inertia", "mass", "angle", "vel", "spin")
    scene = Scene(**{**s.__dict__, **{f: getattr(s, f)[discs].copy() for f in keep}, "n_mobile": len(discs),
                     "wall_point": np.zeros((0, 2)), "wall_normal": np.zeros((0, 2)),
                     "prev_keys": None, "prev_impulse": None})
    scene.vel[:] = 0.0
    scene.spin[:] = 0.0
    h = float(h)
    Fd = F.reshape(-1, 3)
    free_vel = h * scene.inv_mass[:, None] * Fd[:, :2]
    free_spin = h * scene.inv_inertia * Fd[:, 2]
    W = delassus_blocks(sub.body_a, sub.body_b, sub.arm_a, sub.arm_b, scene.inv_mass, scene.inv_inertia)
    problem = StepProblem(h, 1.0, sub, W, free_vel, free_spin, np.zeros((sub.n, 2)), scene.pos.copy(),
                          scene.angle.copy(), scene.vel.copy(), scene.spin.copy())
    used = np.diff(Hs.indptr) > 0          # rows of discs (or torques) no unknown force touches:
    return Slice(Hs[used], F[used], contacts.mu[inner].copy(), forces[inner].copy(), discs, inner,
                 check_scene(scene, "slice"), problem)    # balanced by the loads, 0 = ~1e-13 left out


def relax(sl, guess, order, settings):
    """NLGS on the slice from the impulse guess ``h * forces``: ``(forces, converged, |u_f|
    relative to the free velocities)``."""
    h = sl.problem.h
    res, vel, spin = solve_problem(sl.scene, sl.problem, None if guess is None else h * guess, order, settings)
    scale = max(np.abs(sl.problem.free_vel).max(), np.abs(sl.problem.free_spin * sl.scene.radius).max(), 1e-300)
    umax = max(np.abs(vel).max(), np.abs(spin * sl.scene.radius).max()) / scale
    return res.impulse / h, bool(res.converged), float(umax)


__all__ = ["Cell", "make_cell", "cell_contacts", "prepare", "step", "rest_state", "plate_load",
           "Slice", "slice_problem", "relax", "PLATE_NORMAL"]
