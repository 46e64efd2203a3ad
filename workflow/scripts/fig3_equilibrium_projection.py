"""Figure 3: exact projections of A ∩ C on every contact's force plane (projection.nc)."""
import xarray as xr

from ncd.figures import equilibrium
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
state = xr.load_dataset(snakemake.input.state)  # noqa: F821
ds = equilibrium.projection_dataset(state, snakemake.params.config,  # noqa: F821
                                    Progress(log, state.sizes["contact"], "projections"))
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("dim A = %d (2 kappa - 3N = %d), dim A ∩ C = %s, bounded %s, %d LPs, all exact: %s",
         ds.attrs["dimension_A"], ds.attrs["dimension_moreau"], ds.attrs["dimension_AC"],
         bool(ds.attrs["bounded"]), ds.attrs["n_lp_total"], bool(ds.exact.all()))
