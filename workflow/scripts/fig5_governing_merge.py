"""Figure 5: merge the build and analysis shards into packings.nc."""
from ncd.figures import governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
inp = snakemake.input  # noqa: F821
ds = governing.merge(inp.packs, inp.analyses)
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("merged %d analyses of %d builds", ds.sizes["packing"], ds.sizes["build"])
