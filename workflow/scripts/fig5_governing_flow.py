"""Figure 5: the flows of one seed, one per setting, each released from the seed's deposit and
scanned (shards/flow_<i>_seed<s>.nc, i in the order of the rule's outputs)."""
import xarray as xr

from ncd.figures.fig5_governing import flow as governing_flow
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
s = int(snakemake.wildcards.s)
dep = xr.load_dataset(snakemake.input.deposit)   # read-only: each flow's scene copies its arrays (make_scene)
for i, path in enumerate(snakemake.output):
    ds = governing_flow.flow_dataset(dep, snakemake.params.config, i, s, Progress(log, 0, "scans"))
    write_dataset(ds, path)
    log.info("setting %d seed %d: indeterminate %s, solutions %s", i, s, ds.indeterminate.values.ravel().tolist(),
             ds.n_solutions.values.ravel().tolist())
