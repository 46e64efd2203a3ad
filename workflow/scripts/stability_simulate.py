"""Run every case of the stability table (CD at each h, MD at each factor of h_crit) and one binary collision."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.solver.settings import SolverSettings
from ncd.studies.stability.measure import binary_collision, run_table

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = run_table(cfg, log)
ds.attrs.update(provenance(cfg, SolverSettings(**cfg["solver"])))
write_dataset(ds, snakemake.output.table)
write_dataset(binary_collision(), snakemake.output.collision)
