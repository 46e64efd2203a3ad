"""Figure 2: deposit, release and flow of the discs down the slope (trajectory.nc)."""
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start
from ncd.shared import slope

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = slope.trajectory_dataset(cfg, Progress(log, 0, "deposit and flow"))
write_dataset(ds, snakemake.output[0])
k = int(ds.attrs["investigated_step"]) - 1
log.info("deposit: %d steps; flow: %d steps, %d not converged; investigated step %d at t = %.4f s: "
         "%d contacts, mean vx %.4g m/s", ds.sizes["deposit_step"], ds.sizes["step"], int((ds.converged == 0).sum()),
         k + 1, float(ds.attrs["investigated_time"]), int(ds.n_contacts[k]), float(ds.mean_vx[k]))
