"""Figure 5: build the packings of one shard by contact dynamics (shards/packs_<k>-of-<n>.nc)."""
from ncd.figures import governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)  # noqa: F821
ds = governing.pack_shard(cfg, shard, n, Progress(log, 0, "packings"))
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d builds, steps %s, largest interpenetration %.3g R", ds.sizes["build"],
         ds.build_steps.values.tolist(), float(ds.max_penetration.max()))
