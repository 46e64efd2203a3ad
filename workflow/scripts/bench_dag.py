"""Core seconds (wall x threads) of every job of the default run and the DAG's critical path: the job graph
from a dry run (every job, whatever is built), the times from the benchmark files."""
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.studies.bench.runs import dag_table, dry_run, dry_run_jobs, ideal_time

log = start(snakemake)  # snakemake is injected
p = snakemake.params
jobs = dry_run_jobs(dry_run(p.targets, snakemake.config, p.cores))
ds = dag_table(jobs)
ds.attrs.update(provenance({"targets": list(p.targets), "cores": p.cores}), cores=p.cores,
                ideal_s=ideal_time(ds, p.cores), dag_jobs=len(jobs))
log.info("%d jobs (%d with a benchmark file), %.0f core s, critical path %.0f s, ideal run on %d cores %.0f s",
         len(jobs), ds.sizes["job"], ds.attrs["cpu_s"], ds.attrs["critical_path_s"], p.cores, ds.attrs["ideal_s"])
write_dataset(ds, snakemake.output[0])
