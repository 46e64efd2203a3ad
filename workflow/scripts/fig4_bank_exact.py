"""The bank of Figure 4, exactly: angle ranges over A ∩ C at the surface-parallel cuts of one pile (HiGHS LPs)."""
import xarray as xr

from ncd.figures import bank_exact
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
name = snakemake.wildcards.pile  # noqa: F821
cuts = xr.load_dataset(snakemake.input.cuts) if name == "default" else None  # noqa: F821
out = bank_exact.exact_ranges(cfg, snakemake.params.pile_config, xr.load_dataset(snakemake.input.pile),  # noqa: F821
                              name, cuts, log)
out.attrs.update(provenance(cfg))
write_dataset(out, snakemake.output[0])  # noqa: F821
log.info("%s: exact width of the angle range, median %.1f deg; history outside by at most %.2g deg; "
         "largest asymmetry at the LP points %.2g", name, float((out.angle_max - out.angle_min).median()),
         float(out.history_outside.max()), float(out.vertex_asymmetry.max()))
