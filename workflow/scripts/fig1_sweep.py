"""The friction-angle sweep of figure 1 (ncd.figures.fig1_wedged.measure.threshold_sweep)."""
from ncd.figures.fig1_wedged.measure import threshold_sweep
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = threshold_sweep(snakemake.params.config, Progress(log, 0, "friction angles"))
write_dataset(ds, snakemake.output[0])
log.info("wedged fraction per angle: %s", ds.wedged_fraction.round(3).values)
