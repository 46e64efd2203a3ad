"""Figure 2: the census of the exact solutions of the investigated step (census.nc)."""
import os

# One BLAS thread whatever the rule's threads (Snakemake sets OPENBLAS_NUM_THREADS to them),
# set before numpy loads: the dense solves of Lemke's bases keep the same bits whatever -j,
# and the rule's threads run the census's independent solves side by side instead.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import xarray as xr  # noqa: E402 (after the BLAS thread count)

from ncd.figures.fig2_slope import census  # noqa: E402
from ncd.io.netcdf import write_dataset  # noqa: E402
from ncd.pipeline.jobs import start  # noqa: E402

log = start(snakemake)  # snakemake is injected
inp = snakemake.input
ds = census.census_dataset(xr.load_dataset(inp.trajectory), xr.load_dataset(inp.ensemble),
                           xr.load_dataset(inp.measures), snakemake.params.config, log)
write_dataset(ds, snakemake.output[0])
log.info("%d distinct exact solutions: by NLGS %d, by Lemke %d, by enumeration %d; largest residual %.2g",
         ds.sizes["solution"], ds.attrs["n_nlgs"], ds.attrs["n_lemke"], ds.attrs["n_enumeration"],
         float(ds.residual.max()))
