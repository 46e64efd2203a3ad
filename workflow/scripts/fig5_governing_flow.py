"""Figure 5: one flow of the study, released from its deposit and scanned (shards/flow_<i>_seed<s>.nc)."""
import xarray as xr

from ncd.figures import governing_flow
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
i, s = int(snakemake.wildcards.i), int(snakemake.wildcards.s)  # noqa: F821
dep = xr.load_dataset(snakemake.input.deposit)  # noqa: F821
ds = governing_flow.flow_dataset(dep, snakemake.params.config, i, s, Progress(log, 0, "scans"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("setting %d seed %d: indeterminate %s, solutions %s", i, s, ds.indeterminate.values.ravel().tolist(),
         ds.n_solutions.values.ravel().tolist())
