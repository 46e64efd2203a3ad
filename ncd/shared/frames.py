"""Stored frames of a flow (Figure 2's ``flow.snapshot_every``): disc states and the
contact network with its forces, as arrays for :mod:`ncd.io.export` (VTK, animations)."""
import numpy as np
import xarray as xr

from ncd.core.contacts import match_warm
from ncd.dynamics.stepper import prepare_step


def frame_state(scene, h):
    """A stored frame of the flow (``flow.snapshot_every``): disc states and the contact
    network at the current positions, with the forces r = s/h of the last step (matched
    by body pair).  Each contact is a segment from the centre of ``a`` to the centre of
    ``b``'s (periodic) image, or to the contact point for a wall."""

    nm = scene.n_mobile
    problem = prepare_step(scene, h)
    c = problem.contacts
    if scene.prev_keys is None:
        imp = np.zeros((c.n, 2))
    else:
        imp = match_warm(c, scene.prev_keys, scene.prev_impulse)
    a = scene.pos[c.body_a]
    rb = np.where(c.body_b >= 0, scene.radius[np.maximum(c.body_b, 0)], 0.0)
    b = a - c.normal * (scene.radius[c.body_a] + rb + c.gap)[:, None]
    b = np.where((c.body_b >= 0)[:, None], b, c.point)
    return {"pos": scene.pos[:nm].copy(), "vel": scene.vel[:nm].copy(), "spin": scene.spin[:nm].copy(),
            "angle": scene.angle[:nm].copy(), "time": scene.time, "body_a": c.body_a.copy(),
            "body_b": c.body_b.copy(), "force_n": imp[:, 0] / h, "force_t": imp[:, 1] / h,
            "a": a.copy(), "b": b.copy()}


def frames_dataset(frames, steps, t0=0.0):
    """Stored frames as arrays over ``frame`` x ``disc`` and ``frame`` x ``frame_contact``
    (contacts padded with -1 / NaN): the input of :mod:`ncd.io.export`."""
    nf, nd = len(frames), (frames[0]["pos"].shape[0] if frames else 0)
    nc = max((len(f["body_a"]) for f in frames), default=0)
    pad_i, pad_f = np.full((nf, nc), -1, np.int64), np.full((nf, nc), np.nan)
    cols = {k: pad_i.copy() for k in ("body_a", "body_b")}
    cols.update({k: pad_f.copy() for k in ("force_n", "force_t", "a_x", "a_y", "b_x", "b_y")})
    for i, f in enumerate(frames):
        n = len(f["body_a"])
        for k in ("body_a", "body_b", "force_n", "force_t"):
            cols[k][i, :n] = f[k]
        for end in ("a", "b"):
            cols[f"{end}_x"][i, :n], cols[f"{end}_y"][i, :n] = f[end][:, 0], f[end][:, 1]
    st = lambda k, j=None: np.array([f[k] if j is None else f[k][:, j] for f in frames]).reshape(nf, nd)  # noqa: E731
    fc = ("frame", "frame_contact")
    data = {
        "frame_pos_x": (("frame", "disc"), st("pos", 0), {"units": "m", "long_name": "x of the disc centre"}),
        "frame_pos_y": (("frame", "disc"), st("pos", 1), {"units": "m", "long_name": "y of the disc centre"}),
        "frame_vel_x": (("frame", "disc"), st("vel", 0), {"units": "m s-1", "long_name": "x velocity"}),
        "frame_vel_y": (("frame", "disc"), st("vel", 1), {"units": "m s-1", "long_name": "y velocity"}),
        "frame_spin": (("frame", "disc"), st("spin"), {"units": "s-1", "long_name": "angular velocity"}),
        "frame_angle": (("frame", "disc"), st("angle"), {"units": "rad", "long_name": "rotation angle"}),
        "frame_body_a": (fc, cols["body_a"], {"units": "1", "long_name": "first body of the contact (-1: padding)"}),
        "frame_body_b": (fc, cols["body_b"], {"units": "1", "long_name": "second body (disc, or -1 - wall index)"}),
        "frame_force_n": (fc, cols["force_n"], {"units": "N", "long_name": "normal contact force of the last step"}),
        "frame_force_t": (fc, cols["force_t"], {"units": "N", "long_name": "tangential contact force of the last step"}),
        "frame_line_x0": (fc, cols["a_x"], {"units": "m", "long_name": "x of the centre of body a"}),
        "frame_line_y0": (fc, cols["a_y"], {"units": "m", "long_name": "y of the centre of body a"}),
        "frame_line_x1": (fc, cols["b_x"], {"units": "m", "long_name": "x of the centre of body b's image"}),
        "frame_line_y1": (fc, cols["b_y"], {"units": "m", "long_name": "y of the centre of body b's image"}),
    }
    coords = {"frame": ("frame", np.arange(nf), {"units": "1", "long_name": "stored frame index"}),
              "frame_step": ("frame", np.asarray(steps, np.int64), {"units": "1", "long_name": "flow step of the frame"}),
              "frame_time": ("frame", np.array([f["time"] - t0 for f in frames]),
                             {"units": "s", "long_name": "time since release"})}
    return xr.Dataset(data, coords=coords)
