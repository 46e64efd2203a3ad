"""Collect the wall time of every rule of the figures from their benchmark files."""
import glob

from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.runs import rule_times

log = start(snakemake)  # snakemake is injected
paths = [p for p in glob.glob(snakemake.params.pattern)
         if p.split("/")[-2] in snakemake.params.figures]
ds = rule_times(paths)
log.info("%d rule benchmarks, %.0f s in all", ds.sizes["job"], float(ds.seconds.sum()))
write_dataset(ds, snakemake.output[0])
