"""Merge the shards of one ensemble into a single netCDF file (member order)."""
from ncd.io.netcdf import merge_shards, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = merge_shards(snakemake.input.shards, dim=snakemake.params.dim)
write_dataset(ds, snakemake.output[0])
log.info("merged %d shards, %d members", len(snakemake.input.shards), ds.sizes[snakemake.params.dim])
