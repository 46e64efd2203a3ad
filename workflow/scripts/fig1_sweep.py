"""The friction-angle sweep of figure 1 (ncd.figures.wedged.threshold_sweep)."""
from ncd.figures.wedged import threshold_sweep
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = threshold_sweep(snakemake.params.config, Progress(log, 0, "friction angles"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("wedged fraction per angle: %s", ds.wedged_fraction.round(3).values)
