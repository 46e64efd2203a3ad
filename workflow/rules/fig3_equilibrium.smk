# Figure 3 of Moreau (2005), section 4: indetermination clouds of 28 discs at rest,
# with the exact projections of A ∩ C and a uniform sample of it.
#   simulate    packing deposited until at rest          -> state.nc
#   explore     NLGS runs, one shard of one mode          -> shards/<mode>_<k>-of-<n>.nc
#   merge       every shard of the three modes            -> ensemble.nc
#   projection  LP projections of A ∩ C on each contact   -> projection.nc
#   uniform     hit-and-run sample of A ∩ C               -> uniform.nc
#   notebook    notebooks/fig3_equilibrium.ipynb (figure, table and sentences:
#               ncd/figures/fig3_equilibrium/plots.py)          -> results/figures/fig3_equilibrium.png|pdf
FIG = "fig3_equilibrium"
CFG = section(FIG)
F3 = f"results/{FIG}"
F3_MODES = ("zero", "random", "warm")


rule fig3_equilibrium_simulate:
    input:
        code=code_of("fig3_equilibrium_simulate"),
    output:
        f"{F3}/state.nc",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "simulate"),
    benchmark:
        bench(FIG, "simulate")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig3_equilibrium_simulate.py"


rule fig3_equilibrium_explore:
    input:
        state=f"{F3}/state.nc",
        code=code_of("fig3_equilibrium_explore"),
    output:
        temp(f"{F3}/shards/{{name}}_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        name="|".join(F3_MODES),
        shard=r"\d+",
        n=r"\d+",
    threads: ENSEMBLE_THREADS
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "explore_{name}_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "explore_{name}_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig3_equilibrium_explore.py"


rule fig3_equilibrium_merge:
    input:
        shards=[f for m in F3_MODES for f in shard_files(FIG, m, CFG["modes"][m]["shards"])],
        code=code_of("merge_shards"),
    output:
        f"{F3}/ensemble.nc",
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


rule fig3_equilibrium_projection:
    input:
        state=f"{F3}/state.nc",
        code=code_of("fig3_equilibrium_projection"),
    output:
        f"{F3}/projection.nc",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "projection"),
    benchmark:
        bench(FIG, "projection")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig3_equilibrium_projection.py"


rule fig3_equilibrium_probes:
    """The one-step equilibrium test against the LP on positions in and out of equilibrium
    around the packing (ncd.figures.fig3_equilibrium.probes): data for the §2 claim."""
    input:
        state=f"{F3}/state.nc",
        code=code_of("fig3_equilibrium_probes"),
    output:
        f"{F3}/probes.nc",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "probes"),
    benchmark:
        bench(FIG, "probes")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig3_equilibrium_probes.py"


rule fig3_equilibrium_uniform:
    input:
        state=f"{F3}/state.nc",
        code=code_of("fig3_equilibrium_uniform"),
    output:
        f"{F3}/uniform.nc",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "uniform"),
    benchmark:
        bench(FIG, "uniform")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig3_equilibrium_uniform.py"


rule fig3_equilibrium_notebook:
    input:
        state=f"{F3}/state.nc",
        ensemble=f"{F3}/ensemble.nc",
        projection=f"{F3}/projection.nc",
        uniform=f"{F3}/uniform.nc",
        probes=f"{F3}/probes.nc",
        notebook=notebook_file(FIG),
        notebook_py=notebook_file(FIG, "py"),
        code=notebook_code("fig3_equilibrium"),
    output:
        png=figure_output(FIG, "png"),
        pdf=figure_output(FIG, "pdf"),
        finding=f"results/figures/{FIG}.finding.rst",   # included by the report's caption
    params:
        config=without_shards(CFG),
    log:
        notebook=f"results/notebooks/{FIG}.ipynb",
    benchmark:
        bench(FIG, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig3_equilibrium.ipynb"


rule fig3_equilibrium:
    input:
        figure_targets(FIG),
