"""Figure 3: deposit the discs until at rest and store the packing (state.nc)."""
from ncd.figures import equilibrium
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
scene, info = equilibrium.deposit(cfg, Progress(log, cfg["packing"]["max_steps"], "deposit"))
ds = equilibrium.state_dataset(scene, info, cfg)
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("at rest after %d steps: %d discs, %d contacts (%d with walls), test |u_f| = %.2e |g| h",
         info["steps"], ds.sizes["disc"], ds.sizes["contact"], ds.attrs["n_wall_contacts"],
         ds.attrs["rest_max_velocity"])
