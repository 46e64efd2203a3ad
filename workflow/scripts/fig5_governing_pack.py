"""Figure 5: build the packings of one shard by contact dynamics (shards/packs_<k>-of-<n>.nc)."""
import os
import sys

# one BLAS thread per job: with -j2 on 2 cores, OpenBLAS's default threads oversubscribe
# the cores (dense SVDs measured 6-18x slower on the loaded machine)
NUMPY_PRELOADED = "numpy" in sys.modules
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from ncd.figures import governing  # noqa: E402
from ncd.io import write_dataset  # noqa: E402
from ncd.pipeline import Progress, start  # noqa: E402

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("BLAS threads: OPENBLAS_NUM_THREADS=%s%s", os.environ["OPENBLAS_NUM_THREADS"],
         " (numpy was loaded before: not applied)" if NUMPY_PRELOADED else "")
cfg = snakemake.params.config  # noqa: F821
shard, n = int(snakemake.wildcards.shard), int(snakemake.wildcards.n)  # noqa: F821
ds = governing.pack_shard(cfg, shard, n, Progress(log, 0, "packings"))
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("%d packings, build steps %s, largest interpenetration %.3g R", ds.sizes["packing"],
         ds.build_steps.values.tolist(), float(ds.max_penetration.max()))
