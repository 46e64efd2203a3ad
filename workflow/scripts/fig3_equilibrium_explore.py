"""Figure 3: one shard of the NLGS runs of one exploration mode (zero, random, warm)."""
import xarray as xr

from ncd.figures.fig3_equilibrium import measure as equilibrium
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
w = snakemake.wildcards
state = xr.load_dataset(snakemake.input.state)
progress = Progress(log, 0, f"{w.name} shard {w.shard}/{w.n}")
ds = equilibrium.run_ensemble(state, snakemake.params.config, w.name, int(w.shard), int(w.n), progress)
write_dataset(ds, snakemake.output[0])
log.info("%d runs, %d converged, sweeps median %d max %d, %.1f s of NLGS", ds.sizes["run"],
         int(ds.converged.sum()), int(ds.sweeps.median()), int(ds.sweeps.max()), float(ds.wall_time.sum()))
