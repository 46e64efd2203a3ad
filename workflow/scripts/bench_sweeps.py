"""Sweeps to a fixed tolerance against N (zero guess and warm start)."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import environment, sweeps_table

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = sweeps_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output[0])  # noqa: F821
