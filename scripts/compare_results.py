"""Compare two results/ trees netCDF file by netCDF file, measured times aside.

    python scripts/compare_results.py RESULTS_A RESULTS_B [--ignore REGEX ...] [--common-only]

Every ``*.nc`` file under RESULTS_A is paired with the file of the same relative path
under RESULTS_B (files present in only one tree are listed).  For each pair the
dimensions, every variable (data and coordinates: dtype, dimensions, shape and values,
NaN positions included, read raw: no masking or scaling) and every attribute (global
and per variable) must be equal.  Left out of the comparison:

* measurements of the machine, not of the mechanics: variables and attributes whose
  name matches :data:`MEASURED` (``wall_time`` and its kin, ``seconds``, ``*_s`` timings
  of the benchmark, ns per update, speed-up, memory, the machine);
* provenance of the checkout: :data:`PROVENANCE` (``git_commit``);
* the folders ``benchmarks/`` and ``logs/`` (Snakemake's timings and the jobs' logs)
  and hidden files (partial writes ``.<name>.<pid>.part``).

Names in this project that contain "wall" but are geometry (``wall``, ``x_wall``,
``wall_point_x``, ``n_wall_contacts``) are compared: only ``wall_time``-like names are
measurements.  The keys left out are printed.

Output: one line per file, ``identical`` or ``differs`` with the variables and
attributes that differ (numbers: largest absolute difference), then a summary line.
Exit status 0 when every file is identical and none is missing, 1 otherwise (2: usage).
"""
import argparse
import re
import sys
from pathlib import Path

import netCDF4
import numpy as np

MEASURED = [r"wall_?time", r"wall_?clock", r"time_s(_|$)", r"elapsed", r"seconds", r"runtime",
            r"_(s|ms|us|ns)$", r"^(s|ms|us|ns)_per_", r"^time_(mean|median|settle|total)$", r"speed_?up",
            r"peak_memory", r"memory_growth", r"(^|_)max_rss", r"cpu_count", r"^machine$"]
PROVENANCE = [r"^git_commit$"]
SKIP_DIRS = {"benchmarks", "logs"}


class Comparison:
    def __init__(self, ignore):
        self.patterns = [re.compile(p) for p in ignore]
        self.ignored = set()

    def skip(self, name, kind):
        if any(p.search(name) for p in self.patterns):
            self.ignored.add(f"{kind} {name}")
            return True
        return False

    def attrs(self, a, b, where):
        diffs = []
        keys = sorted(set(a.ncattrs()) | set(b.ncattrs()))
        for k in keys:
            if self.skip(k, "attribute"):
                continue
            label = f"{where}attr {k}"
            if k not in a.ncattrs() or k not in b.ncattrs():
                diffs.append(f"{label} only in {'A' if k in a.ncattrs() else 'B'}")
                continue
            d = value_difference(a.getncattr(k), b.getncattr(k))
            if d is not None:
                diffs.append(f"{label} ({d})")
        return diffs

    def group(self, a, b, prefix=""):
        diffs = self.attrs(a, b, prefix)
        da = {k: len(v) for k, v in a.dimensions.items()}
        db = {k: len(v) for k, v in b.dimensions.items()}
        if da != db:
            diffs.append(f"{prefix}dimensions {da} != {db}")
        for name in sorted(set(a.variables) | set(b.variables)):
            if self.skip(name, "variable"):
                continue
            label = f"{prefix}{name}"
            if name not in a.variables or name not in b.variables:
                diffs.append(f"{label} only in {'A' if name in a.variables else 'B'}")
                continue
            va, vb = a.variables[name], b.variables[name]
            for v in (va, vb):
                v.set_auto_maskandscale(False)
            if va.dtype != vb.dtype or va.dimensions != vb.dimensions or va.shape != vb.shape:
                diffs.append(f"{label} dtype/dims/shape {va.dtype}{va.dimensions}{va.shape} != "
                             f"{vb.dtype}{vb.dimensions}{vb.shape}")
                continue
            d = value_difference(va[...], vb[...])
            if d is not None:
                diffs.append(f"{label} ({d})")
            diffs += self.attrs(va, vb, f"{label}: ")
        for name in sorted(set(a.groups) | set(b.groups)):
            if name not in a.groups or name not in b.groups:
                diffs.append(f"{prefix}group {name} only in {'A' if name in a.groups else 'B'}")
            else:
                diffs += self.group(a.groups[name], b.groups[name], f"{prefix}{name}/")
        return diffs

    def files(self, path_a, path_b):
        with netCDF4.Dataset(path_a) as a, netCDF4.Dataset(path_b) as b:
            return self.group(a, b)


def value_difference(x, y):
    """None when ``x`` and ``y`` are equal (same shape, NaN in the same places), else a
    short description: the largest absolute difference of numbers, or how many differ."""
    x, y = np.asarray(x), np.asarray(y)
    if x.shape != y.shape:
        return f"shape {x.shape} != {y.shape}"
    numeric = x.dtype.kind in "biufc" and y.dtype.kind in "biufc"
    if not numeric:
        if x.dtype.kind != y.dtype.kind and not (x.dtype.kind in "OSU" and y.dtype.kind in "OSU"):
            return f"type {x.dtype} != {y.dtype}"
        neq = np.asarray(x.astype(str) != y.astype(str))
        return None if not neq.any() else f"{int(neq.sum())} of {neq.size} values differ"
    if x.dtype != y.dtype:
        return f"dtype {x.dtype} != {y.dtype}"
    if np.array_equal(x, y, equal_nan=x.dtype.kind in "fc"):
        return None
    if x.dtype.kind in "fc":
        nan_x, nan_y = np.isnan(x), np.isnan(y)
        if (nan_x != nan_y).any():
            return f"NaN at {int((nan_x != nan_y).sum())} different positions"
        ok = ~nan_x & (x != y)
        with np.errstate(invalid="ignore", over="ignore"):
            diff = np.abs(x[ok].astype(np.complex128 if x.dtype.kind == "c" else np.float64) - y[ok])
        return f"max abs difference {float(np.max(diff)):.3g} at {int(ok.sum())} of {x.size}"
    diff = np.abs(x.astype(np.float64) - y.astype(np.float64))
    return f"max abs difference {float(diff.max()):.6g} at {int((x != y).sum())} of {x.size}"


def netcdf_files(root):
    """Relative paths of the ``*.nc`` files under ``root`` (benchmarks/, logs/ and hidden files left out)."""
    root = Path(root)
    out = set()
    for p in root.rglob("*.nc"):
        rel = p.relative_to(root)
        if any(part in SKIP_DIRS or part.startswith(".") for part in rel.parts):
            continue
        out.add(rel)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results_a", type=Path)
    parser.add_argument("results_b", type=Path)
    parser.add_argument("--ignore", action="append", default=[], metavar="REGEX",
                        help="also leave out variables and attributes whose name matches REGEX")
    parser.add_argument("--common-only", action="store_true",
                        help="files present in only one tree do not make the trees differ")
    args = parser.parse_args(argv)
    for root in (args.results_a, args.results_b):
        if not root.is_dir():
            parser.error(f"{root} is not a folder")
    cmp = Comparison(MEASURED + PROVENANCE + args.ignore)
    fa, fb = netcdf_files(args.results_a), netcdf_files(args.results_b)
    n_same = n_diff = 0
    for rel in sorted(fa | fb):
        if rel not in fa or rel not in fb:
            print(f"{rel}: only in {args.results_a if rel in fa else args.results_b}")
            continue
        try:
            diffs = cmp.files(args.results_a / rel, args.results_b / rel)
        except OSError as exc:
            diffs = [f"cannot read: {exc}"]
        if diffs:
            n_diff += 1
            print(f"{rel}: differs: " + "; ".join(diffs))
        else:
            n_same += 1
            print(f"{rel}: identical")
    only = len(fa ^ fb)
    print(f"ignored keys: {', '.join(sorted(cmp.ignored)) if cmp.ignored else 'none'}")
    print(f"summary: {n_same} identical, {n_diff} differ, {len(fa - fb)} only in A, {len(fb - fa)} only in B "
          f"({len(fa & fb)} files compared)")
    return 0 if n_diff == 0 and (only == 0 or args.common_only) else 1


if __name__ == "__main__":
    sys.exit(main())
