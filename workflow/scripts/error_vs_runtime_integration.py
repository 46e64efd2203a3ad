"""Time-integration work-precision: CD over h, MD over h and stiffness, per observable."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.solver.settings import SolverSettings
from ncd.studies.error_vs_runtime.measure import integration_table

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = integration_table(cfg, log)
ds.attrs.update(provenance(cfg, SolverSettings(**cfg["solver"])))
write_dataset(ds, snakemake.output[0])
