"""One shard of the figure-1 exploration ensemble (ncd.figures.wedged.explore_shard)."""
from ncd.figures.wedged import explore_shard
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)  # noqa: F821
ds = explore_shard(snakemake.params.config, shard, n, Progress(log, 0, f"shard {shard}/{n}"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d runs, %d converged, %d wedged", ds.sizes["run"], int(ds.converged.sum()), int((ds.outcome == 1).sum()))
