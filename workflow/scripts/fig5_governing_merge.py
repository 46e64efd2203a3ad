"""Figure 5: merge the packing, exact and Unger shards into packings.nc."""
import os
import sys

# one BLAS thread per job: with -j2 on 2 cores, OpenBLAS's default threads oversubscribe
# the cores (dense SVDs measured 6-18x slower on the loaded machine)
NUMPY_PRELOADED = "numpy" in sys.modules
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from ncd.figures import governing  # noqa: E402
from ncd.io import write_dataset  # noqa: E402
from ncd.pipeline import start  # noqa: E402

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("BLAS threads: OPENBLAS_NUM_THREADS=%s%s", os.environ["OPENBLAS_NUM_THREADS"],
         " (numpy was loaded before: not applied)" if NUMPY_PRELOADED else "")
inp = snakemake.input  # noqa: F821
ds = governing.merge(inp.packs, inp.exact, inp.unger)
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("merged %d packings", ds.sizes["packing"])
