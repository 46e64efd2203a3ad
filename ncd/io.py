"""netCDF output: provenance attributes, atomic writes, shard merging.

Files are written whole or not at all (a temporary file in the same folder,
then ``os.replace``), carry no timestamps, and hold the scene configuration as a
YAML string, the solver settings, the ncd version and the git commit.
"""
import os
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from . import __version__


def git_commit():
    """The commit of the source tree (``+dirty`` when it has changes), or "unknown"."""
    root = Path(__file__).resolve().parent.parent
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                             text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "ncd"],
                               cwd=root, capture_output=True, text=True, check=True).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def provenance(config, settings=None, **extra):
    """Attributes for a dataset: config as YAML, solver settings, version, commit."""
    attrs = {"config_yaml": yaml.safe_dump(config, sort_keys=True), "ncd_version": __version__,
             "git_commit": git_commit(),
             "reference": "J. J. Moreau, Indetermination in the numerical simulation of granular "
                          "systems, Powders and Grains 2005"}
    if settings is not None:
        attrs.update(settings.as_attrs())
    for k, v in extra.items():
        attrs[k] = int(v) if isinstance(v, (bool, np.bool_)) else v
    return attrs


def write_dataset(ds, path):
    """Write ``ds`` to ``path`` atomically (no partial file is ever left)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for name, var in ds.variables.items():
        if var.dtype.kind == "f" and np.isinf(var.values).any():
            raise ValueError(f"variable {name} holds inf values; refusing to write {path}")
    fd, tmp = tempfile.mkstemp(suffix=".nc.part", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.chmod(tmp, 0o644)  # mkstemp creates 0600 files
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def merge_shards(paths, dim="run"):
    """Concatenate shard files along ``dim`` in member order; attrs of the first shard."""
    parts = [xr.load_dataset(p) for p in paths]
    ds = xr.concat(parts, dim=dim, data_vars="minimal", coords="minimal", compat="override",
                   combine_attrs="override")
    for var in ds.variables.values():
        var.encoding.pop("dtype", None)  # a string variable must not keep the first shard's width
    return ds.sortby(dim)
