"""A moved or cloned checkout with its results/ and .snakemake/ plans nothing: every rule
input and output is relative to the working directory."""
import shutil

import pytest
from conftest import run_snakemake


@pytest.mark.pipeline
def test_moved_checkout_plans_nothing(dag_repo, tmp_path):
    moved = tmp_path / "moved"
    shutil.copytree(dag_repo, moved, symlinks=True)  # copy2: modification times kept
    proc = run_snakemake(moved, "-n", "all", "bench")
    out = proc.stdout + proc.stderr
    assert "Nothing to be done" in out, out[-3000:]
    assert str(dag_repo) not in (moved / "results" / "index.html").read_text()
