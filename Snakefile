# ncd: reproduce the figures of Moreau (2005), "Indetermination in the numerical
# simulation of granular systems".  `snakemake -j2` builds every figure;
# `snakemake -j2 fig1_wedged` builds one figure and only its inputs.
from pathlib import Path

from snakemake.utils import min_version, validate

min_version("8.0")

configfile: str(Path(workflow.basedir) / "config.yaml")

validate(config, str(Path(workflow.basedir) / "workflow/schemas/config.schema.yaml"))

include: "workflow/rules/common.smk"

for _figure in FIGURES:
    include: f"workflow/rules/{_figure}.smk"

# the benchmark suite: `snakemake -j2 bench` (not part of the default target)
if "bench" in config:
    include: "workflow/rules/bench.smk"


rule all:
    default_target: True
    input:
        [figure_targets(f) for f in FIGURES],
