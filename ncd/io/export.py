"""ParaView and animation output of stored frames (``frame`` x ``disc`` arrays).

Input: a dataset with a ``frame`` dimension holding, per frame, the discs
(``<p>pos_x``, ``<p>pos_y`` over ``disc``; optional ``<p>vel_x``, ``<p>vel_y``,
``<p>spin``, ``<p>angle``) and optionally the contact network (``<p>line_x0``,
``<p>line_y0``, ``<p>line_x1``, ``<p>line_y1``, ``<p>force_n``, ``<p>force_t`` over a
padded contact dimension, NaN where absent), with ``<p>`` a prefix (``frame_`` in
fig2's trajectory), and ``radius`` over ``disc``.  The construction files of Figure 4
(:mod:`ncd.shared.construction`) name the same quantities ``frame_x``, ``frame_y``,
``frame_vx``, ``frame_vy``, ``frame_spin`` and ``frame_radius`` (``frame`` x ``disc``, NaN
for a grain not yet poured: such discs are left out of the frame), with the fixed ground
discs in ``ground_x``, ``ground_y``, ``ground_radius``.

- :func:`write_vtk`: one VTK unstructured-grid file (``.vtu``) per frame for the discs
  (vertices with radius, velocity, spin) and one for the contacts (lines with normal
  and tangential force), both written by ``meshio``, and a ``.pvd``
  collection of each (``pyevtk.vtk.VtkGroup``) with the frames' times: open the ``.pvd`` in ParaView,
  then Glyph (sphere, scale by ``radius``) and Tube (by ``force_n``).
- :func:`animate`: the discs and the force chains (line width proportional to the
  normal force) as an mp4 through matplotlib and ffmpeg, or an animated GIF
  through Pillow when ffmpeg is absent.
"""
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

# alternative names of the frame variables (Figure 4's construction files)
ALIAS = {"pos_x": "x", "pos_y": "y", "vel_x": "vx", "vel_y": "vy"}


class ExportError(ValueError):
    """The dataset has no stored frames (or not the variables named in the module doc)."""


def frame_prefix(ds):
    """The prefix of the frame variables (``frame_`` or ``""``), or raise :class:`ExportError`."""
    for prefix in ("frame_", "snapshot_", ""):
        for name in ("pos_x", "x"):
            var = ds.get(f"{prefix}{name}")
            if var is not None and "frame" in var.dims:
                return prefix
    raise ExportError("no frame variables (pos_x over frame x disc): were frames stored? "
                      "(fig2_slope: flow.snapshot_every > 0; fig4_pile: construction.frame_every > 0)")


def frame_times(ds, prefix):
    for name in (f"{prefix}time", "frame_time", "time"):
        if name in ds.coords or name in ds.data_vars:
            t = ds[name]
            if t.dims == ("frame",):
                return np.asarray(t.values, float)
    return np.arange(ds.sizes["frame"], dtype=float)


def _get(ds, prefix, name, i):
    v = ds.get(f"{prefix}{name}")
    if v is None and name in ALIAS:
        v = ds.get(f"{prefix}{ALIAS[name]}")
    return None if v is None else np.asarray(v.isel(frame=i).values, float)


def frame_discs(ds, prefix, i):
    """``(x, y, radius, present)`` of frame ``i``: the discs with finite centres
    (``present``, a mask over ``disc``) and their radii (per frame if stored)."""
    x, y = _get(ds, prefix, "pos_x", i), _get(ds, prefix, "pos_y", i)
    r = _get(ds, prefix, "radius", i)
    r = np.asarray(ds["radius"].values, float) if r is None else r
    present = np.isfinite(x) & np.isfinite(y) & np.isfinite(r)
    return x[present], y[present], r[present], present


def _all_frames(ds, prefix, name):
    v = ds.get(f"{prefix}{name}")
    return ds[f"{prefix}{ALIAS[name]}"].values if v is None else v.values


def write_ground(ds, path):
    """The fixed ground discs (``ground_x``, ``ground_y``, ``ground_radius``) as one ``.vtu``."""
    import meshio

    x, y = ds["ground_x"].values.astype(float), ds["ground_y"].values.astype(float)
    pts = np.column_stack([x, y, np.zeros_like(x)])
    meshio.write(path, meshio.Mesh(pts, [("vertex", np.arange(len(x)).reshape(-1, 1))],
                                   point_data={"radius": np.ascontiguousarray(ds["ground_radius"].values, float)}),
                 binary=True)
    return Path(path)


def write_vtk(ds, outdir, name="flow"):
    """Write ``<outdir>/<name>_discs_<i>.vtu``, ``<name>_contacts_<i>.vtu`` and the two ``.pvd``
    collections (and ``<name>_ground.vtu`` if the dataset has ground discs); returns
    the paths of the collections (then of the ground file).  All or nothing: the files
    are written in a temporary folder of ``outdir`` and moved into place at the end
    (frames of an earlier, longer export under the same name are removed)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{name}_", dir=outdir))
    try:
        out = _write_vtk(ds, tmp, name)
        new = {f.name for f in tmp.iterdir()}
        for old in list(outdir.glob(f"{name}_discs_*.vtu")) + list(outdir.glob(f"{name}_contacts_*.vtu")):
            if old.name not in new:
                old.unlink()
        for f in sorted(tmp.iterdir()):
            os.replace(f, outdir / f.name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return [outdir / p.name for p in out]


def _write_vtk(ds, outdir, name):
    import meshio
    from pyevtk.vtk import VtkGroup

    prefix = frame_prefix(ds)
    times = frame_times(ds, prefix)
    discs = VtkGroup(str(outdir / f"{name}_discs"))
    lines = VtkGroup(str(outdir / f"{name}_contacts")) if f"{prefix}line_x0" in ds else None
    for i in range(ds.sizes["frame"]):
        x, y, radius, present = frame_discs(ds, prefix, i)
        z = np.zeros_like(x)
        zero = np.zeros_like(x)
        vx, vy = (_get(ds, prefix, "vel_x", i), _get(ds, prefix, "vel_y", i))
        data = {"radius": np.ascontiguousarray(radius)}
        if vx is not None:
            data["velocity"] = (np.ascontiguousarray(vx[present]), np.ascontiguousarray(vy[present]), zero.copy())
        for extra in ("spin", "angle"):
            val = _get(ds, prefix, extra, i)
            if val is not None:
                data[extra] = np.ascontiguousarray(val[present])
        pts = np.column_stack([x, y, z])
        point_data = {k: (np.column_stack(v) if isinstance(v, tuple) else v) for k, v in data.items()}
        path = outdir / f"{name}_discs_{i:04d}.vtu"
        meshio.write(path, meshio.Mesh(pts, [("vertex", np.arange(len(x)).reshape(-1, 1))],
                                       point_data=point_data), binary=True)
        discs.addFile(filepath=str(Path(path).resolve()), sim_time=float(times[i]))
        if lines is not None:
            x0, y0, x1, y1 = (_get(ds, prefix, k, i) for k in ("line_x0", "line_y0", "line_x1", "line_y1"))
            ok = np.isfinite(x0) & np.isfinite(x1)
            lx = np.ascontiguousarray(np.column_stack([x0[ok], x1[ok]]).ravel())
            ly = np.ascontiguousarray(np.column_stack([y0[ok], y1[ok]]).ravel())
            cell = {k: np.ascontiguousarray(_get(ds, prefix, k, i)[ok])
                    for k in ("force_n", "force_t") if f"{prefix}{k}" in ds}
            pts = np.column_stack([lx, ly, np.zeros_like(lx)])
            conn = np.arange(len(lx)).reshape(-1, 2)
            path = outdir / f"{name}_contacts_{i:04d}.vtu"
            meshio.write(path, meshio.Mesh(pts, [("line", conn)], cell_data={k: [v] for k, v in cell.items()}),
                         binary=True)
            lines.addFile(filepath=str(Path(path).resolve()), sim_time=float(times[i]))
    discs.save()
    out = [outdir / f"{name}_discs.pvd"]
    if lines is not None:
        lines.save()
        out.append(outdir / f"{name}_contacts.pvd")
    if "ground_x" in ds:
        out.append(write_ground(ds, outdir / f"{name}_ground.vtu"))
    return out


def animation_writer(fps):
    """matplotlib's ffmpeg writer when ffmpeg is on PATH, else Pillow's (animated GIF)."""
    from matplotlib import animation

    if shutil.which("ffmpeg") and animation.FFMpegWriter.isAvailable():
        return animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"]), "mp4"
    return animation.PillowWriter(fps=fps), "gif"


def animate(ds, path, fps=10, title="", period=None, dpi=100):
    """The frames as a movie: discs (grey) and force chains (lines, width ∝ normal force).
    ``path``'s suffix is replaced by the writer's (``.mp4`` or ``.gif``); returns the path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation
    from matplotlib.collections import EllipseCollection, LineCollection

    prefix = frame_prefix(ds)
    writer, ext = animation_writer(fps)
    path = Path(path).with_suffix(f".{ext}")
    path.parent.mkdir(parents=True, exist_ok=True)
    times = frame_times(ds, prefix)
    xs, ys = _all_frames(ds, prefix, "pos_x"), _all_frames(ds, prefix, "pos_y")
    radius = ds[f"{prefix}radius"].values if f"{prefix}radius" in ds else np.asarray(ds["radius"].values, float)
    rmax = float(np.nanmax(radius))
    has_ground = "ground_x" in ds
    has_lines = f"{prefix}line_x0" in ds
    fmax = float(np.nanmax(ds[f"{prefix}force_n"].values)) if has_lines else 1.0
    fmax = fmax if np.isfinite(fmax) and fmax > 0 else 1.0
    xmin, xmax = (0.0, period) if period else (np.nanmin(xs) - rmax, np.nanmax(xs) + rmax)
    ymin, ymax = min(0.0, np.nanmin(ys) - rmax) - (rmax if has_ground else 0.0), np.nanmax(ys) + rmax
    width = 10.0
    height = max(2.0, width * (ymax - ymin) / (xmax - xmin)) + 0.6
    height = 2 * round(height * dpi / 2) / dpi  # even pixel sizes (H.264 with yuv420p needs them)
    fig, ax = plt.subplots(figsize=(width, height))
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    if has_ground:
        g = 2 * ds["ground_radius"].values
        ax.add_collection(EllipseCollection(g, g, np.zeros_like(g), units="xy", offset_transform=ax.transData,
                                            offsets=np.column_stack([ds["ground_x"].values, ds["ground_y"].values]),
                                            facecolor="0.45", edgecolor="0.3", linewidth=0.3))
    x0, y0, r0, _ = frame_discs(ds, prefix, 0)
    discs = EllipseCollection(2 * r0, 2 * r0, np.zeros_like(r0), units="xy", offsets=np.column_stack([x0, y0]),
                              offset_transform=ax.transData, facecolor="0.85", edgecolor="0.5", linewidth=0.3)
    ax.add_collection(discs)
    chains = LineCollection([], colors="firebrick")
    ax.add_collection(chains)
    label = ax.set_title(title)

    def draw(i):
        x, y, r, _ = frame_discs(ds, prefix, i)
        discs.set_widths(2 * r)
        discs.set_heights(2 * r)
        discs.set_angles(np.zeros_like(r))
        discs.set_offsets(np.column_stack([x, y]))
        if has_lines:
            x0, y0, x1, y1 = (ds[f"{prefix}{k}"].values[i] for k in ("line_x0", "line_y0", "line_x1", "line_y1"))
            f = ds[f"{prefix}force_n"].values[i]
            ok = np.isfinite(x0) & np.isfinite(f) & (f > 0)
            if period:  # a chain across the periodic boundary: drawn from a's side only
                ok &= np.abs(x1 - x0) < 0.5 * period
            chains.set_segments(np.stack([np.column_stack([x0[ok], y0[ok]]), np.column_stack([x1[ok], y1[ok]])], 1))
            chains.set_linewidths(0.2 + 3.0 * f[ok] / fmax)
        label.set_text(f"{title}  t = {times[i]:.3f} s".strip() if times[-1] >= 1 else
                       f"{title}  t = {1e3 * times[i]:.1f} ms".strip())
        return discs, chains, label

    anim = animation.FuncAnimation(fig, draw, frames=ds.sizes["frame"], blit=False)
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}_", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:                                        # all or nothing: a failed encoding keeps the old file
        anim.save(tmp, writer=writer, dpi=dpi)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
