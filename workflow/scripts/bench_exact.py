"""Collect the cost of the exact angle ranges of every pile of fig4_history with an exact file."""
import glob

from ncd.io.netcdf import write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.runs import exact_costs

log = start(snakemake)  # snakemake is injected
ds = exact_costs(glob.glob(snakemake.params.pattern))
log.info("%d piles with exact ranges, %.0f s of LPs in all", ds.sizes["pile"], float(ds.lp_seconds.sum()))
write_dataset(ds, snakemake.output[0])
