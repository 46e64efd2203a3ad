"""An NLGS ensemble on 1 and 2 threads: speed-up and bit-for-bit equality."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import ensemble_table, environment

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = ensemble_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output[0])  # noqa: F821
