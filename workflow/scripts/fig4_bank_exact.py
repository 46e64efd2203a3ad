"""The bank of Figure 4, exactly: angle ranges over A ∩ C at the surface-parallel cuts of one pile (HiGHS LPs)."""
import xarray as xr

from ncd.figures.fig4_bank import exact as bank_exact
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
name = snakemake.wildcards.pile
cuts = xr.load_dataset(snakemake.input.cuts) if name == "default" else None
out = bank_exact.exact_ranges(cfg, snakemake.params.pile_config, xr.load_dataset(snakemake.input.pile),
                              name, cuts, log)
out.attrs.update(provenance(cfg))
write_dataset(out, snakemake.output[0])
log.info("%s: exact width of the angle range, median %.1f deg; history outside by at most %.2g deg; "
         "largest asymmetry at the LP points %.2g", name, float((out.angle_max - out.angle_min).median()),
         float(out.history_outside.max()), float(out.vertex_asymmetry.max()))
