"""Figure 3: one shard of the NLGS runs of one exploration mode (zero, random, warm)."""
import xarray as xr

from ncd.figures import equilibrium
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
w = snakemake.wildcards  # noqa: F821
state = xr.load_dataset(snakemake.input.state)  # noqa: F821
progress = Progress(log, 0, f"{w.name} shard {w.shard}/{w.n}")
ds = equilibrium.run_ensemble(state, snakemake.params.config, w.name, int(w.shard), int(w.n), progress)  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d runs, %d converged, sweeps median %d max %d, %.1f s of NLGS", ds.sizes["run"],
         int(ds.converged.sum()), int(ds.sweeps.median()), int(ds.sweeps.max()), float(ds.wall_time.sum()))
