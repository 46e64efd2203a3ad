"""Figure 5: build the packings of one shard by contact dynamics (shards/packs_<k>-of-<n>.nc)."""
from ncd.figures.fig5_governing import measure as governing
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)
ds = governing.pack_shard(cfg, shard, n, Progress(log, 0, "packings"))
write_dataset(ds, snakemake.output[0])
log.info("%d builds, steps %s, largest interpenetration %.3g R", ds.sizes["build"],
         ds.build_steps.values.tolist(), float(ds.max_penetration.max()))
