"""Figure 5: the deposit of one (mu, seed), shared by the flows of that mu (shards/deposit_mu<m>_seed<s>.nc)."""
import os
import sys

# one BLAS thread per job: with -j2 on 2 cores, OpenBLAS's default threads oversubscribe
# the cores (dense SVDs measured 6-18x slower on the loaded machine)
NUMPY_PRELOADED = "numpy" in sys.modules
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
from ncd.figures import governing_flow  # noqa: E402
from ncd.io import write_dataset  # noqa: E402
from ncd.pipeline import Progress, start  # noqa: E402

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("BLAS threads: OPENBLAS_NUM_THREADS=%s%s", os.environ["OPENBLAS_NUM_THREADS"],
         " (numpy was loaded before: not applied)" if NUMPY_PRELOADED else "")
m, s = int(snakemake.wildcards.m), int(snakemake.wildcards.s)  # noqa: F821
ds = governing_flow.deposit_dataset(snakemake.params.config, m, s, Progress(log, 0, "deposit"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("deposit mu %.3g seed %d: %d steps", ds.attrs["mu"], s, ds.attrs["deposit_steps"])
