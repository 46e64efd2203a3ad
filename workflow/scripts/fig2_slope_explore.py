"""Figure 2: one shard of the zero-guess and warm-start NLGS runs at the investigated step."""
import xarray as xr

from ncd.dynamics.explore import shard_members
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start
from ncd.shared import slope

log = start(snakemake)  # snakemake is injected
w = snakemake.wildcards
cfg = snakemake.params.config
members = shard_members(cfg["explore"]["runs"], int(w.shard), int(w.n))
traj = xr.load_dataset(snakemake.input.trajectory)
ds = slope.run_ensemble(traj, cfg, members, Progress(log, 0, f"shard {w.shard}/{w.n}"))
write_dataset(ds, snakemake.output[0])
last = ds.isel(tol=-1)
log.info("%d members x %d inits, %d converged at tol %.0e, sweeps median %d max %d, %.1f s of NLGS",
         ds.sizes["run"], ds.sizes["init"], int(last.converged.sum()), float(ds.tol[-1]),
         int(last.sweeps.median()), int(last.sweeps.max()), float(last.wall_time.sum()))
