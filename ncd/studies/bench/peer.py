"""ncd side by side with pymunk (Chipmunk2D in C, sequential impulses) on one poured pile.

Both engines get the same scene (a rough ground between two walls, discs drawn once and
released one at a time at rest above the top of the pile, restitution 0, friction ``mu``)
and the same work per step: ``iterations`` Gauss-Seidel sweeps from the previous step's
impulses (``space.iterations`` in Chipmunk; exactly that many NLGS sweeps in ncd).
Chipmunk multiplies the two shapes' friction coefficients, so each gets ``sqrt(mu)``;
its Baumgarte-like position correction, which ncd does not do, is limited by a small
``collision_slop``.  Only the step calls are timed, in the same process.
"""
import time

import numpy as np
import xarray as xr

from ncd.core.detection import disc_pairs
from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.explore import member_rng
from ncd.dynamics.stepper import prepare_step, step
from ncd.io.netcdf import provenance
from ncd.shared.construction import carry_warm
from ncd.solver.settings import SolverSettings

ENGINES = ("ncd", "pymunk")

DEFAULTS = {
    "n_discs": 1000,      # mobile discs poured
    "diameter": 0.01,     # mean diameter d (m); ground discs have diameter d
    "size_ratio": 1.5,    # d_max / d_min (>= 1)
    "density": 1.0,       # kg/m^2 (2-D)
    "gravity": 9.81,      # m/s^2, along -y
    "mu": 0.5,            # Coulomb friction, every pair
    "h": 1.0e-3,          # time step (s) = 0.031 sqrt(d/g)
    "iterations": 10,     # Gauss-Seidel sweeps per step (both engines)
    "drop_every": 64,     # steps between releases
    "settle": 1.0,        # s simulated after the last release
    "ground_width": 60,   # ground length, in mean diameters (>= 2)
    "root_seed": 5,       # the generator default_rng((0, root_seed))
}
INTEGER_KEYS = ("n_discs", "iterations", "drop_every", "ground_width", "root_seed")
JITTER_D = 1e-3           # source x jitter, in mean diameters
SLOP_D = 1e-3             # Chipmunk collision_slop, in mean diameters


def check_cfg(cfg):
    """``DEFAULTS`` updated by ``cfg``; :class:`InputError` names an unknown or bad key."""
    unknown = sorted(set(cfg) - set(DEFAULTS))
    if unknown:
        raise InputError(f"{', '.join(unknown)}: unknown key(s); expected some of {sorted(DEFAULTS)}")
    out = {**DEFAULTS, **cfg}
    bounds = {"root_seed": (0, ">="), "size_ratio": (1, ">="), "ground_width": (2, ">=")}
    for k, v in out.items():
        lo, op = bounds.get(k, (0, ">"))
        integer = k in INTEGER_KEYS
        number = isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool)
        if not (number and np.isfinite(v) and (v >= lo if op == ">=" else v > lo) and (not integer or v == int(v))):
            raise InputError(f"{k} = {v!r} must be {'an integer' if integer else 'a number'} {op} {lo}")
        out[k] = int(v) if integer else float(v)
    return out


def solver_settings(cfg):
    """Exactly ``iterations`` NLGS sweeps (the tolerance is never met)."""
    return SolverSettings(tol=1e-300, max_sweeps=cfg["iterations"], check_every=cfg["iterations"])


def build(cfg):
    """The shared scene: ``dict`` of mobile radii and release jitters (in release order),
    ground disc centres and radii, wall abscissae and ``d_max``."""
    d, s, n = cfg["diameter"], cfg["size_ratio"], cfg["n_discs"]
    rng = member_rng(0, cfg["root_seed"])
    d_min, d_max = 2 * d / (1 + s), 2 * d * s / (1 + s)
    radius = 0.5 * rng.uniform(d_min, d_max, n)
    jitter = JITTER_D * d * rng.uniform(-1.0, 1.0, n)
    w = cfg["ground_width"]
    gx = (np.arange(w) + 0.5 - 0.5 * w) * d
    return {"radius": radius, "jitter": jitter, "d_max": d_max, "x_wall": 0.5 * w * d,
            "ground_pos": np.column_stack([gx, np.zeros(w)]), "ground_radius": np.full(w, 0.5 * d)}


def max_overlap(pos, radius, geo):
    """Largest interpenetration (m) of mobile discs ``pos, radius`` with each other, the
    ground discs and the walls (0 if none)."""
    n = len(radius)
    p = np.vstack([pos, geo["ground_pos"]])
    r = np.concatenate([radius, geo["ground_radius"]])
    a, b, _ = disc_pairs(p, r, n, 0.0)
    worst = 0.0
    if len(a):
        worst = float(np.max(r[a] + r[b] - np.hypot(*(p[a] - p[b]).T)))
    walls = np.maximum(radius - (pos[:, 0] + geo["x_wall"]), radius - (geo["x_wall"] - pos[:, 0]))
    return max(worst, float(walls.max()), 0.0)


def coulomb_violation(fn, ft, mu):
    """``max(0, |f_t| - mu f_n) / (mu f_n)`` over contacts (inf for a loaded contact with
    ``f_n <= 0``; 0 without contacts)."""
    fn, ft = np.asarray(fn, float), np.asarray(ft, float)
    keep = (fn != 0) | (ft != 0)
    fn, ft = fn[keep], ft[keep]
    v = np.where(fn > 0, np.maximum(0.0, np.abs(ft) - mu * fn) / (mu * np.where(fn > 0, fn, 1.0)), np.inf)
    return float(v.max(initial=0.0))


class NcdEngine:
    """The pile in ncd: the scene is rebuilt at each release (warm memory carried)."""
    name = "ncd"

    def __init__(self, cfg, geo):
        self.cfg, self.geo, self.scene = cfg, geo, None
        self.settings = solver_settings(cfg)
        x = geo["x_wall"]
        self.walls = [((-x, 0.0), (1.0, 0.0)), ((x, 0.0), (-1.0, 0.0))]
        self.report, self.before = None, None

    def add(self, xy, r):
        old, c = self.scene, self.cfg
        n = 0 if old is None else old.n_mobile

        def grow(name, tail):       # the mobile part of the old state, plus the new disc
            return np.concatenate([getattr(old, name)[:n], tail]) if n else np.asarray(tail, float)

        new = make_scene(grow("pos", [xy]), grow("radius", [r]), c["density"],
                             obstacle_pos=self.geo["ground_pos"], obstacle_radius=self.geo["ground_radius"],
                             walls=self.walls, gravity=(0.0, -c["gravity"]), mu=c["mu"],
                             vel=grow("vel", [[0.0, 0.0]]), spin=grow("spin", [0.0]),
                             angle=grow("angle", [0.0]), overlap_tolerance=np.inf)
        if old is not None:
            new.time = old.time
            carry_warm(old, new)
        self.scene = new

    def step(self, last=False):
        if last:
            self.before = self.scene.copy()
        t0 = time.perf_counter()
        self.report = step(self.scene, self.cfg["h"], settings=self.settings)
        return time.perf_counter() - t0

    def state(self):
        """Positions, radii, masses, moments, velocities and spins of the mobile discs."""
        s, n = self.scene, self.scene.n_mobile
        return s.pos[:n], s.radius[:n], s.mass[:n], 1.0 / s.inv_inertia[:n], s.vel[:n], s.spin[:n]

    def contact_forces(self):
        """Last step: ``(f_n, f_t, on_obstacle, vertical impulse on the mobile disc)``."""
        problem = prepare_step(self.before, self.cfg["h"])
        c, s = problem.contacts, self.scene
        if not np.array_equal(c.key, s.prev_keys):
            raise RuntimeError("the rebuilt last-step contacts differ from the stepped ones")
        imp = s.prev_impulse
        vertical = imp[:, 0] * c.normal[:, 1] + imp[:, 1] * c.normal[:, 0]   # t_y = n_x
        return imp[:, 0], imp[:, 1], (c.body_b >= s.n_mobile) | (c.body_b < 0), vertical

    def extra(self, fn):
        return self.report.n_contacts, self.report.residual


class PymunkEngine:
    """The pile in pymunk: static ground circles and thick wall segments on the space's
    static body, one dynamic body per disc."""
    name = "pymunk"

    def __init__(self, cfg, geo):
        import pymunk
        import pymunk.batch
        self.pm, self.cfg, self.geo = pymunk, cfg, geo
        d, self.fr = cfg["diameter"], np.sqrt(cfg["mu"])
        sp = self.space = pymunk.Space()
        sp.gravity = (0.0, -cfg["gravity"])
        sp.iterations = cfg["iterations"]
        sp.collision_slop = SLOP_D * d
        sb = sp.static_body
        shapes = [pymunk.Circle(sb, r, tuple(p)) for p, r in zip(geo["ground_pos"], geo["ground_radius"])]
        top = 2 * cfg["n_discs"] * geo["d_max"] + 10 * d     # above any release point
        for side in (-1, 1):
            x = side * (geo["x_wall"] + d)
            shapes.append(pymunk.Segment(sb, (x, -d), (x, top), d))
        for sh in shapes:
            sh.friction, sh.elasticity = self.fr, 0.0
        sp.add(*shapes)
        self.bodies, self.index, self.built = [], {}, []   # built: (radius, mass, moment) read back
        self.buf, self.ids = pymunk.batch.Buffer(), None

    def add(self, xy, r):
        m = self.cfg["density"] * np.pi * r ** 2
        body = self.pm.Body(m, 0.5 * m * r ** 2)
        body.position = (float(xy[0]), float(xy[1]))
        shape = self.pm.Circle(body, r)
        shape.friction, shape.elasticity = self.fr, 0.0
        self.space.add(body, shape)
        self.index[body.id] = len(self.bodies)
        self.bodies.append(body)
        self.built.append((shape.radius, body.mass, body.moment))

    def step(self, last=False):
        t0 = time.perf_counter()
        self.space.step(self.cfg["h"])
        return time.perf_counter() - t0

    def state(self):
        b = self.pm.batch
        self.buf.clear()
        fields = b.BodyFields.BODY_ID | b.BodyFields.POSITION | b.BodyFields.VELOCITY | \
            b.BodyFields.ANGULAR_VELOCITY
        b.get_space_bodies(self.space, fields, self.buf)
        ids = np.frombuffer(self.buf.int_buf(), dtype=np.uintp)
        if self.ids is None or not np.array_equal(ids, self.ids):
            self.ids = ids.copy()
            self.rows = np.array([i for i, x in enumerate(ids) if int(x) in self.index])
            self.order = np.argsort([self.index[int(x)] for x in ids[self.rows]])
        f = np.frombuffer(self.buf.float_buf(), dtype=float).reshape(-1, 5)[self.rows[self.order]]
        radius, mass, moment = np.array(self.built).T
        return f[:, :2], radius, mass, moment, f[:, 2:4], f[:, 4]

    def contact_forces(self):
        """Active arbiters of the last step, each once: ``total_impulse`` is the impulse
        on the arbiter's first body, ``normal`` points from it to the second."""
        rows = []

        def visit(arb, i):
            b0, b1 = arb.bodies
            other = b1 if b0 is self.bodies[i] else b0
            static = other.body_type == self.pm.Body.STATIC
            if not static and self.index[other.id] < i:
                return                                   # disc pair seen from its other disc
            j, n = arb.total_impulse, arb.normal
            sign = 1.0 if b0 is self.bodies[i] else -1.0  # impulse on disc i, normal away from it
            jx, jy, nx, ny = sign * j.x, sign * j.y, sign * n.x, sign * n.y
            rows.append((-(jx * nx + jy * ny), jy * nx - jx * ny, static, jy))

        for i, body in enumerate(self.bodies):
            body.each_arbiter(visit, i)
        a = np.array(rows, dtype=float).reshape(-1, 4)
        return a[:, 0], a[:, 1], a[:, 2] > 0, a[:, 3]

    def extra(self, fn):
        return len(fn), np.nan


def run(engine, cfg, geo, log=None, log_every=10.0):
    """Pour and settle with ``engine``; returns a dict of measures."""
    h, every, n = cfg["h"], cfg["drop_every"], cfg["n_discs"]
    d, g = cfg["diameter"], cfg["gravity"]
    n_steps = (n - 1) * every + int(round(cfg["settle"] / h))
    walls, worst, released = [], 0.0, 0
    top = float(geo["ground_radius"].max())
    last_log = time.perf_counter()
    for k in range(n_steps):
        if released < n and k % every == 0:
            engine.add((geo["jitter"][released], top + geo["d_max"]), geo["radius"][released])
            released += 1
        walls.append(engine.step(last=k == n_steps - 1))
        pos, radius = engine.state()[:2]
        worst = max(worst, max_overlap(pos, radius, geo))
        top = max(float(geo["ground_radius"].max()), float(np.max(pos[:, 1] + radius)))
        if log is not None and time.perf_counter() - last_log > log_every:
            last_log = time.perf_counter()
            log.info("%s: step %d/%d, %d discs, %.2f ms/step, max overlap %.2e d", engine.name, k + 1,
                     n_steps, released, 1e3 * np.mean(walls), worst / d)
    pos, radius, mass, moment, vel, spin = engine.state()
    fn, ft, on_ground, vertical = engine.contact_forces()
    weight = mass.sum() * g
    ke = 0.5 * np.sum(mass * np.sum(vel ** 2, axis=1)) + 0.5 * np.sum(moment * spin ** 2)
    n_contacts, residual = engine.extra(fn)
    x = geo["x_wall"]
    return {
        "n_steps": n_steps, "time_mean": float(np.mean(walls)), "time_median": float(np.median(walls)),
        "time_settle": float(np.median(walls[(n - 1) * every:])), "time_total": float(np.sum(walls)),
        "n_contacts": n_contacts, "n_loaded": int(np.sum(fn > 0)),
        "overlap_max": worst / d, "overlap_end": max_overlap(pos, radius, geo) / d,
        "ground_reaction": float(vertical[on_ground].sum() / h / weight),
        "coulomb_violation": coulomb_violation(fn, ft, cfg["mu"]),
        "kinetic_energy": float(ke / (np.sum(mass) * g * d)),
        "pile_height": float((np.max(pos[:, 1] + radius) - geo["ground_radius"].max()) / d),
        "n_on_ground": int(np.sum((np.abs(pos[:, 0]) < x) & (pos[:, 1] > 0))),
        "residual": residual,
        "x": pos[:, 0].copy(), "y": pos[:, 1].copy(), "mass": mass.copy(), "moment": moment.copy(),
        "radius_built": radius.copy(),
    }


VARIABLES = {   # name: (units, long_name)
    "n_steps": ("1", "time steps"),
    "time_mean": ("s", "mean wall time of one step call"),
    "time_median": ("s", "median wall time of one step call"),
    "time_settle": ("s", "median wall time of one step call after the last release (all discs)"),
    "time_total": ("s", "wall time of all step calls"),
    "n_contacts": ("1", "contacts of the last step"),
    "n_loaded": ("1", "contacts of the last step with a positive normal impulse"),
    "overlap_max": ("d", "largest interpenetration after any step, over the mean diameter"),
    "overlap_end": ("d", "largest interpenetration at the end, over the mean diameter"),
    "ground_reaction": ("1", "vertical impulse of ground and walls in the last step / h / weight"),
    "coulomb_violation": ("1", "max over last-step contacts of max(0, |f_t| - mu f_n) / (mu f_n)"),
    "kinetic_energy": ("1", "final kinetic energy / sum(m g d)"),
    "pile_height": ("d", "highest disc point above the ground top, over the mean diameter"),
    "n_on_ground": ("1", "discs above the ground between the walls at the end"),
    "residual": ("1", "natural-map residual of the last step (ncd only)"),
}


def compare(cfg, log=None):
    """Pour the same pile with ncd and pymunk; returns an :class:`xarray.Dataset`.

    ``cfg`` keys as :data:`DEFAULTS` (missing keys take the default; unknown keys or bad
    values raise :class:`InputError`).  Variables along ``engine = ["ncd", "pymunk"]``:
    :data:`VARIABLES`, and per disc ``x, y``, ``mass, moment, radius_built`` read back from
    each engine and ``radius`` as drawn.  ``log``: a :class:`logging.Logger` for progress."""
    import pymunk
    cfg = check_cfg(cfg)
    geo = build(cfg)
    tiny = {**cfg, "n_discs": 2, "drop_every": 1, "settle": 2 * cfg["h"]}
    out = {}
    for cls in (NcdEngine, PymunkEngine):
        run(cls(tiny, build(tiny)), tiny, build(tiny))    # warm-up: numba cache loads, first calls
        out[cls.name] = run(cls(cfg, geo), cfg, geo, log)
    data = {k: ("engine", np.array([out[e][k] for e in ENGINES]), {"units": u, "long_name": ln})
            for k, (u, ln) in VARIABLES.items()}
    for k, u, ln in (("x", "m", "final abscissa"), ("y", "m", "final height"), ("mass", "kg", "mass as built"),
                     ("moment", "kg m2", "moment of inertia as built"), ("radius_built", "m", "radius as built")):
        data[k] = (("engine", "disc"), np.array([out[e][k] for e in ENGINES]), {"units": u, "long_name": ln})
    data["radius"] = ("disc", geo["radius"], {"units": "m", "long_name": "radius (release order)"})
    return xr.Dataset(
        data, coords={"engine": list(ENGINES), "disc": np.arange(cfg["n_discs"])},
        attrs=provenance(cfg, solver_settings(cfg), pymunk_version=pymunk.version,
                         chipmunk_version=pymunk.chipmunk_version,
                         collision_slop=SLOP_D * cfg["diameter"],
                         collision_bias=float(pymunk.Space().collision_bias),
                         source_jitter_d=JITTER_D, weight=float(np.sum(out["ncd"]["mass"]) * cfg["gravity"])))
