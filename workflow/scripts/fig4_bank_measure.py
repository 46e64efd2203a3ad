"""The bank of the piles of Figure 4: surface-parallel cuts, Love-Weber stress, reciprocity (measures.nc)."""
import xarray as xr

from ncd.figures.fig4_bank import measure as bank
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
piles = [("default", "default", bank.measure_pile(cfg, xr.load_dataset(snakemake.input.construction),
                                                  xr.load_dataset(snakemake.input.cuts)))]
for path in snakemake.input.piles:
    ds = xr.load_dataset(path)
    piles.append((f"{ds.attrs['history']}_{int(ds.attrs['member']):03d}", ds.attrs["history"],
                  bank.measure_pile(cfg, ds)))
out = bank.bank_dataset(cfg, piles)
out.attrs.update(provenance(cfg))
write_dataset(out, snakemake.output[0])
for h in out.history.values:
    s = out.sel(history=h)
    log.info("%s: angle to the vertical, median %.2f deg [%.2f, %.2f]; load / column weight %.3f; "
             "tau/sigma_n / tan(flank) %.3f; largest |asymmetry| %.2g", h, float(s.angle), float(s.angle_lo),
             float(s.angle_hi), float(s["carried"]), float(s.failure),
             float(abs(out.asymmetry.where(out.pile_history == h)).max()))
