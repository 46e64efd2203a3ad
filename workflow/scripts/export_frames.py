"""VTK time series (ParaView) and an animation of a figure's stored frames (ncd.io.export)."""
import xarray as xr

from ncd.io.export import animate, write_vtk
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = xr.load_dataset(snakemake.input[0])
name = snakemake.params.name
for pvd in write_vtk(ds, snakemake.output.vtk, name):
    log.info("wrote %s", pvd)
period = float(ds.attrs.get("period", 0.0)) or None
out = animate(ds, snakemake.output.animation, title=f"{snakemake.wildcards.figure}: {name}",
              period=period)
log.info("wrote %s (%d frames)", out, ds.sizes["frame"])
