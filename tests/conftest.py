"""Shared fixtures: one run of the whole Snakemake DAG on a reduced configuration.

The DAG runs once per test session in a temporary directory, with
``tests/config_reduced.yaml`` overlaid on ``config.yaml``.  Set
``NCD_RESULTS_DIR`` to a directory where ``snakemake -j2`` already ran (e.g. the
repository itself) to check the full-size figure data instead.
"""
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
REDUCED = ROOT / "tests" / "config_reduced.yaml"


def run_snakemake(workdir, *args, configfiles=(REDUCED,), check=True):
    """Run the workflow of this repository in ``workdir``; returns the CompletedProcess."""
    cmd = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "-d", str(workdir),
           "--configfile", str(ROOT / "config.yaml"), *map(str, configfiles), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if check and proc.returncode != 0:
        raise AssertionError(f"snakemake failed ({' '.join(cmd)}):\n{proc.stdout[-4000:]}\n{proc.stderr[-8000:]}")
    return proc


@pytest.fixture(scope="session")
def results(tmp_path_factory):
    """Directory holding ``results/`` of a full DAG run (reduced config unless NCD_RESULTS_DIR)."""
    if os.environ.get("NCD_RESULTS_DIR"):
        return Path(os.environ["NCD_RESULTS_DIR"]) / "results"
    workdir = tmp_path_factory.mktemp("dag")
    run_snakemake(workdir, "-j2")
    return workdir / "results"
