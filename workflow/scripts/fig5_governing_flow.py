"""Figure 5: one flow of the study, released from its deposit and scanned (shards/flow_<i>_seed<s>.nc)."""
import xarray as xr

from ncd.figures.fig5_governing import flow as governing_flow
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
i, s = int(snakemake.wildcards.i), int(snakemake.wildcards.s)
dep = xr.load_dataset(snakemake.input.deposit)
ds = governing_flow.flow_dataset(dep, snakemake.params.config, i, s, Progress(log, 0, "scans"))
write_dataset(ds, snakemake.output[0])
log.info("setting %d seed %d: indeterminate %s, solutions %s", i, s, ds.indeterminate.values.ravel().tolist(),
         ds.n_solutions.values.ravel().tolist())
