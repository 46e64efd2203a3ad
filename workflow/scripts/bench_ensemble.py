"""An NLGS ensemble on 1 and 2 threads: speed-up and bit-for-bit equality."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.solver import ensemble_table, environment

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = ensemble_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output[0])
