"""scripts/compare_results.py: two results/ trees compared file by file, measured times aside."""
import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

SCRIPT = Path(__file__).resolve().parent.parent / "scripts" / "compare_results.py"


def load():
    spec = importlib.util.spec_from_file_location("compare_results", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def dataset(**change):
    ds = xr.Dataset({"force_n": ("run", np.array([1.0, np.nan, 3.0])),
                     "wall_time": ("run", np.array([0.5, 0.6, 0.7])),
                     "wall_point_x": ("wall", np.array([0.0, 1.0]))},
                    coords={"run": np.arange(3), "wall": np.arange(2)},
                    attrs={"mu": 0.5, "git_commit": "abc", "construction_wall_time": 12.0})
    ds["force_n"].attrs["units"] = "N"
    for key, value in change.items():
        target, name = key.split("__") if "__" in key else ("", key)
        if target == "var":
            ds[name] = ("run", value)
        else:
            ds.attrs[name] = value
    return ds


def tree(root, ds, name="fig/data.nc"):
    path = root / name
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path)
    return root


def run(a, b, *args):
    return subprocess.run([sys.executable, str(SCRIPT), str(a), str(b), *args], capture_output=True, text=True, check=False)


def test_identical_trees(tmp_path):
    a, b = tree(tmp_path / "a", dataset()), tree(tmp_path / "b", dataset())
    out = run(a, b)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "fig/data.nc: identical" in out.stdout and "1 identical, 0 differ" in out.stdout
    assert "git_commit" in out.stdout     # the ignored keys are printed


def test_a_changed_value_differs(tmp_path):
    a = tree(tmp_path / "a", dataset())
    b = tree(tmp_path / "b", dataset(var__force_n=np.array([1.0, np.nan, 3.5])))
    out = run(a, b)
    assert out.returncode == 1
    assert "differs" in out.stdout and "force_n" in out.stdout and "0.5" in out.stdout


def test_nan_position_and_geometry_named_wall_differ(tmp_path):
    a = tree(tmp_path / "a", dataset())
    b = tree(tmp_path / "b", dataset(var__force_n=np.array([1.0, 2.0, 3.0])))
    assert run(a, b).returncode == 1
    ds = dataset()
    ds["wall_point_x"] = ("wall", np.array([0.0, 2.0]))
    c = tree(tmp_path / "c", ds)
    out = run(a, c)
    assert out.returncode == 1 and "wall_point_x" in out.stdout


def test_only_measured_times_and_commit_changed_is_identical(tmp_path):
    a = tree(tmp_path / "a", dataset())
    b = tree(tmp_path / "b", dataset(var__wall_time=np.array([9.0, 9.0, 9.0]), construction_wall_time=99.0,
                                     git_commit="def+dirty"))
    out = run(a, b)
    assert out.returncode == 0, out.stdout
    assert "wall_time" in out.stdout.split("ignored keys:")[1]


def test_changed_attribute_and_missing_file(tmp_path):
    a = tree(tmp_path / "a", dataset())
    b = tree(tmp_path / "b", dataset(mu=0.6))
    out = run(a, b)
    assert out.returncode == 1 and "attr mu" in out.stdout
    tree(tmp_path / "a", dataset(), "fig/extra.nc")
    tree(tmp_path / "b", dataset(), "benchmarks/ignored.nc")    # benchmarks/ is never compared
    out = run(a, tmp_path / "b")
    assert "fig/extra.nc: only in" in out.stdout and "ignored.nc" not in out.stdout


def test_value_difference_types():
    diff = load().value_difference
    assert diff(np.array([1, 2], np.int32), np.array([1, 2], np.int64)).startswith("dtype")
    assert diff("abc", "abc") is None and "differ" in diff(["a", "b"], ["a", "c"])
    assert diff(np.array([np.nan, 1.0]), np.array([np.nan, 1.0])) is None


@pytest.mark.parametrize("bad", ["missing"])
def test_usage_error(tmp_path, bad):
    out = run(tmp_path / bad, tmp_path)
    assert out.returncode == 2
