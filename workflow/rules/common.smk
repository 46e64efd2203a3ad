# Helpers shared by the per-figure rule files (workflow/rules/<figure>.smk).
#
# Conventions of a figure <fig> (see workflow/README.md):
#   config section  config[<fig>], validated by workflow/schemas/<fig>.schema.yaml
#   data            results/<fig>/*.nc (simulation, exploration shards, merged ensembles)
#   notebook        notebooks/<fig>.ipynb (paired with notebooks/<fig>.py), run by a
#                   `notebook:` rule writing results/figures/<fig>.png and .pdf;
#                   its executed copy goes to results/notebooks/<fig>.ipynb and the
#                   generic rule `render_html` turns it into results/html/<fig>.html
#   logs, benches   results/logs/<fig>/<rule>*.log, results/benchmarks/<fig>/<rule>*.tsv
import glob
import os
from pathlib import Path

from ncd.pipeline.config import check_config
from ncd.pipeline.imports import closure

ROOT = Path(workflow.basedir)
# Every rule input and output is relative to the working directory, so that a moved or
# cloned checkout with its results/ and .snakemake/ plans nothing (tests/test_relocation.py).
REL = Path(os.path.relpath(ROOT))
# The conda environment of every rule (`--software-deployment-method conda`).
CONDA_ENV = "../envs/ncd.yaml"

# Figures in the order of the paper; each has a rules file and a config section.
FIGURES = [f for f in ("fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile", "fig4_history", "fig4_bank",
                       "fig5_governing", "stability", "error_vs_runtime")
           if (ROOT / "workflow" / "rules" / f"{f}.smk").exists()]

# Every config section (a missing figure section included) is checked here, before any
# job: its schema (integers that are integers), finite numbers everywhere, and the
# cross-field constraints of ncd/pipeline/config.py; errors name section and key.
check_config(config, FIGURES, ROOT / "workflow" / "schemas")

# Threads of an ensemble rule: its NLGS runs are spread over them (ncd.dynamics.explore.run_parallel,
# results identical whatever the count).  One: Snakemake starts a job only when its threads are free
# at once, so a 2-thread job waits behind the stream of 1-thread jobs until nothing else is left (on
# -j2 Figure 2's ensembles then started last and set the run time).  Parallelism comes from the
# shards instead; raise it per rule with --set-threads on a larger machine.
ENSEMBLE_THREADS = 1

# Snakemake starts the ready job of highest priority first.  The longest chains of the default
# run (the critical path of results/bench/dag.nc: Figure 2's flow, its ensembles and census;
# Figure 5's builds and analyses, the most CPU of the run in a few long shards; then Figure 4's
# pile, which fig4_bank reads) go first, so that the many short independent jobs fill the cores
# around them and at the end, instead of one long shard running alone last.
PRIORITY = {"fig2_slope": 100, "fig5_governing": 75, "fig4_pile": 50}

# The code a rule runs: the import closure of its script (or notebook) inside ncd/, read from
# the imports (ncd.pipeline.imports), so that no list of modules is kept by hand.  An edit of a
# figure's computation reruns the rules whose scripts import it, an edit of its plots.py or
# page.py only its notebook (and the pages after it), an edit of a lower layer every rule
# above it.  One input stands for the set: results/code/<name>.sha256, the SHA-256 of each
# file, rebuilt (rule code_stamp) when one of them is newer; Snakemake stats every input of
# every ready job each time it picks jobs, so one stamp per rule keeps that cheap.
CODE_SETS = {}


def code(name, files):
    """The stamp of the source set ``files`` under ``name`` (one name, one set)."""
    files = sorted(str(f) for f in files)
    if CODE_SETS.setdefault(name, files) != files:
        raise ValueError(f"code set {name!r} is defined twice with different files")
    return f"results/code/{name}.sha256"


def code_of(script):
    """The stamp of ``workflow/scripts/<script>.py`` and the ncd files it imports."""
    path = REL / "workflow" / "scripts" / f"{script}.py"
    return code(script, [str(path)] + closure([path], REL / "ncd"))


def notebook_code(figure):
    """The stamp of the ncd files a figure's notebook imports (read from its jupytext pair,
    ``notebooks/<figure>.py``; the notebook files themselves are inputs of their own)."""
    return code(f"{figure}_notebook", closure([REL / "notebooks" / f"{figure}.py"], REL / "ncd"))


def section(figure):
    """The config section of a figure (checked with every other by check_config above)."""
    return config[figure]


def without_shards(cfg):
    """A plain copy of a config (sub)section without any ``shards`` key: the ``params``
    of every rule but the merges, so that a new shard count reruns only the ensemble's
    explore and merge rules (and what reads the merged file), and stays out of provenance."""
    if isinstance(cfg, dict):
        return {k: without_shards(v) for k, v in cfg.items() if k != "shards"}
    if isinstance(cfg, (list, tuple)):
        return [without_shards(v) for v in cfg]
    return cfg


def shard_files(figure, name, n_shards):
    """Shard files of ensemble ``name``: results/<fig>/shards/<name>_<k>-of-<n>.nc."""
    return [f"results/{figure}/shards/{name}_{k}-of-{n_shards}.nc" for k in range(n_shards)]


def notebook_file(figure, ext="ipynb"):
    """The notebook of a figure: ``.ipynb`` (run by Snakemake) or ``.py`` (its jupytext pair;
    an input too, so that editing it reruns the notebook, and ncd.pages.notebook.paths stops the
    run when the pair differs: `jupytext --sync` was forgotten)."""
    return str(REL / "notebooks" / f"{figure}.{ext}")


# figures whose notebook writes the report caption from the data (caption_output)
CAPTIONS_FROM_DATA = ("fig1_wedged", "fig2_slope", "stability", "error_vs_runtime")


def caption_output(figure):
    """``results/figures/<figure>.caption.rst``: the report caption the figure's notebook writes
    (its finding, computed from the data), beside the PNG."""
    return f"results/figures/{figure}.caption.rst"


def figure_output(figure, ext):
    """``results/figures/<figure>.<ext>``, marked for ``snakemake --report report.zip`` with the
    caption its notebook wrote (CAPTIONS_FROM_DATA), else ``workflow/report/<figure>.rst`` (or
    the generic ``figure.rst``)."""
    name = figure if (ROOT / "workflow" / "report" / f"{figure}.rst").exists() else "figure"
    # a caption path is relative to the rules file (workflow/rules/)
    caption = f"../../{caption_output(figure)}" if figure in CAPTIONS_FROM_DATA else f"../report/{name}.rst"
    return report(f"results/figures/{figure}.{ext}", caption=caption, category=figure, subcategory=ext.upper())


def figure_targets(figure):
    return [f"results/html/{figure}.html", f"results/figures/{figure}.png",
            f"results/figures/{figure}.pdf"]


def log(figure, rule_name):
    return f"results/logs/{figure}/{rule_name}.log"


def bench(figure, rule_name):
    return f"results/benchmarks/{figure}/{rule_name}.tsv"


rule code_stamp:
    """The stamp of a source set (see ``code`` above): one line per file, its SHA-256 and path.
    First of all (a fraction of a second each): a rule's priority counts only once its stamp
    exists, so a stamp left among the other ready jobs would hold its chain back."""
    localrule: True
    priority: 1000
    input:
        lambda w: CODE_SETS[w.name],
    output:
        "results/code/{name}.sha256",
    wildcard_constraints:
        name=r"[A-Za-z0-9_]+",
    params:
        algorithm="sha256",
    log:
        log("code", "{name}"),
    benchmark:
        bench("code", "{name}")
    conda:
        CONDA_ENV
    script:
        "../scripts/code_stamp.py"
