"""Figure 2 of Moreau (2005), section 3: a grain's acceleration in a flow down a slope.

Polydisperse discs on a rough periodic ground are deposited under gravity normal to the
ground (:func:`deposit`), released down the slope and stepped with warm starts
(:func:`flow`).  The core problem of the investigated step is solved many times by NLGS
with random review orders, from the zero guess and from the previous impulses
(:func:`run_ensemble`, section 2).  Each run goes on from tolerance to tolerance, so that
the spread of the clouds against the tolerance tells a true indeterminacy (a fixed spread)
from the iteration error of runs stopped early (a shrinking one); the measures are in
:mod:`ncd.shared.slope_analysis`.
"""
import time

import numpy as np
import xarray as xr

from ncd.core.scene import make_scene
from ncd.dynamics.explore import explore, member_rng, run_parallel
from ncd.dynamics.stepper import initial_guess, kinetic_energy, prepare_step, solve_problem, step
from ncd.io.netcdf import provenance
from ncd.shared.frames import frame_state, frames_dataset
from ncd.shared.slope_analysis import solutions
from ncd.solver.settings import SolverSettings

INITS = ("zero", "warm")
SCAN_FIELDS = ("solutions", "max_spread", "visible", "converged", "sweeps")


def _settings(cfg):
    return SolverSettings(**cfg)


def gravity_vector(p, tilted=True):
    """Gravity of the slope (ground along x, sloping down to +x), or normal to the ground."""
    g = p["gravity"]
    if not tilted:
        return np.array([0.0, -g])
    th = np.radians(p["slope_deg"])
    return g * np.array([np.sin(th), -np.cos(th)])


def geometry(p):
    """Radii, initial centres, ground discs and period of the scene.

    Diameters uniform in ``[d_min, size_ratio d_min]`` (mean ``diameter``), centres on a
    loose grid just above the ground, a row of touching fixed discs of the mean diameter
    on ``y = 0`` across the period."""
    rng = np.random.default_rng(p["seed"])
    n, d = p["n_discs"], p["diameter"]
    d_min = 2.0 * d / (1.0 + p["size_ratio"])
    radius = 0.5 * rng.uniform(d_min, p["size_ratio"] * d_min, n)
    n_ground = p["width_diameters"]
    period = n_ground * d
    ground = np.column_stack([(np.arange(n_ground) + 0.5) * d, np.zeros(n_ground)])
    cell = (1.0 + p["grid_gap"]) * 2.0 * radius.max()
    ncol = int(period // cell)
    row, col = np.divmod(np.arange(n), ncol)
    x = (col + 0.5) * (period / ncol) + rng.uniform(-0.5, 0.5, n) * (period / ncol - 2 * radius)
    y = 0.5 * d + (row + 0.5) * cell + p["grid_gap"] * d
    return radius, np.column_stack([x, y]), ground, period


def build_scene(p, tilted=False, overlap_tolerance=1e-2):
    """The scene at its initial grid (gravity normal to the ground unless ``tilted``)."""
    radius, pos, ground, period = geometry(p)
    return make_scene(pos, radius, p["density"], obstacle_pos=ground, obstacle_radius=0.5 * p["diameter"],
                      gravity=gravity_vector(p, tilted), mu=p["mu"], e_n=p["restitution"],
                      e_t=p["restitution"], period=period, overlap_tolerance=overlap_tolerance)


def mean_velocity(scene):
    """Mass-weighted mean velocity of the mobile discs."""
    m = scene.mobile_mass
    return (m[:, None] * scene.vel[: scene.n_mobile]).sum(axis=0) / m.sum()


def deposit(cfg, progress=None):
    """Deposit the discs under gravity normal to the ground until the largest
    speed falls below ``rest_speed``; returns ``(scene, series)``."""
    p, dp = cfg["scene"], cfg["deposit"]
    scene = build_scene(p)
    settings = _settings(dp["solver"])
    ke, sweeps, pen = [], [], []
    for k in range(1, dp["max_steps"] + 1):
        rep = step(scene, dp["h"], settings=settings, init="warm")
        ke.append(kinetic_energy(scene))
        sweeps.append(rep.sweeps)
        pen.append(rep.max_penetration)
        vmax = float(np.abs(scene.vel[: scene.n_mobile]).max())
        if progress is not None:
            progress(k, dp["max_steps"], f"contacts {rep.n_contacts}, max speed {vmax:.2e}")
        if vmax < dp["rest_speed"]:
            return scene, {"kinetic_energy": np.array(ke), "sweeps": np.array(sweeps),
                           "max_penetration": np.array(pen)}
    raise RuntimeError(f"the deposit is not at rest after {dp['max_steps']} steps "
                       f"(max speed {vmax:.3g} >= rest_speed {dp['rest_speed']}): raise deposit.max_steps")


def snapshot(scene):
    """The state needed to restart a step: positions, velocities and the
    previous step's contact impulses (warm-start memory)."""
    nm = scene.n_mobile
    keys = np.zeros(0, np.int64) if scene.prev_keys is None else scene.prev_keys
    imp = np.zeros((0, 2)) if scene.prev_impulse is None else scene.prev_impulse
    return {"pos": scene.pos[:nm].copy(), "vel": scene.vel[:nm].copy(), "spin": scene.spin[:nm].copy(),
            "angle": scene.angle[:nm].copy(), "time": scene.time, "prev_keys": keys.copy(),
            "prev_impulse": imp.copy()}


def scan_step(scene, h, sc):
    """A small exploration of the next step: ``sc["runs"]`` zero-guess and as many warm-start runs.

    Per init, over the converged runs only: distinct solutions (fields within
    ``sc["threshold"] |g|``), the largest grain spread and the grains spreading more than
    ``sc["visible"] |g|``; also the converged count (0: nothing known) and median sweeps."""
    problem = prepare_step(scene, h)
    settings = SolverSettings(tol=sc["tol"], max_sweeps=sc["max_sweeps"], check_every=sc["check_every"])
    g = float(np.hypot(*scene.gravity))
    nm = scene.n_mobile
    out = {}
    for init in INITS:
        res = explore(scene, problem, np.arange(sc["runs"]), sc["root_seed"], init=init, settings=settings)
        ok = res["converged"]
        sweeps = int(np.median(res["sweeps"]))
        if not ok.any():
            out[init] = (0, 0.0, 0, 0, sweeps)
            continue
        acc = (res["vel"][ok] - problem.vel_initial[None, :nm]) / h
        spread = np.sqrt(acc.var(axis=0).sum(axis=1))
        labels, _ = solutions(acc.reshape(len(acc), -1), sc["threshold"] * g)
        out[init] = (labels.max() + 1, spread.max(), int((spread > sc["visible"] * g).sum()), int(ok.sum()), sweeps)
    return out


def flow(scene, cfg, progress=None, frames=None):
    """Release (tilt gravity) and step the flow ``flow.n_steps`` steps with warm starts.

    Returns ``(series, state, reference, scan)``: per-step records, the snapshot before step
    ``flow.step``, that step's accelerations as the trajectory computed them, and every
    ``scan.every`` steps a :func:`scan_step`.  A list ``frames`` receives ``(step, frame)``
    every ``flow.snapshot_every`` steps."""
    fp, sc = cfg["flow"], cfg["scan"]
    scan = {k: [] for k in ("scan_step", *(f"{i}_{q}" for i in INITS
                                          for q in SCAN_FIELDS))}
    scene.gravity = gravity_vector(cfg["scene"], tilted=True)
    t0 = scene.time
    settings = _settings(fp["solver"])
    h, nm = fp["h"], scene.n_mobile
    names = ("time", "mean_vx", "mean_vy", "kinetic_energy", "sweeps", "residual", "converged",
             "n_contacts", "max_penetration")
    series = {k: [] for k in names}
    state = reference = None
    for k in range(1, fp["n_steps"] + 1):
        if k == fp["step"]:
            state = snapshot(scene)
            vel_i = scene.vel[:nm].copy()
        if sc["every"] > 0 and k % sc["every"] == 0:
            found = scan_step(scene, h, sc)
            scan["scan_step"].append(k)
            for init in INITS:
                for q, val in zip(SCAN_FIELDS, found[init]):
                    scan[f"{init}_{q}"].append(val)
        rep = step(scene, h, settings=settings, init="warm")
        every = fp.get("snapshot_every", 0)
        if frames is not None and every > 0 and k % every == 0:
            frames.append((k, frame_state(scene, h)))
        if k == fp["step"]:
            reference = (scene.vel[:nm] - vel_i) / h
        v = mean_velocity(scene)
        for name, val in zip(names, (scene.time - t0, v[0], v[1], kinetic_energy(scene), rep.sweeps,
                                     rep.residual, rep.converged, rep.n_contacts, rep.max_penetration)):
            series[name].append(val)
        if progress is not None:
            progress(k, fp["n_steps"], f"mean vx {v[0]:.3g}, sweeps {rep.sweeps}")
    state["time"] -= t0
    return ({k: np.array(v) for k, v in series.items()}, state, reference,
            {k: np.array(v) for k, v in scan.items()})


def trajectory_dataset(cfg, progress=None):
    """Deposit, release, flow: the time series and the state of the investigated step."""
    if cfg["flow"]["step"] > cfg["flow"]["n_steps"]:
        raise ValueError(f"flow.step = {cfg['flow']['step']} exceeds flow.n_steps = {cfg['flow']['n_steps']}")
    scene, dep = deposit(cfg, progress)
    t_release = scene.time
    frames = []
    series, state, reference, scan = flow(scene, cfg, progress, frames)
    nm = scene.n_mobile
    ds = xr.Dataset(
        {
            **{k: ("step", v) for k, v in series.items()},
            **{f"deposit_{k}": ("deposit_step", v) for k, v in dep.items()},
            **{f"scan_{k}": ("scan_step", v) for k, v in scan.items() if k != "scan_step"},
            "pos_x": ("disc", state["pos"][:, 0]), "pos_y": ("disc", state["pos"][:, 1]),
            "vel_x": ("disc", state["vel"][:, 0]), "vel_y": ("disc", state["vel"][:, 1]),
            "spin": ("disc", state["spin"]),
            "angle": ("disc", state["angle"], {"units": "rad", "long_name": "rotation angle of the disc"}),
            "radius": ("disc", scene.radius[:nm]),
            "ground_x": ("ground", scene.pos[nm:, 0]), "ground_y": ("ground", scene.pos[nm:, 1]),
            "ground_radius": ("ground", scene.radius[nm:]),
            "prev_key": ("prev_contact", state["prev_keys"]),
            "prev_impulse_n": ("prev_contact", state["prev_impulse"][:, 0]),
            "prev_impulse_t": ("prev_contact", state["prev_impulse"][:, 1]),
            "reference_accel_x": ("disc", reference[:, 0]),
            "reference_accel_y": ("disc", reference[:, 1]),
        },
        coords={"step": np.arange(1, len(series["time"]) + 1), "disc": np.arange(nm),
                "deposit_step": np.arange(1, len(dep["sweeps"]) + 1),
                "scan_step": scan["scan_step"].astype(np.int64)},
        attrs=provenance(cfg, _settings(cfg["flow"]["solver"]), investigated_step=cfg["flow"]["step"],
                         investigated_time=state["time"], h=cfg["flow"]["h"], period=scene.period,
                         gravity_x=scene.gravity[0], gravity_y=scene.gravity[1], t_release=t_release),
    )
    ds["time"].attrs["description"] = "time since release (end of the step)"
    ds["converged"] = ds["converged"].astype(np.int8)
    if frames:
        ds = ds.merge(frames_dataset([f for _, f in frames], [k for k, _ in frames], t_release))
    return ds


def scene_at_step(traj, cfg):
    """Rebuild the scene before the investigated step, with its warm-start memory."""
    p = cfg["scene"]
    nm = traj.sizes["disc"]
    scene = make_scene(
        np.column_stack([traj.pos_x.values, traj.pos_y.values]), traj.radius.values, p["density"],
        obstacle_pos=np.column_stack([traj.ground_x.values, traj.ground_y.values]),
        obstacle_radius=traj.ground_radius.values, gravity=(traj.attrs["gravity_x"], traj.attrs["gravity_y"]),
        mu=p["mu"], e_n=p["restitution"], e_t=p["restitution"], period=traj.attrs["period"],
        vel=np.column_stack([traj.vel_x.values, traj.vel_y.values]), spin=traj.spin.values,
        angle=traj.angle.values, overlap_tolerance=cfg["flow"]["overlap_tolerance"])
    assert scene.n_mobile == nm
    scene.time = float(traj.attrs["investigated_time"])
    scene.prev_keys = traj.prev_key.values.astype(np.int64)
    scene.prev_impulse = np.column_stack([traj.prev_impulse_n.values, traj.prev_impulse_t.values])
    return scene


def run_member(scene, problem, member, root_seed, init, tolerances, ecfg, local_exact=False):
    """One NLGS run with the random review order of ``member``, continued from
    tolerance to tolerance (each stage restarts from the previous impulses with
    the same order).  Returns per-tolerance accelerations and diagnostics and
    the impulses and statuses at the last tolerance.  ``local_exact``: every stage
    with local exact solves where the residual stalls (:mod:`ncd.solver.local_exact`)."""
    h, nm = problem.h, scene.n_mobile
    out = {"accel": np.zeros((len(tolerances), nm, 2)), "sweeps": np.zeros(len(tolerances), np.int64),
           "residual": np.zeros(len(tolerances)), "converged": np.zeros(len(tolerances), bool),
           "wall_time": np.zeros(len(tolerances))}
    first = SolverSettings(tol=tolerances[0], max_sweeps=ecfg["max_sweeps"], check_every=ecfg["check_every"],
                           local_exact=local_exact)
    res = explore(scene, problem, [member], root_seed, init=init, review="random", settings=first)
    order = member_rng(member, root_seed).permutation(problem.contacts.n)  # the order explore drew
    impulse, vel, spin = res["impulse"][0], res["vel"][0], res["spin"][0]
    sweeps, wall = int(res["sweeps"][0]), float(res["wall_time"][0])
    ok, residual = bool(res["converged"][0]), float(res["residual"][0])
    status = None
    for j, tol in enumerate(tolerances):
        if j > 0:
            budget = ecfg["max_sweeps"] - sweeps
            if ok and budget > 0:
                t0 = time.perf_counter()
                result, v, w = solve_problem(scene, problem, impulse, order,
                                             SolverSettings(tol=tol, max_sweeps=budget,
                                                            check_every=ecfg["check_every"],
                                                            local_exact=local_exact))
                wall += time.perf_counter() - t0
                impulse, vel, spin, residual = result.impulse, v[:nm], w[:nm], result.residual
                sweeps += result.sweeps
                ok = result.converged
                status = result.status
            else:
                ok = False
        out["accel"][j] = (vel - problem.vel_initial[:nm]) / h
        out["sweeps"][j], out["residual"][j], out["converged"][j], out["wall_time"][j] = sweeps, residual, ok, wall
    if status is None:  # a single tolerance: recompute the statuses of the final impulses
        result, _, _ = solve_problem(scene, problem, impulse, order, SolverSettings(tol=1.0, max_sweeps=1))
        status = result.status
    out["impulse"], out["status"] = impulse, status
    out["spin_accel"] = (spin - problem.spin_initial[:nm]) / h
    return out


def run_ensemble(traj, cfg, members, progress=None):
    """Zero-guess and warm-start runs of ``members`` at the investigated step
    (the same review order for both inits of a member): a Dataset with dims
    ``init, tol, run, disc`` and ``init, run, contact``."""
    ecfg = cfg["explore"]
    tolerances = sorted(ecfg["tolerances"], reverse=True)
    scene = scene_at_step(traj, cfg)
    problem = prepare_step(scene, float(traj.attrs["h"]))
    members = np.asarray(members, dtype=np.int64)
    nm, nc, nt, nr = scene.n_mobile, problem.contacts.n, len(tolerances), len(members)
    acc = np.zeros((len(INITS), nt, nr, nm, 2))
    diag = {k: np.zeros((len(INITS), nt, nr), dt) for k, dt in
            (("sweeps", np.int64), ("residual", float), ("converged", np.int8), ("wall_time", float))}
    imp = np.zeros((len(INITS), nr, nc, 2))
    spin_acc = np.zeros((len(INITS), nr, nm))
    status = np.zeros((len(INITS), nr, nc), np.int8)
    total = len(INITS) * nr
    # the warm runs with local exact solves (a fifteenth of plain NLGS's sweeps to 1e-8);
    # the members below plain_check_runs are also run warm by plain NLGS: their distance
    # to the local-exact run says whether both land on the same solution
    local = bool(ecfg["warm_local_exact"])
    checked = np.flatnonzero(members < ecfg["plain_check_runs"]) if local else np.zeros(0, np.int64)
    plain_distance = np.full((nt, nr), np.nan)
    g = float(np.hypot(*scene.gravity))
    for i, init in enumerate(INITS):
        def task(r, i=i, init=init):
            out = run_member(scene, problem, members[r], ecfg["root_seed"], init, tolerances, ecfg,
                             local_exact=local and init == "warm")
            if local and init == "warm" and r in checked:
                plain = run_member(scene, problem, members[r], ecfg["root_seed"], init, tolerances, ecfg)
                plain_distance[:, r] = np.abs(out["accel"] - plain["accel"]).max(axis=(1, 2)) / g
            acc[i, :, r] = out["accel"]
            for k in diag:
                diag[k][i, :, r] = out[k]
            imp[i, r], status[i, r], spin_acc[i, r] = out["impulse"], out["status"], out["spin_accel"]

        def report(done, n, i=i, init=init):
            if progress is not None:
                progress(i * nr + done, total, f"{init} runs done {done}/{n}: sweeps "
                                               f"{diag['sweeps'][i, -1, done - 1]}, residual "
                                               f"{diag['residual'][i, -1, done - 1]:.2e}")
        run_parallel(task, nr, progress=report)
    c = problem.contacts
    warm = initial_guess(scene, problem, "warm")
    ds = xr.Dataset(
        {
            "accel_x": (("init", "tol", "run", "disc"), acc[..., 0]),
            "accel_y": (("init", "tol", "run", "disc"), acc[..., 1]),
            **{k: (("init", "tol", "run"), v) for k, v in diag.items()},
            "spin_accel": (("init", "run", "disc"), spin_acc),
            "impulse_n": (("init", "run", "contact"), imp[..., 0]),
            "impulse_t": (("init", "run", "contact"), imp[..., 1]),
            "status": (("init", "run", "contact"), status),
            "body_a": ("contact", c.body_a), "body_b": ("contact", c.body_b),
            "normal_x": ("contact", c.normal[:, 0]), "normal_y": ("contact", c.normal[:, 1]),
            "contact_mu": ("contact", c.mu),
            "warm_guess_n": ("contact", warm[:, 0]),
            "warm_guess_t": ("contact", warm[:, 1]),
            "warm_plain_distance": (("tol", "run"), plain_distance),
        },
        coords={"init": list(INITS), "tol": tolerances, "run": members, "disc": np.arange(nm),
                "contact": np.arange(nc)},
        attrs=provenance(cfg, root_seed=ecfg["root_seed"], max_sweeps=ecfg["max_sweeps"], warm_local_exact=int(local),
                         check_every=ecfg["check_every"], h=float(traj.attrs["h"]),
                         investigated_step=int(traj.attrs["investigated_step"]),
                         gravity_x=scene.gravity[0], gravity_y=scene.gravity[1]),
    )
    ds["status"].attrs["description"] = "final status per contact: 0 no contact, 1 stick, 2/3 slide, 4 fallback"
    ds["sweeps"].attrs["description"] = "cumulative sweeps of the run when it reached this tolerance"
    ds["warm_plain_distance"].attrs.update(
        units="1", long_name="warm run with local exact solves against plain NLGS",
        description=("largest grain acceleration difference over |g| between the warm run with local exact "
                     "solves and the plain-NLGS warm run of the same member (explore.plain_check_runs "
                     "first members; NaN: not checked)"))
    ds["wall_time"].attrs["description"] = ("cumulative wall time (s) of the run at this tolerance, measured while "
                                            "the rule's other threads ran other members (a measurement)")
    return ds

