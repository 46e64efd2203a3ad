"""Time-integration work-precision: CD over h, MD over h and stiffness, per observable."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.workflow import start
from ncd.solver.settings import SolverSettings
from ncd.studies.work_precision import integration_table

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = integration_table(cfg, log)
ds.attrs.update(provenance(cfg, SolverSettings(**cfg["solver"])))
write_dataset(ds, snakemake.output[0])  # noqa: F821
