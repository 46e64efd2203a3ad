"""Piles of three construction histories (Moreau 2005, section 5): a point source, a rain
that builds the same heap, and a layer.

Member ``m`` of each history draws from independent generators
``default_rng((m, root_seed, stream))``: the ground and the grain radii are the same for
every history, only the source differs.

* ``point``: Figure 4's localized source above the axis;
* ``rain``: a rain through a sieve that follows the growing heap
  (:class:`ncd.shared.sources.SieveRain`), as in the experiments that compare the two
  procedures on heaps of the same shape (Vanel et al. 1999; Geng et al. 2001);
* ``layer``: a uniform rain over the base half-width ``L`` of the member's point pile from
  the first grain on, onto the finite base ``|x| <= L`` (grains rolling off it are removed):
  it deposits a flat-topped layer, not a heap, and serves as the shape that differs.

Construction: :func:`ncd.shared.construction.build` (checkpoints, frames); one netCDF file per pile.
"""
import numpy as np

from ncd.shared.construction import add_frames, build
from ncd.shared.pile import add_to_pile, construction_dataset, free_surface, make_ground, pile_scene
from ncd.shared.sources import PointSource, RainSource, SieveRain, mean_diameter

HISTORIES = ("point", "rain", "layer")
DROP_D = 2.0     # a grain this far (mean diameters) below the ground discs' centres has left the base
STREAMS = {"ground": 0, "radii": 1, "point": 2, "layer": 3, "rain": 4}


def member_rng(member, root_seed, stream):
    """The generator of one stream of one pile."""
    return np.random.default_rng((int(member), int(root_seed), STREAMS[stream]))


def grain_radii(cfg, member, count=None):
    """The radii of the grains of pile ``member``, in order of insertion (both histories);
    ``count`` (default ``grains.n``) radii of one sequence: a longer one starts with the
    shorter (the rain pours past ``grains.n`` when grains fall off its base)."""
    g = cfg["grains"]
    n = g["n"] if count is None else int(count)
    return member_rng(member, cfg["root_seed"], "radii").uniform(g["radius_min"], g["radius_max"], n)


def base_half_width(cfg, pos, radius, y0):
    """``(L, fits)``: the base half-width ``(right toe - left toe) / 2`` of the flank fits of
    the free surface (profile bins ``surface.bin_d``, fits between ``surface.fit_range``)."""
    fits = free_surface(cfg, pos, radius, y0)[2]
    return 0.5 * (fits["right"]["toe"] - fits["left"]["toe"]), fits


def finite_base(ground, half_width):
    """The ground discs with centres in ``|x| <= half_width`` (the base of a rain pile)."""
    keep = np.abs(ground[0][:, 0]) <= half_width
    if keep.sum() < 2:
        raise ValueError(f"base half-width {half_width!r} m keeps fewer than 2 ground discs")
    return ground[0][keep], ground[1][keep]


def construct(cfg, history, member, point_half_width=None, log=None, checkpoint=None, info=None):
    """Build pile ``member`` of ``history``; returns :func:`build`'s tuple plus the ground.

    ``point_half_width`` (m, the base half-width ``L`` of the member's point-source pile)
    is required for ``history == "layer"``: its rain falls over ``|x| <= width_fraction L``
    onto the finite base ``|x| <= L`` (:func:`finite_base`).  ``info`` (a dict) receives
    the insertion index of each grain and the removed grains (:func:`build`).
    """
    if history not in HISTORIES:
        raise ValueError(f"history = {history!r} must be one of {HISTORIES}")
    root = cfg["root_seed"]
    ground = make_ground(cfg, member_rng(member, root, "ground"))
    y0 = float(np.mean(ground[1]))
    radii = grain_radii(cfg, member)
    rng = member_rng(member, root, history)
    drop, limit = None, None
    if history == "point":
        source = PointSource(cfg, rng, y0, radii)
    elif history == "rain":
        source = SieveRain(cfg, rng, y0, radii)
    else:
        if point_half_width is None or not np.isfinite(point_half_width) or point_half_width <= 0:
            raise ValueError(f"history 'layer' needs point_half_width > 0 (the point-source pile's base "
                             f"half-width), got {point_half_width!r}")
        ground = finite_base(ground, point_half_width)
        limit = int(np.ceil(cfg["layer"]["pour_limit"] * len(radii)))
        source = RainSource(cfg, rng, y0, cfg["layer"]["width_fraction"] * point_half_width,
                            cfg["layer"]["sites"], grain_radii(cfg, member, limit), spread=cfg["layer"]["spread"])
        drop = -DROP_D * mean_diameter(cfg)
    c = cfg["construction"]
    key = {**cfg, "history": history, "member": int(member),
           "point_half_width": None if point_half_width is None else float(point_half_width)}
    factory = lambda p, r, v, w, a: pile_scene(cfg, p, r, *ground, vel=v, spin=w, angle=a)  # noqa: E731
    info = {} if info is None else info
    if limit is not None:       # the layer pours `limit` grains; those that roll off the base are removed
        key["grains"] = {**cfg["grains"], "n": limit}
    scene, rec, eq, frames = build(key, ground, source, factory, log, checkpoint=checkpoint,
                                   checkpoint_every=c["checkpoint_every"], frame_every=c["frame_every"],
                                   drop_below=drop, info=info,
                                   add_grains=lambda s, p, r, v: add_to_pile(cfg, s, p, r, v))
    if history == "rain":
        info["sieve_half_width"] = float(source.half_width)    # the sieve's final half-width
    return scene, rec, ground, eq, frames


def pile_dataset(cfg, history, member, scene, rec, ground, eq, frames, point_half_width=None, info=None):
    """One pile's file: :func:`ncd.shared.pile.construction_dataset` plus the frames,
    the base half-width and the flank fits, the insertion index of every grain and the
    count of grains removed off the base (``info`` of :func:`construct`)."""
    ds = construction_dataset(cfg, scene, rec, ground, eq)
    nm = scene.n_mobile
    y0 = float(np.mean(ground[1]))
    L, fits = base_half_width(cfg, scene.pos[:nm], scene.radius[:nm], y0)
    add_frames(ds, frames, cfg["h"])
    info = info or {}
    order = np.asarray(info.get("order", np.arange(nm)), np.int64)
    removed = np.asarray(info.get("removed", np.zeros((0, 4))), float).reshape(-1, 4)
    ds["poured_index"] = ("grain", order, {"units": "1", "long_name": "insertion index of the grain (same "
                                           "sequence of radii for both histories of a member)"})
    layer = history == "layer"
    # point_half_width: the L of the member's point pile (its own for a point pile; a layer's
    # base); a rain heap has none of its own and is read against its own base half-width
    if history != "rain":
        ds.attrs["point_half_width"] = float(point_half_width) if layer else float(L)
    else:
        ds.attrs["sieve_half_width"] = float(info.get("sieve_half_width", np.nan))
    ds.attrs.update(history=history, member=int(member), root_seed=int(cfg["root_seed"]), y_ground=y0,
                    base_half_width=float(L),
                    layer_half_width=cfg["layer"]["width_fraction"] * float(point_half_width) if layer else np.nan,
                    base_edge=float(np.max(np.abs(ground[0][:, 0]) + ground[1])) if layer else np.nan,
                    n_poured=int(nm + len(removed)), n_removed=int(len(removed)),
                    n_removed_left=int(np.sum(removed[:, 2] < 0)), n_removed_right=int(np.sum(removed[:, 2] > 0)),
                    construction_wall_time=float(np.sum(rec["wall_time"])),
                    **{f"{f}_{q}": v for f in ("left", "right") for q, v in fits[f].items()})
    return ds


def ground_forces(ds):
    """``(x, fx, fy)`` of the ground contacts of a pile file (history forces, N).

    A contact with ``body_b`` not a grain is a ground contact; the force on the
    grain is ``f_n n + f_t t`` with ``t = (-n_y, n_x)`` (:mod:`ncd.core.contacts`)."""
    nm = ds.sizes["grain"]
    b = ds["body_b"].values
    g = (b < 0) | (b >= nm)
    nx, ny = ds["normal_x"].values[g], ds["normal_y"].values[g]
    fn, ft = ds["force_n"].values[g], ds["force_t"].values[g]
    return ds["point_x"].values[g], nx * fn - ny * ft, ny * fn + nx * ft
