"""Inputs an audit found that crashed the interpreter or slipped through: sparse
matrices with a corrupt structure, a scene changed between MD runs, sweep and pivot
budgets beyond int64, Lemke covering vectors, config sections that are not mappings,
a scene whose time is not a number, partial exports.  Reproducers that once crashed run
in a subprocess, so that a regression fails the test instead of killing the runner."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import xarray as xr

import ncd


def run_isolated(code):
    """Run ``code`` in a fresh interpreter; returns (returncode, stdout + stderr)."""
    p = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout + p.stderr


CORRUPT = {
    "csr index far out of range": "W = sp.csr_matrix((A.data, np.array([0, 2**40, 1, 0, 2, 3]), A.indptr), shape=(4, 4))",
    "csr index one past the end": "W = sp.csr_matrix((A.data, np.array([0, 4, 1, 0, 2, 3]), A.indptr), shape=(4, 4))",
    "csc with 1-based indices": "W = A.tocsc(); W.indices = W.indices + 1",
}


@pytest.mark.parametrize("make", CORRUPT.values(), ids=CORRUPT.keys())
def test_solve_local_refuses_a_corrupt_sparse_w(make):
    code, out = run_isolated(f"""
        import numpy as np, scipy.sparse as sp, ncd
        A = sp.csr_matrix(np.array([[2, 0, .1, 0], [0, 2, 0, 0], [.1, 0, 2, 0], [0, 0, 0, 2.]]))
        {make}
        try:
            ncd.solve_local(W, [-1, .5, -1, .2], .3)
            print("ACCEPTED")
        except ncd.InputError as e:
            print("INPUTERROR", e)
        """)
    assert code == 0, out
    assert "INPUTERROR W (" in out and "invalid structure" in out, out


def test_force_polytope_refuses_a_corrupt_sparse_h():
    code, out = run_isolated("""
        import numpy as np, scipy.sparse as sp, ncd
        from ncd.exact.exact_set import ExactSet
        H = sp.csr_matrix(np.ones((3, 4))); H.indices[2] = 99
        for make in (lambda: ncd.exact.polytope.ForcePolytope(H, [1, 1, 1], 0.5), lambda: ExactSet(H, [1, 1, 1], 0.5)):
            try:
                make(); print("ACCEPTED")
            except ncd.InputError as e:
                print("INPUTERROR", e)
        """)
    assert code == 0 and out.count("INPUTERROR H (csr") == 2, out


def test_exact_set_checks_its_arguments():
    from ncd.exact.exact_set import ExactSet
    H = np.array([[1.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 1.0]])
    with pytest.raises(ncd.InputError, match=r"mu must be finite"):
        ExactSet(H, [-1.0, 0.0], np.nan)
    es = ExactSet(H, [-1.0, 0.0], 0.5)
    with pytest.raises(ncd.InputError, match=r"c has shape \(3,\), expected \(4,\)"):
        es.interval(np.ones(3))
    with pytest.raises(ncd.InputError, match=r"c must be finite"):
        es.interval([np.nan, 0, 0, 0])
    with pytest.raises(ncd.InputError, match=r"L has shape"):
        es.polygon(np.ones((3, 4)))
    with pytest.raises(ncd.InputError, match=r"n_dirs = 0 is outside"):
        es.polygon(np.eye(2, 4), n_dirs=0)
    with pytest.raises(ncd.InputError, match=r"contact = 5 is outside \[0, 1\]"):
        es.fp.project(5)
    lo, hi = es.interval([1.0, 0.0, 1.0, 0.0])          # the two normal forces carry the unit load
    assert lo == pytest.approx(1.0) and hi == pytest.approx(1.0)


def test_md_run_checks_the_scene_on_every_call():
    from ncd.dynamics.md import MD, MDParams
    s = ncd.make_scene([[0, .1], [.2, .1], [.1, .27320508]], radius=.1, walls=[((0, 0), (0, 1))])
    md = MD(s, MDParams(k_n=1e5))
    assert md.run(1e-5, 10).steps == 10
    s.vel = np.zeros((1, 2))                           # freed an invalid pointer in the kernel
    with pytest.raises(ncd.InputError, match=r"scene.vel has shape \(1, 2\), expected \(3, 2\)"):
        md.run(1e-5, 10)
    s.vel = np.zeros((3, 2))
    s.wall_point, s.wall_normal = np.zeros((0, 2)), np.zeros((0, 2))   # cached wall contacts: rebuilt
    report = md.run(1e-5, 10)
    assert report.steps == 10 and report.rebuilds == 0
    for args, pattern in (((1e-5, 2.5), r"n_steps = 2\.5 must be an integer"),
                          ((1e-5, 10 ** 30), r"n_steps = 10+ is outside"), (("x", 1), r"h = 'x'")):
        with pytest.raises(ncd.InputError, match=pattern):
            md.run(*args)


@pytest.mark.parametrize("value", [2 ** 63, 2 ** 64, 10 ** 9 + 1])
def test_sweep_budgets_beyond_the_kernels_counters_are_refused(value):
    for field in ("max_sweeps", "check_every"):
        with pytest.raises(ncd.InputError, match=rf"settings.{field} = {value} is outside \[1, 1000000000\]"):
            ncd.SolverSettings(**{field: value})


def test_lemke_checks_covering_budget_and_scale():
    from ncd.solver.lcp import frictional_lcp, lemke
    for kw, pattern in ((dict(covering=[np.inf, 1]), r"covering must be finite"),
                        (dict(covering=[1e-320, 1]), r"covering must be 2 positive numbers >= 1e-150"),
                        (dict(max_pivots=2.7), r"max_pivots = 2\.7 must be an integer"),
                        (dict(max_pivots=2 ** 63), r"max_pivots = \d+ is outside")):
        with pytest.raises(ncd.InputError, match=pattern):
            lemke(np.eye(2), [-1, -1], **kw)
    with pytest.raises(ncd.InputError, match=r"M has an entry of size 1e\+308"):
        lemke(1e308 * np.eye(2), [-1, -1])
    with pytest.raises(ncd.InputError, match=r"M must hold real numbers"):
        lemke((1 + 1j) * np.eye(2), [-1, -1])
    with pytest.raises(ncd.InputError, match=r"mu must be >= 0"):
        frictional_lcp(np.eye(2), [1, 1], -1)
    z, info = lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), [-1.0, -1.0])
    assert info["status"] == "solution" and np.allclose(z, [1 / 3, 1 / 3]) and info["residual"] < 1e-14


@pytest.mark.parametrize("section", [None, 5, [1, 2]])
def test_config_section_that_is_not_a_mapping(section):
    import copy
    from pathlib import Path

    import yaml

    from ncd.pipeline.config import ConfigError, check_config
    root = Path(__file__).resolve().parents[1]
    cfg = copy.deepcopy(yaml.safe_load((root / "config.yaml").read_text()))
    cfg["fig1_wedged"] = section
    with pytest.raises(ConfigError, match=r"config section 'fig1_wedged' must be a mapping"):
        check_config(cfg, ["fig1_wedged"], root / "workflow" / "schemas")


def test_config_checker_refuses_what_it_cannot_read(tmp_path):
    from pathlib import Path

    from ncd.pipeline.config import ConfigError, check_config
    root = Path(__file__).resolve().parents[1]
    with pytest.raises(ConfigError, match=r"must be a mapping of sections; got NoneType"):
        check_config(None, [], root / "workflow" / "schemas")
    with pytest.raises(ConfigError, match=r"is not a directory"):
        check_config({}, [], tmp_path / "absent")
    loop = {}
    loop["a"] = loop
    with pytest.raises(ConfigError, match=r"nests too deeply"):
        check_config({"x": loop}, [], root / "workflow" / "schemas")
    with pytest.raises(ConfigError, match=r"an integer of 401 digits: not a finite number"):
        check_config({"x": {"h": 10 ** 400}}, [], root / "workflow" / "schemas")


@pytest.mark.parametrize("time", [np.nan, "0.1", np.inf])
def test_scene_time_is_checked_before_anything_moves(time):
    s = ncd.make_scene([[0.0, 0.5]], 0.5, walls=[((0.0, 0.0), (0.0, 1.0))])
    s.time = time
    pos = s.pos.copy()
    with pytest.raises(ncd.InputError, match=r"scene.time = .* must be a finite real number"):
        ncd.step(s, 1e-3)
    np.testing.assert_array_equal(s.pos, pos)


def test_a_period_shrunk_below_three_diameters_is_named():
    s = ncd.make_scene([[0.0, 0.5], [1.5, 0.5]], 0.5, walls=[((0.0, 0.0), (0.0, 1.0))], period=10.0)
    s.period = 2.0
    with pytest.raises(ncd.InputError, match=r"scene\.period = 2\.0 must be at least three largest diameters"):
        ncd.step(s, 1e-3)


def test_outside_distance_with_a_repeated_vertex():
    from ncd.exact.polygon import outside_distance
    square = [[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]]
    assert outside_distance([[5, 5]], square)[0] == pytest.approx(np.hypot(4, 4))
    assert outside_distance([[0.5, 0.5]], square)[0] == 0.0
    with pytest.raises(ValueError, match="finite"):
        outside_distance([[np.nan, 0]], square)


def test_merge_refuses_repeated_members(tmp_path):
    from ncd.io.netcdf import merge_shards
    ds = xr.Dataset({"x": ("run", np.arange(3.0))}, coords={"run": np.arange(3)})
    ds.to_netcdf(tmp_path / "a.nc")
    with pytest.raises(ValueError, match=r"repeat run \[0, 1, 2\]"):
        merge_shards([tmp_path / "a.nc", tmp_path / "a.nc"])


def test_a_failed_vtk_export_leaves_the_old_one_intact(tmp_path, monkeypatch):
    from ncd.io import export
    frames = 3
    ds = xr.Dataset({"frame_time": ("frame", np.arange(frames) * 0.1),
                     "frame_x": (("frame", "disc"), np.zeros((frames, 2))),
                     "frame_y": (("frame", "disc"), np.ones((frames, 2))),
                     "radius": ("disc", np.full(2, 0.5))})
    try:
        export.frame_prefix(ds)
    except Exception:
        pytest.skip("frame layout of this export differs from the synthetic one")
    first = export.write_vtk(ds, tmp_path, "flow")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real = export.frame_discs

    def broken(d, prefix, i):
        if i == 2:
            raise RuntimeError("disk full")
        return real(d, prefix, i)
    monkeypatch.setattr(export, "frame_discs", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        export.write_vtk(ds, tmp_path, "flow")
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert after == before and [p.name for p in first][0] in after


def test_huge_wall_normals_are_normalised_and_coincident_centres_refused():
    s = ncd.make_scene([[0.0, 1.0]], 0.5, walls=[((0, 0), (1e300, 1e300)), ((0, -5), (0.3, 0.7))])
    np.testing.assert_allclose(s.wall_normal, [[2 ** -0.5, 2 ** -0.5], np.array([0.3, 0.7]) / np.hypot(0.3, 0.7)],
                               rtol=1e-15)
    with pytest.raises(ncd.InputError, match=r"discs 0 and 1 have coincident centres"):
        ncd.make_scene([[0.0, 1.0], [0.0, 1.0]], 0.5, overlap_tolerance=np.inf)


def test_unsorted_warm_start_keys_and_a_lone_obstacle_radius_are_refused():
    with pytest.raises(ncd.InputError, match=r"obstacle_radius = 0.5 is given without obstacle_pos"):
        ncd.make_scene([[0.0, 1.0]], 0.5, obstacle_radius=0.5)
    s = ncd.make_scene([[0.0, 0.5], [1.0, 0.5]], 0.5, walls=[((0.0, 0.0), (0.0, 1.0))])
    ncd.step(s, 1e-3)
    assert len(s.prev_keys) == 3 and np.all(np.diff(s.prev_keys) > 0)
    s.prev_keys, s.prev_impulse = s.prev_keys[::-1].copy(), s.prev_impulse[::-1].copy()
    pos = s.pos.copy()
    with pytest.raises(ncd.InputError, match=r"scene.prev_keys must increase strictly"):
        ncd.step(s, 1e-3)
    np.testing.assert_array_equal(s.pos, pos)


def test_an_inverse_mass_that_is_not_one_over_the_mass_is_named():
    s = ncd.make_scene([[0.0, 0.5], [1.5, 2.0]], 0.5, walls=[((0.0, 0.0), (0.0, 1.0))])
    s.inv_mass[1] = 2.0 * s.inv_mass[1]          # the solver would move a disc of another mass
    pos = s.pos.copy()
    with pytest.raises(ncd.InputError, match=r"scene\.inv_mass\[1\] = .* is not 1 / mass\[1\]"):
        ncd.step(s, 1e-3)
    np.testing.assert_array_equal(s.pos, pos)
    s.inv_mass[1] = 1.0 / s.mass[1]
    ncd.step(s, 1e-3)                               # consistent again: it steps
    assert s.pos[1, 1] < pos[1, 1]
