"""Figure 4: the exact set A ∩ C of the final pile by LP -- cut polygons, angle ranges, ground pressure (exact.nc)."""
import xarray as xr

from ncd.figures.fig4_pile import exact as pile_exact
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
ds = pile_exact.exact_dataset(snakemake.params.config, xr.load_dataset(snakemake.input.construction),
                              xr.load_dataset(snakemake.input.cuts), log)
write_dataset(ds, snakemake.output[0])
a = ds.attrs
m = list(ds.choice.values).index(a["dip_main_choice"])
log.info("default cut: %d vertices, %d LPs, %.1f s; cuts where every admissible state arches: %d of %d; "
         "dip (%s, units of W/2L, > 0 a dip): history %.4g, binning spread %.3g, exact range [%.4g, %.4g] -> %s, called: %s",
         int(ds.n_vertices[0]), int(ds.n_lp[0]), float(ds.polygon_wall_time[0]), int(ds.all_arch.sum()),
         ds.sizes["cut"], a["dip_main_choice"], float(ds.dip_history[m]), a["dip_binning_spread"],
         float(ds.dip_min[m]), float(ds.dip_max[m]), a["dip_geometry"],
         a["dip_called"])
