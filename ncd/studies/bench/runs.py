"""What a run of the workflow cost: each rule's wall time (its ``benchmark:`` file), the LP time
of the exact sets, and the DAG of the default run with each job's CPU seconds and the
critical path (the longest chain of jobs each waiting for the one before), read from a
dry run.  Read after the run, so nothing here times anything itself.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr
import yaml


def rule_times(paths):
    """Wall time (s) and peak memory (MB) of every rule from Snakemake benchmark files
    ``results/benchmarks/<figure>/<rule>.tsv``, as a Dataset over ``job``."""
    rows = []
    for p in sorted(Path(x) for x in paths):
        lines = p.read_text().splitlines()
        head, values = lines[0].split("\t"), lines[1].split("\t")
        rec = dict(zip(head, values))
        rss = rec.get("max_rss", "-")
        rows.append((p.parent.name, p.stem, float(rec["s"]), float(rss) if rss not in ("-", "NA", "") else np.nan))
    return xr.Dataset({"figure": ("job", [r[0] for r in rows]), "rule": ("job", [r[1] for r in rows]),
                       "seconds": ("job", np.array([r[2] for r in rows])),
                       "max_rss_mb": ("job", np.array([r[3] for r in rows]))},
                      coords={"job": np.arange(len(rows))})


def exact_costs(paths):
    """The cost of the exact angle ranges of every pile with an exact file
    ``.../exact/n<N>/<history>_<member>.nc`` (:mod:`ncd.figures.fig4_history.exact`), as a Dataset
    over ``pile``: the grains of its size, contacts, cuts, LPs, the LP solver (config
    ``exact.solver``) and the wall time of the LPs (single-threaded solvers, so about their CPU time on an
    unloaded core).  Piles of the size study appear when it has run."""
    rows = []
    for p in sorted(Path(x) for x in paths):
        with xr.open_dataset(p) as e:
            cfg = yaml.safe_load(e.attrs["config_yaml"]) if "config_yaml" in e.attrs else {}
            rows.append((int(p.parent.name.lstrip("n")), str(e.attrs["history"]), int(e.attrs["member"]),
                         int(e.attrs["n_contacts"]), int(e.n_lp.size), int(e.n_lp.sum()),
                         str(cfg.get("exact", {}).get("solver", "highs")), float(e.attrs["lp_wall_time"])))
    col = lambda i: np.array([r[i] for r in rows])                        # noqa: E731
    one = lambda i, u, ln: ("pile", col(i), {"units": u, "long_name": ln})  # noqa: E731
    return xr.Dataset({"grains": one(0, "1", "grains of the pile's size (the n of its directory)"),
                       "history": ("pile", col(1).astype(str), {"units": "1", "long_name": "construction history"}),
                       "member": one(2, "1", "pile member"),
                       "n_contacts": one(3, "1", "contacts of the pile's final state"),
                       "n_cuts": one(4, "1", "cuts of the pile (an angle range sought at each)"),
                       "n_lp": one(5, "1", "linear programs of the pile"),
                       "solver": ("pile", col(6).astype(str), {"units": "1", "long_name":
                                  "LP solver: highs or clp (simplex from basis to basis), clarabel (interior point)"}),
                       "lp_seconds": one(7, "s", "wall time of the pile's LPs (single-threaded)")},
                      coords={"pile": np.arange(len(rows))})


def dry_run_jobs(text):
    """The jobs of a Snakemake dry run's printout (``snakemake -n --forceall --cores N``):
    a list of dicts with ``rule``, ``inputs``, ``outputs``, ``benchmark`` (None when the
    rule has none) and ``threads`` (1 when not printed).  Snakemake prints a job's block
    as ``rule NAME:`` (or ``localrule``/``checkpoint``) and indented ``key: value`` lines."""
    jobs, job = [], None
    for line in text.splitlines():
        head = line.split()[0] if line.strip() else ""
        if head in ("rule", "localrule", "checkpoint") and line.rstrip().endswith(":"):
            job = {"rule": line.split()[1].rstrip(":"), "inputs": [], "outputs": [], "benchmark": None,
                   "threads": 1}
            jobs.append(job)
        elif job is not None and line.startswith("    ") and ":" in line:
            key, value = (x.strip() for x in line.split(":", 1))
            if key in ("input", "output"):
                job[key + "s"] = [v.strip() for v in value.split(",") if v.strip()]
            elif key == "benchmark":
                job["benchmark"] = value
            elif key == "threads":
                job["threads"] = int(value)
        elif not line.startswith(" "):
            job = None
    return jobs


def read_benchmark(path):
    """``(wall_s, cpu_s)`` of a Snakemake benchmark file (its first record): ``s`` and the
    sampled ``cpu_time`` (wall time where Snakemake recorded none)."""
    lines = Path(path).read_text().splitlines()
    rec = dict(zip(lines[0].split("\t"), lines[1].split("\t")))
    wall = float(rec["s"])
    cpu = float(rec["cpu_time"]) if rec.get("cpu_time", "NA") not in ("-", "NA", "") else wall
    return wall, cpu


def critical_path(durations, edges):
    """Length and jobs of the longest chain of a DAG: ``durations[j]`` the time of job ``j``,
    ``edges`` pairs ``(a, b)``, b needing a.  The jobs are listed first to last."""
    n = len(durations)
    preds = [[] for _ in range(n)]
    succs = [[] for _ in range(n)]
    for a, b in edges:
        preds[b].append(a)
        succs[a].append(b)
    indeg = [len(p) for p in preds]
    ready = [j for j in range(n) if indeg[j] == 0]
    finish = np.zeros(n)
    via = np.full(n, -1)
    while ready:
        j = ready.pop()
        start = max((finish[p] for p in preds[j]), default=0.0)
        if preds[j]:
            via[j] = max(preds[j], key=lambda p: finish[p])
        finish[j] = start + durations[j]
        for b in succs[j]:
            indeg[b] -= 1
            if indeg[b] == 0:
                ready.append(b)
    if np.any(np.array(indeg) > 0):
        raise ValueError("the job graph has a cycle")
    if n == 0:
        return 0.0, []
    last = int(np.argmax(finish))
    path = [last]
    while via[path[-1]] >= 0:
        path.append(int(via[path[-1]]))
    return float(finish[last]), path[::-1]


def dag_table(jobs, root="."):
    """The jobs of a run with a benchmark file, as a Dataset over ``job``: figure (the
    benchmark's folder; "index" for the files at the top), rule (its name), threads, wall
    seconds, core seconds (``wall x threads``) and Snakemake's sampled ``cpu_time``.

    Snakemake samples a job's process tree now and then, so its ``cpu_time`` misses
    children that end between samples (a default run: 3,317 s against 4,503 s of wall
    time in single-thread jobs on an idle machine); a notebook job's ``cpu_time`` also
    counts Snakemake's own main process from its start (548 s for a 20-s notebook at the
    end of a default run whose main process had used 514 s).
    On a machine that never runs more threads than cores (``-j`` at most the cores), a
    job holds its threads for its wall time: that time is its cost (``cpu_s``) and its
    time alone (``alone_s``), from which the critical path of the DAG is found
    (``critical``: 1 on it).  Attributes: ``critical_path_s``, ``cpu_s`` (all jobs) and
    ``ideal_s`` (the larger of the critical path and the core seconds over the cores: no
    schedule on ``cores`` cores is shorter)."""
    root = Path(root)
    producer = {out: k for k, job in enumerate(jobs) for out in job["outputs"]}
    edges = sorted({(producer[i], k) for k, job in enumerate(jobs) for i in job["inputs"] if i in producer})
    rows = []
    for job in jobs:
        bench = job["benchmark"]
        if bench is None or not (root / bench).exists():
            rows.append(None)
            continue
        wall, sampled = read_benchmark(root / bench)
        folder = Path(bench).parent.name
        rows.append((folder if folder != "benchmarks" else "index", Path(bench).stem, job["threads"], wall,
                     wall * job["threads"], sampled))
    durations = [0.0 if r is None else r[3] for r in rows]
    length, path = critical_path(durations, edges)
    keep = [k for k, r in enumerate(rows) if r is not None]
    on_path = set(path)
    step = {k: i for i, k in enumerate(p for p in path if rows[p] is not None)}
    ds = xr.Dataset({"figure": ("job", [rows[k][0] for k in keep]),
                     "rule": ("job", [rows[k][1] for k in keep]),
                     "threads": ("job", np.array([rows[k][2] for k in keep], np.int64)),
                     "wall_s": ("job", np.array([rows[k][3] for k in keep])),
                     "cpu_s": ("job", np.array([rows[k][4] for k in keep])),
                     "cpu_time_s": ("job", np.array([rows[k][5] for k in keep])),
                     "alone_s": ("job", np.array([durations[k] for k in keep])),
                     "critical": ("job", np.array([int(k in on_path) for k in keep], np.int8)),
                     "critical_order": ("job", np.array([step.get(k, -1) for k in keep], np.int64))},
                    coords={"job": np.arange(len(keep))})
    cpu = float(ds.cpu_s.sum())
    ds.attrs.update(critical_path_s=length, cpu_s=cpu, jobs=len(keep))
    meta = {"wall_s": ("s", "wall time of the job"),
            "cpu_s": ("s", "core seconds the job held: wall time x threads"),
            "cpu_time_s": ("s", "Snakemake's sampled cpu_time (misses short-lived children; for reference)"),
            "alone_s": ("s", "the job's time alone on its threads: its wall time"),
            "threads": ("1", "threads of the job"),
            "critical": ("1", "1: the job is on the critical path of the DAG"),
            "critical_order": ("1", "position on the critical path (-1: not on it)"),
            "figure": ("1", "folder of the benchmark file"), "rule": ("1", "name of the benchmark file")}
    for k, (units, name) in meta.items():
        ds[k].attrs.update(units=units, long_name=name)
    return ds


def dag_summary(ds):
    """For the bench page, from a :func:`dag_table` Dataset with its run's attributes: CPU and
    wall seconds per figure, the jobs of the critical path in order, and a sentence."""
    jobs = ds.to_dataframe()
    per_fig = jobs.groupby("figure")[["cpu_s", "wall_s"]].sum().sort_values("cpu_s", ascending=False).round(1)
    path = jobs[jobs.critical == 1].sort_values("critical_order")[["figure", "rule", "threads", "cpu_s", "alone_s"]]
    cores = int(ds.attrs.get("cores", 2))
    top = per_fig.index[0] if len(per_fig) else "none"
    text = (f"{int(ds.attrs['jobs'])} jobs, {float(ds.attrs['cpu_s']):.0f} core seconds (wall x threads) in all ({top} the largest, "
            f"{float(per_fig.cpu_s.iloc[0]) if len(per_fig) else 0.0:.0f} s).  Critical path "
            f"{float(ds.attrs['critical_path_s']):.0f} s through {len(path)} jobs ("
            + ", ".join(f"{r.figure}/{r.rule}" for r in path.itertuples()) + f"); no run on {cores} cores "
            f"takes less than {ideal_time(ds, cores):.0f} s.")
    return per_fig, path.round(1).reset_index(drop=True), text


def ideal_time(ds, cores=2):
    """The shortest a run of the jobs of ``ds`` (:func:`dag_table`) can take on ``cores``
    cores: the larger of its critical path and its CPU seconds spread over the cores."""
    return max(float(ds.attrs["critical_path_s"]), float(ds.attrs["cpu_s"]) / cores)


def dry_run(targets, config, cores=2, workdir="."):
    """The printout of ``snakemake -n --forceall`` for ``targets`` with ``config`` (a dict,
    passed as a config file): every job of a full run, whatever is built already.  No lock
    is taken, so a running Snakemake (the one running this) is not disturbed."""
    with tempfile.TemporaryDirectory() as tmp:
        cfg = Path(tmp) / "config.yaml"
        cfg.write_text(yaml.safe_dump(config, sort_keys=True))
        # the targets first: --configfile takes every argument after it
        cmd = [sys.executable, "-m", "snakemake", *targets, "-n", "--forceall", "--nolock", "--cores", str(cores),
               "--configfile", str(cfg)]
        out = subprocess.run(cmd, cwd=workdir, capture_output=True, text=True, check=True)
    return out.stdout + out.stderr
