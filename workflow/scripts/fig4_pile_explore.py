"""Figure 4: one shard of zero-guess NLGS runs (random review orders) on the final pile; the
ensemble's runs are finished (config ``ensemble.finish``), the tolerance study's are plain NLGS."""
import xarray as xr

from ncd.dynamics.explore import shard_members
from ncd.figures.fig4_pile import measure as pile
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
w = snakemake.wildcards
cfg = snakemake.params.config
e = cfg["ensemble"]
study = cfg["tolerance_study"]
runs, tols = (e["runs"], [e["tol"]]) if w.name == "ensemble" else (study["runs"], study["tolerances"])
members = shard_members(runs, int(w.shard), int(w.n))
ds = pile.ensemble_shard(cfg, xr.load_dataset(snakemake.input.construction),
                         xr.load_dataset(snakemake.input.cuts), members, tols, e["root_seed"], log,
                         finish=e["finish"] if w.name == "ensemble" else "none")    # the study: plain NLGS
if w.name == "ensemble":
    ds = ds.isel(tol=0)
write_dataset(ds, snakemake.output[0])
