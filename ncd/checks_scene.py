"""Checks of scenes, contacts, steps and ensembles (issue 14), on the primitives
of :mod:`ncd.checks` (which re-exports them: call them as ``checks.scene`` etc.).

The scene and contact checks have a fast path (type and shape tests, then one
numba pass over the values, a few microseconds) since every step calls them;
when it fails, the slow path names the argument and the offending value.
"""
import numbers

import numpy as np

from ._cache import njit
from .checks import (_F64, _finite_flat, _first_bad, _ok, _show, array, impulse_guess, integer, permutation,
                     real, settings_arg, shape_of)
from .model import InputError, Scene, SimulationError

MAX_GRID_CELLS = 1e7      # cells of the contact detection grid (8 bytes each)
MASS_RTOL = 1e-12         # |mass inv_mass - 1| of a mobile disc (make_scene: 1 / mass, a rounding at most)


def scene(s, name="scene", state=False):
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
        raise InputError(f"{name}.time = {_show(t)} must be a finite real number")
    period(f"{name}.period", s.period, float(s.radius.max()))
    if state and not all(np.isfinite(getattr(s, f)).all() for f in ("pos", "vel", "spin", "angle")):
        raise SimulationError(f"{name} state (pos, vel, spin, angle) is non-finite at t = {s.time}")
    return s


def period(name, value, largest_radius):
    """A period along x is 0 (not periodic) or at least three largest diameters (a pair of
    discs then touches across it once at most)."""
    if value > 0 and value < 6 * largest_radius:
        raise InputError(f"{name} = {value} must be at least three largest diameters ({6 * largest_radius})")


def _scene_ok(s):
    """Fast path of :func:`scene` (a few microseconds): True if every check passes;
    False sends the scene to the slow path, which names what is wrong."""
    r, nm = s.radius, s.n_mobile
    if type(r) is not np.ndarray or r.ndim != 1 or r.dtype != _F64 or type(nm) is not int:
        return False
    nd = r.shape[0]
    v1, v2 = (nd,), (nd, 2)
    wp, wn = s.wall_point, s.wall_normal
    if not (1 <= nm <= nd and _ok(s.inv_mass, v1) and _ok(s.inv_inertia, v1) and _ok(s.mass, v1)
            and _ok(s.pos, v2) and _ok(s.vel, v2) and _ok(s.spin, v1) and _ok(s.angle, v1)
            and _ok(s.gravity, (2,)) and type(wp) is np.ndarray and type(wn) is np.ndarray
            and wp.dtype == _F64 and wn.dtype == _F64 and wp.ndim == 2 and wp.shape == wn.shape
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
            and _ok(s.prev_impulse, (len(pk), 2)) and s.prev_impulse.flags.c_contiguous
            and _finite_flat(s.prev_impulse.reshape(-1)) and bool(np.all(pk[1:] > pk[:-1])))


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
    return _finite_flat(wp) and _finite_flat(wn) and _finite_flat(g)


def _scene_slow(s, name):
    """The checks of :func:`scene` one by one, raising on the first that fails."""
    rshape = shape_of(f"{name}.radius", s.radius)
    nd = rshape[0] if len(rshape) == 1 else -1
    if nd < 1:
        raise InputError(f"{name}.radius has shape {rshape}, expected (n_disc,) with n_disc >= 1")
    integer(f"{name}.n_mobile", s.n_mobile, 1, nd)
    for field, shape, fin in (("radius", (nd,), True), ("inv_mass", (nd,), True), ("inv_inertia", (nd,), True),
                              ("mass", (nd,), False), ("pos", (nd, 2), False), ("vel", (nd, 2), False),
                              ("spin", (nd,), False), ("angle", (nd,), False),
                              ("wall_point", (None, 2), True), ("wall_normal", (None, 2), True),
                              ("gravity", (2,), True)):
        value = getattr(s, field)
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{field} must be a numpy array; got {_show(value)}")
        array(f"{name}.{field}", value, shape, finite=fin)
    if np.any(s.radius <= 0):
        _first_bad(f"{name}.radius", s.radius, s.radius <= 0, "must be > 0")
    if not np.all(np.isfinite(s.mass[: s.n_mobile]) & (s.mass[: s.n_mobile] > 0)):
        raise InputError(f"{name}.mass of the mobile discs must be finite and > 0")
    if np.any(s.inv_mass[: s.n_mobile] <= 0):
        _first_bad(f"{name}.inv_mass", s.inv_mass, s.inv_mass <= 0, "must be > 0 for mobile discs")
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
        _first_bad(f"{name}.inv_mass + radius^2 inv_inertia", w_tt, ~(w_tt <= 1e300),
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
                         f"got {_show(s.prev_keys)} and {_show(s.prev_impulse)}")
    if s.prev_keys is not None:
        keys = np.asarray(s.prev_keys)
        if keys.size and keys.dtype.kind not in "iu":
            raise InputError(f"{name}.prev_keys must be integers; got dtype {keys.dtype}")
        if keys.ndim == 1 and np.any(keys[1:] <= keys[:-1]):
            k = int(np.argmax(keys[1:] <= keys[:-1]))
            raise InputError(f"{name}.prev_keys must increase strictly (the warm start searches them); "
                             f"prev_keys[{k}] = {keys[k]}, prev_keys[{k + 1}] = {keys[k + 1]}")
        if not isinstance(s.prev_impulse, np.ndarray):
            raise InputError(f"{name}.prev_impulse must be a numpy array; got {_show(s.prev_impulse)}")
        array(f"{name}.prev_impulse", s.prev_impulse, (len(keys), 2))
    return s


def contacts(s, c, name="contacts"):
    """A :class:`ncd.Contacts` of ``s``: every field of length ``n``, disc
    indices in range (``body_a`` mobile, ``body_b`` a disc or ``-1 - wall``),
    unit normals, finite arms and laws."""
    from .contacts import Contacts
    if not isinstance(c, Contacts):
        raise InputError(f"{name} must be an ncd.Contacts; got {type(c).__name__}")
    if _contacts_ok(s, c):
        return c
    for field, value in vars(c).items():
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{field} must be a numpy array; got {_show(value)}")
    ashape = shape_of(f"{name}.body_a", c.body_a)
    n = ashape[0] if len(ashape) == 1 else -1
    if n < 0:
        raise InputError(f"{name}.body_a has shape {ashape}, expected (n,)")
    for field in ("body_a", "body_b", "key"):
        value = np.asarray(getattr(c, field))
        if value.shape != (n,) or (n and value.dtype.kind not in "iu"):
            raise InputError(f"{name}.{field} must be integers of shape ({n},); got {value.dtype} {value.shape}")
    for field, shape in (("normal", (n, 2)), ("point", (n, 2)), ("gap", (n,)), ("arm_a", (n,)),
                         ("arm_b", (n,)), ("shift_b", (n,)), ("mu", (n,)), ("e_n", (n,)), ("e_t", (n,))):
        array(f"{name}.{field}", getattr(c, field), shape)
    if n == 0:
        return c
    a, b = np.asarray(c.body_a), np.asarray(c.body_b)
    bad = (a < 0) | (a >= s.n_mobile)
    if np.any(bad):
        _first_bad(f"{name}.body_a", a, bad, f"must be a mobile disc in range({s.n_mobile})")
    bad = (b < -len(s.wall_point)) | (b >= s.n_disc) | (a == b)
    if np.any(bad):
        _first_bad(f"{name}.body_b", b, bad,
                   f"must be another disc in range({s.n_disc}) or -1 - wall with {len(s.wall_point)} walls")
    norm = np.hypot(c.normal[:, 0], c.normal[:, 1])
    if np.any(np.abs(norm - 1.0) > 1e-6):
        k = int(np.argmax(np.abs(norm - 1.0)))
        raise InputError(f"{name}.normal[{k}] = {c.normal[k]} is not a unit vector")
    if np.any(np.asarray(c.mu) < 0):
        _first_bad(f"{name}.mu", np.asarray(c.mu), np.asarray(c.mu) < 0, "must be >= 0")
    for field in ("e_n", "e_t"):
        e = np.asarray(getattr(c, field))
        if np.any((e < 0) | (e > 1)):
            _first_bad(f"{name}.{field}", e, (e < 0) | (e > 1), "must be in [0, 1]")
    return c


def _contacts_ok(s, c):
    """Fast path of :func:`contacts` (False: the slow path names the fault)."""
    a, b, key = c.body_a, c.body_b, c.key
    if type(a) is not np.ndarray or a.ndim != 1 or a.dtype != np.int64:
        return False
    n = a.shape[0]
    v1, v2 = (n,), (n, 2)
    if not (type(b) is np.ndarray and b.shape == v1 and b.dtype == np.int64 and type(key) is np.ndarray
            and key.shape == v1 and key.dtype.kind in "iu" and _ok(c.normal, v2) and _ok(c.point, v2)
            and all(_ok(getattr(c, f), v1) for f in ("gap", "arm_a", "arm_b", "shift_b", "mu", "e_n", "e_t"))):
        return False
    if n == 0:
        return True
    return _contact_values_ok(a, b, c.normal, c.point, c.gap, c.arm_a, c.arm_b, c.shift_b, c.mu, c.e_n, c.e_t,
                              s.n_mobile, s.n_disc, len(s.wall_point))


@njit(cache=True)
def _contact_values_ok(a, b, normal, point, gap, arm_a, arm_b, shift_b, mu, e_n, e_t, nm, nd, n_walls):
    """The value checks of :func:`_contacts_ok` in one pass."""
    for c in range(a.shape[0]):
        if not (0 <= a[c] < nm and -n_walls <= b[c] < nd and a[c] != b[c]
                and abs(normal[c, 0] ** 2 + normal[c, 1] ** 2 - 1.0) <= 1e-6
                and np.isfinite(point[c, 0]) and np.isfinite(point[c, 1]) and np.isfinite(gap[c])
                and np.isfinite(arm_a[c]) and np.isfinite(arm_b[c]) and np.isfinite(shift_b[c])
                and 0.0 <= mu[c] < np.inf and 0.0 <= e_n[c] <= 1.0 and 0.0 <= e_t[c] <= 1.0):
            return False
    return True


def disc_blocks(W, n, name="W"):
    """Delassus blocks of disc contacts, (n, 2, 2): finite, diagonal, ``W_nn, W_tt > 0``."""
    if _ok(W, (n, 2, 2)) and W.flags.c_contiguous and _disc_blocks_ok(W):
        return W
    W = array(name, W, (n, 2, 2))
    if n and (np.any(W[:, 0, 1] != 0) or np.any(W[:, 1, 0] != 0)):
        k = int(np.argmax((W[:, 0, 1] != 0) | (W[:, 1, 0] != 0)))
        raise InputError(f"{name}[{k}] = {W[k].tolist()}: disc contacts have diagonal Delassus blocks "
                         "(use solve_local for a general W)")
    if n and (np.any(W[:, 0, 0] <= 0) or np.any(W[:, 1, 1] <= 0)):
        k = int(np.argmax((W[:, 0, 0] <= 0) | (W[:, 1, 1] <= 0)))
        raise InputError(f"{name}[{k}] = {W[k].tolist()} is not positive definite")
    return W


@njit(cache=True)
def _disc_blocks_ok(W):
    for c in range(W.shape[0]):
        if not (W[c, 0, 1] == 0.0 and W[c, 1, 0] == 0.0 and 0.0 < W[c, 0, 0] < np.inf and 0.0 < W[c, 1, 1] < np.inf):
            return False
    return True


def disc_problem(s, c, vel, spin, guess, review_order, settings, bias, W):
    """All arguments of :func:`ncd.solve_discs`; returns ``(guess, order, bias)``."""
    scene(s)
    contacts(s, c)
    n, nd = c.n, s.n_disc
    for nm_, value, shape in (("vel", vel, (nd, 2)), ("spin", spin, (nd,))):
        if not (isinstance(value, np.ndarray) and value.dtype == np.float64 and value.flags.writeable):
            raise InputError(f"{nm_} must be a writeable float64 numpy array of shape {shape} (modified in place); "
                             f"got {_show(value)}")
        array(nm_, value, shape)
    settings_arg(settings)
    W = None if W is None else disc_blocks(W, n)
    bias = np.zeros((n, 2)) if bias is None else array("bias", bias, (n, 2))
    return impulse_guess("guess", guess, n), permutation("review_order", review_order, n), bias, W


def step_problem(s, problem, name="problem", full=False):
    """A :class:`ncd.StepProblem` built for ``s`` (:func:`ncd.prepare_step`).  Without
    ``full``, only what :func:`ncd.solve_problem` reads before :func:`ncd.solve_discs`
    checks the rest (contacts, W, bias: :func:`disc_problem`)."""
    from .stepper import StepProblem
    scene(s)
    if not isinstance(problem, StepProblem):
        raise InputError(f"{name} must be an ncd.StepProblem (from ncd.prepare_step); got {type(problem).__name__}")
    nd = s.n_disc
    for field, shape in (("free_vel", (nd, 2)), ("free_spin", (nd,))):
        value = getattr(problem, field)
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{field} must be a numpy array; got {_show(value)}")
        array(f"{name}.{field}", value, shape)
    if full:
        contacts(s, problem.contacts, f"{name}.contacts")
        disc_blocks(problem.W, problem.contacts.n, f"{name}.W")
        array(f"{name}.bias", problem.bias, (problem.contacts.n, 2))
    return problem


def step_args(h, theta, gap_tolerance, vel=None, spin=None, n_disc=None):
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


def step_call(s, h, theta=0.5, settings=None, init="zero", gap_tolerance=None, speed_limit=np.inf,
              velocity_tol=0.0):
    """Arguments of :func:`ncd.step` and :func:`ncd.equilibrium_test` known before
    the contacts are (``init``'s shape and ``review_order`` are checked once they are)."""
    scene(s)
    h, theta = step_args(h, theta, gap_tolerance)
    if settings is not None:
        settings_arg(settings)
    if isinstance(init, str):
        if init not in ("zero", "warm"):
            raise InputError(f"init = {init!r} must be 'zero', 'warm' or an impulse array")
    elif init is not None:
        array("init", init, (None,) * len(shape_of("init", init)))
    real("speed_limit", speed_limit, 0.0, lo_open=True, allow_inf=True)
    real("velocity_tol", velocity_tol, 0.0)
    return h, theta


@njit(cache=True)
def _extent(pos, radius):
    """``x_min, x_max, y_min, y_max`` of ``pos`` and the largest radius."""
    x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
    for i in range(pos.shape[0]):
        x0, x1 = min(x0, pos[i, 0]), max(x1, pos[i, 0])
        y0, y1 = min(y0, pos[i, 1]), max(y1, pos[i, 1])
    return x0, x1, y0, y1, radius.max()


def detection_args(s, alert, pos):
    """Arguments of :func:`ncd.detect_contacts`; returns ``pos`` (the scene's if None)."""
    scene(s)
    alert = real("alert", alert, 0.0)
    pos = array("pos", s.pos if pos is None else pos, (s.n_disc, 2))
    x0, x1, y0, y1, rmax = _extent(pos, s.radius)
    if max(-x0, x1, -y0, y1) > 1e150:
        raise InputError(f"pos must be below 1e150 in magnitude; got {max(-x0, x1, -y0, y1):.3g}")
    # the cell grid of ncd.detection.disc_pairs (same formulas): refuse what would not fit in memory
    n = len(pos)
    cell = 2.0 * rmax + alert
    span = (x1 - x0, y1 - y0)
    with np.errstate(over="ignore"):
        if s.period > 0:
            cells = max(1.0, s.period / cell) * (span[1] / cell + 1.0)
        else:
            cell = max(cell, float(np.sqrt((span[0] + cell) * (span[1] + cell) / (4.0 * n + 16.0))))
            cells = (span[0] / cell + 1.0) * (span[1] / cell + 1.0)
    if not cells <= MAX_GRID_CELLS:
        raise InputError(f"the contact detection grid would need {cells:.3g} cells (> {MAX_GRID_CELLS:.0g}): "
                         f"the discs span {span[0]:.3g} x {span[1]:.3g}"
                         + (f" (period {s.period:.3g})" if s.period > 0 else "")
                         + f" for a cell of {cell:.3g} (largest diameter plus alert)")
    return pos


def explore_args(s, problem, members, root_seed, init, review, guess_scale, settings, progress, threads):
    """Arguments of :func:`ncd.explore.explore`; returns ``members`` as int64."""
    from .explore import INIT_MODES
    step_problem(s, problem, full=True)
    members = np.asarray(members) if not isinstance(members, (str, bytes)) else np.asarray(None)
    if members.ndim != 1 or (members.size and members.dtype.kind not in "iu"):
        raise InputError(f"members must be a 1-D array of integers; got {members.dtype} {members.shape}")
    if members.size and members.dtype.kind == "u" and members.max() > np.iinfo(np.int64).max:
        raise InputError(f"members must be below 2**63; got {members.max()}")
    if members.size and members.min() < 0:
        raise InputError(f"members must be >= 0 (they seed default_rng); got {members.min()}")
    integer("root_seed", root_seed, 0)
    if not isinstance(init, str) or init not in INIT_MODES:
        raise InputError(f"init = {init!r} must be one of {INIT_MODES}")
    if not isinstance(review, str) or review not in ("fixed", "random"):
        raise InputError(f"review = {review!r} must be 'fixed' or 'random'")
    if init == "random" and guess_scale is None:
        raise InputError("init = 'random' needs guess_scale > 0, got None")
    if guess_scale is not None:
        real("guess_scale", guess_scale, 0.0, lo_open=True)
    settings_arg(settings)
    if progress is not None and not callable(progress):
        raise InputError(f"progress = {_show(progress)} must be callable or None")
    if threads is not None:
        integer("threads", threads, 1)
    return members.astype(np.int64)
