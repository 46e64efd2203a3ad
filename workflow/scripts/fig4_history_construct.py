"""Figure 4 over construction histories: build the three piles of one member (checkpointed), in
the order point, rain, layer (the layer's base is the point pile's), each written with its frames.
One job per member rather than per pile: a job's start-up (interpreter, imports, numba's cache)
is paid once for the three."""
import os

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
for name in history.HISTORIES:
    checkpoint = snakemake.params.checkpoints[name]
    base = half if name == "layer" else None
    info = {}
    scene, rec, ground, eq, frames = history.construct(cfg, name, int(w.member), base, log, checkpoint, info)
    ds = history.pile_dataset(cfg, name, int(w.member), scene, rec, ground, eq, frames, base, info)
    write_dataset(ds, snakemake.output[name])
    if name == "point":   # the finite base of the layer: this point-source pile's base half-width
        half = float(ds.attrs["base_half_width"])
    d = ds.attrs["mean_diameter"]
    log.info("%s pile %s: %d grains, %d steps, %.1f ms/step (%.0f s), base half-width %.1f d, flanks %.1f/%.1f deg, "
             "at rest |u_f| = %.2g g h, %d of %d poured grains removed off the base", name, w.member, ds.sizes["grain"],
             ds.sizes["step"], 1e3 * float(ds.wall_time.mean()), float(ds.wall_time.sum()), ds.attrs["base_half_width"] / d,
             ds.attrs["left_angle"], ds.attrs["right_angle"], ds.attrs["eq_max_velocity"],
             ds.attrs["n_removed"], ds.attrs["n_poured"])
for checkpoint in snakemake.params.checkpoints.values():   # kept to the end: a killed job resumes every pile
    if os.path.exists(checkpoint):
        os.remove(checkpoint)
