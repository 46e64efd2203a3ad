"""A real Slurm cluster: the sharded fig1 ensemble run with
``snakemake --executor slurm`` (profile workflow/profiles/slurm) on the single-node
cluster of scripts/slurm/start.sh equals a local run, data and attributes.

Skipped when Slurm is absent (no ``sbatch``/``slurmctld``) or the plugin is not
installed (``pip install -e ".[cluster]"``); install Slurm with
``sudo scripts/slurm/start.sh --install``.  Set NCD_REQUIRE_CLUSTER=1 to turn a cluster
that does not start into a failure (CI does, once its own start succeeded)."""
import os
import re
import shutil
import subprocess

import pytest
import xarray as xr
from conftest import ROOT, copy_workflow, run_snakemake

pytestmark = pytest.mark.cluster


@pytest.fixture(scope="module")
def slurm():
    """A running Slurm cluster with an idle node (started by scripts/slurm/start.sh if needed)."""
    if not (shutil.which("sbatch") and shutil.which("slurmctld")):
        pytest.skip("Slurm is not installed: sudo scripts/slurm/start.sh --install")
    pytest.importorskip("snakemake_executor_plugin_slurm", reason='pip install -e ".[cluster]"')

    def idle():
        proc = subprocess.run(["sinfo", "-h", "-N", "-o", "%t"], capture_output=True, text=True)
        return proc.returncode == 0 and any(s.startswith(("idle", "mix")) for s in proc.stdout.split())

    if not idle():
        start = subprocess.run([str(ROOT / "scripts" / "slurm" / "start.sh")], capture_output=True, text=True)
        if start.returncode != 0 or not idle():
            message = f"the Slurm cluster does not start:\n{start.stdout}\n{start.stderr}"
            if os.environ.get("NCD_REQUIRE_CLUSTER"):
                pytest.fail(message)
            pytest.skip(message)


def test_a_sharded_ensemble_on_slurm_equals_the_local_run(slurm, tmp_path):
    repo = copy_workflow(tmp_path / "repo")
    target = "results/fig1_wedged/ensemble.nc"
    run_snakemake(repo, "-j2", target, workdir=tmp_path / "local")                 # 2 shards, local
    overlay = tmp_path / "shards.yaml"
    overlay.write_text("fig1_wedged: {ensemble: {shards: 3}}\n")
    proc = run_snakemake(repo, "--profile", str(repo / "workflow" / "profiles" / "slurm"), target,
                         extra_configs=[overlay], workdir=tmp_path / "cluster")
    out = proc.stdout + proc.stderr
    submitted = re.findall(r"has been submitted with SLURM jobid (\d+)", out)
    assert len(submitted) == 4, out[-3000:]                                         # 3 shards and the merge
    assert sorted(set(re.findall(r"rule_fig1_wedged_explore/ensemble_(\d)_3/", out))) == ["0", "1", "2"], out[-3000:]
    local = xr.load_dataset(tmp_path / "local" / target)
    cluster = xr.load_dataset(tmp_path / "cluster" / target)
    assert local.sizes["run"] == 420 and "shards" not in local.attrs["config_yaml"]
    timing = [v for v in local.data_vars if "wall_time" in v]
    xr.testing.assert_identical(local.drop_vars(timing), cluster.drop_vars(timing))  # data and attributes
