"""Figure 5: one flow of the study, released from its deposit and scanned (shards/flow_<i>_seed<s>.nc)."""
import os
import sys

# one BLAS thread per job: with -j2 on 2 cores, OpenBLAS's default threads oversubscribe
# the cores (dense SVDs measured 6-18x slower on the loaded machine)
NUMPY_PRELOADED = "numpy" in sys.modules
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import xarray as xr  # noqa: E402

from ncd.figures import governing_flow  # noqa: E402
from ncd.io import write_dataset  # noqa: E402
from ncd.pipeline import Progress, start  # noqa: E402

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("BLAS threads: OPENBLAS_NUM_THREADS=%s%s", os.environ["OPENBLAS_NUM_THREADS"],
         " (numpy was loaded before: not applied)" if NUMPY_PRELOADED else "")
i, s = int(snakemake.wildcards.i), int(snakemake.wildcards.s)  # noqa: F821
dep = xr.load_dataset(snakemake.input.deposit)  # noqa: F821
ds = governing_flow.flow_dataset(dep, snakemake.params.config, i, s, Progress(log, 0, "scans"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("setting %d seed %d: indeterminate %s, solutions %s", i, s, ds.indeterminate.values.ravel().tolist(),
         ds.n_solutions.values.ravel().tolist())
