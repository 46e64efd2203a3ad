"""The construction loop of a pile (Moreau 2005, section 5), with checkpoints and frames.

Grains from a source (:mod:`ncd.shared.sources`) are added every ``insert_every`` steps
of warm-started Moreau-Jean steps (section 2); once all are in, the equilibrium test of
section 2 decides when the pile is at rest.  A checkpoint (``.npz``, written atomically)
holds the whole loop state, so that a resumed run ends bit for bit where an
uninterrupted one ends.  With ``drop_below`` (a finite base, as for the rain) grains
that roll off the base are removed and the pouring goes on until the pile is complete.
"""
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from ncd.core.contacts import pair_key
from ncd.core.errors import SimulationError
from ncd.dynamics.stepper import equilibrium_test, step
from ncd.shared.sources import mean_diameter
from ncd.solver.settings import SolverSettings

RECORD = ("time", "n_grains", "kinetic_energy", "sweeps", "residual", "converged", "n_contacts",
          "max_penetration", "source_height", "wall_time")
FRAME = ("x", "y", "radius", "vx", "vy", "spin")


def add_frames(ds, frames, h):
    """Add the frames ``(frame_steps, frames)`` of :func:`build` to ``ds`` as ``frame_<q>``
    (``frame`` x ``disc``, q in :data:`FRAME`), ``frame_step`` and ``frame_time`` (read by
    :mod:`ncd.io.export`); returns ``ds``."""
    steps, fr = frames
    units = {"x": "m", "y": "m", "radius": "m", "vx": "m s-1", "vy": "m s-1", "spin": "rad s-1"}
    names = {"x": "centre x", "y": "centre y", "radius": "radius", "vx": "velocity x", "vy": "velocity y",
             "spin": "angular velocity"}
    for j, q in enumerate(FRAME):
        ds[f"frame_{q}"] = (("frame", "disc"), fr[:, j, :],
                            {"units": units[q], "long_name": f"grain {names[q]} in a stored frame (NaN: not yet poured)"})
    ds["frame_step"] = ("frame", np.asarray(steps, np.int64), {"units": "1", "long_name": "construction step of the frame"})
    ds["frame_time"] = ("frame", np.asarray(steps) * h, {"units": "s", "long_name": "time of the frame"})
    return ds


def _frame(scene, n_target):
    """The mobile grains' state, padded with NaN to ``n_target`` discs."""
    nm = scene.n_mobile
    out = np.full((len(FRAME), n_target), np.nan)
    out[:, :nm] = [scene.pos[:nm, 0], scene.pos[:nm, 1], scene.radius[:nm], scene.vel[:nm, 0],
                   scene.vel[:nm, 1], scene.spin[:nm]]
    return out


def _kinetic_energy(scene):
    """:func:`ncd.kinetic_energy` (same expression, same bits) without its input checks,
    which cost as much as the sum itself on every construction step."""
    nm = scene.n_mobile
    m = scene.mass[:nm]
    inertia = 0.5 * m * scene.radius[:nm] ** 2
    v = scene.vel[:nm]
    return float(0.5 * np.sum(m * (v[:, 0] ** 2 + v[:, 1] ** 2)) + 0.5 * np.sum(inertia * scene.spin[:nm] ** 2))


def write_checkpoint(path, cfg, k, scene, born, source, rec, frames, frame_steps, order=None, removed=()):
    """Write the loop's state after step ``k`` to ``path`` (temporary file, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nm = scene.n_mobile
    data = dict(step=k, config=yaml.safe_dump(cfg, sort_keys=True), time=scene.time,
                pos=scene.pos, vel=scene.vel, spin=scene.spin, angle=scene.angle, radius=scene.radius[:nm],
                prev_keys=scene.prev_keys, prev_impulse=scene.prev_impulse, born=born,
                rng_state=json.dumps(source.rng.bit_generator.state), source_state=json.dumps(source.state()),
                frames=np.array(frames).reshape(-1, len(FRAME), cfg["grains"]["n"]),
                frame_steps=np.array(frame_steps, np.int64),
                order=np.arange(nm) if order is None else np.asarray(order, np.int64),
                removed=np.array(removed, float).reshape(-1, 4),
                **{f"rec_{key}": np.array(v) for key, v in rec.items()})
    fd, tmp = tempfile.mkstemp(suffix=".npz.part", dir=path.parent)
    os.close(fd)
    try:
        with open(tmp, "wb") as f:
            np.savez(f, **data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def read_checkpoint(path, cfg):
    """The checkpoint at ``path`` as a dict, or None if absent or of another configuration."""
    path = Path(path)
    if not path.exists():
        return None
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    if str(data["config"]) != yaml.safe_dump(cfg, sort_keys=True):
        return None
    return data


def build(cfg, ground, source, scene_factory, log=None, log_every=10.0, checkpoint=None,
          checkpoint_every=0, frame_every=0, drop_below=None, info=None, pour_limit=None, add_grains=None):
    """Pour ``grains.n`` discs from ``source`` onto ``ground`` and step until at rest.

    Returns ``(scene, record, eq, (frame_steps, frames))``: final scene, per-step record, the
    warm-started :class:`ncd.EquilibriumResult` and :data:`FRAME` every ``frame_every`` steps.
    ``checkpoint`` saves and resumes; ``drop_below`` removes grains off a finite base (pouring
    until ``grains.n`` stand or ``pour_limit`` are poured); ``info`` gets ``order``, ``removed``.
    ``add_grains(scene, pos, radius, vel)``, if given, returns ``scene`` with new grains at rest
    in angle and spin appended, the scene ``scene_factory`` would build from all the grains
    (:func:`ncd.shared.pile.add_to_pile`): a pouring then validates only the new grains."""
    c = cfg["construction"]
    d = mean_diameter(cfg)
    h = cfg["h"]
    n_target = cfg["grains"]["n"]
    pour_limit = n_target if pour_limit is None else int(pour_limit)
    settings = SolverSettings(**c["settings"])
    eq_settings = SolverSettings(**c["equilibrium"])
    min_age = int(np.ceil(0.5 * np.sqrt(d / cfg["gravity"]) / h))
    rest_speed = c["rest_speed"] * np.sqrt(cfg["gravity"] * d)
    x_edge = ground[0][:, 0].max()
    scene = None
    born = np.zeros(0, np.int64)
    order = np.zeros(0, np.int64)      # insertion index of each grain of the scene
    removed = []
    rec = {k: [] for k in RECORD}
    frames, frame_steps = [], []
    k0 = 1
    saved = read_checkpoint(checkpoint, cfg) if checkpoint is not None and checkpoint_every > 0 else None
    if saved is not None:
        nm = len(saved["radius"])
        scene = scene_factory(saved["pos"][:nm], saved["radius"], saved["vel"][:nm], saved["spin"][:nm],
                              saved["angle"][:nm])
        scene.pos, scene.vel, scene.spin, scene.angle = (saved[k].copy() for k in ("pos", "vel", "spin", "angle"))
        scene.time = float(saved["time"])
        scene.prev_keys, scene.prev_impulse = saved["prev_keys"], saved["prev_impulse"]
        born = saved["born"]
        order = saved.get("order", np.arange(nm))
        removed = [tuple(r) for r in saved.get("removed", np.zeros((0, 4)))]
        source.restore(json.loads(str(saved["source_state"])), json.loads(str(saved["rng_state"])))
        rec = {k: list(saved[f"rec_{k}"]) for k in RECORD}
        frames, frame_steps = list(saved["frames"]), list(saved["frame_steps"])
        k0 = int(saved["step"]) + 1
        if log is not None:
            log.info("resumed from checkpoint %s after step %d (%d grains)", checkpoint, k0 - 1, nm)
    last_log = time.perf_counter()
    for k in range(k0, c["max_steps"] + 1):
        nm = 0 if scene is None else scene.n_mobile
        poured = nm + len(removed)
        if nm < n_target and poured < pour_limit and (k - 1) % cfg["source"]["insert_every"] == 0:
            st = (scene.pos[:nm], scene.radius[:nm], scene.vel[:nm], scene.spin[:nm], scene.angle[:nm]) \
                if scene else (np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros(0), np.zeros(0))
            source.update_height(st[0], st[1], st[2], k - born >= min_age)
            p, r = source.draw(st[0], st[1], min(n_target - nm, pour_limit - poured))
            if len(r):
                v = source.velocities(len(r))
                if scene is not None and add_grains is not None:
                    new = add_grains(scene, p, r, v)
                else:
                    new = scene_factory(np.vstack([st[0], p]), np.concatenate([st[1], r]), np.vstack([st[2], v]),
                                        np.concatenate([st[3], np.zeros(len(r))]),
                                        np.concatenate([st[4], np.zeros(len(r))]))
                if scene is not None:
                    new.time = scene.time
                    carry_warm(scene, new)
                scene = new
                born = np.concatenate([born, np.full(len(r), k)])
                order = np.concatenate([order, poured + np.arange(len(r))])
        if scene is None:
            continue
        t0 = time.perf_counter()
        rep = step(scene, h, settings=settings, init="warm")
        wall = time.perf_counter() - t0
        nm = scene.n_mobile
        for key, v in zip(RECORD, (rep.time, nm, _kinetic_energy(scene), rep.sweeps, rep.residual,
                                   rep.converged, rep.n_contacts, rep.max_penetration, source.height, wall)):
            rec[key].append(v)
        if drop_below is not None:
            fallen = scene.pos[:nm, 1] < drop_below
            if fallen.any():
                removed += [(k, order[i], scene.pos[i, 0], scene.pos[i, 1]) for i in np.nonzero(fallen)[0]]
                scene = remove_grains(scene, ~fallen, scene_factory)
                born, order = born[~fallen], order[~fallen]
                nm = scene.n_mobile
        elif np.any((np.abs(scene.pos[:nm, 0]) > x_edge) & (scene.pos[:nm, 1] < 0)):
            raise SimulationError(f"a grain left the ground at step {k}: enlarge ground.half_width_d")
        if frame_every > 0 and k % frame_every == 0:
            frames.append(_frame(scene, n_target))
            frame_steps.append(k)
        if log is not None and time.perf_counter() - last_log > log_every:
            last_log = time.perf_counter()
            log.info("step %d, t = %.4g s: poured %d/%d, %d contacts, KE %.3g J, sweeps %d, residual %.2g, "
                     "max penetration %.3f d, mean %.1f ms/step", k, rep.time, nm, n_target, rep.n_contacts,
                     rec["kinetic_energy"][-1], rep.sweeps, rep.residual, rep.max_penetration / d,
                     1e3 * np.mean(rec["wall_time"]))
        if (nm == n_target or nm + len(removed) >= pour_limit) and k % c["rest_check_every"] == 0:
            vmax = np.max(np.hypot(scene.vel[:nm, 0], scene.vel[:nm, 1]))
            if vmax < rest_speed:
                eq = equilibrium_test(scene, h, settings=eq_settings, init="warm",
                                          velocity_tol=c["velocity_tol"])
                if log is not None:
                    log.info("step %d: max speed %.3g m/s, equilibrium test at_rest=%s (max |u_f| = %.3g g h,"
                             " %d sweeps, residual %.2g)", k, vmax, eq.at_rest, eq.max_velocity,
                             eq.result.sweeps, eq.result.residual)
                if eq.at_rest:
                    if not frame_steps or frame_steps[-1] != k:
                        frames.append(_frame(scene, n_target))
                        frame_steps.append(k)
                    if info is not None:
                        info.update(order=order, removed=np.array(removed, float).reshape(-1, 4))
                    return (scene, {key: np.array(v) for key, v in rec.items()}, eq,
                            (np.array(frame_steps, np.int64), np.array(frames).reshape(-1, len(FRAME), n_target)))
        if checkpoint is not None and checkpoint_every > 0 and k % checkpoint_every == 0 and scene is not None:
            write_checkpoint(checkpoint, cfg, k, scene, born, source, rec, frames, frame_steps, order, removed)
    raise SimulationError(f"the pile is not at rest after max_steps = {c['max_steps']} "
                          f"(poured {scene.n_mobile if scene else 0}/{n_target})")


def carry_warm(old, new, mobile_map=None):
    """Give ``new`` the warm-start memory of ``old``: the body-pair keys are re-encoded
    for the new disc count.  ``new`` is ``old`` plus grains appended after its mobile
    discs, or (``mobile_map``: new index of each old mobile grain, -1 if removed) ``old``
    without some grains; the contacts of a removed grain are dropped."""
    if old.prev_keys is None or len(old.prev_keys) == 0:
        return
    base = old.n_disc + 1024   # the key layout of ncd.core.contacts.pair_key
    a, b = np.divmod(old.prev_keys, base)
    impulse = old.prev_impulse
    if mobile_map is not None:
        mobile_b = b < old.n_mobile
        keep = (mobile_map[a] >= 0) & ~(mobile_b & (mobile_map[np.where(mobile_b, b, 0)] < 0))
        a, b, impulse = a[keep], b[keep], impulse[keep]
        b = np.where(b < old.n_mobile, mobile_map[np.minimum(b, old.n_mobile - 1)], b)
        a = mobile_map[a]
    added = new.n_mobile - old.n_mobile
    b = np.where(b >= old.n_mobile, b + added, b)      # obstacles (and walls) shift
    b_new = np.where(b >= new.n_disc, -1 - (b - new.n_disc), b)
    keys = pair_key(a, b_new, new.n_disc)
    order = np.argsort(keys, kind="stable")
    new.prev_keys = keys[order]
    new.prev_impulse = impulse[order]


def remove_grains(scene, keep, scene_factory):
    """A new scene of the mobile grains ``keep`` (a mask) of ``scene``, same time, with
    the warm-start memory of the remaining contacts."""
    nm = scene.n_mobile
    st = [v[:nm][keep] for v in (scene.pos, scene.radius, scene.vel, scene.spin, scene.angle)]
    new = scene_factory(*st)
    new.time = scene.time
    carry_warm(scene, new, np.where(keep, np.cumsum(keep) - 1, -1))
    return new
