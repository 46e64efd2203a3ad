"""One shard of the figure-1 exploration ensemble (ncd.figures.fig1_wedged.measure.explore_shard)."""
from ncd.figures.fig1_wedged.measure import explore_shard
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)
ds = explore_shard(snakemake.params.config, shard, n, Progress(log, 0, f"shard {shard}/{n}"))
write_dataset(ds, snakemake.output[0])
log.info("%d runs, %d converged, %d wedged", ds.sizes["run"], int(ds.converged.sum()), int((ds.outcome == 1).sum()))
