"""Every netCDF output of a run is self-describing (CF-style) and compressed, and its
ensemble shards were removed after merging (``temp()``)."""
import netCDF4
import pytest

from ncd.io.netcdf import CONVENTIONS

pytestmark = pytest.mark.pipeline


def outputs(results):
    files = sorted(p for p in results.rglob("*.nc") if "benchmarks" not in p.parts)
    assert files, f"no netCDF under {results}"
    return files


def test_every_variable_has_units_and_long_name(results):
    missing = []
    for path in outputs(results):
        with netCDF4.Dataset(path) as nc:
            for name, var in nc.variables.items():
                attrs = var.ncattrs()
                units = var.getncattr("units").strip() if "units" in attrs else ""
                long_name = var.getncattr("long_name").strip() if "long_name" in attrs else ""
                if not long_name or (not units and var.dtype is not str):
                    missing.append(f"{path.relative_to(results)}:{name}")
    assert missing == [], f"{len(missing)} variables without units/long_name: {missing[:20]}"


def test_global_attributes_and_versions(results):
    for path in outputs(results):
        with netCDF4.Dataset(path) as nc:
            attrs = set(nc.ncattrs())
            assert {"Conventions", "title", "source", "references"} <= attrs, path
            assert nc.getncattr("Conventions") == CONVENTIONS
            assert "Moreau" in nc.getncattr("references")
            if "config_yaml" in attrs:  # a provenance record: versions included
                assert {"python_version", "numpy_version", "numba_version", "snakemake_version"} <= attrs, path


def test_flags_are_cf_flags(results):
    for path in outputs(results):
        with netCDF4.Dataset(path) as nc:
            for name, var in nc.variables.items():
                if "flag_values" in var.ncattrs():
                    meanings = var.getncattr("flag_meanings").split()
                    assert len(meanings) == len(list(var.getncattr("flag_values")) if hasattr(
                        var.getncattr("flag_values"), "__len__") else [0]), f"{path.name}:{name}"


def test_compressed_and_no_shards_left(results):
    for path in outputs(results):
        with netCDF4.Dataset(path) as nc:
            arrays = [v for v in nc.variables.values() if v.ndim > 0 and v.dtype is not str and v.size > 1]
            assert any(v.filters().get("zlib") for v in arrays), f"{path.name} not compressed"
    assert not list(results.glob("*/shards/*.nc")), "shards left after merging"
