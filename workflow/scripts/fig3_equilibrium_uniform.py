"""Figure 3: points drawn uniformly from A ∩ C by hit-and-run (uniform.nc)."""
import xarray as xr

from ncd.figures.fig3_equilibrium import measure as equilibrium
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
state = xr.load_dataset(snakemake.input.state)
ds = equilibrium.uniform_dataset(state, snakemake.params.config)
write_dataset(ds, snakemake.output[0])
log.info("%d samples in dimension %d, max R-hat %.4f, max equilibrium residual %.1e",
         ds.sizes["sample"], ds.attrs["dimension_AC"], ds.attrs["rhat_max"], ds.attrs["max_equilibrium_residual"])
