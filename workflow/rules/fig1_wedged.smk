# Figure 1 (Moreau 2005, section 1): the wedged disc.  See workflow/README.md.
FIG = "fig1_wedged"
CFG = section(FIG)


rule fig1_wedged_explore:
    """One shard of the one-step exploration ensemble (random and zero initial guesses)."""
    input:
        code=code_of("fig1_explore"),
    output:
        temp("results/fig1_wedged/shards/{name}_{shard}-of-{n}.nc"),
    wildcard_constraints:
        name="ensemble",
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    threads: 1
    log:
        log(FIG, "explore_{name}_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "explore_{name}_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig1_explore.py"


rule fig1_wedged_merge:
    input:
        shards=shard_files(FIG, "ensemble", CFG["ensemble"]["shards"]),
        code=code_of("merge_shards"),
    output:
        "results/fig1_wedged/ensemble.nc",
    params:
        dim="run",
    log:
        log(FIG, "merge"),
    benchmark:
        bench(FIG, "merge")
    conda:
        CONDA_ENV
    script:
        "../scripts/merge_shards.py"


rule fig1_wedged_simulate:
    """The two evolutions (zero guess at every step; wedged first guess then warm starts)."""
    input:
        code=code_of("fig1_simulate"),
    output:
        "results/fig1_wedged/evolutions.nc",
    params:
        config=without_shards(CFG),
    threads: 1
    log:
        log(FIG, "simulate"),
    benchmark:
        bench(FIG, "simulate")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig1_simulate.py"


rule fig1_wedged_sweep:
    """Fraction of wedged outcomes against the friction angle."""
    input:
        code=code_of("fig1_sweep"),
    output:
        "results/fig1_wedged/sweep.nc",
    params:
        config=without_shards(CFG),
    threads: 1
    log:
        log(FIG, "sweep"),
    benchmark:
        bench(FIG, "sweep")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig1_sweep.py"


rule fig1_wedged_notebook:
    input:
        ensemble="results/fig1_wedged/ensemble.nc",
        evolutions="results/fig1_wedged/evolutions.nc",
        sweep="results/fig1_wedged/sweep.nc",
        notebook=notebook_file("fig1_wedged"),
        notebook_py=notebook_file("fig1_wedged", "py"),
        code=notebook_code("fig1_wedged"),
    output:
        png=figure_output("fig1_wedged", "png"),
        pdf=figure_output("fig1_wedged", "pdf"),
        caption=caption_output("fig1_wedged"),
    log:
        notebook="results/notebooks/fig1_wedged.ipynb",
    benchmark:
        bench(FIG, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig1_wedged.ipynb"


rule fig1_wedged:
    input:
        figure_targets(FIG),
