"""Figure 2: spreads, principal axes, solutions and verdict of the ensembles (measures.nc)."""
import xarray as xr

from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start
from ncd.shared import slope_analysis

log = start(snakemake)  # snakemake is injected
traj = xr.load_dataset(snakemake.input.trajectory)
ens = xr.load_dataset(snakemake.input.ensemble)
ds = slope_analysis.measures_dataset(traj, ens, snakemake.params.config)
write_dataset(ds, snakemake.output[0])
log.info("grain %d, verdict: %s; %s", int(ds.attrs["grain"]), ds.attrs["verdict"],
         ", ".join(f"{k} {ds.attrs[k]:.3g}" for k in ds.attrs if k.startswith("verdict_")))
