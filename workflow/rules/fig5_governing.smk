# Figure 5 (issue 15): what governs indeterminacy — static packings across friction,
# measured exactly (LPs on A ∩ C) and Unger, Kertész & Wolf's way (noise + NLGS).
#   pack      packings of one shard built by contact dynamics  -> shards/packs_<k>-of-<n>.nc
#   exact     exact measures of A ∩ C (HiGHS LPs)              -> shards/exact_<k>-of-<n>.nc
#   unger     noise + NLGS relaxations (exploration)           -> shards/unger_<k>-of-<n>.nc
#   merge     every shard of the three                         -> packings.nc
#   notebook  notebooks/fig5_governing.ipynb                    -> results/figures/fig5_governing.png|pdf
FIG = "fig5_governing"
CFG = section(FIG)
F5 = f"results/{FIG}"
F5_STAGES = ("packs", "exact", "unger")


rule fig5_governing_pack:
    input:
        ncd_sources(FIG),
    output:
        temp(f"{F5}/shards/packs_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "pack_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "pack_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_pack.py"


rule fig5_governing_exact:
    input:
        ncd_sources(FIG),
        packs=f"{F5}/shards/packs_{{shard}}-of-{{n}}.nc",
    output:
        temp(f"{F5}/shards/exact_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "exact_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "exact_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_exact.py"


rule fig5_governing_unger:
    input:
        ncd_sources(FIG),
        packs=f"{F5}/shards/packs_{{shard}}-of-{{n}}.nc",
    output:
        temp(f"{F5}/shards/unger_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "unger_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "unger_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_unger.py"


rule fig5_governing_merge:
    input:
        **{s: shard_files(FIG, s, CFG["shards"]) for s in F5_STAGES},
    output:
        f"{F5}/packings.nc",
    log:
        log(FIG, "merge"),
    benchmark:
        bench(FIG, "merge")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_merge.py"


rule fig5_governing_notebook:
    input:
        packings=f"{F5}/packings.nc",
        notebook=notebook_file(FIG),
        notebook_py=notebook_file(FIG, "py"),
    output:
        png=figure_output(FIG, "png"),
        pdf=figure_output(FIG, "pdf"),
    params:
        config=without_shards(CFG),
    log:
        notebook=f"results/notebooks/{FIG}.ipynb",
    benchmark:
        bench(FIG, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig5_governing.ipynb"


rule fig5_governing:
    input:
        figure_targets(FIG),
