"""Figure 2: the census of the exact solutions of the investigated step (census.nc)."""
import xarray as xr

from ncd.figures import census
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
inp = snakemake.input  # noqa: F821
ds = census.census_dataset(xr.load_dataset(inp.trajectory), xr.load_dataset(inp.ensemble),
                           xr.load_dataset(inp.measures), snakemake.params.config, log)  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d distinct exact solutions: by NLGS %d, by Lemke %d, by enumeration %d; largest residual %.2g",
         ds.sizes["solution"], ds.attrs["n_nlgs"], ds.attrs["n_lemke"], ds.attrs["n_enumeration"],
         float(ds.residual.max()))
