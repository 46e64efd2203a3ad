"""Collect the cost of the exact angle ranges of every pile of fig4_history with an exact file."""
import glob

from ncd.io.netcdf import write_dataset
from ncd.pipeline.workflow import start
from ncd.studies.bench import exact_costs

log = start(snakemake)  # noqa: F821 (snakemake is injected)
ds = exact_costs(glob.glob(snakemake.params.pattern))  # noqa: F821
log.info("%d piles with exact ranges, %.0f s of LPs in all", ds.sizes["pile"], float(ds.lp_seconds.sum()))
write_dataset(ds, snakemake.output[0])  # noqa: F821
