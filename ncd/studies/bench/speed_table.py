"""The README's speed table: its rows read from a run's ``results/bench/*.nc``, the TSV that
holds them (``docs/speed.tsv``) and the Markdown block between two markers of the README
(``scripts/speed_table.py`` writes it; a test checks the README holds exactly that).
"""
from pathlib import Path

import numpy as np
import xarray as xr

from ncd.studies.bench.solver import power_law

SPEED_COLUMNS = ("quantity", "value", "unit", "source")
SPEED_START, SPEED_END = "<!-- speed table: scripts/speed_table.py -->", "<!-- end of speed table -->"


def _sig(x, digits=3):
    """``digits`` significant digits, and every digit of the integer part above them."""
    x = float(x)
    return f"{x:.0f}" if abs(x) >= 10 ** digits else f"{x:.{digits}g}"


def speed_rows(results):
    """The rows of the README's speed table, read from a run's ``results/bench/*.nc``
    (those present): a list of dicts with :data:`SPEED_COLUMNS`, values as printed."""
    bench_dir = Path(results) / "bench"
    rows = []

    def row(quantity, value, unit, source):
        rows.append({"quantity": quantity, "value": value, "unit": unit, "source": f"results/bench/{source}"})

    if (bench_dir / "dag.nc").exists():
        dag = xr.load_dataset(bench_dir / "dag.nc")
        cores = int(dag.attrs["cores"])
        row("default run: core time of all jobs (wall x threads)", _sig(dag.attrs["cpu_s"]), "s", "dag.nc")
        row("default run: critical path of the DAG", _sig(dag.attrs["critical_path_s"]), "s", "dag.nc")
        row(f"default run: shortest possible on {cores} cores", _sig(dag.attrs["ideal_s"]), "s", "dag.nc")
    if (bench_dir / "core.nc").exists():
        core = xr.load_dataset(bench_dir / "core.nc")
        k = int(np.argmin(np.abs(core.n_discs.values - 10_000)))
        n = int(core.n_discs.values[k])
        row(f"NLGS contact update, N = {n}: numba / C", f"{_sig(core.ns_per_update.values[k])} / "
            f"{_sig(core.ns_per_update_c.values[k])}", "ns", "core.nc")
        for name, var in (("one Moreau-Jean step", "step_s"), ("building a packing", "build_s")):
            if var in core:
                p, _ = power_law(core.n_discs.values, core[var].values)
                row(f"{name} against N: exponent p of t ~ N^p", f"{p:.2f}", "1", "core.nc")
    if (bench_dir / "tolerance_problems.nc").exists():
        tp = xr.load_dataset(bench_dir / "tolerance_problems.nc")
        tight = float(tp.tol.min())
        for problem, label in (("fig2_step_warm", "fig2's step, warm start"), ("pile", "the pile's final state")):
            if problem in tp.problem.values:
                t = tp.seconds.sel(problem=problem, tol=tight).median("order")
                row(f"{label}, to {tight:.0e}: plain NLGS / local exact solves",
                    f"{_sig(t.sel(solver='nlgs'))} / {_sig(t.sel(solver='nlgs+local'))}", "s",
                    "tolerance_problems.nc")
    if (bench_dir / "exact_sets.nc").exists():
        ex = xr.load_dataset(bench_dir / "exact_sets.nc")
        for h in sorted(set(ex.history.values)):
            e = ex.where(ex.history == h, drop=True)
            sizes = sorted({int(n) for n in e.grains.values})
            med = [float(np.median(e.lp_seconds.values[e.grains.values == n])) for n in sizes]
            row(f"exact angle ranges of one {h} pile, N = {' / '.join(map(str, sizes))}: LP time (median)",
                " / ".join(_sig(m, 2) for m in med), "s", "exact_sets.nc")
    if (bench_dir / "peer.nc").exists():
        peer = xr.load_dataset(bench_dir / "peer.nc")
        row("poured pile, median step: ncd / pymunk", f"{_sig(peer.time_median.sel(engine='ncd') * 1e3)} / "
            f"{_sig(peer.time_median.sel(engine='pymunk') * 1e3)}", "ms", "peer.nc")
    return rows


SOURCES = ("dag.nc", "core.nc", "tolerance_problems.nc", "exact_sets.nc", "peer.nc")   # in table order


def merge_rows(new, previous, results):
    """The table after a run that produced only some of the bench files: ``new``
    (:func:`speed_rows` of ``results``) for every file present there, ``previous`` (the
    committed table) for the others, in :data:`SOURCES` order.  A row is kept only
    while its own file is absent: one run's numbers never mix with another's within a
    file's rows, and each row names the file it comes from."""
    present = {f for f in SOURCES if (Path(results) / "bench" / f).exists()}

    def name(r):
        return r["source"].rsplit("/", 1)[-1]
    for label, rows in (("new", new), ("previous", previous)):    # a file missing from SOURCES would drop its rows
        unknown = sorted({name(r) for r in rows} - set(SOURCES))
        if unknown:
            raise ValueError(f"{label} speed rows from {unknown}, not among the bench files {SOURCES}")
    return [r for f in SOURCES for r in (new if f in present else previous) if name(r) == f]


def write_speed_csv(rows, path):
    """The rows of :func:`speed_rows` as a tab-separated file (the table's committed source)."""
    lines = ["\t".join(SPEED_COLUMNS)] + ["\t".join(r[c] for c in SPEED_COLUMNS) for r in rows]
    Path(path).write_text("\n".join(lines) + "\n")


def read_speed_csv(path):
    lines = Path(path).read_text().splitlines()
    head = lines[0].split("\t")
    return [dict(zip(head, line.split("\t"))) for line in lines[1:] if line]


def speed_markdown(rows):
    """The README's speed block: the markers and a Markdown table of ``rows``."""
    table = ["| quantity | value | unit | from |", "| --- | ---: | --- | --- |"]
    table += [f"| {r['quantity']} | {r['value']} | {r['unit']} | `{r['source']}` |" for r in rows]
    return "\n".join([SPEED_START, *table, SPEED_END])


def replace_speed_block(text, block):
    """``text`` (the README) with its speed block replaced by ``block``."""
    start, end = text.index(SPEED_START), text.index(SPEED_END) + len(SPEED_END)
    return text[:start] + block + text[end:]


def speed_block(text):
    """The speed block of ``text`` (the README), markers included."""
    start, end = text.index(SPEED_START), text.index(SPEED_END) + len(SPEED_END)
    return text[start:end]
