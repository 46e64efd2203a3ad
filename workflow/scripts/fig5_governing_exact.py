"""Figure 5: exact measures of A ∩ C for the packings of one shard (shards/exact_<k>-of-<n>.nc)."""
import xarray as xr

from ncd.figures import governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
packs = xr.load_dataset(snakemake.input.packs)  # noqa: F821
ds = governing.exact_shard(packs, snakemake.params.config, Progress(log, packs.sizes["packing"], "exact"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("dim(A∩C) rank count %s, by LP %s, eta %s, LPs %d", ds.dim_AC_rank.values.tolist(),
         ds.dim_AC_lp.values.tolist(), ds.eta_exact.values.round(3).tolist(), int(ds.n_lp.sum()))
