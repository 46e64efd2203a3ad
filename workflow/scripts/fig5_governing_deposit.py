"""Figure 5: the deposit of one seed, shared by every setting of that seed (shards/deposit_seed<s>.nc)."""
from ncd.figures import governing_flow
from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import Progress, start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
s = int(snakemake.wildcards.s)  # noqa: F821
ds = governing_flow.deposit_dataset(snakemake.params.config, s, Progress(log, 0, "deposit"))  # noqa: F821
write_dataset(ds, snakemake.output[0])  # noqa: F821
log.info("deposit mu %.3g seed %d: %d steps", ds.attrs["mu"], s, ds.attrs["deposit_steps"])
