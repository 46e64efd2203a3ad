"""Figure 4 over construction histories: shape match, ground stress, dip and arching over the piles and the
comparison of the histories with its controls (analysis_n<n>.nc)."""
import xarray as xr

from ncd.figures.fig4_history import analysis as history_analysis
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
files = {}
for path in snakemake.input.piles:
    ds = xr.load_dataset(path)
    files.setdefault(ds.attrs["history"], []).append(ds)
exact = {}
for path in snakemake.input.exact:
    e = xr.load_dataset(path)
    exact[(e.attrs["history"], int(e.attrs["member"]))] = e
out = history_analysis.ensemble_dataset(cfg, files, exact)
out.attrs.update(provenance(cfg))
write_dataset(out, snakemake.output[0])
for h in out.history.values:
    k = out.kernel.values[0]
    s = out.sel(history=h, kernel=k)
    log.info("%s: dip of the mean profile %.3f [%.3f, %.3f] (kernel %.1f d)", h, float(s.dip_mean),
             float(s.dip_lo), float(s.dip_hi), k)
for c in out.comparison.values:
    m = history_analysis.comparison_summary(out, c)
    log.info("%s: shapes matched %s (relative differences %s), differing measures %s", c, m["matched"],
             {k: round(v["rel"], 4) for k, v in m["shape"].items()}, m["differing"])
