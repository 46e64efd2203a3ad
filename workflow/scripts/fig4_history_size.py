"""Figure 4 over construction histories, size study: the analyses of every pile size side by side (size.nc)."""
import xarray as xr

from ncd.figures.fig4_history import size as history_size
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
analyses = [xr.load_dataset(p) for p in snakemake.input.analyses]
out = history_size.size_dataset(analyses, seed=snakemake.params.seed)
out.attrs.update(provenance({"seed": snakemake.params.seed, "analyses": len(analyses)}))
write_dataset(out, snakemake.output[0])
for h in out.history.values:
    s = out.sel(history=h)
    log.info("%s: grains %s, dip %s, arching %s deg (p %s)", h, out.grains.values.tolist(),
             s.dip_mean.isel(kernel=0).values.round(3).tolist(), s.arching_mean.values.round(2).tolist(),
             s.arching_size_p.values.round(3).tolist())
