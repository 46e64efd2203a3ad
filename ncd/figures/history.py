"""Piles of two construction histories (issue 16; Moreau 2005, section 5).

Member ``m`` of history ``point`` or ``rain`` is built from independent
generators ``default_rng((m, root_seed, stream))``:

* stream 0: the rough ground (:func:`ncd.figures.pile.make_ground`), the same for both histories;
* stream 1: the grain radii, in order of insertion, the same for both histories;
* stream 2 (point) or 3 (rain): the source (slot order and jitter, or rain positions).

The rain falls uniformly over ``|x| <= width_fraction * L``, ``L`` the base
half-width of the point-source pile of the same member (from its flank fits), so a
rain pile's rule reads that pile's file.  Construction: :func:`ncd.figures.construction.build`
(checkpoints, frames); the final state, its history forces and the frames go to one
netCDF file per pile.
"""
import numpy as np
import xarray as xr

from .construction import add_frames, build
from .pile import construction_dataset, free_surface, make_ground, pile_scene
from .sources import PointSource, RainSource

HISTORIES = ("point", "rain")
STREAMS = {"ground": 0, "radii": 1, "point": 2, "rain": 3}


def member_rng(member, root_seed, stream):
    """The generator of one stream of one pile."""
    return np.random.default_rng((int(member), int(root_seed), STREAMS[stream]))


def grain_radii(cfg, member):
    """The radii of the grains of pile ``member``, in order of insertion (both histories)."""
    g = cfg["grains"]
    return member_rng(member, cfg["root_seed"], "radii").uniform(g["radius_min"], g["radius_max"], g["n"])


def base_half_width(cfg, pos, radius, y0):
    """``(L, fits)``: the base half-width ``(right toe - left toe) / 2`` of the flank fits of
    the free surface (profile bins ``surface.bin_d``, fits between ``surface.fit_range``)."""
    fits = free_surface(cfg, pos, radius, y0)[2]
    return 0.5 * (fits["right"]["toe"] - fits["left"]["toe"]), fits


def construct(cfg, history, member, rain_half_width=None, log=None, checkpoint=None):
    """Build pile ``member`` of ``history``; returns :func:`build`'s tuple plus the ground.

    ``rain_half_width`` (m) is required for ``history == "rain"``.
    """
    if history not in HISTORIES:
        raise ValueError(f"history = {history!r} must be one of {HISTORIES}")
    root = cfg["root_seed"]
    ground = make_ground(cfg, member_rng(member, root, "ground"))
    y0 = float(np.mean(ground[1]))
    radii = grain_radii(cfg, member)
    rng = member_rng(member, root, history)
    if history == "point":
        source = PointSource(cfg, rng, y0, radii)
    else:
        if rain_half_width is None:
            raise ValueError("history 'rain' needs rain_half_width (the point-source pile's base half-width)")
        source = RainSource(cfg, rng, y0, rain_half_width, cfg["rain"]["sites"], radii)
    c = cfg["construction"]
    key = {**cfg, "history": history, "member": int(member),
           "rain_half_width": None if rain_half_width is None else float(rain_half_width)}
    factory = lambda p, r, v, w, a: pile_scene(cfg, p, r, *ground, vel=v, spin=w, angle=a)  # noqa: E731
    scene, rec, eq, frames = build(key, ground, source, factory, log, checkpoint=checkpoint,
                                   checkpoint_every=c["checkpoint_every"], frame_every=c["frame_every"])
    return scene, rec, ground, eq, frames


def pile_dataset(cfg, history, member, scene, rec, ground, eq, frames, rain_half_width=None):
    """One pile's file: :func:`ncd.figures.pile.construction_dataset` plus the frames,
    the base half-width and the flank fits."""
    ds = construction_dataset(cfg, scene, rec, ground, eq)
    nm = scene.n_mobile
    y0 = float(np.mean(ground[1]))
    L, fits = base_half_width(cfg, scene.pos[:nm], scene.radius[:nm], y0)
    add_frames(ds, frames, cfg["h"])
    ds.attrs.update(history=history, member=int(member), root_seed=int(cfg["root_seed"]), y_ground=y0,
                    base_half_width=float(L), rain_half_width=np.nan if rain_half_width is None else
                    float(rain_half_width), construction_wall_time=float(np.sum(rec["wall_time"])),
                    **{f"{f}_{q}": v for f in ("left", "right") for q, v in fits[f].items()})
    return ds


def ground_forces(ds):
    """``(x, fx, fy)`` of the ground contacts of a pile file (history forces, N).

    A contact with ``body_b`` not a grain is a ground contact; the force on the
    grain is ``f_n n + f_t t`` with ``t = (-n_y, n_x)`` (:mod:`ncd.contacts`)."""
    nm = ds.sizes["grain"]
    b = ds["body_b"].values
    g = (b < 0) | (b >= nm)
    nx, ny = ds["normal_x"].values[g], ds["normal_y"].values[g]
    fn, ft = ds["force_n"].values[g], ds["force_t"].values[g]
    return ds["point_x"].values[g], nx * fn - ny * ft, ny * fn + nx * ft


def all_at_rest(paths):
    """Per pile file: at_rest, the equilibrium test's max |u_f| / (g h), residual."""
    out = []
    for p in paths:
        with xr.open_dataset(p) as ds:
            out.append((bool(ds.attrs["at_rest"]), float(ds.attrs["eq_max_velocity"]),
                        float(ds.attrs["eq_residual"])))
    return out
