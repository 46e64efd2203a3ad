"""Figure 4: free surface, cut resultants and ground pressure of the history forces (cuts.nc)."""
import xarray as xr

from ncd.figures.fig4_pile import measure as pile
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = pile.cuts_dataset(snakemake.params.config, xr.load_dataset(snakemake.input.construction))
write_dataset(ds, snakemake.output[0])
a = ds.attrs
k = 0  # the default cut
log.info("flanks: left %.1f°, right %.1f°; default cut x = %.2f d: %d contacts, resultant (%.4g, %.4g) N, "
         "%.1f° below horizontal (%.1f° from the surface)", a["left_angle"], a["right_angle"],
         float(ds.cut_x[k]) / a["mean_diameter"], int(ds.n_crossing[k]), float(ds.history_fx[k]),
         float(ds.history_fy[k]), float(ds.history_angle[k]), float(ds.history_deviation[k]))
