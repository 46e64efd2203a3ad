"""Moreau-Jean time stepping (Moreau 2005, section 2) and the equilibrium test.

One step from ``t_i`` to ``t_f = t_i + h`` with the theta-method:

1. middle configuration ``q_m = q_i + (1 - theta) h u_i``;
2. active set (Moreau's rule): the contacts whose gap at ``q_m`` is
   ``<= gap_tolerance`` (a tiny positive slack, default ``1e-9`` of the
   smallest radius, so that exactly touching discs are in contact);
3. impulsional dynamics ``M (u_f - u_i) = h F + sum_alpha H_alpha s_alpha``
   with the contact law imposed on ``U_alpha(u_f)``, or with restitution on
   Moreau's weighted mean ``(U_f + e U_i) / (1 + e)`` per component for
   approaching contacts; solved by NLGS (:mod:`ncd.solver.nlgs`);
4. ``q_f = q_m + theta h u_f``.

The report of each step carries the largest interpenetration (``-min gap`` at
``q_m``), the NLGS sweeps, change, residual and converged flag.  A state that
goes non-finite or faster than ``speed_limit`` raises :class:`SimulationError`.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ncd.core import validate
from ncd.core.contacts import (
    Contacts,
    check_contacts,
    check_disc_blocks,
    delassus_blocks,
    detect_contacts,
    local_velocity,
    match_warm,
)
from ncd.core.errors import InputError, SimulationError
from ncd.core.jit import njit
from ncd.core.model import Scene, check_scene
from ncd.core.validate import array, real, shape_of, show
from ncd.solver.finish import global_delassus
from ncd.solver.nlgs import Delassus, Observer, restitution_bias, solve_discs
from ncd.solver.settings import NLGSResult, SolverSettings, check_settings_arg


@dataclass
class StepProblem:
    """The core problem of one step: contacts, Delassus blocks, free velocities."""
    h: float
    theta: float
    contacts: Contacts
    W: np.ndarray
    free_vel: np.ndarray
    free_spin: np.ndarray
    bias: np.ndarray
    pos_mid: np.ndarray
    angle_mid: np.ndarray
    vel_initial: np.ndarray
    spin_initial: np.ndarray
    _delassus: tuple[Scene, Delassus] | None = dataclasses.field(default=None, init=False, repr=False,
                                                                 compare=False)

    def delassus(self, scene: Scene) -> Delassus:
        """``(W, H, M^-1)`` of :func:`ncd.solver.finish.global_delassus`, built at the first
        call and kept: the finishing stage and local exact solves of every run of an
        ensemble on this problem share it (a run of Figure 3 cost three times its sweeps
        rebuilding it)."""
        if self._delassus is None or self._delassus[0] is not scene:
            self._delassus = (scene, global_delassus(scene, self.contacts))
        return self._delassus[1]

    @property
    def max_penetration(self) -> float:
        return float(max(0.0, -self.contacts.gap.min())) if self.contacts.n else 0.0


@dataclass
class StepReport:
    time: float
    n_contacts: int
    sweeps: int
    residual: float
    change: float
    converged: bool
    max_penetration: float


@njit(cache=True)
def _finite(a):
    """Every entry of ``a`` finite (one pass, no temporary)."""
    for x in a.flat:
        if not np.isfinite(x):
            return False
    return True


@validate.finite_problem
def prepare_step(scene: Scene, h: float, theta: float = 0.5, gap_tolerance: float | None = None,
                 vel: np.ndarray | None = None, spin: np.ndarray | None = None, check: bool = True) -> StepProblem:
    """Build the core problem of the step from the current state (or ``vel, spin``).

    ``check=False``: the caller has checked the arguments (:func:`step` does, once per
    step: the checks of a 10^3-disc step cost about a fifth of its time otherwise)."""
    if check:
        check_scene(scene)
        h, theta = check_step_args(h, theta, gap_tolerance, vel, spin, scene.n_disc)
    vel = scene.vel if vel is None else vel
    spin = scene.spin if spin is None else spin
    nm = scene.n_mobile
    gap_tol = 1e-9 * scene.radius.min() if gap_tolerance is None else gap_tolerance
    pos_mid = scene.pos.copy()
    pos_mid[:nm] += (1.0 - theta) * h * vel[:nm]
    angle_mid = scene.angle + (1.0 - theta) * h * spin
    if not (_finite(pos_mid) and _finite(angle_mid)):
        # a non-finite state would otherwise reach the detection grid
        raise SimulationError(f"state is non-finite at t = {scene.time:.6g} (positions, angles "
                              f"or velocities): cannot build the step")
    contacts = detect_contacts(scene, alert=gap_tol, pos=pos_mid, check=check)
    W = delassus_blocks(contacts.body_a, contacts.body_b, contacts.arm_a, contacts.arm_b,
                        scene.inv_mass, scene.inv_inertia)
    c = contacts
    U_i = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((c.n, 2)))
    free_vel = vel.copy()
    free_vel[:nm] += h * scene.gravity
    return StepProblem(h, theta, contacts, W, free_vel, spin.copy(), restitution_bias(c, U_i),
                       pos_mid, angle_mid, vel.copy(), spin.copy())


def solve_problem(scene: Scene, problem: StepProblem, guess: ArrayLike | None = None,
                  review_order: ArrayLike | None = None, settings: SolverSettings = SolverSettings(),
                  observe: Observer | None = None, check: bool = True) -> tuple[NLGSResult, np.ndarray, np.ndarray]:
    """Solve a prepared step; returns ``(result, vel_f, spin_f)`` without touching the scene.

    ``observe(impulse, vel, spin) -> 1-D array``: the figure's observable, scaled to
    order one; NLGS then runs in chunks of ``settings.check_every`` sweeps and the run
    is converged only when it has settled too (:mod:`ncd.solver.convergence`).
    ``check=False``: the caller has checked the arguments (as :func:`step` does)."""
    if check:
        check_step_problem(scene, problem)   # guess, review_order: in solve_discs
        check_settings_arg(settings)
    vel = problem.free_vel.copy()
    spin = problem.free_spin.copy()
    delassus = problem.delassus(scene) if settings.finish != "none" or settings.local_exact else None
    result = solve_discs(scene, problem.contacts, vel, spin, guess, review_order, settings,
                         bias=problem.bias, W=problem.W, observe=observe, check=check, delassus=delassus)
    return result, vel, spin


def initial_guess(scene: Scene, problem: StepProblem, init: str | ArrayLike) -> np.ndarray | None:
    """``init``: "zero", "warm" (previous impulses matched by body pair) or an array."""
    if not isinstance(init, str):
        return validate.impulse_guess("init", init, problem.contacts.n)
    if isinstance(init, str):
        if init == "zero":
            return None
        if init == "warm":
            return match_warm(problem.contacts, scene.prev_keys, scene.prev_impulse)
        raise InputError(f"init = {init!r} must be 'zero', 'warm' or an impulse array")
    return np.asarray(init, dtype=float).reshape(problem.contacts.n, 2)


def step(scene: Scene, h: float, theta: float = 0.5, settings: SolverSettings = SolverSettings(),
         init: str | ArrayLike = "warm", review_order: ArrayLike | None = None, gap_tolerance: float | None = None,
         speed_limit: float = np.inf) -> StepReport:
    """Advance ``scene`` by one Moreau-Jean step in place; returns a :class:`StepReport`."""
    h, theta = check_step_call(scene, h, theta, settings, init, gap_tolerance, speed_limit)
    # checked once here; the stages below skip their own checks of the same arguments
    problem = prepare_step(scene, h, theta, gap_tolerance, check=False)
    guess = initial_guess(scene, problem, init)
    if review_order is not None:
        review_order = validate.permutation("review_order", review_order, problem.contacts.n)
    result, vel, spin = solve_problem(scene, problem, guess, review_order, settings, check=False)
    nm = scene.n_mobile
    pos = problem.pos_mid.copy()
    pos[:nm] += theta * h * vel[:nm]
    angle = problem.angle_mid + theta * h * spin
    speed = np.abs(vel[:nm]).max()
    if not (_finite(pos) and _finite(vel) and _finite(spin)):
        raise SimulationError(f"state became non-finite at t = {scene.time + h:.6g} "
                              f"(NLGS residual {result.residual:.3g}, sweeps {result.sweeps})")
    if speed > speed_limit:
        raise SimulationError(f"speed {speed:.3g} exceeds speed_limit = {speed_limit:.3g} "
                              f"at t = {scene.time + h:.6g}: the simulation diverged")
    if scene.period > 0:
        pos[:nm, 0] %= scene.period
    scene.pos, scene.angle, scene.vel, scene.spin = pos, angle, vel, spin
    scene.time += h
    scene.prev_keys = problem.contacts.key
    scene.prev_impulse = result.impulse
    return StepReport(scene.time, problem.contacts.n, result.sweeps, result.residual,
                      result.change, result.converged, problem.max_penetration)


@dataclass
class EquilibriumResult:
    """Outcome of the one-step equilibrium test (section 2, last paragraph)."""
    at_rest: bool
    max_velocity: float      # max |u_f| over translation and r * spin, relative to |g| h
    forces: np.ndarray       # (n, 2) contact forces r = s / h
    contacts: Contacts
    result: NLGSResult


def equilibrium_test(scene: Scene, h: float, settings: SolverSettings = SolverSettings(),
                     init: str | ArrayLike = "zero", review_order: ArrayLike | None = None,
                     velocity_tol: float = 1e-6, gap_tolerance: float | None = None) -> EquilibriumResult:
    """One step from zero velocity: is ``u_f = 0`` (within ``velocity_tol * |g| h``)?

    The scene is not modified.  The contact forces are ``r = s / h``.
    """
    h, _ = check_step_call(scene, h, 1.0, settings, init, gap_tolerance, velocity_tol=velocity_tol)
    zero_v = np.zeros_like(scene.vel)
    zero_w = np.zeros_like(scene.spin)
    problem = prepare_step(scene, h, 1.0, gap_tolerance, vel=zero_v, spin=zero_w)
    guess = initial_guess(scene, problem, init)
    result, vel, spin = solve_problem(scene, problem, guess, review_order, settings)
    nm = scene.n_mobile
    g = np.linalg.norm(scene.gravity)
    umax = max(np.abs(vel[:nm]).max(), np.abs(spin[:nm] * scene.radius[:nm]).max())
    rel = float(umax / (g * h)) if g > 0 else float(umax)
    return EquilibriumResult(rel <= velocity_tol, rel, result.impulse / h, problem.contacts, result)


@validate.finite_value
def kinetic_energy(scene: Scene) -> float:
    check_scene(scene, state=True)
    nm = scene.n_mobile
    m = scene.mass[:nm]
    inertia = 0.5 * m * scene.radius[:nm] ** 2
    v = scene.vel[:nm]
    # v_x^2 + v_y^2: the bits of np.sum(v ** 2, axis=1), whose reduction over rows of two
    # costs more than the rest of the energy
    return float(0.5 * np.sum(m * (v[:, 0] ** 2 + v[:, 1] ** 2)) + 0.5 * np.sum(inertia * scene.spin[:nm] ** 2))


# ------------------------------------------------------------ argument checks
def check_step_problem(s, problem, name="problem", full=False):
    """A :class:`ncd.StepProblem` built for ``s`` (:func:`ncd.prepare_step`).  Without
    ``full``, only what :func:`ncd.solve_problem` reads before :func:`ncd.solve_discs`
    checks the rest (contacts, W, bias: :func:`ncd.solver.nlgs.check_disc_problem`)."""
    check_scene(s)
    if not isinstance(problem, StepProblem):
        raise InputError(f"{name} must be an ncd.StepProblem (from ncd.prepare_step); got {type(problem).__name__}")
    nd = s.n_disc
    for field, shape in (("free_vel", (nd, 2)), ("free_spin", (nd,))):
        value = getattr(problem, field)
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{field} must be a numpy array; got {show(value)}")
        array(f"{name}.{field}", value, shape)
    if full:
        check_contacts(s, problem.contacts, f"{name}.contacts")
        check_disc_blocks(problem.W, problem.contacts.n, f"{name}.W")
        array(f"{name}.bias", problem.bias, (problem.contacts.n, 2))
    return problem


def check_step_args(h, theta, gap_tolerance, vel=None, spin=None, n_disc=None):
    """Scalars of :func:`ncd.prepare_step` / :func:`ncd.step`; ``vel, spin`` when given.
    Returns ``(h, theta)`` as floats."""
    try:
        hv = real("h", h, allow_inf=True)
    except InputError:
        hv = np.nan
    if not (np.isfinite(hv) and hv > 0):
        raise InputError(f"time step h = {h!r} must be > 0")
    try:
        real("theta", theta, 0.0, 1.0, lo_open=True)
    except InputError:
        raise InputError(f"theta = {theta!r} must be in (0, 1]") from None
    if gap_tolerance is not None:
        real("gap_tolerance", gap_tolerance, 0.0)
    if vel is not None:
        array("vel", vel, (n_disc, 2))
    if spin is not None:
        array("spin", spin, (n_disc,))
    return hv, float(theta)


def check_step_call(s, h, theta=0.5, settings=None, init="zero", gap_tolerance=None, speed_limit=np.inf,
                    velocity_tol=0.0):
    """Arguments of :func:`ncd.step` and :func:`ncd.equilibrium_test` known before
    the contacts are (``init``'s shape and ``review_order`` are checked once they are)."""
    check_scene(s)
    h, theta = check_step_args(h, theta, gap_tolerance)
    if settings is not None:
        check_settings_arg(settings)
    if isinstance(init, str):
        if init not in ("zero", "warm"):
            raise InputError(f"init = {init!r} must be 'zero', 'warm' or an impulse array")
    elif init is not None:
        array("init", init, (None,) * len(shape_of("init", init)))
    real("speed_limit", speed_limit, 0.0, lo_open=True, allow_inf=True)
    real("velocity_tol", velocity_tol, 0.0)
    return h, theta
