"""Figure 5: exact measures, random walk and uniform sample of the slices of one shard (shards/analyses_<k>-of-<n>.nc)."""
from ncd.figures.fig5_governing import measure as governing
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)
builds = governing.builds_of(snakemake.input.packs)
ds = governing.analysis_shard(builds, cfg, shard, n, Progress(log, 0, "analyses"))
write_dataset(ds, snakemake.output[0])
log.info("dim(A∩C) %s, eta walk %s, eta uniform %s, chain gaps %s", ds.dim_AC_rank.values.tolist(),
         ds.eta_walk.values.round(4).tolist(), ds.eta_uniform.values.round(4).tolist(),
         ds.eta_uniform_gap.values.round(3).tolist())
