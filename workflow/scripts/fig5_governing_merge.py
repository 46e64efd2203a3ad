"""Figure 5: merge the build and analysis shards into packings.nc."""
from ncd.figures.fig5_governing import measure as governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
inp = snakemake.input
ds = governing.merge(inp.packs, inp.analyses)
write_dataset(ds, snakemake.output[0])
log.info("merged %d analyses of %d builds", ds.sizes["packing"], ds.sizes["build"])
