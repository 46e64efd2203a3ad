"""Ensembles are reproducible member by member; netCDF output is whole or absent."""
import numpy as np
import pytest
import xarray as xr

import ncd
from ncd.dynamics.explore import explore, member_rng, shard_members
from ncd.io.netcdf import merge_shards, provenance, write_dataset


def _small_packing():
    """Five discs in a box, settled: a statically indeterminate little problem."""
    pos = [[0.5, 0.5], [1.5, 0.5], [1.0, 1.37], [2.5, 0.5], [2.0, 1.37]]
    scene = ncd.make_scene(pos, 0.5, 1.0, walls=[((0, 0), (0, 1)), ((0, 0), (1, 0)), ((3, 0), (-1, 0))],
                           mu=0.5, overlap_tolerance=0.5)
    for _ in range(400):
        ncd.step(scene, 2e-3, settings=ncd.SolverSettings(tol=1e-10))
    return scene


@pytest.fixture(scope="module")
def packing():
    return _small_packing()


def test_shards_reproduce_the_single_run_bit_for_bit(packing):
    problem = ncd.prepare_step(packing, 1e-3, vel=np.zeros_like(packing.vel), spin=np.zeros_like(packing.spin))
    settings = ncd.SolverSettings(tol=1e-10)
    whole = explore(packing, problem, np.arange(12), 7, init="random", guess_scale=0.05, settings=settings)
    parts = [explore(packing, problem, shard_members(12, k, 3), 7, init="random", guess_scale=0.05,
                     settings=settings) for k in range(3)]
    for key in ("impulse", "vel", "spin", "sweeps", "residual", "converged"):
        np.testing.assert_array_equal(whole[key], np.concatenate([p[key] for p in parts]))
    assert whole["converged"].all()
    assert np.all(whole["residual"] <= 1e-10)
    # members differ from each other (random orders and guesses are really drawn)
    assert len({tuple(member_rng(m, 7).permutation(problem.contacts.n)) for m in range(12)}) > 1


def test_shard_members_partition():
    parts = [shard_members(101, k, 4) for k in range(4)]
    np.testing.assert_array_equal(np.concatenate(parts), np.arange(101))
    with pytest.raises(ValueError, match="shard 4"):
        shard_members(10, 4, 4)


def test_write_is_atomic_and_refuses_inf(tmp_path):
    ds = xr.Dataset({"x": ("run", np.array([1.0, np.inf]))})
    target = tmp_path / "out.nc"
    with pytest.raises(ValueError, match="variable x"):
        write_dataset(ds, target)
    assert list(tmp_path.iterdir()) == []


def test_merge_and_provenance(tmp_path):
    attrs = provenance({"mu": 0.5}, ncd.SolverSettings(tol=1e-9), root_seed=3)
    assert "mu: 0.5" in attrs["config_yaml"] and attrs["solver_tol"] == 1e-9
    assert attrs["ncd_version"] == ncd.__version__ and attrs["git_commit"]
    assert not any("date" in k or "time" in k for k in attrs)
    paths = []
    for k, members in enumerate((np.arange(3, 6), np.arange(0, 3))):
        ds = xr.Dataset({"v": ("run", members * 2.0)}, coords={"run": members}, attrs=attrs)
        paths.append(tmp_path / f"s{k}.nc")
        write_dataset(ds, paths[-1])
    merged = merge_shards(paths)
    np.testing.assert_array_equal(merged["run"], np.arange(6))
    np.testing.assert_array_equal(merged["v"], np.arange(6) * 2.0)
