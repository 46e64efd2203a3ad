"""Figure 5: Unger et al.'s eta (noise + NLGS relaxation) for one shard (shards/unger_<k>-of-<n>.nc)."""
import xarray as xr

from ncd.figures import governing
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
packs = xr.load_dataset(snakemake.input.packs)  # noqa: F821
ds = governing.unger_shard(packs, snakemake.params.config, Progress(log, packs.sizes["packing"], "unger"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("eta (Unger et al.'s way) %s, relaxations at rest %d of %d", ds.eta_unger.values.round(3).tolist(),
         int(ds.relaxed_ok.sum()), ds.relaxed_ok.size)
