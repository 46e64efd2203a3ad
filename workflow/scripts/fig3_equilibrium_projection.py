"""Figure 3: exact projections of A ∩ C on every contact's force plane (projection.nc)."""
import xarray as xr

from ncd.figures.fig3_equilibrium import measure as equilibrium
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
state = xr.load_dataset(snakemake.input.state)
ds = equilibrium.projection_dataset(state, snakemake.params.config,
                                    Progress(log, state.sizes["contact"], "projections"))
write_dataset(ds, snakemake.output[0])
log.info("dim A = %d (2 kappa - 3N = %d), dim A ∩ C = %s, bounded %s, %d LPs, all exact: %s",
         ds.attrs["dimension_A"], ds.attrs["dimension_moreau"], ds.attrs["dimension_AC"],
         bool(ds.attrs["bounded"]), ds.attrs["n_lp_total"], bool(ds.exact.all()))
