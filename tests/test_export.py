"""ncd.io.export: stored frames to VTK (ParaView) and to an animation, values preserved."""
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import xarray as xr

from ncd.io.export import ExportError, animate, write_vtk
from ncd.shared.frames import frames_dataset


def _frames(n_frames=3, n_discs=4):
    rng = np.random.default_rng(1)
    frames = []
    for i in range(n_frames):
        pos = rng.random((n_discs, 2))
        n_c = 2 + i  # the contact count changes from frame to frame
        frames.append({"pos": pos, "vel": rng.random((n_discs, 2)), "spin": rng.random(n_discs),
                       "angle": rng.random(n_discs), "time": 0.1 * (i + 1),
                       "body_a": np.arange(n_c) % n_discs, "body_b": -np.ones(n_c, int),
                       "force_n": np.arange(1.0, n_c + 1), "force_t": -np.arange(n_c) * 0.1,
                       "a": pos[np.arange(n_c) % n_discs], "b": pos[np.arange(n_c) % n_discs] + 0.05})
    ds = frames_dataset(frames, [2, 4, 6])
    return ds.assign(radius=("disc", np.full(n_discs, 0.05))), frames


def test_frames_are_padded_and_described():
    ds, frames = _frames()
    assert ds.sizes["frame"] == 3 and ds.sizes["frame_contact"] == 4
    np.testing.assert_array_equal(ds.frame_body_a.values[0], [0, 1, -1, -1])
    assert np.isnan(ds.frame_force_n.values[0, 2:]).all()
    for name, var in ds.data_vars.items():
        if name.startswith("frame_"):
            assert var.attrs["units"] and var.attrs["long_name"], name


def test_vtk_series_round_trip(tmp_path):
    ds, frames = _frames()
    discs, contacts = write_vtk(ds, tmp_path, "flow")
    for pvd in (discs, contacts):
        files = [e.attrib for e in ET.parse(pvd).getroot().iter("DataSet")]
        assert [float(f["timestep"]) for f in files] == pytest.approx([0.1, 0.2, 0.3])
        assert all((tmp_path / f["file"]).exists() for f in files)
    m = meshio.read(tmp_path / "flow_discs_0001.vtu")
    np.testing.assert_allclose(m.points[:, :2], frames[1]["pos"])
    np.testing.assert_allclose(m.point_data["velocity"][:, :2], frames[1]["vel"])
    np.testing.assert_allclose(m.point_data["spin"], frames[1]["spin"])
    c = meshio.read(tmp_path / "flow_contacts_0002.vtu")
    assert len(c.cells[0].data) == 4
    np.testing.assert_allclose(c.cell_data["force_n"][0], [1, 2, 3, 4])
    np.testing.assert_allclose(c.points[c.cells[0].data[3], :2], [frames[2]["a"][3], frames[2]["b"][3]])


def _frame_count(path):
    """Frames of a GIF (Pillow) or of an mp4 (ffprobe, decoding every frame)."""
    if path.suffix == ".gif":
        from PIL import Image

        with Image.open(path) as im:
            return im.n_frames
    import subprocess

    out = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                          "stream=nb_read_frames", "-of", "csv=p=0", str(path)], capture_output=True, text=True)
    return int(out.stdout.strip())


def test_animation_has_every_frame(tmp_path):
    ds, _ = _frames()
    path = animate(ds, tmp_path / "movie.mp4", fps=5)
    assert path.exists() and path.stat().st_size > 1000
    assert _frame_count(path) == 3


def test_no_frames_is_a_clear_error(tmp_path):
    with pytest.raises(ExportError, match="snapshot_every"):
        write_vtk(xr.Dataset({"pos_x": ("disc", np.zeros(2))}), tmp_path)


def _construction(n_frames=3, n_discs=5):
    """A construction file of Figure 4 with frames (ncd.shared.construction.add_frames):
    grains poured one frame after another (NaN until poured), ground discs."""
    from ncd.shared.construction import FRAME, add_frames

    rng = np.random.default_rng(2)
    fr = np.full((n_frames, len(FRAME), n_discs), np.nan)
    for i in range(n_frames):
        k = 2 + i  # grains poured so far
        fr[i, :, :k] = rng.random((len(FRAME), k))
        fr[i, FRAME.index("radius"), :k] = 0.01 + 0.001 * np.arange(k)
    ds = xr.Dataset({"x": ("grain", fr[-1, 0]), "radius": ("grain", fr[-1, 2]),
                     "ground_x": ("ground", [0.0, 0.02, 0.04]), "ground_y": ("ground", np.zeros(3)),
                     "ground_radius": ("ground", np.full(3, 0.01))})
    return add_frames(ds, (100 * np.arange(1, n_frames + 1), fr), 3e-4), fr


def test_construction_frames_to_vtk(tmp_path):
    ds, fr = _construction()
    assert ds["frame_time"].values == pytest.approx([0.03, 0.06, 0.09])
    assert all(ds[f"frame_{q}"].attrs["units"] for q in ("x", "vx", "spin"))
    discs, ground = write_vtk(ds, tmp_path, "construction")
    files = [e.attrib for e in ET.parse(discs).getroot().iter("DataSet")]
    assert [float(f["timestep"]) for f in files] == pytest.approx([0.03, 0.06, 0.09])
    for i in range(3):  # only the grains poured by frame i, with their frame's values
        m = meshio.read(tmp_path / f"construction_discs_{i:04d}.vtu")
        k = 2 + i
        assert len(m.points) == k
        np.testing.assert_allclose(m.points[:, 0], fr[i, 0, :k])
        np.testing.assert_allclose(m.points[:, 1], fr[i, 1, :k])
        np.testing.assert_allclose(m.point_data["radius"], fr[i, 2, :k])
        np.testing.assert_allclose(m.point_data["velocity"][:, :2], fr[i, 3:5, :k].T)
        np.testing.assert_allclose(m.point_data["spin"], fr[i, 5, :k])
    g = meshio.read(ground)
    np.testing.assert_allclose(g.points[:, 0], [0.0, 0.02, 0.04])
    np.testing.assert_allclose(g.point_data["radius"], 0.01)


def test_construction_animation_has_every_frame(tmp_path):
    ds, _ = _construction(n_frames=4)
    path = animate(ds, tmp_path / "pile.mp4", fps=5)
    assert path.exists() and path.stat().st_size > 1000
    assert _frame_count(path) == 4
