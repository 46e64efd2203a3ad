# ncd: reproduce the figures of Moreau (2005), "Indetermination in the numerical
# simulation of granular systems".  `snakemake -j2` builds every figure;
# `snakemake -j2 fig1_wedged` builds one figure and only its inputs.
import os
import sys
from pathlib import Path

from snakemake.utils import min_version, validate

min_version("9.10")

configfile: str(Path(workflow.basedir) / "config.yaml")

# One BLAS thread per job (inherited by every job's interpreter): with -j2 on 2 cores the
# default OpenBLAS threads oversubscribe the cores (dense SVDs slow down several-fold), and
# a fixed thread count keeps dense linear algebra's bits the same whatever -j.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

validate(config, str(Path(workflow.basedir) / "workflow/schemas/config.schema.yaml"))

# Snakemake samples the process tree of every running job (psutil's memory_full_info reads
# /proc/<pid>/smaps_rollup) twice a second for a job's first samples, a cost of this process's
# CPU per job.  The figures read only the benchmark files' wall time `s`, measured apart from
# the samples, so a sample ten times rarer serves (workflow/README.md).
import snakemake.benchmark as _benchmark

_benchmark.BENCHMARK_INTERVAL_SHORT = max(_benchmark.BENCHMARK_INTERVAL_SHORT, 5.0)

# Snakemake's scheduler loop re-arms a one-second timer on each pass while jobs wait, and each
# finished job starts one more chain of them: the loop runs about once a second per finished job,
# a cost that grows with the run; one pending timer at a time wakes it as surely
# (ncd.pipeline.scheduler.coalesce_reevaluations; workflow/README.md).
from ncd.pipeline.scheduler import coalesce_reevaluations

coalesce_reevaluations()

include: "workflow/rules/common.smk"
include: "workflow/rules/html.smk"

# A run killed with SIGKILL leaves its locks: remove them (and stray *.part files) when no
# Snakemake process or job still runs here, so that a plain rerun needs no --unlock; its
# unfinished jobs are rerun by profiles/default (rerun-incomplete).  See ncd.pipeline.jobs.
if workflow.is_main_process and not workflow.dryrun:
    from ncd.pipeline.jobs import recover_killed_run

    recover_killed_run(".", logger=lambda m: print(m, file=sys.stderr))

for _figure in FIGURES:
    include: f"workflow/rules/{_figure}.smk"

# the reproduction page results/index.html (claims, verdicts, provenance, run times)
include: "workflow/rules/index.smk"

# ParaView (VTK) and animations of stored frames: `snakemake -j2 export` (not in the default target)
include: "workflow/rules/export.smk"

# the benchmark suite: `snakemake -j2 bench` (not part of the default target)
if "bench" in config:
    include: "workflow/rules/bench.smk"


rule all:
    default_target: True
    input:
        [figure_targets(f) for f in FIGURES],
        "results/index.html",
