"""Merge the shards of one ensemble into a single netCDF file (member order)."""
from ncd.io.netcdf import merge_shards, write_dataset
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = merge_shards(snakemake.input, dim=snakemake.params.dim)  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("merged %d shards, %d members", len(snakemake.input), ds.sizes[snakemake.params.dim])  # noqa: F821
