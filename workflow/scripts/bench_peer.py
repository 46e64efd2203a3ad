"""ncd and pymunk side by side on the same poured pile."""
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.peer import compare
from ncd.studies.bench.solver import environment

log = start(snakemake)  # snakemake is injected
ds = compare(snakemake.params.config, log)
ds.attrs.update(environment())
write_dataset(ds, snakemake.output[0])
