"""Collect the wall time of every rule of the figures from their benchmark files."""
import glob

from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import rule_times

log = start(snakemake)  # noqa: F821 (snakemake is injected)
paths = [p for p in glob.glob(snakemake.params.pattern)  # noqa: F821
         if p.split("/")[-2] in snakemake.params.figures]  # noqa: F821
ds = rule_times(paths)
log.info("%d rule benchmarks, %.0f s in all", ds.sizes["job"], float(ds.seconds.sum()))
write_dataset(ds, snakemake.output[0])  # noqa: F821
