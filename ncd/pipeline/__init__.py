"""Layer 9 (the top), pipeline: the glue between the Snakemake workflow and the package, above the
science it runs: each job's logging, threads and signals and the recovery of a killed run
(:mod:`.jobs`), a patch of Snakemake's scheduler loop (:mod:`.scheduler`), the config checks
run before any job (:mod:`.config`) and the code inputs of a rule read from its imports
(:mod:`.imports`).
"""
