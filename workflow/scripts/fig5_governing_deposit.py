"""Figure 5: the deposit of one seed, shared by every setting of that seed (shards/deposit_seed<s>.nc)."""
from ncd.figures.fig5_governing import flow as governing_flow
from ncd.io.netcdf import write_dataset
from ncd.io.progress import Progress
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
s = int(snakemake.wildcards.s)
ds = governing_flow.deposit_dataset(snakemake.params.config, s, Progress(log, 0, "deposit"))
write_dataset(ds, snakemake.output[0])
log.info("deposit mu %.3g seed %d: %d steps", ds.attrs["mu"], s, ds.attrs["deposit_steps"])
