"""Figure 4 (Moreau 2005, section 5): a 2-D pile poured from a localized source.

The pile is built by :func:`ncd.shared.pile.construct` (warm-started NLGS until the
equilibrium test of section 2 passes).  Its final arrangement is then explored by NLGS
runs from the zero guess with random review orders (section 5), keeping per run the
measures of :mod:`ncd.shared.cuts` (cut resultants, ground pressure) and the run's
outcome (:func:`ncd.solver.convergence.classify`: converged at rest, in motion, or not).
The warm-guess ensemble explores the same problem from the construction's last impulses
(:func:`antecedent`), with other random orders: the "antecedent contact forces" of section 5.
"""

import numpy as np
import scipy.sparse as sp
import xarray as xr

from ncd.core.contacts import match_warm
from ncd.core.errors import SimulationError
from ncd.dynamics.explore import explore
from ncd.io.netcdf import provenance
from ncd.io.progress import Progress
from ncd.shared import cuts as cm
from ncd.shared.pile import construct, cut_specs, equilibrium_problem, final_scene, free_surface
from ncd.shared.sources import mean_diameter
from ncd.solver.convergence import MAX_SPEED_ATTRS, outcome_attrs
from ncd.solver.settings import SolverSettings


def cuts_dataset(cfg, construction):
    """cuts.nc: free-surface profile and flank fits, the cuts (default, moved by
    ``± shift_d`` mean diameters, a scan of both flanks) with their history resultants,
    and the history ground pressure (section 5)."""
    ds = construction
    scene = final_scene(cfg, ds)
    problem = equilibrium_problem(cfg, scene, ds)
    c, nm = problem.contacts, scene.n_mobile
    d = mean_diameter(cfg)
    pos, radius = scene.pos[:nm], scene.radius[:nm]
    forces = np.column_stack([ds["force_n"].values, ds["force_t"].values]).ravel()
    y0 = float(np.mean(ds["ground_radius"].values))          # ground level: mean top of the ground discs
    xs, height, fits, m, sb = free_surface(cfg, pos, radius, y0)
    # cuts
    k = cfg["cut"]
    depth = lambda x: float(np.interp(x, xs[np.isfinite(height)], height[np.isfinite(height)]))  # noqa: E731
    x_def = k["flank_fraction"] * fits["right"]["toe"]
    specs = [("default", x_def, 1), ("minus", x_def - k["shift_d"] * d, 1), ("plus", x_def + k["shift_d"] * d, 1)]
    step = k["scan_step_d"] * d
    for name, outer in (("left", -1), ("right", 1)):
        toe = abs(fits[name]["toe"])
        specs += [("scan", outer * j * step, outer) for j in range(1, int((toe - 0.5 * step) / step) + 1)]
    kind = np.array([s[0] for s in specs])
    x_cut = np.array([s[1] for s in specs])
    outer = np.array([s[2] for s in specs])
    loc = np.array([depth(x) for x in x_cut])
    y_lo = y0 + k["segment"][0] * loc
    y_hi = y0 + k["segment"][1] * loc
    counts = cm.cut_matrix(c, scene.pos, nm, list(zip(x_cut, outer, y_lo, y_hi)))[1]
    keep = (kind != "scan") | (counts > 0)          # scan cuts beyond the toe cross nothing
    kind, x_cut, outer, loc, y_lo, y_hi = (v[keep] for v in (kind, x_cut, outer, loc, y_lo, y_hi))
    C, counts = cm.cut_matrix(c, scene.pos, nm, list(zip(x_cut, outer, y_lo, y_hi)))
    F = (C @ forces).reshape(-1, 2)
    loaded = cm.cut_matrix(c.subset(ds["force_n"].values > 0), scene.pos, nm,
                           list(zip(x_cut, outer, y_lo, y_hi)))[1]
    slope = np.where(outer > 0, fits["right"]["angle"], fits["left"]["angle"])
    phi, dev = cm.flank_angles(F[:, 0], F[:, 1], outer, slope)
    # ground pressure
    pb = cfg["pressure"]["bin_d"] * d
    mp = int(np.ceil(m * sb / pb))
    p_edges = (np.arange(-mp, mp + 2) - 0.5) * pb              # a bin centred under the source
    G = cm.ground_matrix(c, nm, p_edges) @ forces
    col = np.histogram(pos[:, 0], p_edges, weights=scene.mass[:nm] * cfg["gravity"])[0]
    out = xr.Dataset(
        {
            "height": ("x_profile", height),
            "kind": ("cut", kind), "cut_x": ("cut", x_cut), "outer": ("cut", outer),
            "y_lo": ("cut", y_lo), "y_hi": ("cut", y_hi), "depth": ("cut", loc),
            "n_crossing": ("cut", counts), "n_loaded": ("cut", loaded),
            "surface_angle": ("cut", slope), "history_fx": ("cut", F[:, 0]), "history_fy": ("cut", F[:, 1]),
            "history_angle": ("cut", phi), "history_deviation": ("cut", dev),
            "bin_lo": ("bin", p_edges[:-1]), "bin_hi": ("bin", p_edges[1:]),
            "history_pressure": ("bin", G[2:] / pb), "column_weight": ("bin", col / pb),
        },
        coords={"x_profile": xs, "cut": np.arange(len(kind)), "bin": 0.5 * (p_edges[1:] + p_edges[:-1])},
        attrs=provenance(cfg, mean_diameter=d, y_ground=y0, apex_height=float(np.nanmax(height)),
                         weight=ds.attrs["weight"], history_ground_fx=float(G[0]), history_ground_fy=float(G[1]),
                         n_grains=nm, n_contacts=c.n,
                         **{f"{f}_{q}": v for f in ("left", "right") for q, v in fits[f].items()}),
    )
    out["history_angle"].attrs["units"] = "degrees below the horizontal, pointing outward"
    out["history_deviation"].attrs["units"] = "degrees, resultant angle minus free-surface slope"
    out["history_pressure"].attrs["units"] = "N/m: vertical ground force per unit length"
    return out


def _observable(cfg, scene, contacts, C, edges):
    """``observe(impulse, vel, spin)``: the default cut resultant and the binned ground
    pressure times the bin width, over the pile's weight (order one)."""
    nm = scene.n_mobile
    weight = float(np.sum(scene.mass[:nm]) * cfg["gravity"])
    rows = cm.ground_matrix(contacts, nm, edges)[2:]
    M = sp.vstack([C[:2], rows]).tocsr() / (cfg["h"] * weight)

    def observe(impulse, vel, spin):
        return M @ np.asarray(impulse).ravel()
    return observe


def antecedent(cfg, construction, log=None):
    """``(keys, impulse)``: the impulses of the construction's last step, the warm guess its
    final equilibrium test started from (the "antecedent contact forces" of section 5).

    construction.nc keeps that test's solution (the history forces), not its guess, so the
    construction is replayed (:func:`ncd.shared.pile.construct`, deterministic) and checked
    against construction.nc bit for bit (positions, contacts, history forces)."""
    scene, _, _, eq = construct(cfg, log)
    nm, ds = scene.n_mobile, construction
    same = (nm == ds.sizes["grain"] and np.array_equal(scene.pos[:nm, 0], ds["x"].values)
            and np.array_equal(scene.pos[:nm, 1], ds["y"].values)
            and np.array_equal(eq.contacts.key, ds["key"].values)
            and np.array_equal(eq.forces[:, 0], ds["force_n"].values)
            and np.array_equal(eq.forces[:, 1], ds["force_t"].values))
    if not same:
        raise SimulationError("the replayed construction differs from construction.nc: its last impulses "
                              "cannot stand for the antecedent forces of the stored pile")
    return np.asarray(scene.prev_keys, np.int64).copy(), np.asarray(scene.prev_impulse, float).copy()


def ensemble_shard(cfg, construction, cuts, members, tolerances, root_seed, log=None, finish=None, guess=None):
    """NLGS runs from the zero guess with random orders on the final state (section 5), one
    set per tolerance: cut resultants, ground force, velocity summary and solver record per run.

    ``finish="active_set"`` hands each run over at ``tol`` to :mod:`ncd.solver.finish`, an
    exact solution whose observable needs no tracking; ``"none"``: plain NLGS, converged
    only when the observable has settled too.  ``guess``: ``(keys, impulse)`` of a warm guess
    matched by body pair (:func:`antecedent`); None: the zero guess."""
    e = cfg["ensemble"]
    h, g = cfg["h"], cfg["gravity"]
    scene = final_scene(cfg, construction)
    problem = equilibrium_problem(cfg, scene, construction)
    c, nm = problem.contacts, scene.n_mobile
    init, warm_attrs = "zero", {}
    if guess is not None:
        init = "warm"
        scene.prev_keys, scene.prev_impulse = np.asarray(guess[0], np.int64), np.asarray(guess[1], float)
        s0 = match_warm(c, scene.prev_keys, scene.prev_impulse)
        hist = h * np.column_stack([construction["force_n"].values, construction["force_t"].values])
        warm_attrs = dict(guess_matched=int(np.count_nonzero(np.any(s0 != 0, axis=1))),
                          guess_offset=float(np.abs(s0 - hist).sum() / max(np.abs(hist).sum(), 1e-300)),
                          rest_speed_tol=float(cfg["construction"]["velocity_tol"]),
                          guess_note="the impulses of the construction's last step (the warm guess of its equilibrium "
                                     "test), matched by body pair; guess_offset: their relative L1 distance to h times "
                                     "the history forces; rest_speed_tol: the equilibrium test's at-rest speed (g h)")
    C, _ = cm.cut_matrix(c, scene.pos, nm, cut_specs(cuts))
    edges = np.append(cuts["bin_lo"].values, cuts["bin_hi"].values[-1])
    G = cm.ground_matrix(c, nm, edges)
    members = np.asarray(members, dtype=np.int64)
    shape = (len(members), len(tolerances))
    res = {k: np.zeros(shape + tail) for k, tail in (
        ("cut_force_x", (cuts.sizes["cut"],)), ("cut_force_y", (cuts.sizes["cut"],)),
        ("ground_pressure", (cuts.sizes["bin"],)), ("ground_fx", ()), ("ground_fy", ()),
        ("unbalanced_fy", ()), ("max_velocity", ()), ("n_moving", ()), ("sweeps", ()), ("residual", ()),
        ("change", ()), ("converged", ()), ("wall_time", ()), ("outcome", ()), ("max_speed", ()),
        ("observable_change", ()), ("finish_rounds", ()), ("finish_correction", ()))}
    finish = e.get("finish", "none") if finish is None else finish
    observe = _observable(cfg, scene, c, C, edges) if finish == "none" else None
    for j, tol in enumerate(tolerances):
        settings = SolverSettings(tol=float(tol), max_sweeps=e["max_sweeps"], check_every=e["check_every"],
                                      finish=finish, finish_tol=e.get("finish_tol", 1e-10),
                                      observable_tol=e.get("observable_tol", 1e-6))
        rows = np.arange(len(members))
        if j > 0 and finish == "none":
            # Plain NLGS from the zero guess is deterministic and checked on the same grid of
            # sweeps whatever tol: a run unconverged at the previous (looser) tolerance is the
            # same run, unconverged, at this one; a converged run whose residual already meets
            # this tolerance stops at the same check.  Both are copied; only the others run.
            for k in res:
                res[k][:, j] = res[k][:, j - 1]
            rows = np.flatnonzero(res["converged"][:, j - 1].astype(bool) & (res["residual"][:, j - 1] > tol))
        if len(rows) == 0:
            continue
        prog = Progress(log, len(rows), f"tol {tol:g}") if log is not None else None
        out = explore(scene, problem, members[rows], root_seed, init=init, settings=settings, progress=prog,
                      observe=observe)
        s = out["impulse"].reshape(len(rows), -1)
        F = (C @ s.T).T / h
        res["cut_force_x"][rows, j], res["cut_force_y"][rows, j] = F[:, 0::2], F[:, 1::2]
        GG = (G @ s.T).T / h
        res["ground_fx"][rows, j], res["ground_fy"][rows, j] = GG[:, 0], GG[:, 1]
        res["ground_pressure"][rows, j] = GG[:, 2:] / np.diff(edges)
        speed = np.maximum(np.hypot(out["vel"][..., 0], out["vel"][..., 1]),
                           np.abs(out["spin"]) * scene.radius[:nm]) / (g * h)
        res["max_velocity"][rows, j] = speed.max(axis=1, initial=0.0)
        res["n_moving"][rows, j] = (speed > e["moving_tol"]).sum(axis=1)
        res["unbalanced_fy"][rows, j] = out["vel"][..., 1] @ scene.mass[:nm] / h
        for k in ("sweeps", "residual", "change", "converged", "wall_time", "outcome", "max_speed",
                  "observable_change", "finish_rounds", "finish_correction"):
            res[k][rows, j] = out[k]
        if log is not None:
            copied = f" ({len(members) - len(rows)} copied from the previous tolerance)" if j > 0 else ""
            log.info("tol %g: %d runs%s, %d converged, sweeps %d..%d", tol, len(members), copied,
                     res["converged"][:, j].sum(), res["sweeps"][:, j].min(), res["sweeps"][:, j].max())
    data = {}
    for k, v in res.items():
        tail = () if v.ndim == 2 else ("cut",) if k.startswith("cut") else ("bin",)
        v = v.astype(bool) if k == "converged" else v.astype(np.int64) if k in ("sweeps", "n_moving", "finish_rounds") \
            else v.astype(np.int8) if k == "outcome" else v
        data[k] = (("run", "tol") + tail, v)
    ds = xr.Dataset(data, coords={"run": members, "tol": np.asarray(tolerances, float),
                                  "cut": cuts["cut"].values, "bin": cuts["bin"].values},
                    attrs=provenance(cfg, root_seed=root_seed, h=h, weight=construction.attrs["weight"],
                                     max_sweeps=e["max_sweeps"], check_every=e["check_every"],
                                     moving_tol=e["moving_tol"], init=init, review="random", finish=finish,
                                     finish_tol=e.get("finish_tol", 1e-10) if finish != "none" else np.nan,
                                     **warm_attrs))
    ds["max_velocity"].attrs["units"] = "g h (largest |u_f| or |r w_f| over grains; 0 at equilibrium)"
    ds["outcome"].attrs.update(outcome_attrs())
    ds["max_speed"].attrs.update(MAX_SPEED_ATTRS)
    ds["observable_change"].attrs.update(units="1", long_name="largest relative change of the observable (default "
                                         "cut resultant and kernel ground pressure, over the weight) over the last checks")
    ds["finish_rounds"].attrs.update(units="1", long_name="LP projections of the finishing stage (0: none)")
    ds["finish_correction"].attrs.update(units="1", long_name="relative L1 move of the impulses by the accepted "
                                         "projection (0: NLGS got there, NaN: unconverged)")
    ds["unbalanced_fy"].attrs["note"] = "sum of m u_f,y / h: ground_fy - weight equals it exactly"
    ds["wall_time"].attrs["note"] = ("measured seconds per run (a plain-NLGS run copied from the previous tolerance: "
                                     "that run's), while the rule's other threads ran other members "
                                     "(the only non-reproducible variable)")
    return ds
