"""Figure 3: points drawn uniformly from A ∩ C by hit-and-run (uniform.nc)."""
import xarray as xr

from ncd.figures import equilibrium
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
state = xr.load_dataset(snakemake.input.state)  # noqa: F821
ds = equilibrium.uniform_dataset(state, snakemake.params.config)  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d samples in dimension %d, max R-hat %.4f, max equilibrium residual %.1e",
         ds.sizes["sample"], ds.attrs["dimension_AC"], ds.attrs["rhat_max"], ds.attrs["max_equilibrium_residual"])
