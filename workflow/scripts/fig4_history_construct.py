"""Figure 4 over construction histories: build one pile of one history (checkpointed), write its file with frames."""
import os

import xarray as xr

from ncd.core.errors import InputError
from ncd.figures.fig4_history import construct as history
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
w = snakemake.wildcards
if int(w.n) != cfg["grains"]["n"]:
    raise InputError(f"file name n{w.n} differs from fig4_history.grains.n = {cfg['grains']['n']}")
half = None
if w.history == "layer":   # the finite base of the layer: the member's point-source pile's base half-width
    with xr.open_dataset(snakemake.input.point) as p:
        half = float(p.attrs["base_half_width"])
checkpoint = snakemake.params.checkpoint
info = {}
scene, rec, ground, eq, frames = history.construct(cfg, w.history, int(w.member), half, log, checkpoint, info)
ds = history.pile_dataset(cfg, w.history, int(w.member), scene, rec, ground, eq, frames, half, info)
write_dataset(ds, snakemake.output[0])
if os.path.exists(checkpoint):
    os.remove(checkpoint)
d = ds.attrs["mean_diameter"]
log.info("%s pile %s: %d grains, %d steps, %.1f ms/step (%.0f s), base half-width %.1f d, flanks %.1f/%.1f deg, "
         "at rest |u_f| = %.2g g h, %d of %d poured grains removed off the base", w.history, w.member, ds.sizes["grain"], ds.sizes["step"],
         1e3 * float(ds.wall_time.mean()), float(ds.wall_time.sum()), ds.attrs["base_half_width"] / d,
         ds.attrs["left_angle"], ds.attrs["right_angle"], ds.attrs["eq_max_velocity"],
         ds.attrs["n_removed"], ds.attrs["n_poured"])
