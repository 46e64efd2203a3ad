"""The pile of Figure 4 (Moreau 2005, section 5) as a scene: rough ground, pouring,
the final state and its one-step equilibrium problem.

Shared by the pile figure, the construction-history ensembles and the exact sets:
the ground is a row of fixed discs; the construction (:func:`construct`) pours grains
with warm-started NLGS until the equilibrium test passes; the final scene and the
rest problem are rebuilt from ``construction.nc`` so that every later analysis reads
the same arrangement of grains.
"""

import numpy as np
import xarray as xr

from ncd.core.contacts import h_matrix
from ncd.core.errors import SimulationError
from ncd.core.scene import add_discs, make_scene
from ncd.dynamics.explore import member_rng
from ncd.dynamics.stepper import prepare_step
from ncd.io.netcdf import provenance
from ncd.shared import cuts as cm
from ncd.shared.construction import build
from ncd.shared.sources import PointSource as Source
from ncd.shared.sources import mean_diameter
from ncd.solver.settings import SolverSettings


def make_ground(cfg, rng):
    """A rough ground: touching fixed discs, centres on ``y = 0``, radii uniform,
    spanning ``|x| <= half_width_d`` mean diameters."""
    g = cfg["ground"]
    half = g["half_width_d"] * mean_diameter(cfg)
    xs, rs = [], []
    x = -half
    while x < half:
        r = rng.uniform(g["radius_min"], g["radius_max"])
        xs.append(x + r)
        rs.append(r)
        x += 2 * r
    return np.column_stack([xs, np.zeros(len(xs))]), np.array(rs)


def pile_scene(cfg, pos, radius, ground_pos, ground_radius, vel=None, spin=None, angle=None):
    """The scene: grains, ground discs, gravity, friction; no walls, no restitution."""
    c = cfg["construction"]
    return make_scene(pos, radius, cfg["grains"]["density"], obstacle_pos=ground_pos,
                          obstacle_radius=ground_radius, gravity=(0.0, -cfg["gravity"]), mu=cfg["mu"],
                          mu_obstacle=cfg["mu_ground"], vel=vel, spin=spin, angle=angle,
                          overlap_tolerance=c["overlap_tolerance"])


def add_to_pile(cfg, scene, pos, radius, vel):
    """The :func:`pile_scene` of ``scene``'s grains and new grains (positions, radii,
    velocities; at rest in angle and spin) appended after them, built from ``scene``
    without validating its grains again (:func:`ncd.core.scene.add_discs`)."""
    return add_discs(scene, pos, radius, cfg["grains"]["density"], vel=vel,
                     overlap_tolerance=cfg["construction"]["overlap_tolerance"])


def construct(cfg, log=None, log_every=10.0, checkpoint=None, checkpoint_every=0, frame_every=0):
    """Pour ``grains.n`` discs from the localized source and step until at rest (the loop is
    :func:`ncd.shared.construction.build`).

    Returns ``(scene, record, ground, eq)`` (``eq``: the warm-started equilibrium test of the
    final state, i.e. the history forces), plus ``(frame_steps, frames)`` if ``frame_every > 0``.
    Raises :class:`SimulationError` if a grain leaves the ground or the pile is not at rest."""
    rng = member_rng(0, cfg["seed"])
    ground = make_ground(cfg, rng)
    source = Source(cfg, rng, float(np.mean(ground[1])))
    factory = lambda p, r, v, w, a: pile_scene(cfg, p, r, *ground, vel=v, spin=w, angle=a)  # noqa: E731
    scene, rec, eq, frames = build(cfg, ground, source, factory, log, log_every, checkpoint, checkpoint_every,
                                   frame_every, add_grains=lambda s, p, r, v: add_to_pile(cfg, s, p, r, v))
    return (scene, rec, ground, eq) + ((frames,) if frame_every > 0 else ())


def construction_dataset(cfg, scene, rec, ground, eq):
    """construction.nc: the per-step record, the final state and its history forces."""
    nm = scene.n_mobile
    c = eq.contacts
    h = cfg["h"]
    ds = xr.Dataset(
        {
            **{k: ("step", v) for k, v in rec.items()},
            "x": ("grain", scene.pos[:nm, 0]), "y": ("grain", scene.pos[:nm, 1]),
            "radius": ("grain", scene.radius[:nm]), "mass": ("grain", scene.mass[:nm]),
            "vx": ("grain", scene.vel[:nm, 0]), "vy": ("grain", scene.vel[:nm, 1]),
            "spin": ("grain", scene.spin[:nm]), "angle": ("grain", scene.angle[:nm]),
            "ground_x": ("ground", ground[0][:, 0]), "ground_y": ("ground", ground[0][:, 1]),
            "ground_radius": ("ground", ground[1]),
            "body_a": ("contact", c.body_a), "body_b": ("contact", c.body_b), "key": ("contact", c.key),
            "normal_x": ("contact", c.normal[:, 0]), "normal_y": ("contact", c.normal[:, 1]),
            "point_x": ("contact", c.point[:, 0]), "point_y": ("contact", c.point[:, 1]),
            "gap": ("contact", c.gap),
            "force_n": ("contact", eq.forces[:, 0]), "force_t": ("contact", eq.forces[:, 1]),
        },
        coords={"step": np.arange(1, len(rec["time"]) + 1)},
        attrs=provenance(cfg, SolverSettings(**cfg["construction"]["settings"]), h=h,
                         mean_diameter=mean_diameter(cfg), n_grains=nm, n_steps=len(rec["time"]),
                         weight=float(np.sum(scene.mass[:nm]) * cfg["gravity"]),
                         at_rest=eq.at_rest, eq_max_velocity=eq.max_velocity, eq_sweeps=eq.result.sweeps,
                         eq_residual=eq.result.residual, eq_converged=eq.result.converged,
                         eq_solver_tol=cfg["construction"]["equilibrium"]["tol"]),
    )
    ds["wall_time"].attrs["note"] = "measured seconds per step (the only non-reproducible variable)"
    ds["force_n"].attrs["note"] = "history forces: warm-started equilibrium test of the final state, r = s/h"
    return ds


def final_scene(cfg, construction):
    """Rebuild the final scene (at rest) from construction.nc."""
    ds = construction
    pos = np.column_stack([ds["x"].values, ds["y"].values])
    gpos = np.column_stack([ds["ground_x"].values, ds["ground_y"].values])
    return pile_scene(cfg, pos, ds["radius"].values, gpos, ds["ground_radius"].values,
                      angle=ds["angle"].values)


def equilibrium_problem(cfg, scene, construction=None):
    """The one-step problem from rest (theta = 1, as in :func:`ncd.equilibrium_test`);
    checks that its contacts are those of the stored history forces."""
    problem = prepare_step(scene, cfg["h"], 1.0, vel=np.zeros_like(scene.vel),
                               spin=np.zeros_like(scene.spin))
    if construction is not None and not np.array_equal(problem.contacts.key, construction["key"].values):
        raise SimulationError("the contacts of the rebuilt final state differ from construction.nc")
    return problem


def cut_specs(ds):
    """``[(x_cut, outer, y_lo, y_hi)]`` of the cuts of cuts.nc."""
    return list(zip(ds["cut_x"].values, ds["outer"].values.astype(int), ds["y_lo"].values, ds["y_hi"].values))


def free_surface(cfg, pos, radius, y0):
    """``(xs, height, fits, m, bin)``: the free-surface profile above ``y0`` in bins of
    ``surface.bin_d`` mean diameters (``2 m`` bins centred at ``xs``) and its flank fits
    between ``surface.fit_range`` (:func:`ncd.shared.cuts.fit_flanks`)."""
    d = mean_diameter(cfg)
    sb = cfg["surface"]["bin_d"] * d
    m = int(np.ceil((np.abs(pos[:, 0]).max() + d) / sb))
    edges = np.arange(-m, m + 1) * sb
    xs = 0.5 * (edges[1:] + edges[:-1])
    height = cm.surface_profile(pos, radius, edges) - y0
    return xs, height, cm.fit_flanks(xs, height, 0.0, cfg["surface"]["fit_range"]), m, sb


def pile_problem(cfg, construction):
    """``(scene, contacts, H, F, mu)`` of the final configuration: ``H r + F = 0`` (forces)."""
    scene = final_scene(cfg, construction)
    c = equilibrium_problem(cfg, scene, construction).contacts
    nm = scene.n_mobile
    F = np.zeros((nm, 3))
    F[:, :2] = scene.mass[:nm, None] * scene.gravity[None, :]
    return scene, c, h_matrix(scene, c), F.ravel(), c.mu
