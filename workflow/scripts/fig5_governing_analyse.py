"""Figure 5: exact measures, random walk and uniform sample of the slices of one shard (shards/analyses_<k>-of-<n>.nc)."""
from ncd.figures import governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)  # noqa: F821
builds = governing.builds_of(snakemake.input.packs)  # noqa: F821
ds = governing.analysis_shard(builds, cfg, shard, n, Progress(log, 0, "analyses"))
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("dim(A∩C) %s, eta walk %s, eta uniform %s, chain gaps %s", ds.dim_AC_rank.values.tolist(),
         ds.eta_walk.values.round(4).tolist(), ds.eta_uniform.values.round(4).tolist(),
         ds.eta_uniform_gap.values.round(3).tolist())
