"""Figure 5's uniform sampler, random and coordinate directions, on the same slices of this run."""
import xarray as xr

from ncd.figures.fig5_governing.sampler import compare, pick_slices, summary
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = xr.load_dataset(snakemake.input.packings)
out = compare(ds, snakemake.params.config, pick_slices(ds, snakemake.params.per_mu), snakemake.params.root_seed)
log.info("%s", summary(out))
write_dataset(out, snakemake.output[0])
