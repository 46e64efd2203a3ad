"""The bank of Figure 4 tilted: the tilt at which each flank of the default pile and of the first point-source
piles fails, their grains' friction angle (tilt.nc)."""
import xarray as xr

from ncd.figures.fig4_bank import tilt
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
pile_cfg = snakemake.params.pile_config
tilt.check_tilt(cfg["tilt"])
piles = [("default", "default", snakemake.input.construction,
          tilt.tilt_pile(cfg["tilt"], pile_cfg["default"], xr.load_dataset(snakemake.input.construction),
                         xr.load_dataset(snakemake.input.cuts), "default", log))]
for path in snakemake.input.piles:
    ds = xr.load_dataset(path)
    name = f"{ds.attrs['history']}_{int(ds.attrs['member']):03d}"
    piles.append((name, ds.attrs["history"], path, tilt.tilt_pile(cfg["tilt"], pile_cfg["point"], ds, None, name, log)))
out = tilt.tilt_dataset(cfg, piles)
out.attrs.update(provenance(cfg, default_pile_config=tilt.config_text(pile_cfg["default"]),
                            point_pile_config=tilt.config_text(pile_cfg["point"])))
write_dataset(out, snakemake.output[0])
for h in out.history.values:
    log.info("%s: failure tilt, median over piles and flanks %.2f deg [%.2f, %.2f]", h, float(out.margin.sel(history=h)),
             float(out.margin_lo.sel(history=h)), float(out.margin_hi.sel(history=h)))
