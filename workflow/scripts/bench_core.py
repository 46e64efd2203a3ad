"""Core benchmark: sweep cost (numba and C), detection, step time, memory; start-up."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import core_table, environment, startup

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = core_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment(), **{f"startup_{k}": v for k, v in startup().items()}))
write_dataset(ds, snakemake.output[0])  # noqa: F821
