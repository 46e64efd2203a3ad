"""Figure 5: the Figure 2 flow across friction, time step and slope.

The flow is Figure 2's (:mod:`ncd.shared.slope`).  The design is one factor at a time
around Figure 2's settings (:func:`settings_table`); every setting of a seed is released
from the same deposit (:func:`deposit_dataset`), so the settings of a seed differ in their
one parameter only.  Each flow is scanned at the same times whatever ``h``
(:func:`scan_step`) by zero-guess and warm-start NLGS runs; per scan, the distinct
solutions of the converged runs, the largest spread of a grain's acceleration and, when
there are several solutions, the measures of :mod:`ncd.figures.fig5_governing.line`.
"""
import numpy as np
import xarray as xr

from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.explore import explore
from ncd.dynamics.stepper import prepare_step, step
from ncd.figures.fig5_governing.line import line_analysis
from ncd.io.netcdf import provenance
from ncd.shared import slope
from ncd.shared.slope_analysis import solutions
from ncd.shared.step_solutions import StepSolutions
from ncd.solver.settings import SolverSettings

FACTORS = ("base", "mu", "h", "slope")
SCAN_VARS = {
    "scan_step": ("1", "flow step scanned (the step from this state)"),
    "n_contacts": ("1", "contacts of the scanned step"),
    "mean_vx": ("m s-1", "mean velocity of the discs along the slope"),
    "converged_zero": ("1", "converged zero-guess runs"),
    "converged_warm": ("1", "converged warm-start runs"),
    "sweeps_median": ("1", "median NLGS sweeps of the runs"),
    "n_solutions": ("1", "distinct solutions of the converged runs (both inits)"),
    "n_solutions_zero": ("1", "distinct solutions of the converged zero-guess runs"),
    "n_solutions_warm": ("1", "distinct solutions of the converged warm-start runs"),
    "spread": ("1", "largest RMS spread of a grain's acceleration over the converged runs / |g|"),
    "visible": ("1", "grains whose spread exceeds visible |g|"),
    "n_exact": ("1", "distinct end points polished to exact solutions (1 when the runs agree)"),
    "n_unpolished": ("1", "distinct end points the polish did not bring to an exact solution"),
    "indeterminate": ("1", "1: two distinct exact solutions or more; 0: one; -1: unknown (no converged "
                           "run, or end points not polished)"),
}
LINE_VARS = {
    "exact_spread": ("1", "largest distance of a grain's acceleration between exact solutions / |g|"),
    "n_switched": ("1", "contacts whose status differs between the solutions"),
    "n_moving": ("1", "grains whose acceleration differs between the solutions"),
    "n_clusters": ("1", "connected groups of those grains (through contacts active in a solution)"),
    "field_rank": ("1", "independent directions of the solutions' acceleration fields"),
    "cluster_size": ("1", "grains of the chosen grain's cluster (differing grains connected to it)"),
    "cluster_rank": ("1", "independent directions of the solutions over that cluster"),
    "cloud_rank": ("1", "rank of the acceleration cloud of the grain of largest spread (1: a line)"),
    "cloud_major": ("1", "RMS extent of that cloud along its major axis / |g|"),
    "cloud_minor": ("1", "RMS extent of that cloud along its minor axis / |g|"),
    "predicted_line": ("1", "1: the grain's cluster has one degree of freedom (a line predicted)"),
    "hypothesis_holds": ("1", "1: the prediction agrees with the cloud's rank (line or not)"),
    "null_impulse": ("1", "dim of the impulses keeping the first solution's statuses (null K)"),
    "null_velocity": ("1", "dim of the grain velocities keeping the first solution's statuses"),
}


def settings_table(f):
    """The settings of the flow study: arrays ``mu, h, slope_deg, factor`` (index in
    :data:`FACTORS`), the base first, then each extra value of one factor."""
    b = f["base"]
    rows = [(b["mu"], b["h"], b["slope_deg"], 0)]
    for key, factor in (("mu", 1), ("h", 2), ("slope_deg", 3)):
        for v in f[key]:
            if v == b[key]:
                raise InputError(f"flows.{key} repeats the base value {v}: list extra values only")
            rows.append(tuple(v if k == key else b[k] for k in ("mu", "h", "slope_deg")) + (factor,))
    mu, h, sl, fac = (np.array(c) for c in zip(*rows))
    if (mu < 0).any() or (h <= 0).any():
        raise InputError(f"flows: mu = {mu.tolist()} must be >= 0 and h = {h.tolist()} > 0")
    return {"mu": mu.astype(float), "h": h.astype(float), "slope_deg": sl.astype(float),
            "factor": fac.astype(np.int8)}


def deposit_mu(f):
    """The friction coefficient of the deposits: the base's (every setting is released from it)."""
    return float(f["base"]["mu"])


def scan_times(f):
    """Times after release of the scans: ``scan_every, 2 scan_every, ... <= duration``."""
    n = int(np.floor(f["duration"] / f["scan_every"] + 1e-9))
    if n < 1:
        raise InputError(f"flows.duration = {f['duration']} is shorter than scan_every = {f['scan_every']}")
    return f["scan_every"] * np.arange(1, n + 1)


def _scene_cfg(cfg, mu, seed):
    p = dict(cfg["scene"], mu=float(mu))
    p["seed"] = [int(seed), int(cfg["flows"]["root_seed"])]     # default_rng((seed, root))
    return p


def deposit_dataset(cfg, seed, progress=None):
    """Deposit of seed ``seed`` at the base's friction (:func:`deposit_mu`) -> Dataset (dim disc)."""
    mu = deposit_mu(cfg["flows"])
    c = {"scene": _scene_cfg(cfg, mu, seed), "deposit": cfg["deposit"]}
    scene, dep = slope.deposit(c, progress)
    snap = slope.snapshot(scene)
    nm = scene.n_mobile
    v = lambda dims, x, u, ln: (dims, x, {"units": u, "long_name": ln})  # noqa: E731
    ds = xr.Dataset(
        {"pos_x": v("disc", snap["pos"][:, 0], "m", "x of the disc centre"),
         "pos_y": v("disc", snap["pos"][:, 1], "m", "y of the disc centre"),
         "vel_x": v("disc", snap["vel"][:, 0], "m s-1", "x velocity"),
         "vel_y": v("disc", snap["vel"][:, 1], "m s-1", "y velocity"),
         "spin": v("disc", snap["spin"], "s-1", "angular velocity"),
         "angle": v("disc", snap["angle"], "rad", "rotation angle"),
         "radius": v("disc", scene.radius[:nm], "m", "disc radius"),
         "ground_x": v("ground", scene.pos[nm:, 0], "m", "x of a ground disc"),
         "ground_y": v("ground", scene.pos[nm:, 1], "m", "y of a ground disc"),
         "ground_radius": v("ground", scene.radius[nm:], "m", "ground disc radius"),
         "prev_key": v("prev_contact", snap["prev_keys"], "1", "contact key of the last deposit step"),
         "prev_impulse_n": v("prev_contact", snap["prev_impulse"][:, 0], "N s", "normal impulse, last step"),
         "prev_impulse_t": v("prev_contact", snap["prev_impulse"][:, 1], "N s", "tangential impulse, last step")},
        attrs=provenance(c, SolverSettings(**cfg["deposit"]["solver"]), mu=mu, seed=int(seed),
                         deposit_steps=len(dep["sweeps"]), period=float(scene.period), time=float(scene.time)))
    return ds


def scene_of_deposit(dep, cfg, mu, slope_deg):
    """The deposit as a scene released on the slope ``slope_deg`` at friction ``mu``."""
    p = cfg["scene"]
    scene = make_scene(
        np.column_stack([dep.pos_x.values, dep.pos_y.values]), dep.radius.values, p["density"],
        obstacle_pos=np.column_stack([dep.ground_x.values, dep.ground_y.values]),
        obstacle_radius=dep.ground_radius.values,
        gravity=slope.gravity_vector(dict(p, slope_deg=slope_deg), tilted=True), mu=float(mu),
        e_n=p["restitution"], e_t=p["restitution"], period=float(dep.attrs["period"]),
        vel=np.column_stack([dep.vel_x.values, dep.vel_y.values]), spin=dep.spin.values,
        angle=dep.angle.values, overlap_tolerance=cfg["flows"]["overlap_tolerance"])
    scene.time = 0.0
    scene.prev_keys = dep.prev_key.values.astype(np.int64)
    scene.prev_impulse = np.column_stack([dep.prev_impulse_n.values, dep.prev_impulse_t.values])
    return scene


def scan_step(scene, h, sc, members):
    """Zero-guess and warm-start runs of the next step -> (dict of SCAN_VARS and LINE_VARS)."""
    problem = prepare_step(scene, h)
    settings = SolverSettings(tol=sc["tol"], max_sweeps=sc["max_sweeps"], check_every=sc["check_every"],
                              finish=sc["finish"], finish_tol=sc["finish_tol"])
    g = float(np.hypot(*scene.gravity))
    nm = scene.n_mobile
    vi = problem.vel_initial[:nm]
    observe = lambda imp, vel, spin: ((vel[:nm] - vi) / (g * h)).ravel()  # noqa: E731  accelerations / |g|
    out = {"n_contacts": problem.contacts.n, "sweeps": []}
    acc, imp = [], []
    for init in slope.INITS:
        res = explore(scene, problem, members, sc["root_seed"], init=init, settings=settings, observe=observe)
        ok = res["outcome"] > 0
        out[f"converged_{init}"] = int(ok.sum())
        out["sweeps"] += res["sweeps"].tolist()
        a = (res["vel"][ok] - vi[None]) / h
        if ok.any():
            out[f"n_solutions_{init}"] = int(solutions(a.reshape(len(a), -1), sc["threshold"] * g)[0].max() + 1)
        else:
            out[f"n_solutions_{init}"] = 0
        acc.append(a)
        imp.append(res["impulse"][ok])
    out["sweeps_median"] = float(np.median(out.pop("sweeps")))
    acc, imp = np.concatenate(acc), np.concatenate(imp)
    if not len(acc):
        out.update(n_solutions=0, spread=np.nan, visible=0, n_exact=0, n_unpolished=0, indeterminate=-1)
        return out
    labels, reps = solutions(acc.reshape(len(acc), -1), sc["threshold"] * g)
    spread = np.sqrt(acc.var(axis=0).sum(axis=1))
    out.update(n_solutions=len(reps), spread=float(spread.max() / g),
               visible=int((spread > sc["visible"] * g).sum()), n_exact=1, n_unpolished=0, indeterminate=0)
    if len(reps) > 1:
        out.update(_exact_solutions(scene, problem, acc, imp, reps, spread, sc, g))
    return out


def _exact_solutions(scene, problem, acc, imp, reps, spread, sc, g):
    """Polish each distinct end point on its statuses
    (:class:`ncd.shared.step_solutions.StepSolutions`) to a natural-map residual ``<= polish_tol``;
    the polished ones still distinct are exact solutions (``n_exact``); with two or more, the
    measures of :mod:`ncd.figures.fig5_governing.line`."""

    st = StepSolutions(scene, problem)
    sols, status, failed = [], [], 0
    for r in reps:
        s, res = st.polish(imp[r], tol=sc["polish_tol"])
        failed += res > sc["polish_tol"]
        if res <= sc["polish_tol"]:
            a = st.accel(s)
            if all(np.abs(a - b).max() > sc["threshold"] * g for b in sols):
                sols.append(a)
                status.append(st.status(s))
    # two exact solutions: indeterminate; one, every end point polished: determinate
    # (the NLGS end points differed by iteration error); otherwise unknown
    out = {"n_exact": len(sols), "n_unpolished": failed,
           "indeterminate": 1 if len(sols) > 1 else (0 if failed == 0 else -1)}
    if len(sols) < 2:
        return out
    sols = np.array(sols)
    out["exact_spread"] = float(np.hypot(*(sols - sols[:1]).transpose(2, 0, 1)).max() / g)
    grain = int(np.argmax(spread))
    line = line_analysis(sols, np.array(status), problem.contacts.body_a, problem.contacts.body_b,
                         acc[:, grain], grain, sc["threshold"] * g, st.W, st.H, problem.contacts.mu)
    line["cloud_major"] /= g
    line["cloud_minor"] /= g
    out.update(line)
    return out


def run_flow(dep, cfg, setting, seed, progress=None):
    """Release the deposit with setting ``setting`` and scan it -> dict of arrays over scans."""
    f = cfg["flows"]
    tab = settings_table(f)
    mu, h, sl = float(tab["mu"][setting]), float(tab["h"][setting]), float(tab["slope_deg"][setting])
    scene = scene_of_deposit(dep, cfg, mu, sl)
    times = scan_times(f)
    steps = np.maximum(1, np.rint(times / h).astype(int))
    flow_settings = SolverSettings(**f["solver"])
    rows = []
    nm = scene.n_mobile
    for k in range(1, steps[-1] + 1):
        if k in steps:
            j = int(np.searchsorted(steps, k))
            members = ((setting * 1000 + seed) * 1000 + j) * 1000 + np.arange(f["scan"]["runs"])
            row = scan_step(scene, h, f["scan"], members)
            row["scan_step"] = k
            row["mean_vx"] = float(slope.mean_velocity(scene)[0])
            rows.append(row)
            if progress is not None:
                progress(j + 1, len(steps), f"step {k}: {row['n_solutions']} solutions, "
                                            f"converged {row['converged_zero']}+{row['converged_warm']}")
        step(scene, h, settings=flow_settings, init="warm")
        if not np.isfinite(scene.vel[:nm]).all():
            raise RuntimeError(f"flow setting {setting} seed {seed} is non-finite at step {k}")
    return {q: np.array([r.get(q, np.nan if q in LINE_VARS else 0) for r in rows], float)
            for q in (*SCAN_VARS, *LINE_VARS)}


def flow_dataset(dep, cfg, setting, seed, progress=None):
    """One flow's scans as a Dataset with dims ``(flow, scan)`` (flow = setting * seeds + seed)."""
    f = cfg["flows"]
    tab = settings_table(f)
    rec = run_flow(dep, cfg, setting, seed, progress)
    var = lambda x, u, ln: (("flow", "scan"), x[None], {"units": u, "long_name": ln})  # noqa: E731
    data = {q: var(rec[q], *SCAN_VARS[q]) for q in SCAN_VARS}
    data.update({q: var(rec[q], *LINE_VARS[q]) for q in LINE_VARS})
    for q in ("scan_step", "n_contacts", "converged_zero", "converged_warm", "n_solutions", "n_solutions_zero",
              "n_solutions_warm", "visible", "n_exact", "n_unpolished",
              "indeterminate"):
        data[q] = (data[q][0], data[q][1].astype(np.int64), data[q][2])
    fl = lambda x, u, ln: ("flow", np.array([x]), {"units": u, "long_name": ln})  # noqa: E731
    data.update(setting=fl(setting, "1", "setting index (settings_table)"),
                seed=fl(seed, "1", "flow seed (deposit radii and grid)"),
                mu=fl(tab["mu"][setting], "1", "friction coefficient"),
                h=fl(tab["h"][setting], "s", "time step"),
                slope_deg=fl(tab["slope_deg"][setting], "degree", "slope angle"),
                factor=fl(tab["factor"][setting], "1", "factor varied from the base"),
                deposit_steps=fl(int(dep.attrs["deposit_steps"]), "1", "steps of the shared deposit"))
    ds = xr.Dataset(data, coords={
        "flow": ("flow", [setting * f["seeds"] + seed], {"units": "1", "long_name": "flow index"}),
        "scan": ("scan", np.arange(len(rec["scan_step"])), {"units": "1", "long_name": "scan index"}),
        "scan_time": ("scan", scan_times(f), {"units": "s", "long_name": "time after release of the scan"})},
        attrs=provenance(cfg, SolverSettings(**f["solver"])))
    ds["factor"].attrs.update(flag_values=np.arange(len(FACTORS), dtype=np.int8), flag_meanings=" ".join(FACTORS))
    ds["indeterminate"].attrs.update(flag_values=np.array([-1, 0, 1]), flag_meanings="unknown determinate "
                                                                                        "indeterminate")
    return ds


__all__ = ["FACTORS", "settings_table", "deposit_mu", "scan_times", "deposit_dataset", "scene_of_deposit",
           "scan_step", "run_flow", "flow_dataset"]
