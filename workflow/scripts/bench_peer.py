"""ncd and pymunk side by side on the same poured pile."""
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import environment
from ncd.studies.peer import compare

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = compare(snakemake.params.config, log)  # noqa: F821
ds.attrs.update(environment())
write_dataset(ds, snakemake.output[0])  # noqa: F821
