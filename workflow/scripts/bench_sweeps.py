"""Sweeps to a fixed tolerance against N (zero guess and warm start)."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.solver import environment, sweeps_table

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = sweeps_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output[0])
