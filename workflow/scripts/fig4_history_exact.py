"""Figure 4 over construction histories: exact angle ranges over A ∩ C at the arching cuts of
the point and rain piles of one member (HiGHS LPs), one file per pile."""
import xarray as xr

from ncd.figures.fig4_history import exact as history_exact
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
for name in snakemake.output.keys():   # the rule's histories, one file each
    pile = xr.load_dataset(snakemake.input[name])
    out = history_exact.exact_ranges(cfg, pile, log)
    out.attrs.update(provenance(cfg))
    write_dataset(out, snakemake.output[name])
    log.info("%s: exact deviation ranges (deg): min %s, max %s; history angle outside the exact range by at most "
             "%.2g degree", name, out.exact_deviation_min.values.round(1).tolist(),
             out.exact_deviation_max.values.round(1).tolist(), float(out.history_outside.max()))
