"""Figure 3: the one-step equilibrium test against the LP around the packing (probes.nc)."""
import xarray as xr

from ncd.figures.fig3_equilibrium import probes
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
state = xr.load_dataset(snakemake.input.state)
ds = probes.probe_dataset(state)
ds.attrs.update(provenance(snakemake.params.config))
write_dataset(ds, snakemake.output[0])
for k, name in enumerate(ds.position.values):
    log.info("%s: u_f = 0 %s (zero, warm), A ∩ C non-empty %s", name, ds.at_rest.values[k].tolist(),
             ds.admits_equilibrium.values[k].tolist())
