"""Figure 4: pour the pile and settle it until the warm equilibrium test passes (construction.nc,
with frames every `construction.frame_every` steps)."""
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start
from ncd.shared import pile
from ncd.shared.construction import add_frames

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
frame_every = cfg["construction"]["frame_every"]
scene, record, ground, eq, *frames = pile.construct(cfg, log, frame_every=frame_every)
ds = pile.construction_dataset(cfg, scene, record, ground, eq)
if frame_every > 0:  # frames for ParaView and the animation (ncd.io.export, `snakemake export`)
    add_frames(ds, frames[0], cfg["h"])
write_dataset(ds, snakemake.output[0])
d = ds.attrs["mean_diameter"]
log.info("%d grains, %d steps (t = %.3f s), %.1f ms/step, sweeps mean %.0f, %d steps not converged, "
         "max interpenetration %.3f d; at rest: |u_f| = %.2g g h (%d sweeps)", ds.sizes["grain"], ds.sizes["step"],
         float(ds.time[-1]), 1e3 * float(ds.wall_time.mean()), float(ds.sweeps.mean()),
         int((~ds.converged.astype(bool)).sum()), float(ds.max_penetration.max()) / d,
         ds.attrs["eq_max_velocity"], ds.attrs["eq_sweeps"])
