"""Where the CPU of the figures' jobs goes: a run of the figures with the quick overlay's
counts (config/quick.yaml as caps over this run's config) in a scratch working directory,
under py-spy, each sample filed under its job's figure and its category (kernel, LP solver,
other compiled code, Python: ncd.studies.bench.profile)."""
import glob
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import yaml

from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench import profile as prof

log = start(snakemake)  # snakemake is injected
p = snakemake.params
root = Path(p.root).resolve()
config = prof.capped(snakemake.config, yaml.safe_load((root / p.overlay).read_text()))
with tempfile.TemporaryDirectory(prefix="ncd-profile-") as tmp:
    scratch = Path(tmp)
    work = scratch / "run"
    work.mkdir()
    cfg = scratch / "config.yaml"
    cfg.write_text(yaml.safe_dump(config, sort_keys=True))
    # the targets first: --configfile takes every argument after it; the wrappers are kept,
    # their preambles name each job's rule (ncd.studies.bench.profile.read_wrapper)
    command = [sys.executable, "-m", "snakemake", "-s", root / "Snakefile", "-d", work, "--cores", p.cores,
               "--skip-script-cleanup", *p.targets, "--configfile", cfg]
    env = dict(os.environ)
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env.get("PATH", "")   # jupyter for the notebooks
    raw = scratch / "profile.raw"
    log.info("py-spy at %s samples per second: %s", p.rate, " ".join(map(str, command)))
    cmd, printout = prof.record(command, raw, p.rate, env=env)
    Path(snakemake.log.run).write_text(printout)
    total, errors = prof.recording_counts(printout)
    samples = prof.parse_raw(raw.read_text())
    figures = prof.sample_figures(samples, prof.rules_table(root / "workflow" / "rules"), "workflow/rules")
    ds = prof.profile_table(samples, figures, p.rate, order=p.figures)
    bench_files = glob.glob(str(work / "results" / "benchmarks" / "*" / "*.tsv")) + \
        glob.glob(str(work / "results" / "benchmarks" / "*.tsv"))
    wall = prof.job_wall(bench_files)
    shown = " ".join(str(c) for c in cmd).replace(str(scratch), "<scratch>").replace(str(root), "<repo>")
    shown = shown.replace(sys.executable, "python").replace(prof.py_spy(), "py-spy")

ds["job_wall_s"] = ("figure", np.array([wall.get(str(f), np.nan) for f in ds.figure.values]),
                    {"units": "s", "long_name": "wall seconds of the figure's jobs in the profiled run "
                     "(their benchmark files)"})
ds.attrs.update(provenance(config, targets=list(p.targets), cores=int(p.cores)), command=shown,
                config_label=str(config.get("run", {}).get("label", "full")), overlay=str(p.overlay),
                pyspy_samples=total, pyspy_errors=errors,
                pyspy_version=prof.py_spy_version())
log.info("%d samples (py-spy: %d, %d errors); %s", int(ds.samples.sum()), total, errors,
         "; ".join(f"{f}: kernels {k:.2f}, solvers {s:.2f}" for f, k, s in
                   zip(ds.figure.values, ds.kernel_share.values, ds.solver_share.values)))
write_dataset(ds, snakemake.output[0])
