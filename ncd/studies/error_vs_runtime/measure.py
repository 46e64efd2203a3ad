"""Work-precision: error against run time, Contact Dynamics (CD) against the soft-contact
baseline (MD, :mod:`ncd.dynamics.md`).

NLGS at one step (Moreau 2005, section 2): on the core problem of one step, each setting
(initial guess, stopping criterion, tolerance) gives a wall time, sweeps, the natural-map
residual and the distance to the limit of the same iteration run to ``reference.tol``.
Time integration: an observable with a known value against wall time, for CD over ``h``
and MD over ``h`` and stiffness: an incline (closed form, sliding or rolling), a settled
heap (wall reaction against the weight) and a slope flow (against a fine CD reference).
"""
import time

import numpy as np
import xarray as xr

from ncd.core.scene import make_scene
from ncd.dynamics.md import MD, MDParams, critical_step, wall_reaction
from ncd.dynamics.stepper import initial_guess, prepare_step, solve_problem, step
from ncd.solver.settings import SolverSettings
from ncd.studies import cases as scenes


# ------------------------------------------------------------------ NLGS at one step
def nlgs_state(name, cfg, h, settings, seed):
    """A state ready for its next step (previous impulses stored for the warm start)."""
    if name == "packing28":
        s = scenes.box(cfg["n"], seed=seed, columns=cfg["columns"])
        scenes.settle(s, h, cfg["settle"], settings, min_duration=0.1)
    elif name == "pile":
        s = scenes.pile(cfg["n_base"], seed=seed)
        scenes.settle(s, h, cfg["settle"], settings, min_duration=0.1)
    elif name == "slope":
        s = scenes.slope(cfg["columns"], cfg["layers"], seed=seed)
        for _ in range(int(round(cfg["flow"] / h))):
            step(s, h, settings=settings)
    else:
        raise ValueError(f"state {name!r} must be packing28, pile or slope")
    return s


def _velocity_error(s, problem, vel, spin, vel_ref, spin_ref):
    nm = s.n_mobile
    d = max(np.abs(vel[:nm] - vel_ref[:nm]).max(),
            np.abs((spin[:nm] - spin_ref[:nm]) * s.radius[:nm]).max())
    return float(d / (np.linalg.norm(s.gravity) * problem.h))


FINISH_HANDOFF = 1e-4     # NLGS tolerance handed to the finishing stage (criterion "finish")
ANDERSON_MEMORY = 20      # criterion "anderson": Anderson-accelerated NLGS (ncd.solver.anderson), residual criterion


def nlgs_work_precision(s, h, tols, inits, criteria, reference, repeats, max_sweeps):
    """All settings on the core problem of the next step of ``s``; a Dataset over ``(init, criterion, tol)``.

    ``"finish"``: NLGS to ``max(tol, FINISH_HANDOFF)``, then :mod:`ncd.solver.finish` to ``tol``;
    ``"anderson"``: Anderson-accelerated NLGS (:mod:`ncd.solver.anderson`, memory
    :data:`ANDERSON_MEMORY`); ``"anderson_local"``: the same with local exact solves where
    it stalls (:mod:`ncd.solver.local_exact`)."""
    problem = prepare_step(s, h)
    guesses = {init: initial_guess(s, problem, init) for init in inits}
    ref_settings = SolverSettings(tol=reference["tol"], max_sweeps=reference["max_sweeps"])
    refs = {init: solve_problem(s, problem, guesses[init], None, ref_settings) for init in inits}
    shape = (len(inits), len(criteria), len(tols))
    out = {k: np.zeros(shape) for k in ("wall_time", "residual", "change", "error_impulse", "error_velocity")}
    out.update(sweeps=np.zeros(shape, np.int64), converged=np.zeros(shape, np.int8))
    for i, init in enumerate(inits):
        s_ref, v_ref, w_ref = refs[init]
        norm = max(np.linalg.norm(s_ref.impulse), 1e-300)
        for j, crit in enumerate(criteria):
            for k, tol in enumerate(tols):
                settings = (SolverSettings(tol=max(tol, FINISH_HANDOFF), max_sweeps=max_sweeps, finish="active_set",
                                           finish_tol=tol) if crit == "finish"
                            else SolverSettings(tol=tol, max_sweeps=max_sweeps, accel="anderson",
                                                accel_memory=ANDERSON_MEMORY, local_exact=crit == "anderson_local")
                            if crit in ("anderson", "anderson_local")
                            else SolverSettings(tol=tol, max_sweeps=max_sweeps, criterion=crit))
                best = np.inf
                for _ in range(repeats):
                    t0 = time.perf_counter()
                    res, vel, spin = solve_problem(s, problem, guesses[init], None, settings)
                    best = min(best, time.perf_counter() - t0)
                out["wall_time"][i, j, k] = best
                out["residual"][i, j, k] = res.residual
                out["change"][i, j, k] = res.change
                out["sweeps"][i, j, k] = res.sweeps
                out["converged"][i, j, k] = res.converged
                out["error_impulse"][i, j, k] = np.linalg.norm(res.impulse - s_ref.impulse) / norm
                out["error_velocity"][i, j, k] = _velocity_error(s, problem, vel, spin, v_ref, w_ref)
    dims = ("init", "criterion", "tol")
    ds = xr.Dataset({k: (dims, v) for k, v in out.items()},
                    coords={"init": list(inits), "criterion": list(criteria), "tol": np.asarray(tols, float)})
    ds["reference_sweeps"] = ("init", [refs[i][0].sweeps for i in inits])
    ds["reference_residual"] = ("init", [refs[i][0].residual for i in inits])
    ds["reference_converged"] = ("init", np.array([refs[i][0].converged for i in inits], np.int8))
    if len(inits) == 2:
        (a, va, wa), (b, vb, wb) = refs[inits[0]], refs[inits[1]]
        ds.attrs["limits_distance_impulse"] = float(np.linalg.norm(a.impulse - b.impulse) /
                                                    max(np.linalg.norm(b.impulse), 1e-300))
        ds.attrs["limits_distance_velocity"] = _velocity_error(s, problem, va, wa, vb, wb)
    ds.attrs.update(n_contacts=int(problem.contacts.n), n_discs=int(s.n_mobile), h=float(h))
    ds["error_velocity"].attrs["description"] = "max |u_f - u_f*| / (|g| h), u_f* the reference of the same init"
    ds["error_impulse"].attrs["description"] = "|s - s*| / |s*|, s* the reference of the same init"
    ds["wall_time"].attrs["description"] = "best of repeats, seconds (a measurement: differs between reruns)"
    return ds


# ------------------------------------------------------------------ time integration
def incline_scene(angle_deg, mu, r=0.01):
    """One disc at rest on a plane, gravity tilted by ``angle_deg``."""
    a = np.radians(angle_deg)
    return make_scene([[0.0, r]], r, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))],
                      gravity=(scenes.G * np.sin(a), -scenes.G * np.cos(a)), mu=mu)


def incline_exact(angle_deg, mu, duration):
    """Distance travelled from rest in ``duration``: slide or roll (closed form)."""
    a = np.radians(angle_deg)
    if mu < np.tan(a) / 3:
        acc = scenes.G * (np.sin(a) - mu * np.cos(a))
    else:
        acc = 2.0 / 3.0 * scenes.G * np.sin(a)
    return 0.5 * acc * duration ** 2


def heap_observables(s, vel_before=None, h=None, md=None):
    """``(R / W - 1, phi)``: CD from the momentum balance of the last step, MD from forces."""
    nm = s.n_mobile
    m = s.mobile_mass
    weight = -np.sum(m) * s.gravity[1]
    if md is not None:
        c, f = md.contact_forces()
        ry = wall_reaction(s, c, f)[1]
    else:
        ry = np.sum(m * (s.vel[:nm, 1] - vel_before[:nm, 1])) / h - np.sum(m) * s.gravity[1]
    width = s.wall_point[2, 0] - s.wall_point[1, 0]
    top = np.max(s.pos[:nm, 1] + s.radius[:nm])
    phi = np.sum(np.pi * s.radius[:nm] ** 2) / (width * top)
    return float(ry / weight - 1.0), float(phi)


def _scene_for(name, cfg, variant, seed):
    if name == "incline":
        return incline_scene(variant["angle"], variant["mu"])
    if name == "heap":
        return scenes.box(cfg["n"], seed=seed, columns=cfg["columns"])
    if name == "slope_flow":
        return scenes.slope(cfg["columns"], cfg["layers"], angle_deg=variant["angle"], seed=seed)
    raise ValueError(f"observable {name!r} must be incline, heap or slope_flow")


def _measure(name, s, vel_before=None, h=None, md=None, x0=None):
    """Observables of a finished run: a dict quantity -> value."""
    if name == "heap":
        reaction, phi = heap_observables(s, vel_before, h, md)
        return {"reaction": reaction, "packing_fraction": phi}
    if name == "slope_flow":
        return {"mean_velocity": float(np.mean(s.vel[: s.n_mobile, 0]))}
    return {"distance": float(s.pos[0, 0] - x0)}


def _run_cd(s, h, duration, settings):
    n = int(round(duration / h))
    t0 = time.perf_counter()
    work = 0
    vel_before = s.vel.copy()
    for _ in range(n):
        vel_before = s.vel.copy()
        rep = step(s, h, settings=settings)
        work += rep.sweeps * rep.n_contacts
    return time.perf_counter() - t0, work, vel_before


def _run_md(s, k_n, k_t_ratio, h, duration, speed_limit):
    md = MD(s, MDParams(k_n=k_n, k_t_ratio=k_t_ratio))
    n = int(round(duration / h))
    t0 = time.perf_counter()
    rep = md.run(h, n, speed_limit)
    return time.perf_counter() - t0, md, rep


def integration_runs(name, cfg, common, seed, log=None):
    """All CD and MD runs of one observable; a Dataset with dimension ``run`` (one row
    per run and quantity)."""
    settings = SolverSettings(**common["solver"])
    rows = []
    if name == "incline":
        variants = [{"mu": mu, "angle": cfg["angle"]} for mu in cfg["mu"]]
    elif name == "slope_flow":
        variants = [{"mu": 0.5, "angle": a} for a in cfg["angle"]]
    else:
        variants = [{"mu": 0.5, "angle": 0.0}]

    def add(method, variant, h, k_factor, k_n, h_crit, wall, work, values, refs, diverged=0, div_step=-1):
        for q, v in values.items():
            ref = refs[q]
            err = abs(v - ref) / abs(ref) if q in ("distance", "mean_velocity") else abs(v - ref)
            rows.append(dict(quantity=q, method=method, mu=variant["mu"], angle=variant["angle"],
                             h=h, k_factor=k_factor, k_n=k_n, h_over_hcrit=h / h_crit if h_crit else 0.0,
                             value=0.0 if diverged else v, reference=ref,
                             error=-1.0 if diverged else err, wall_time=wall, work=work,
                             diverged=diverged, diverged_step=div_step))
            if log is not None:
                log.info("%s %s %s h=%.3g k=%g: %s=%.6g (ref %.6g) err=%.3g wall=%.2fs", name, method,
                         variant, h, k_factor, q, v, ref, rows[-1]["error"], wall)

    for variant in variants:
        base = _scene_for(name, cfg, variant, seed)
        refs = {"distance": incline_exact(cfg["angle"], variant["mu"], cfg["duration"])} if name == "incline" else {}
        _run_cd(base.copy(), cfg["h"][0], 2 * cfg["h"][0], settings)          # compile, load caches
        MD(base.copy(), MDParams(k_n=1.0)).run(1e-6, 2)
        if name == "slope_flow":
            # the reference: CD at h_reference, tight tolerance; its own uncertainty: CD at h_reference / 2
            ref_settings = SolverSettings(**{**common["solver"], "tol": cfg["reference_tol"]})
            for label, h in (("CD_reference", cfg["h_reference"]), ("CD_reference_check", cfg["h_reference"] / 2)):
                s = base.copy()
                wall, work, vb = _run_cd(s, h, cfg["duration"], ref_settings)
                measured = _measure(name, s, vb, h)
                refs = refs or dict(measured)
                add(label, variant, h, 0.0, 0.0, 0.0, wall, work, measured, refs)
        for h in sorted(cfg["h"]):
            s = base.copy()
            wall, work, vb = _run_cd(s, h, cfg["duration"], settings)
            measured = _measure(name, s, vb, h, x0=base.pos[0, 0])
            if name == "heap" and not refs:
                # ground reaction: the weight (exact); packing fraction: the finest CD run
                refs = {"reaction": 0.0, "packing_fraction": measured["packing_fraction"]}
            add("CD", variant, h, 0.0, 0.0, 0.0, wall, work, measured, refs)
        load = base.mobile_mass.sum() * scenes.G * (1.0 if name == "incline" else 2 * 0.01 / _width(base))
        k0 = load / (common["md_overlap"] * 0.01)
        v_scale = max(np.sqrt(2 * scenes.G * np.ptp(base.pos[: base.n_mobile, 1]) + 0.02 * scenes.G),
                      scenes.G * cfg["duration"])
        for c in cfg["md_stiffness"]:
            k_n = c * k0
            h_crit = critical_step(base, k_n)
            for f in cfg["md_h_factors"]:
                s = base.copy()
                h = f * h_crit
                wall, md, rep = _run_md(s, k_n, common["md_k_t_ratio"], h, cfg["duration"],
                                        common["speed_factor"] * v_scale)
                values = {q: 0.0 for q in refs} if rep.diverged else _measure(name, s, md=md, x0=base.pos[0, 0])
                add("MD", variant, h, c, k_n, h_crit, wall, rep.steps * max(md._contacts.n, 1), values, refs,
                    int(rep.diverged), rep.diverged_step)
    data = {k: ("run", np.array([r[k] for r in rows])) for k in rows[0]}
    ds = xr.Dataset(data, coords={"run": np.arange(len(rows))})
    ds["error"].attrs["description"] = ("relative error for distance and mean_velocity, absolute for "
                                        "reaction (R/W - 1) and packing_fraction; -1 if diverged")
    ds["work"].attrs["description"] = "CD: sum of sweeps x contacts; MD: steps x candidate pairs"
    for v in ds.data_vars.values():
        if v.dtype.kind == "f" and not np.all(np.isfinite(v.values)):
            raise ValueError(f"non-finite value in {v.name}")
    return ds


def _width(s):
    return s.period if s.period > 0 else s.wall_point[2, 0] - s.wall_point[1, 0]


def nlgs_table(cfg, log=None):
    """NLGS work-precision of every state of ``cfg["nlgs"]["states"]``, stacked along ``state``."""
    c = cfg["nlgs"]
    settings = SolverSettings(**cfg["solver"])
    parts = []
    for name, state_cfg in c["states"].items():
        t0 = time.perf_counter()
        s = nlgs_state(name, state_cfg, c["h"], settings, cfg["root_seed"])
        ds = nlgs_work_precision(s, c["h"], c["tols"], c["inits"], c["criteria"], c["reference"],
                                 c["repeats"], c["max_sweeps"])
        for key in ("n_contacts", "n_discs", "limits_distance_impulse", "limits_distance_velocity"):
            ds[key] = ds.attrs.pop(key, 0.0)
        parts.append(ds.expand_dims(state=[name]))
        if log is not None:
            log.info("%s: %d discs, %d contacts, reference sweeps %s, %.1f s", name, s.n_mobile,
                     int(ds.n_contacts), ds.reference_sweeps.values, time.perf_counter() - t0)
    return xr.concat(parts, dim="state")


def integration_table(cfg, log=None):
    """Time-integration runs of every observable, concatenated along ``run``."""
    c = cfg["integration"]
    common = {k: v for k, v in c.items() if k != "observables"}
    common["solver"] = cfg["solver"]
    parts = []
    for name, obs_cfg in c["observables"].items():
        ds = integration_runs(name, obs_cfg, common, cfg["root_seed"], log)
        parts.append(ds.assign(observable=("run", [name] * ds.sizes["run"])))
    ds = xr.concat(parts, dim="run")
    return ds.assign_coords(run=np.arange(ds.sizes["run"]))
