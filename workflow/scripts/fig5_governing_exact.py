"""Figure 5: exact measures of A ∩ C for the packings of one shard (shards/exact_<k>-of-<n>.nc)."""
import os
import sys

# one BLAS thread per job: with -j2 on 2 cores, OpenBLAS's default threads oversubscribe
# the cores (dense SVDs measured 6-18x slower on the loaded machine)
NUMPY_PRELOADED = "numpy" in sys.modules
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import xarray as xr  # noqa: E402

from ncd.figures import governing  # noqa: E402
from ncd.io import write_dataset  # noqa: E402
from ncd.pipeline import Progress, start  # noqa: E402

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("BLAS threads: OPENBLAS_NUM_THREADS=%s%s", os.environ["OPENBLAS_NUM_THREADS"],
         " (numpy was loaded before: not applied)" if NUMPY_PRELOADED else "")
packs = xr.load_dataset(snakemake.input.packs)  # noqa: F821
ds = governing.exact_shard(packs, snakemake.params.config, Progress(log, packs.sizes["packing"], "exact"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("dim(A∩C) rank count %s, by LP %s, eta %s, LPs %d", ds.dim_AC_rank.values.tolist(),
         ds.dim_AC_lp.values.tolist(), ds.eta_exact.values.round(3).tolist(), int(ds.n_lp.sum()))
