"""Shared fixtures: one run of the whole Snakemake DAG on a reduced configuration.

The workflow files are copied to a temporary directory (so that tests may touch
them) and the DAG runs there once per test session, with
``tests/config_reduced.yaml`` overlaid on ``config.yaml``.  Set
``NCD_RESULTS_DIR`` to a directory where ``snakemake -j2`` already ran (e.g. the
repository itself) to check the full-size figure data instead.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

# Snakemake gives each job one BLAS thread per rule thread (the rules use one). A member
# recomputed here must sum in the same order to match its job's file bit for bit: with
# OpenBLAS's default threads, a warm run of Figure 2 with local exact solves differed by 4e-13.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

ROOT = Path(__file__).resolve().parent.parent
WORKFLOW_FILES = ("Snakefile", "config.yaml", "config/quick.yaml", "profiles", "workflow", "notebooks", "ncd",
                  "tests/config_reduced.yaml", "tests/config_reduced_size.yaml")


def copy_workflow(dst):
    """Copy the files the DAG reads into ``dst``; returns ``dst``."""
    for name in WORKFLOW_FILES:
        src = ROOT / name
        target = dst / name
        target.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, target, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
        else:
            shutil.copy2(src, target)
    return dst


def run_snakemake(repo, *args, extra_configs=(), check=True, workdir=None):
    """Run the workflow copied in ``repo`` (reduced config plus ``extra_configs``)."""
    configs = [repo / "config.yaml", repo / "tests" / "config_reduced.yaml", *extra_configs]
    cmd = [sys.executable, "-m", "snakemake", "-s", str(repo / "Snakefile"), "-d", str(workdir or repo),
           "--configfile", *map(str, configs), *args]
    env = dict(os.environ)
    # the notebook rules call jupyter: make this interpreter's scripts reachable
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env.get("PATH", "")
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if check and proc.returncode != 0:
        raise AssertionError(f"snakemake failed ({' '.join(cmd)}):\n{proc.stdout[-4000:]}\n{proc.stderr[-8000:]}")
    return proc


@pytest.fixture(scope="session")
def dag_repo(tmp_path_factory):
    """A copy of the workflow in which the reduced DAG (every figure, the benchmark
    suite and fig4_history's size study) has run completely."""
    repo = copy_workflow(tmp_path_factory.mktemp("repo"))
    run_snakemake(repo, "-j2", "all", "bench", "fig4_history_size")
    return repo


@pytest.fixture(scope="session")
def results(request):
    """Directory holding ``results/`` of a full DAG run (reduced config unless NCD_RESULTS_DIR)."""
    if os.environ.get("NCD_RESULTS_DIR"):
        return Path(os.environ["NCD_RESULTS_DIR"]) / "results"
    return request.getfixturevalue("dag_repo") / "results"


DAG_FIXTURES = {"dag_repo", "results", "fresh_repo"}


def pytest_collection_modifyitems(config, items):
    """Mark ``pipeline`` every test that needs the reduced DAG, full-size data or a
    Snakemake run of its own (a fixture of DAG_FIXTURES, or a call of run_snakemake or
    copy_workflow), so that ``pytest -m "not pipeline"`` runs the unit tests alone."""
    for item in items:
        names = getattr(getattr(item, "function", None), "__code__", None)
        calls = set(names.co_names) if names is not None else set()
        if DAG_FIXTURES & set(getattr(item, "fixturenames", ())) or {"run_snakemake", "copy_workflow"} & calls:
            item.add_marker(pytest.mark.pipeline)
