"""netCDF output: CF metadata, provenance attributes, atomic writes, shard merging.

Every file is self-describing: global ``Conventions``, ``title``, ``source`` and
``references`` (the paper), ``units`` and ``long_name`` on every variable (a
producer sets them; :data:`ncd.io.metadata.KNOWN` fills the common names it did not
set), ``flag_values``/``flag_meanings`` on categorical ones, zlib compression.
Files carry no timestamps: reruns give identical bytes of data.

Writes are whole or absent.  The data go to ``.<name>.<pid>.part`` in the target's
folder and are renamed over the target when complete.  Policy on signals:
SIGTERM or SIGINT during the write removes the partial file and then ends the
process with that signal at once (the write runs in a worker thread, netCDF4 releases
the GIL, so the main thread handles the signal immediately; Python's own SIGINT
handling is bypassed, so no lock inside xarray/netCDF4 can hang it).  SIGKILL cannot be caught: its ``.part`` file
stays until the next write of the same target, which removes every stale
``.<name>.<pid>.part`` whose process is gone.
"""
import os
import platform
import signal
import subprocess
import threading
import warnings
from importlib import metadata as _metadata
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from ncd.core.version import __version__
from ncd.io.metadata import default_attrs

REFERENCES = ("J. J. Moreau, Indetermination in the numerical simulation of granular systems, "
              "in Powders and Grains 2005, R. Garcia-Rojo, H. J. Herrmann, S. McNamara (eds.), "
              "Balkema, Leiden, 2005 (hal-01824602)")
CONVENTIONS = "CF-1.10"
COMPRESSION = {"zlib": True, "complevel": 4, "shuffle": True}
STRICT_ENV = "NCD_STRICT_METADATA"  # "1": a variable without units/long_name is an error


def git_commit():
    """The commit of the source tree (``+dirty`` when it has changes), or "unknown"."""
    root = Path(__file__).resolve().parents[2]
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                             text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "ncd"],
                               cwd=root, capture_output=True, text=True, check=True).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def versions():
    """Versions of Python and of the packages a result depends on (attribute names ``<pkg>_version``)."""
    out = {"python_version": platform.python_version()}
    for pkg in ("numpy", "numba", "scipy", "xarray", "netCDF4", "snakemake"):
        try:
            out[f"{pkg.lower()}_version"] = _metadata.version(pkg)
        except _metadata.PackageNotFoundError:
            out[f"{pkg.lower()}_version"] = "absent"
    return out


def provenance(config, settings=None, **extra):
    """Attributes for a dataset: config as YAML, solver settings, versions, commit."""
    attrs = {"config_yaml": yaml.safe_dump(config, sort_keys=True), "ncd_version": __version__,
             "git_commit": git_commit(), **versions(),
             "reference": "J. J. Moreau, Indetermination in the numerical simulation of granular "
                          "systems, Powders and Grains 2005"}
    if settings is not None:
        attrs.update({k: int(v) if isinstance(v, (bool, np.bool_)) else v
                      for k, v in settings.as_attrs().items()})
    for k, v in extra.items():
        attrs[k] = int(v) if isinstance(v, (bool, np.bool_)) else v
    return attrs


def missing_metadata(ds):
    """Names of the variables (data and coordinates) of ``ds`` lacking ``units`` or ``long_name``."""
    return sorted(str(n) for n, v in ds.variables.items()
                  if not str(v.attrs.get("units", "")).strip() and v.dtype.kind not in "OSU"
                  or not str(v.attrs.get("long_name", "")).strip())


def describe(ds, path=None):
    """A copy of ``ds`` with CF metadata: global attributes, and the documented defaults of
    :data:`ncd.io.metadata.KNOWN` on every variable that lacks its own ``units``/``long_name``."""
    ds = ds.copy(deep=False)
    for name, var in ds.variables.items():
        for key, value in default_attrs(str(name), var).items():
            if not str(var.attrs.get(key, "")).strip():
                var.attrs[key] = value
    path = Path(path) if path is not None else None
    if path is not None:
        where = path.parent.parent.name if path.parent.name == "shards" else path.parent.name
        title = f"ncd {where}: {path.stem}"
    else:
        title = "ncd dataset"
    ds.attrs = {"Conventions": CONVENTIONS, "title": ds.attrs.get("title", title),
                "source": f"ncd {__version__}: Contact Dynamics of rigid frictional discs "
                          "(Moreau-Jean time stepping, nonlinear Gauss-Seidel)",
                "references": REFERENCES, **{k: v for k, v in ds.attrs.items() if k != "title"}}
    # netCDF has no boolean attribute type
    ds.attrs = {k: int(v) if isinstance(v, (bool, np.bool_)) else v for k, v in ds.attrs.items()}
    return ds


def _encoding(ds):
    enc = {}
    for name, var in ds.variables.items():
        # a loaded file's layout (contiguous, chunk sizes of another length) must not be reused
        var.encoding = {k: v for k, v in var.encoding.items() if k in ("dtype", "_FillValue")}
        if var.dtype.kind in "fiub" and var.ndim > 0:
            enc[name] = dict(COMPRESSION)
    return enc


def _part_name(path, pid=None):
    return path.parent / f".{path.name}.{os.getpid() if pid is None else pid}.part"


def sweep_stale_parts(path):
    """Remove ``.<name>.<pid>.part`` files of ``path`` left by processes that no longer exist."""
    path = Path(path)
    removed = []
    for part in path.parent.glob(f".{path.name}.*.part"):
        try:
            pid = int(part.name[len(path.name) + 2:-len(".part")])
        except ValueError:
            continue
        try:
            os.kill(pid, 0)
            alive = pid != os.getpid()
        except ProcessLookupError:
            alive = False
        except PermissionError:
            alive = True
        if not alive:
            part.unlink(missing_ok=True)
            removed.append(part)
    return removed


def _die_by(signum, part, target):
    """Remove ``part`` and end the process with ``signum`` (its default action)."""
    try:
        os.unlink(part)
    except OSError:
        pass
    os.write(2, f"ncd.io.netcdf: signal {signum} while writing {target}: partial file removed\n".encode())
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)


def _write_guarded(ds, tmp, path, encoding):
    """``to_netcdf`` in a worker thread while the main thread waits with SIGTERM/SIGINT
    handlers: netCDF4 releases the GIL in its C calls, so a signal is handled at once,
    not when a long write of one variable returns."""
    outcome = {}

    def work():
        try:
            ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        except BaseException as exc:  # re-raised in the caller's thread
            outcome["error"] = exc

    previous = {s: signal.signal(s, lambda signum, frame: _die_by(signum, tmp, path))
                for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        worker = threading.Thread(target=work, name="ncd-write", daemon=True)
        worker.start()
        while worker.is_alive():
            worker.join(0.05)
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
    if "error" in outcome:
        raise outcome["error"]


def write_dataset(ds, path):
    """Write ``ds`` to ``path`` with CF metadata and compression, atomically (see module doc)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for name, var in ds.variables.items():
        if var.dtype.kind == "f" and np.isinf(var.values).any():
            raise ValueError(f"variable {name} holds inf values; refusing to write {path}")
    ds = describe(ds, path)
    missing = missing_metadata(ds)
    if missing:
        msg = (f"{path}: variables without units or long_name: {', '.join(missing)} "
               "(set attrs at the producer or add them to ncd.io.metadata.KNOWN)")
        if os.environ.get(STRICT_ENV) == "1":
            raise ValueError(msg)
        warnings.warn(msg, stacklevel=2)
    encoding = _encoding(ds)
    sweep_stale_parts(path)
    tmp = _part_name(path)
    try:
        if threading.current_thread() is threading.main_thread():
            _write_guarded(ds, tmp, path, encoding)
        else:  # signal handlers belong to the main thread
            ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def merge_shards(paths, dim="run"):
    """Concatenate shard files along ``dim`` in member order; attrs of the first shard
    but its ``title`` (which names the shard: :func:`write_dataset` titles the merged file)."""
    parts = [xr.load_dataset(p) for p in paths]
    ds = xr.concat(parts, dim=dim, data_vars="minimal", coords="minimal", compat="override", join="outer",
                   combine_attrs="override")
    ds.attrs.pop("title", None)
    for var in ds.variables.values():
        var.encoding.pop("dtype", None)  # a string variable must not keep the first shard's width
    if dim in ds.coords:
        ids, counts = np.unique(ds[dim].values, return_counts=True)
        if np.any(counts > 1):
            raise ValueError(f"shards {[str(p) for p in paths]} repeat {dim} {ids[counts > 1][:5].tolist()}: "
                             "a shard given twice, or shards of different runs")
    return ds.sortby(dim)
