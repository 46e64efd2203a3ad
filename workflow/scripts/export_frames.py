"""VTK time series (ParaView) and an animation of a figure's stored frames (ncd.io.export)."""
import xarray as xr

from ncd.io.export import animate, write_vtk
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = xr.load_dataset(snakemake.input[0])  # noqa: F821
name = snakemake.params.name  # noqa: F821
for pvd in write_vtk(ds, snakemake.output.vtk, name):  # noqa: F821
    log.info("wrote %s", pvd)
period = float(ds.attrs.get("period", 0.0)) or None
out = animate(ds, snakemake.output.animation, title=f"{snakemake.wildcards.figure}: {name}",  # noqa: F821
              period=period)
log.info("wrote %s (%d frames)", out, ds.sizes["frame"])
