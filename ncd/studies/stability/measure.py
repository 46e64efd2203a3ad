"""Stability of Contact Dynamics (CD) and of the soft-contact baseline (MD) on stiff and
extreme cases (Moreau 2005, section 2: the implicit CD step "secures numerical stability,
allowing one to use considerably larger step-lengths than in MD methods").

Each small case (:mod:`ncd.studies.cases`) runs by CD at every ``h`` of its list and by
MD at ``h = f h_crit``, ``h_crit = 2 sqrt(m_min / k_n)``, with ``k_n`` chosen for an overlap
of ``md_overlap`` radii under the case's load.  Per run: energy drift and growth, largest
interpenetration, NLGS sweeps, divergence; ``stable`` = not diverged and growth within
``energy_tolerance``.
"""
import time

import numpy as np
import xarray as xr

from ncd.core.errors import SimulationError
from ncd.core.scene import make_scene
from ncd.dynamics.md import MD, MDParams, critical_step, potential_energy
from ncd.dynamics.stepper import kinetic_energy, prepare_step, step
from ncd.solver.settings import SolverSettings
from ncd.studies import cases as scenes

KINDS = ("stack", "box", "chain", "impact_wall", "impact_disc", "hexagonal")


def build(kind, p, seed=0):
    """Scene of a case and its scales ``(scene, info)``; ``p`` the case's parameters."""
    r = 0.01
    if kind == "stack":
        s = scenes.stack(p["mass_ratio"], r)
        load = s.mobile_mass.sum() * scenes.G
    elif kind == "box":
        s = scenes.box(p["n"], mu=p.get("mu", 0.5), e=p.get("e", 0.0), seed=seed, r=r)
        width = s.wall_point[2, 0]
        load = s.mobile_mass.sum() * scenes.G * 2 * r / width
    elif kind == "hexagonal":
        s = scenes.hexagonal(p["rows"], p["columns"], r, mu=p.get("mu", 0.5))
        load = s.mobile_mass.sum() * scenes.G / p["columns"]
    elif kind == "chain":
        s = scenes.chain(p["n"], p["speed"], e=p.get("e", 1.0), r=r)
    elif kind == "impact_wall":
        s = scenes.impact_wall(p["speed"], r)
    elif kind == "impact_disc":
        s = scenes.impact_disc(p["speed"], r)
    else:
        raise ValueError(f"kind = {kind!r} must be one of {KINDS}")
    nm = s.n_mobile
    m_min = s.mobile_mass.min()
    speed = float(np.abs(s.vel[:nm]).max())
    overlap = p["md_overlap"] * r
    if kind in ("chain", "impact_wall", "impact_disc"):
        m_eff = m_min if kind == "impact_wall" else 0.5 * m_min
        k_n = m_eff * speed ** 2 / overlap ** 2
    else:
        k_n = load / overlap
    g = np.linalg.norm(s.gravity)
    height = np.ptp(s.pos[:nm, 1]) + 2 * r
    info = dict(k_n=k_n, h_crit=critical_step(s, k_n), r_min=s.radius[:nm].min(),
                e_scale=kinetic_energy(s) + s.mobile_mass.sum() * g * 2 * s.radius[:nm].mean(),
                v_scale=max(speed, np.sqrt(2 * g * height)))
    return s, info


OBSERVABLE_LABEL = ("value of the case's observable: largest displacement / r (stack, hexagonal), final "
                    "E_kin / (M g d) (box), last disc's speed / striker's speed (chain), tunnelled 0 or 1 (impacts)")


def observable(kind, s0, s):
    """The case's observable and its reference value (``s0`` the initial scene).

    stack, hexagonal: largest displacement / r (ref 0); box: E_kin / (M g d) at the end
    (ref 0, settled); chain: speed of the last disc / striker speed (ref 1, Newton's
    cradle with sequential binary collisions); impacts: tunnelled (ref 0).
    """
    nm = s.n_mobile
    r = s.radius[:nm].min()
    if kind in ("stack", "hexagonal"):
        return float(np.abs(s.pos[:nm] - s0.pos[:nm]).max() / r), 0.0
    if kind == "box":
        return kinetic_energy(s) / (s.mobile_mass.sum() * scenes.G * 2 * r), 0.0
    if kind == "chain":
        return float(s.vel[nm - 1, 0] / s0.vel[0, 0]), 1.0
    return float(tunnelled(kind, s0, s)), 0.0


def tunnelled(kind, s0, s):
    """Did a disc pass through a wall (its centre behind the wall line) or through the
    other disc (their order along x reversed)?"""
    if kind == "impact_wall":
        return bool(s.pos[0, 0] < s.wall_point[0, 0])
    if kind == "impact_disc":
        return bool((s.pos[0, 0] - s.pos[1, 0]) * (s0.pos[0, 0] - s0.pos[1, 0]) < 0)
    return False


def _energy(s, md=None):
    e = kinetic_energy(s) + potential_energy(s)
    return e + (md.elastic_energy() if md is not None else 0.0)


def run_cd(s, h, n_steps, settings, speed_limit, n_trace, gap_tolerance=None):
    """Contact Dynamics run; returns a dict of diagnostics and the energy trace."""
    e0 = _energy(s)
    every = max(1, n_steps // n_trace)
    trace, sweeps, res, pen, unconv = [], [], 0.0, 0.0, 0
    out = dict(diverged=0, diverged_step=-1, nan=0)
    for k in range(n_steps):
        try:
            rep = step(s, h, settings=settings, speed_limit=speed_limit, gap_tolerance=gap_tolerance)
        except SimulationError as err:
            out.update(diverged=1, diverged_step=k + 1, nan=int("non-finite" in str(err)))
            break
        sweeps.append(rep.sweeps)
        res = max(res, rep.residual)
        pen = max(pen, rep.max_penetration)
        unconv += not rep.converged
        if (k + 1) % every == 0:
            trace.append(_energy(s))
    out.update(e0=e0, e_end=_energy(s), trace=np.array(trace), max_penetration=pen,
               sweeps_mean=float(np.mean(sweeps)) if sweeps else 0.0,
               sweeps_max=int(np.max(sweeps)) if sweeps else 0, residual_max=res,
               unconverged_steps=unconv)
    return out


def run_md(s, params, h, n_steps, speed_limit, n_trace):
    """Soft-contact run (:class:`ncd.dynamics.md.MD`); same diagnostics as :func:`run_cd`."""
    md = MD(s, params)
    e0 = _energy(s, md)
    every = max(1, n_steps // n_trace)
    trace, ov = [], 0.0
    out = dict(diverged=0, diverged_step=-1, nan=0)
    last = s.copy()
    done = 0
    while done < n_steps:
        k = min(every, n_steps - done)
        rep = md.run(h, k, speed_limit)
        ov = max(ov, rep.max_overlap)
        if rep.diverged:
            finite = all(np.all(np.isfinite(a)) for a in (s.pos, s.vel, s.spin))
            out.update(diverged=1, diverged_step=rep.diverged_step, nan=int(not finite))
            s.pos, s.vel, s.spin = last.pos, last.vel, last.spin   # report the last finite state
            break
        done += k
        last = s.copy()
        trace.append(_energy(s, md))
    e_end = trace[-1] if trace else e0
    out.update(e0=e0, e_end=e_end, trace=np.array(trace), max_penetration=ov * s.radius[: s.n_mobile].min(),
               sweeps_mean=-1.0, sweeps_max=-1, residual_max=-1.0, unconverged_steps=-1)
    return out, md


def run_case(name, cfg, common, log=None):
    """All runs of one case: an :class:`xarray.Dataset` with dimension ``run``."""
    kind, seed = cfg["kind"], common["root_seed"]
    s_ref, info = build(kind, {"md_overlap": common["md_overlap"], **cfg}, seed)
    settings = SolverSettings(**{**common["solver"], **cfg.get("solver", {})})
    gap_tol = cfg["gap_tolerance"] * info["r_min"] if "gap_tolerance" in cfg else None
    speed_limit = common["speed_factor"] * info["v_scale"]
    max_steps = cfg.get("max_steps", common["max_steps"])
    plan = [("CD", h) for h in cfg["h"]] + [("MD", f * info["h_crit"]) for f in cfg["md_h_factors"]]
    n_trace = common["trace_points"]
    rows = []
    for method, h in plan:
        s = s_ref.copy()
        cap = max_steps if method == "CD" else common["md_max_steps"]
        n_steps = int(min(np.ceil(cfg["duration"] / h - 1e-9), cap))
        t0 = time.perf_counter()
        if method == "CD":
            out = run_cd(s, h, n_steps, settings, speed_limit, n_trace, gap_tol)
        else:
            params = MDParams(k_n=info["k_n"], k_t_ratio=common["md_k_t_ratio"])
            out, _ = run_md(s, params, h, n_steps, speed_limit, n_trace)
        wall = time.perf_counter() - t0
        growth = max(0.0, float(np.max(out["trace"], initial=out["e0"])) - out["e0"]) / info["e_scale"]
        obs, obs_ref = observable(kind, s_ref, s)
        rows.append(dict(
            case=name, kind=kind, method=method, restitution=float(s_ref.e_n), h=h, h_over_hcrit=h / info["h_crit"],
            n_steps=n_steps, k_n=info["k_n"], h_crit=info["h_crit"], diverged=out["diverged"],
            diverged_step=out["diverged_step"], nan=out["nan"],
            stable=int(not out["diverged"] and growth <= common["energy_tolerance"]),
            energy_drift=(out["e_end"] - out["e0"]) / info["e_scale"], energy_growth=growth,
            max_penetration=out["max_penetration"] / info["r_min"], sweeps_mean=out["sweeps_mean"],
            sweeps_max=out["sweeps_max"], residual_max=out["residual_max"],
            unconverged_steps=out["unconverged_steps"], tunnelled=int(tunnelled(kind, s_ref, s)),
            observable=obs, observable_ref=obs_ref, wall_time=wall,
            trace=_pad((np.asarray(out["trace"]) - out["e0"]) / info["e_scale"], n_trace),
            trace_points=min(len(out["trace"]), n_trace)))
        if log is not None:
            r = rows[-1]
            log.info("%s %s h=%.3g (%.3g h_crit): stable=%d diverged=%d drift=%.3g pen=%.3g "
                     "sweeps=%.1f wall=%.2fs", name, method, h, r["h_over_hcrit"], r["stable"],
                     r["diverged"], r["energy_drift"], r["max_penetration"], r["sweeps_mean"], wall)
    return to_dataset(rows, n_trace)


def _pad(trace, n):
    """``n`` samples: the trace, then its last value repeated (``trace_points`` says how many)."""
    out = np.zeros(n)
    k = min(len(trace), n)
    out[:k] = trace[:k]
    if 0 < k < n:
        out[k:] = trace[k - 1]
    return out


def to_dataset(rows, n_trace):
    """Rows (dicts) to a dataset; every value finite (checked)."""
    data = {}
    for key in rows[0]:
        if key == "trace":
            data[key] = (("run", "sample"), np.array([r[key] for r in rows]))
        else:
            data[key] = ("run", np.array([r[key] for r in rows]))
    ds = xr.Dataset(data, coords={"run": np.arange(len(rows)), "sample": np.arange(n_trace)})
    for name, var in ds.data_vars.items():
        if var.dtype.kind == "f" and not np.all(np.isfinite(var.values)):
            raise ValueError(f"non-finite value in {name}: {var.values}")
    ds["trace"].attrs["description"] = "(E(t) - E_0) / E_s at evenly spaced steps; padded after trace_points"
    ds["sweeps_mean"].attrs["description"] = "mean NLGS sweeps per step (CD); -1 for MD"
    ds["residual_max"].attrs["description"] = "largest NLGS relative natural-map residual (CD); -1 for MD"
    ds["max_penetration"].attrs["description"] = "largest interpenetration / smallest radius"
    ds["observable"].attrs["description"] = OBSERVABLE_LABEL
    ds["observable_ref"].attrs["description"] = "value of the case's observable for the exact motion"
    return ds


def run_table(cfg, log=None):
    """Every case of the config section, concatenated along ``run`` (case order)."""
    common = {k: v for k, v in cfg.items() if k != "cases"}
    parts = [run_case(name, case, common, log) for name, case in cfg["cases"].items()]
    ds = xr.concat(parts, dim="run")
    return ds.assign_coords(run=np.arange(ds.sizes["run"]))


def binary_collision(e=(0.0, 0.5), h=1e-3):
    """One Moreau–Jean step of a binary collision at each normal restitution of ``e`` (§2: with
    the contact law on u_f alone, e = 0, collisions are perfectly inelastic; the weighted mean
    of u_i and u_f is Newton's law for a binary collision): the ratio U_f/U_i of the normal
    relative velocity over ``restitution``, −e when the scheme holds.  Written by the stability
    rule, so that the §2 restitution claims read data, not a step at render time."""
    es = np.atleast_1d(np.asarray(e, dtype=float))
    ratios = []
    for e_n in es:
        scene = make_scene([[0.0, 0.0], [0.8, 0.0]], [0.5, 0.3], [1.0, 3.0], gravity=(0.0, 0.0),
                           vel=[[1.0, 0.0], [-0.5, 0.0]], e_n=float(e_n), mu=0.0)
        n = prepare_step(scene, h).contacts.normal[0]
        u_i = float((scene.vel[0] - scene.vel[1]) @ n)
        step(scene, h)
        u_f = float((scene.vel[0] - scene.vel[1]) @ n)
        ratios.append(u_f / u_i)
    return xr.Dataset(
        {"velocity_ratio": ("restitution", np.array(ratios),
                            {"units": "1", "long_name": "U_f / U_i of the normal relative velocity after one step"})},
        coords={"restitution": ("restitution", es, {"units": "1", "long_name": "normal restitution coefficient e"})},
        attrs={"h": h})
