"""Figure 3: deposit the discs until at rest and store the packing (state.nc)."""
from ncd.figures.fig3_equilibrium import measure as equilibrium
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
scene, info = equilibrium.deposit(cfg, Progress(log, cfg["packing"]["max_steps"], "deposit"))
ds = equilibrium.state_dataset(scene, info, cfg)
write_dataset(ds, snakemake.output[0])
log.info("at rest after %d steps: %d discs, %d contacts (%d with walls), test |u_f| = %.2e |g| h",
         info["steps"], ds.sizes["disc"], ds.sizes["contact"], ds.attrs["n_wall_contacts"],
         ds.attrs["rest_max_velocity"])
