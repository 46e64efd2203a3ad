"""Run every case of the stability table (CD at each h, MD at each factor of h_crit)."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start
from ncd.solver.settings import SolverSettings
from ncd.studies.stability import run_table

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = run_table(cfg, log)
ds.attrs.update(provenance(cfg, SolverSettings(**cfg["solver"])))
write_dataset(ds, snakemake.output[0])  # noqa: F821
