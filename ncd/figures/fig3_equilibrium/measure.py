"""Figure 3 of Moreau (2005), section 4: indetermination clouds of 28 discs at rest.

Discs are deposited in a small box (:func:`deposit`) until the warm-started equilibrium
test of section 2 finds ``u_f = 0``; the one-step problem from ``u_i = 0`` on that
packing is then solved many times by NLGS in the three exploration modes of section 2
(:func:`run_ensemble`: zero guess with random orders, random guesses, warm start).  The
exact projections of ``A ∩ C`` (:mod:`ncd.exact.polytope`) and a uniform sample of it are
the references the clouds are measured against (:func:`cloud_measures`).
"""
from dataclasses import replace

import numpy as np
import xarray as xr

from ncd.core.contacts import external_load, h_matrix, match_warm
from ncd.core.scene import make_scene
from ncd.dynamics.explore import explore, member_rng, shard_members
from ncd.dynamics.stepper import equilibrium_test, step
from ncd.exact.polygon import boundary_distance, hull_area
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.figures.fig3_equilibrium.packing import rest_problem
from ncd.io.netcdf import provenance
from ncd.solver.convergence import MAX_SPEED_ATTRS, REST, outcome_attrs
from ncd.solver.settings import SolverSettings

MODES = ("zero", "random", "warm")


def _settings(cfg):
    return SolverSettings(**cfg["solver"])


def container(p):
    """Floor ``y = 0`` and walls ``x = 0``, ``x = width`` as ``(point, inward normal)``."""
    w = p["width"]
    return [((0.0, 0.0), (0.0, 1.0)), ((0.0, 0.0), (1.0, 0.0)), ((w, 0.0), (-1.0, 0.0))]


def initial_packing(p):
    """Radii uniform in ``mean (1 ± spread)``; centres on a loose grid above the floor
    (cells of 2.1 largest radii, rows filled left to right) with a small x jitter."""
    rng = member_rng(0, p["seed"])
    n = p["n_discs"]
    radius = p["radius_mean"] * rng.uniform(1 - p["radius_spread"], 1 + p["radius_spread"], n)
    cell = 2.1 * radius.max()
    ncol = int(p["width"] // cell)
    if ncol < 1:
        raise ValueError(f"width = {p['width']} holds no disc of diameter {2 * radius.max():.3g}")
    row, col = np.divmod(np.arange(n), ncol)
    jitter = rng.uniform(-1.0, 1.0, n) * 0.5 * (cell - 2 * radius)
    pos = np.column_stack([(col + 0.5) * cell + jitter, (row + 0.5) * cell])
    return pos, radius


def deposit(cfg, progress=None):
    """Deposit the discs and step until they are at rest.

    Every ``check_every`` steps the warm-started test of section 2 runs; deposition stops when
    it finds ``u_f = 0`` and the discs themselves move slower than ``speed_tol`` (a disc still
    rolling over an equilibrium position would pass the test alone).  Returns ``(scene, info)``."""
    p = cfg["packing"]
    pos, radius = initial_packing(p)
    scene = make_scene(pos, radius, p["density"], walls=container(p), gravity=p["gravity"], mu=p["mu"])
    settings = _settings(cfg)
    h = p["h"]
    max_pen = 0.0
    g = float(np.linalg.norm(scene.gravity))
    nm = scene.n_mobile
    for k in range(1, p["max_steps"] + 1):
        report = step(scene, h, settings=settings, init="warm")
        max_pen = max(max_pen, report.max_penetration)
        if k % p["check_every"] == 0:
            speed = max(np.abs(scene.vel[:nm]).max(), np.abs(scene.spin[:nm] * scene.radius[:nm]).max()) / (g * h)
            eq = equilibrium_test(scene, h, settings, init="warm", velocity_tol=p["velocity_tol"])
            if progress is not None:
                progress(k, p["max_steps"], f"contacts {eq.contacts.n}, speed {speed:.2e} g h, "
                         f"test |u_f| {eq.max_velocity:.2e} g h")
            if eq.at_rest and speed <= p["speed_tol"]:
                return scene, {"steps": k, "time": scene.time, "speed": float(speed), "max_velocity": eq.max_velocity,
                               "max_penetration": max_pen}
    raise RuntimeError(f"the packing is not at rest after {p['max_steps']} steps "
                       f"(speed {speed:.3g} |g| h, test |u_f| = {eq.max_velocity:.3g} |g| h): "
                       "raise packing.max_steps")


def state_dataset(scene, info, cfg):
    """The packing at rest, its contacts, the warm guess and the at-rest forces -> Dataset."""
    p = cfg["packing"]
    h = p["h"]
    problem = rest_problem(scene, h)
    c = problem.contacts
    warm = match_warm(c, scene.prev_keys, scene.prev_impulse)
    eq = equilibrium_test(scene, h, _settings(cfg), init="warm", velocity_tol=p["velocity_tol"])
    nm = scene.n_mobile
    walls = container(p)
    ds = xr.Dataset(
        {"x": ("disc", scene.pos[:nm, 0]), "y": ("disc", scene.pos[:nm, 1]),
         "radius": ("disc", scene.radius[:nm]), "mass": ("disc", scene.mass[:nm]),
         "body_a": ("contact", c.body_a), "body_b": ("contact", c.body_b),
         "normal_x": ("contact", c.normal[:, 0]), "normal_y": ("contact", c.normal[:, 1]),
         "point_x": ("contact", c.point[:, 0]), "point_y": ("contact", c.point[:, 1]),
         "gap": ("contact", c.gap), "mu": ("contact", c.mu), "key": ("contact", c.key),
         "warm_impulse_n": ("contact", warm[:, 0]), "warm_impulse_t": ("contact", warm[:, 1]),
         "rest_force_n": ("contact", eq.forces[:, 0]), "rest_force_t": ("contact", eq.forces[:, 1]),
         "wall_point_x": ("wall", [w[0][0] for w in walls]), "wall_point_y": ("wall", [w[0][1] for w in walls]),
         "wall_normal_x": ("wall", [w[1][0] for w in walls]), "wall_normal_y": ("wall", [w[1][1] for w in walls])},
        coords={"disc": np.arange(nm), "contact": np.arange(c.n), "wall": np.arange(len(walls))},
        attrs=provenance(cfg, _settings(cfg), h=h, gravity=np.asarray(p["gravity"], float),
                         density=p["density"], mu=p["mu"], width=p["width"], at_rest=eq.at_rest,
                         rest_max_velocity=eq.max_velocity, rest_sweeps=eq.result.sweeps,
                         n_contacts=c.n, n_wall_contacts=int((c.body_b < 0).sum()),
                         max_penetration=problem.max_penetration,
                         **{f"deposit_{k}": v for k, v in info.items()}))
    ds["body_b"].attrs["description"] = "disc index, or -1 - wall index (0 floor, 1 left, 2 right)"
    ds["normal_x"].attrs["description"] = "contact normal from body b to disc a; tangent t = (-n_y, n_x)"
    ds["warm_impulse_n"].attrs["description"] = "impulse s of the last deposition step (the warm guess)"
    ds["rest_force_n"].attrs["description"] = "forces r = s/h of the warm equilibrium test"
    return ds


def scene_from_state(state):
    """Rebuild the scene at rest (warm-start memory included) and its rest problem.

    Raises if the contacts found again differ from those stored.
    """
    walls = [((float(state.wall_point_x[k]), float(state.wall_point_y[k])),
              (float(state.wall_normal_x[k]), float(state.wall_normal_y[k]))) for k in state.wall.values]
    scene = make_scene(np.column_stack([state.x.values, state.y.values]), state.radius.values,
                       state.attrs["density"], walls=walls, gravity=state.attrs["gravity"],
                       mu=state.attrs["mu"], overlap_tolerance=1.0)
    problem = rest_problem(scene, state.attrs["h"])
    if not np.array_equal(problem.contacts.key, state.key.values):
        raise ValueError("the contacts of the rebuilt packing differ from those of state.nc")
    scene.prev_keys = state.key.values.copy()
    scene.prev_impulse = np.column_stack([state.warm_impulse_n.values, state.warm_impulse_t.values])
    return scene, problem


def mode_runs(cfg, mode):
    """Global run indices of a mode: zero runs first, then random, then warm."""
    start = 0
    for m in MODES:
        n = cfg["modes"][m]["runs"]
        if m == mode:
            return np.arange(start, start + n)
        start += n
    raise ValueError(f"mode = {mode!r} must be one of {MODES}")


def _mode_args(state, cfg, mode):
    """``explore`` arguments of a mode: init, review and the random-guess range."""
    m = cfg["modes"][mode]
    scale = None
    if mode == "random":    # s_n ~ U[0, guess_factor * largest impulse at rest]
        scale = m["guess_factor"] * state.attrs["h"] * float(np.abs(state.rest_force_n.values).max())
    return {"init": mode, "review": m["review"], "guess_scale": scale}


def run_ensemble(state, cfg, mode, shard, n_shards, progress=None):
    """One shard of the runs of ``mode`` -> Dataset (dims run, contact): forces r = s/h,
    sweeps, residual, converged, wall_time, |u_f| / (|g| h) and the mode of each run."""
    scene, problem = scene_from_state(state)
    runs = mode_runs(cfg, mode)
    members = runs[shard_members(len(runs), shard, n_shards)]
    h = state.attrs["h"]
    # every run finished by the active-set stage (ncd.solver.finish): NLGS at tol leaves grain
    # speeds of ~1e-6 |g| h, the rest bound itself, so the classification rests on an
    # exact solution (residual <= finish_tol) and not on the iteration error
    settings = replace(_settings(cfg), finish="active_set")
    # at rest: |u_f| <= velocity_tol |g| h, the bound of the deposition's equilibrium test
    out = explore(scene, problem, members, cfg["root_seed"], settings=settings, progress=progress,
                  speed_tol=cfg["packing"]["velocity_tol"], **_mode_args(state, cfg, mode))
    g = float(np.linalg.norm(scene.gravity))
    umax = np.maximum(np.abs(out["vel"]).max(axis=(1, 2)),
                      np.abs(out["spin"] * scene.radius[None, :scene.n_mobile]).max(axis=1)) / (g * h)
    ds = xr.Dataset(
        {"force_n": (("run", "contact"), out["impulse"][:, :, 0] / h),
         "force_t": (("run", "contact"), out["impulse"][:, :, 1] / h),
         "sweeps": ("run", out["sweeps"]), "residual": ("run", out["residual"]),
         "change": ("run", out["change"]), "converged": ("run", out["converged"].astype(np.int8)),
         "wall_time": ("run", out["wall_time"]), "max_velocity": ("run", umax),
         "outcome": ("run", out["outcome"], outcome_attrs()),
         "max_speed": ("run", out["max_speed"], dict(MAX_SPEED_ATTRS)),
         "mode": ("run", np.full(len(members), MODES.index(mode), np.int8))},
        coords={"run": members, "contact": np.arange(problem.contacts.n)},
        attrs=provenance(cfg, settings, h=h))
    # a CF flag, not a string: merged string variables keep the first shard's width
    ds["mode"].attrs.update(flag_values=np.arange(len(MODES), dtype=np.int8), flag_meanings=" ".join(MODES),
                            description="exploration mode of the run")
    ds["max_velocity"].attrs["description"] = "max |u_f| (translation and r * spin) / (|g| h)"
    ds["wall_time"].attrs["description"] = ("seconds of the NLGS run, measured while the rule's other threads "
                                            "ran other members (a measurement, not reproducible)")
    return ds


def polytope_of(state):
    """:class:`ncd.exact.polytope.ForcePolytope` of the packing: ``H r + F = 0``, Coulomb sectors."""
    scene, problem = scene_from_state(state)
    return ForcePolytope(h_matrix(scene, problem.contacts), external_load(scene), problem.contacts.mu)


def displayed_contacts(state, area, count):
    """The ``count`` contacts between two mobile discs with the largest polygon areas,
    no two sharing a disc (the paper shows two contacts inside the assembly)."""
    chosen, used = [], set()
    for k in np.argsort(-np.asarray(area), kind="stable"):
        a, b = int(state.body_a[k]), int(state.body_b[k])
        if b >= 0 and a not in used and b not in used and area[k] > 0:
            chosen.append(int(k))
            used.update((a, b))
        if len(chosen) == count:
            break
    return chosen


def projection_dataset(state, cfg, progress=None):
    """Exact projections of ``A ∩ C`` on every contact's force plane -> Dataset."""
    q = cfg["projection"]
    P = polytope_of(state)
    dim_a, dim_moreau = P.dimension()
    bounded = P.is_bounded()
    n = state.sizes["contact"]
    polys = []
    for k in range(n):
        try:
            polys.append(P.project(k, q["n_init"], q["tol"], q["max_lp"]))
        except PolytopeError as err:
            if bounded:
                raise
            polys.append({"vertices": np.zeros((0, 2)), "inner_area": np.nan, "outer_area": np.nan,
                          "n_lp": 0, "exact": False, "error": str(err)})
        if progress is not None:
            progress(k + 1, n)
    nv = max(1, max(len(p["vertices"]) for p in polys))
    vert = np.full((n, nv, 2), np.nan)
    for k, p in enumerate(polys):
        vert[k, :len(p["vertices"])] = p["vertices"]
    area = np.array([p["inner_area"] for p in polys])
    shown = displayed_contacts(state, np.nan_to_num(area), q["display"])
    dim_ac, implicit = (np.nan, np.zeros(3 * n, bool))
    if bounded:
        _, Z, _, _, implicit = P.affine_hull()
        dim_ac = Z.shape[1]
    ds = xr.Dataset(
        {"vertex_n": (("contact", "vertex"), vert[:, :, 0]), "vertex_t": (("contact", "vertex"), vert[:, :, 1]),
         "n_vertices": ("contact", [len(p["vertices"]) for p in polys]),
         "area": ("contact", area), "outer_area": ("contact", [p["outer_area"] for p in polys]),
         "exact": ("contact", np.array([p["exact"] for p in polys], np.int8)),
         "bounded": ("contact", np.array([len(p["vertices"]) > 0 and np.isfinite(p["inner_area"])
                                          for p in polys], np.int8)),
         "n_lp": ("contact", [p["n_lp"] for p in polys]),
         "implicit_zero": ("contact", implicit[2 * n:].astype(np.int8)),
         "implicit_sliding": ("contact", (implicit[:n] | implicit[n:2 * n]).astype(np.int8)),
         "displayed": ("contact", np.isin(np.arange(n), shown).astype(np.int8))},
        coords={"contact": np.arange(n), "vertex": np.arange(nv)},
        attrs=provenance(cfg, None, dimension_A=dim_a, dimension_moreau=dim_moreau,
                         dimension_AC=dim_ac, bounded=bounded, n_discs=state.sizes["disc"],
                         n_contacts=n, force_scale=P.scale, displayed_order=np.array(shown),
                         n_lp_total=P.n_lp))
    ds["vertex_n"].attrs["description"] = "projection vertices (r_n, r_t), counter-clockwise, NaN padded"
    ds["implicit_zero"].attrs["description"] = "r_n = 0 at every point of A ∩ C"
    ds["implicit_sliding"].attrs["description"] = "|r_t| = mu r_n at every point of A ∩ C"
    return ds


def uniform_dataset(state, cfg):
    """Points drawn uniformly from ``A ∩ C`` by hit-and-run -> Dataset (dims sample, contact)."""
    u = cfg["uniform"]
    P = polytope_of(state)
    X, info = P.uniform_samples(lambda k: member_rng(k, u["root_seed"]), u["chains"], u["per_chain"],
                                thin=u["thin"] or None, burn=u["burn"] or None, rounds=u["rounds"])
    n = state.sizes["contact"]
    X = X.reshape(-1, n, 2)
    eq, co = P.violations(X.reshape(len(X), -1))
    return xr.Dataset(
        {"force_n": (("sample", "contact"), X[:, :, 0]), "force_t": (("sample", "contact"), X[:, :, 1]),
         "chain": ("sample", np.repeat(np.arange(u["chains"]), u["per_chain"]))},
        coords={"sample": np.arange(len(X)), "contact": np.arange(n)},
        attrs=provenance(cfg, None, dimension_AC=info["dimension"], rhat_max=info["rhat"],
                         max_equilibrium_residual=float(eq.max()), max_coulomb_violation=float(co.max()),
                         force_scale=P.scale))


def polygon(projection, k):
    """Vertices ``(r_n, r_t)`` of the exact projection on contact ``k``."""
    v = np.column_stack([projection.vertex_n[k].values, projection.vertex_t[k].values])
    return v[np.isfinite(v[:, 0])]


def mode_subset(ensemble, mode):
    """The runs of one exploration mode (``mode`` is a CF flag variable)."""
    return ensemble.isel(run=np.nonzero(ensemble["mode"].values == MODES.index(mode))[0])


def cloud_measures(ensemble, projection, uniform, contacts, band=0.05):
    """Per mode (and the uniform reference) and contact: runs, coverage (cloud hull area /
    polygon area), spread (RMS distance to the cloud mean), and the fraction of points
    within ``band * sqrt(polygon area)`` of the polygon boundary.  A list of dicts."""
    rows = []
    groups = [(m, mode_subset(ensemble, m)) for m in MODES]
    groups.append(("uniform", uniform))
    for k in contacts:
        poly = polygon(projection, k)
        area = float(projection.area[k])
        for name, ds in groups:
            if name != "uniform":       # converged runs at rest only (ncd.solver.convergence)
                rest = ds.outcome.values == REST if "outcome" in ds else ds.converged.values == 1
                ds = ds.isel(run=np.nonzero(rest)[0])
            pts = np.column_stack([ds.force_n.values[:, k], ds.force_t.values[:, k]])
            dist = boundary_distance(pts, poly)
            rows.append({"contact": int(k), "mode": name, "points": len(pts),
                         "coverage": hull_area(pts) / area if area > 0 else np.nan,
                         "spread": float(np.sqrt(((pts - pts.mean(0)) ** 2).sum(1).mean())) if len(pts) else np.nan,
                         "near_boundary": float(np.mean(dist <= band * np.sqrt(area))) if len(pts) else np.nan})
    return rows
