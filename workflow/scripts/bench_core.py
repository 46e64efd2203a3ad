"""Core benchmark: sweep cost (numba and C), detection, step time, memory; start-up."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.solver import core_table, environment, startup

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = core_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment(), **{f"startup_{k}": v for k, v in startup().items()}))
write_dataset(ds, snakemake.output[0])
