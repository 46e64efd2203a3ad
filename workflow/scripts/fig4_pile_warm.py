"""Figure 4: one shard of the warm-guess NLGS runs (random review orders) on the final pile, from the
construction's last impulses (the antecedent contact forces of section 5).  construction.nc keeps the
history forces, not that guess: the construction is replayed once per shard (checked bit for bit against
construction.nc), then the shard's members run with the ensemble's solver settings."""
import xarray as xr

from ncd.dynamics.explore import shard_members
from ncd.figures.fig4_pile import measure as pile
from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
w = snakemake.wildcards
cfg = snakemake.params.config
e, warm = cfg["ensemble"], cfg["warm_ensemble"]
construction = xr.load_dataset(snakemake.input.construction)
guess = pile.antecedent(cfg, construction, log)
log.info("construction replayed: %d antecedent impulses", len(guess[0]))
members = shard_members(warm["runs"], int(w.shard), int(w.n))
ds = pile.ensemble_shard(cfg, construction, xr.load_dataset(snakemake.input.cuts), members, [e["tol"]],
                         warm["root_seed"], log, finish=e["finish"], guess=guess).isel(tol=0)
log.info("warm guess: %d contacts matched, relative L1 distance to the history forces %.3g",
         ds.attrs["guess_matched"], ds.attrs["guess_offset"])
write_dataset(ds, snakemake.output[0])
