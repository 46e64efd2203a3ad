"""The two evolutions of figure 1 (ncd.figures.wedged.evolutions)."""
from ncd.figures.wedged import evolutions
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = evolutions(snakemake.params.config, Progress(log, 2, "evolutions"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d steps; final heights %s", ds.sizes["step"] - 1, ds.y.isel(step=-1).values)
