"""The two evolutions of figure 1 (ncd.figures.fig1_wedged.measure.evolutions)."""
from ncd.figures.fig1_wedged.measure import evolutions
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = evolutions(snakemake.params.config, Progress(log, 2, "evolutions"))
write_dataset(ds, snakemake.output[0])
log.info("%d steps; final heights %s", ds.sizes["step"] - 1, ds.y.isel(step=-1).values)
