"""Figure 1 of Moreau (2005), section 1: a disc B wedged between two fixed discs.

B (radius ``R``) touches two fixed discs (radius ``r``) whose centres lie ``beta`` above
the horizontal through B's centre.  Released at rest, B may fall freely or stay wedged.
Closed form (notebook ``fig1_wedged``): Coulomb ``T <= mu N`` gives
``N >= N_min = m g cos(gamma) / (2 sin(gamma - beta))``, ``gamma = atan(mu)``, so wedging
is possible iff ``gamma > beta``; the lines of action meet at ``(0, y_I(N))``, from
``y_top = R sin(gamma) / cos(gamma - beta)`` at ``N_min`` down towards ``R sin(beta)``.
"""
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.explore import member_rng, shard_members
from ncd.dynamics.stepper import prepare_step, solve_problem, step
from ncd.io.netcdf import provenance
from ncd.solver.settings import SolverSettings

CONTACTS = ("left", "right")
OUTCOMES = "-1: not classified (not converged, or neither falling nor at rest); 0: falls; 1: wedged"


@dataclass(frozen=True)
class Wedge:
    """The scene of figure 1 and its closed-form set of wedged force states."""
    radius: float
    obstacle_radius: float
    beta: float          # radians, contact normals below the horizontal
    mu: float
    density: float = 1.0
    g: float = 9.81

    @classmethod
    def from_config(cls, cfg, mu=None):
        w = cls(float(cfg["radius"]), float(cfg["obstacle_radius"]), np.radians(cfg["beta_deg"]),
                float(cfg["mu"] if mu is None else mu), float(cfg["density"]), float(cfg["gravity"]))
        # the obstacles must not overlap each other
        if (w.radius + w.obstacle_radius) * np.cos(w.beta) <= w.obstacle_radius:
            raise InputError(f"beta_deg = {cfg['beta_deg']}: the two obstacles (radius "
                             f"{w.obstacle_radius}) would overlap; decrease beta_deg or obstacle_radius")
        return w

    @property
    def mass(self):
        return self.density * np.pi * self.radius ** 2

    @property
    def weight(self):
        return self.mass * self.g

    @property
    def gamma(self):
        """Friction angle ``atan(mu)``."""
        return float(np.arctan(self.mu))

    @property
    def obstacle_pos(self):
        d = self.radius + self.obstacle_radius
        return np.array([[-d * np.cos(self.beta), d * np.sin(self.beta)],
                         [d * np.cos(self.beta), d * np.sin(self.beta)]])

    @property
    def normals(self):
        c, s = np.cos(self.beta), np.sin(self.beta)
        return np.array([[c, -s], [-c, -s]])

    @property
    def tangents(self):
        n = self.normals
        return np.column_stack([-n[:, 1], n[:, 0]])

    @property
    def contact_points(self):
        return -self.radius * self.normals

    def scene(self):
        return make_scene([[0.0, 0.0]], self.radius, self.density, obstacle_pos=self.obstacle_pos,
                          obstacle_radius=self.obstacle_radius, gravity=(0.0, -self.g), mu=self.mu)

    # ------------------------------------------------------------ closed form
    @property
    def wedging_possible(self):
        """Section 1: B can stay wedged iff the friction angle exceeds beta."""
        return self.gamma > self.beta

    @property
    def n_min(self):
        """Smallest normal force of a wedged state (inf when wedging is impossible)."""
        if not self.wedging_possible:
            return np.inf
        return self.weight * np.cos(self.gamma) / (2.0 * np.sin(self.gamma - self.beta))

    @property
    def segment(self):
        """``(y_bottom, y_top)`` of I; y_top is reached (N = N_min), y_bottom only as N -> inf."""
        yb = self.radius * np.sin(self.beta)
        if not self.wedging_possible:
            return yb, yb
        return yb, self.radius * np.sin(self.gamma) / np.cos(self.gamma - self.beta)

    def forces(self, N):
        """Wedged contact forces ``(force_n, force_t)``, each (..., 2), for ``N >= N_min``."""
        N = np.asarray(N, dtype=float)
        T = (0.5 * self.weight + N * np.sin(self.beta)) / np.cos(self.beta)
        return np.stack([N, N], -1), np.stack([T, -T], -1)

    def y_of_n(self, N):
        s, c, half = np.sin(self.beta), np.cos(self.beta), 0.5 * self.weight
        return self.radius * s + self.radius * c ** 2 * half / (np.asarray(N, dtype=float) + half * s)

    def n_of_y(self, y):
        s, c, half = np.sin(self.beta), np.cos(self.beta), 0.5 * self.weight
        return half * (self.radius * c ** 2 / (np.asarray(y, dtype=float) - self.radius * s) - s)

    def intersection(self, force_n, force_t):
        """Intersection ``(I_x, I_y)`` of the lines of action of the two contact forces
        (arrays (..., 2) of normal and tangential components); NaN if parallel."""
        F = force_n[..., None] * self.normals + force_t[..., None] * self.tangents   # (..., 2, 2)
        P = self.contact_points

        def cross(u, v):
            return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

        den = cross(F[..., 0, :], F[..., 1, :])
        with np.errstate(divide="ignore", invalid="ignore"):
            a = cross(P[1] - P[0], F[..., 1, :]) / den
        I = P[0] + a[..., None] * F[..., 0, :]
        return I[..., 0], I[..., 1]

    def attrs(self):
        yb, yt = self.segment
        o = self.obstacle_pos
        return {"radius": self.radius, "obstacle_radius": self.obstacle_radius, "density": self.density,
                "mass": self.mass, "gravity": self.g, "beta_deg": float(np.degrees(self.beta)),
                "mu": self.mu, "gamma_deg": float(np.degrees(self.gamma)),
                "B_x": 0.0, "B_y": 0.0, "obstacle_x": o[:, 0], "obstacle_y": o[:, 1],
                "threshold_gamma_deg": float(np.degrees(self.beta)),
                "wedging_possible": int(self.wedging_possible),
                "N_min": float(self.n_min) if self.wedging_possible else np.nan,
                "I_y_bottom": yb, "I_y_bottom_reached": 0, "I_y_top": yt, "I_y_top_reached": 1,
                "contacts": "0: left obstacle, 1: right obstacle; normal from obstacle to B, "
                            "t = (-n_y, n_x); forces = impulse / h"}


# ---------------------------------------------------------------- one step
def random_wedge_guess(rng, wedge, h, force_min, force_max):
    """Initial guess (impulses, (2, 2)): per contact a normal force log-uniform in
    ``[force_min, force_max]`` weights, a tangential one uniform in its cone."""
    fn = wedge.weight * np.exp(rng.uniform(np.log(force_min), np.log(force_max), size=2))
    ft = rng.uniform(-1.0, 1.0, size=2) * wedge.mu * fn
    return h * np.column_stack([fn, ft])


def classify(wedge, h, impulse, vel, spin, converged, velocity_tol):
    """Outcome per run: 0 falls (zero impulses, ``u_f = h g``), 1 wedged (``u_f = 0``), -1 else."""
    gh = wedge.g * h
    speed = np.maximum(np.abs(vel).max(-1), np.abs(spin) * wedge.radius) / gh
    fall_dev = np.maximum(np.abs(vel[..., 0]), np.abs(vel[..., 1] + gh)) / gh
    fall_dev = np.maximum(fall_dev, np.abs(spin) * wedge.radius / gh)
    no_impulse = np.abs(impulse).max(axis=(-2, -1)) <= velocity_tol * wedge.mass * gh
    out = np.full(np.shape(converged), -1, np.int8)
    out[converged & no_impulse & (fall_dev <= velocity_tol)] = 0
    out[converged & ~no_impulse & (speed <= velocity_tol)] = 1
    return out


def _runs(wedge, members, root_seed, h, theta, settings, init, ens, progress=None):
    """NLGS runs of the one-step problem from rest; ``init[k]``: True for a random guess."""
    scene = wedge.scene()
    problem = prepare_step(scene, h, theta, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin))
    if problem.contacts.n != 2 or not np.array_equal(problem.contacts.body_b, [1, 2]):
        raise InputError(f"expected 2 contacts (B with each obstacle), found {problem.contacts.n}")
    n = len(members)
    out = {k: np.zeros((n, 2)) for k in ("impulse_n", "impulse_t", "guess_n", "guess_t")}
    out.update(vel=np.zeros((n, 2)), spin=np.zeros(n), first=np.zeros(n, np.int8),
               sweeps=np.zeros(n, np.int64), residual=np.zeros(n), change=np.zeros(n),
               converged=np.zeros(n, bool), wall_time=np.zeros(n))
    solve_problem(scene, problem, None, None, settings)   # warm-up: compiled code, caches
    for k, member in enumerate(members):
        rng = member_rng(member, root_seed)
        guess = (random_wedge_guess(rng, wedge, h, ens["force_min"], ens["force_max"])
                 if init[k] else np.zeros((2, 2)))
        order = rng.permutation(2) if ens["review"] == "random" else np.arange(2)
        t0 = time.perf_counter()
        res, vel, spin = solve_problem(scene, problem, guess, order, settings)
        out["wall_time"][k] = time.perf_counter() - t0
        out["impulse_n"][k], out["impulse_t"][k] = res.impulse[:, 0], res.impulse[:, 1]
        out["guess_n"][k], out["guess_t"][k] = guess[:, 0], guess[:, 1]
        out["vel"][k], out["spin"][k], out["first"][k] = vel[0], spin[0], order[0]
        out["sweeps"][k], out["residual"][k] = res.sweeps, res.residual
        out["change"][k], out["converged"][k] = res.change, res.converged
        if progress is not None:
            progress(k + 1, n)
    return out


def _plain(x):
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    return x.item() if isinstance(x, np.generic) else x


def _provenance_config(cfg):
    """The config section as plain YAML data, without the shard count (which must not
    change the data)."""
    cfg = _plain(cfg)
    cfg["ensemble"].pop("shards", None)
    return cfg


def explore_shard(cfg, shard, n_shards, progress=None):
    """One shard of the exploration ensemble (section 2: random initial guesses, plus
    zero guesses) of the step from rest -> Dataset over its runs."""
    wedge = Wedge.from_config(cfg)
    ens, h = cfg["ensemble"], float(cfg["h"])
    if not ens["force_min"] < ens["force_max"]:
        raise InputError(f"ensemble.force_min = {ens['force_min']} must be < force_max = {ens['force_max']}")
    total = ens["runs"] + ens["zero_runs"]
    members = shard_members(total, shard, n_shards)
    random_init = members < ens["runs"]
    s = SolverSettings(**cfg["solver"])
    o = _runs(wedge, members, cfg["root_seed"], h, cfg["theta"], s, random_init, ens, progress)
    outcome = classify(wedge, h, np.stack([o["impulse_n"], o["impulse_t"]], -1), o["vel"], o["spin"],
                       o["converged"], cfg["velocity_tol"])
    fn, ft = o["impulse_n"] / h, o["impulse_t"] / h
    ix, iy = wedge.intersection(fn, ft)
    wedged = outcome == 1
    ix, iy = np.where(wedged, ix, np.nan), np.where(wedged, iy, np.nan)
    rc = ("run", "contact")
    ds = xr.Dataset(
        {"force_n": (rc, fn, {"units": "N", "long_name": "normal contact force on B"}),
         "force_t": (rc, ft, {"units": "N", "long_name": "tangential contact force on B"}),
         "guess_force_n": (rc, o["guess_n"] / h), "guess_force_t": (rc, o["guess_t"] / h),
         "zero_guess": ("run", (~random_init).astype(np.int8)),
         "first_reviewed": ("run", o["first"], {"long_name": "contact solved first in each sweep"}),
         "vel_x": ("run", o["vel"][:, 0]), "vel_y": ("run", o["vel"][:, 1]), "spin": ("run", o["spin"]),
         "I_x": ("run", ix), "I_y": ("run", iy, {"long_name": "height of I (NaN unless wedged)"}),
         "outcome": ("run", outcome, {"flag_meanings": OUTCOMES}),
         "sweeps": ("run", o["sweeps"]), "residual": ("run", o["residual"]),
         "change": ("run", o["change"]), "converged": ("run", o["converged"].astype(np.int8)),
         "wall_time": ("run", o["wall_time"], {"units": "s"})},
        coords={"run": members, "contact": np.arange(2)},
        attrs={**provenance(_provenance_config(cfg), s, root_seed=cfg["root_seed"]), **wedge.attrs(),
               "h": h, "theta": float(cfg["theta"]), "velocity_tol": float(cfg["velocity_tol"]),
               "runs_random": ens["runs"], "runs_zero": ens["zero_runs"], "review": ens["review"],
               "guess": f"random runs: per contact normal force log-uniform in [{ens['force_min']}, "
                        f"{ens['force_max']}] m g, tangential uniform in the Coulomb cone; "
                        "zero_guess runs: zero impulses",
               "members": "run = ensemble member; rng = numpy.random.default_rng((run, root_seed))"})
    ds["contact"].attrs["names"] = ", ".join(CONTACTS)
    return ds


# ---------------------------------------------------------------- threshold sweep
def threshold_sweep(cfg, progress=None):
    """Fraction of wedged outcomes (random guesses) against the friction angle gamma."""
    sw, ens, h = cfg["sweep"], cfg["ensemble"], float(cfg["h"])
    if not sw["gamma_min_deg"] < sw["gamma_max_deg"]:
        raise InputError(f"sweep.gamma_min_deg = {sw['gamma_min_deg']} must be < gamma_max_deg = {sw['gamma_max_deg']}")
    gammas = np.linspace(sw["gamma_min_deg"], sw["gamma_max_deg"], sw["n_gamma"])
    s = SolverSettings(**cfg["solver"])
    nr = sw["runs"]
    keys = ("outcome", "converged", "sweeps", "residual", "force_n", "wall_time")
    acc = {k: [] for k in keys}
    for j, gdeg in enumerate(gammas):
        wedge = Wedge.from_config(cfg, mu=np.tan(np.radians(gdeg)))
        members = j * nr + np.arange(nr)
        o = _runs(wedge, members, sw["root_seed"], h, cfg["theta"], s, np.ones(nr, bool), ens)
        outcome = classify(wedge, h, np.stack([o["impulse_n"], o["impulse_t"]], -1), o["vel"], o["spin"],
                           o["converged"], cfg["velocity_tol"])
        for k, v in zip(keys, (outcome, o["converged"].astype(np.int8), o["sweeps"], o["residual"],
                               o["impulse_n"][:, 0] / h, o["wall_time"])):
            acc[k].append(v)
        if progress is not None:
            progress(j + 1, len(gammas))
    gr = ("gamma", "run")
    ds = xr.Dataset({k: (gr, np.array(v)) for k, v in acc.items()},
                    coords={"gamma": gammas, "run": np.arange(nr)})
    conv = ds["converged"] == 1
    ds["n_converged"] = conv.sum("run")
    ds["wedged_fraction"] = ((ds["outcome"] == 1) & conv).sum("run") / ds["n_converged"].where(ds["n_converged"] > 0)
    ds["gamma"].attrs["units"] = "degree"
    ds["force_n"].attrs["long_name"] = "normal force at contact 0 (left)"
    ds["outcome"].attrs["flag_meanings"] = OUTCOMES
    ds["wedged_fraction"].attrs["long_name"] = ("fraction of the converged runs that stay wedged (runs that did "
                                                "not converge left out; NaN when none converged)")
    w0 = Wedge.from_config(cfg)
    ds.attrs = {**provenance(_provenance_config(cfg), s, root_seed=sw["root_seed"]), **w0.attrs(), "h": h,
                "members": "member = gamma index * runs + run; rng = default_rng((member, sweep.root_seed))",
                "threshold_gamma_deg": float(np.degrees(w0.beta))}
    return ds


# ---------------------------------------------------------------- evolutions
def evolutions(cfg, progress=None):
    """Two evolutions from the same state at rest: (a) zero initial guess at every
    step (B falls); (b) a wedged closed-form state (``N = wedge_factor N_min``) as the
    first guess, then warm starts (B stays wedged)."""
    wedge = Wedge.from_config(cfg)
    ev, h, theta = cfg["evolution"], float(cfg["h"]), float(cfg["theta"])
    s = SolverSettings(**cfg["solver"])
    n_steps = int(round(ev["duration"] / h))
    if not wedge.wedging_possible:
        raise InputError(f"mu = {wedge.mu}: friction angle {np.degrees(wedge.gamma):.3g} deg <= beta_deg: "
                         "no wedged state exists for evolution (b)")
    fn0, ft0 = wedge.forces(ev["wedge_factor"] * wedge.n_min)
    first = {"zero_guess": "zero", "wedged_warm": h * np.column_stack([fn0, ft0])}
    names = list(first)
    shape = (len(names), n_steps + 1)
    out = {k: np.zeros(shape) for k in ("x", "y", "angle", "vel_y", "residual")}
    out.update(force_n=np.zeros(shape + (2,)), force_t=np.zeros(shape + (2,)),
               n_contacts=np.zeros(shape, np.int64), sweeps=np.zeros(shape, np.int64),
               converged=np.ones(shape, np.int8))
    for e, name in enumerate(names):
        scene = wedge.scene()
        for k in range(n_steps + 1):
            if k > 0:
                init = "zero" if name == "zero_guess" else (first[name] if k == 1 else "warm")
                rep = step(scene, h, theta, s, init=init)
                out["n_contacts"][e, k], out["sweeps"][e, k] = rep.n_contacts, rep.sweeps
                out["residual"][e, k], out["converged"][e, k] = rep.residual, rep.converged
                obstacle = scene.prev_keys % (scene.n_disc + 1024) - 1   # body_b - 1 = contact index
                out["force_n"][e, k, obstacle] = scene.prev_impulse[:, 0] / h
                out["force_t"][e, k, obstacle] = scene.prev_impulse[:, 1] / h
            out["x"][e, k], out["y"][e, k] = scene.pos[0]
            out["angle"][e, k], out["vel_y"][e, k] = scene.angle[0], scene.vel[0, 1]
        if progress is not None:
            progress(e + 1, len(names))
    es, esc = ("evolution", "step"), ("evolution", "step", "contact")
    ds = xr.Dataset({k: (esc if v.ndim == 3 else es, v) for k, v in out.items()},
                    coords={"evolution": names, "step": np.arange(n_steps + 1),
                            "time": ("step", h * np.arange(n_steps + 1)), "contact": np.arange(2)})
    ds["force_n"].attrs = {"units": "N", "long_name": "normal contact force on B (impulse / h of the step ending at time)"}
    ds["force_t"].attrs = {"units": "N", "long_name": "tangential contact force on B"}
    ds["angle"].attrs = {"units": "rad", "long_name": "rotation angle of B"}
    ds.attrs = {**provenance(_provenance_config(cfg), s), **wedge.attrs(), "h": h, "theta": theta,
                "duration": float(ev["duration"]), "wedge_factor": float(ev["wedge_factor"]),
                "initial_force_n": fn0, "initial_force_t": ft0,
                "evolutions": "zero_guess: zero initial guess at every step; wedged_warm: closed-form "
                              "wedged forces as the first guess, then the previous step's impulses"}
    return ds
