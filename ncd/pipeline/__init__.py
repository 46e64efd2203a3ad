"""Layer 5, pipeline: the glue between the Snakemake workflow and the package: solver
settings from ``config.yaml``, progress logs, recovery of a killed run
(:mod:`.workflow`), and the config checks run before any job (:mod:`.config`).
"""
