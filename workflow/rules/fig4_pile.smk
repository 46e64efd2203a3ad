# Figure 4 of Moreau (2005), section 5: a pile poured from a localized source; the
# resultant across a vertical cut and its indetermination cloud.
#   simulate   pour, settle until the warm equilibrium test passes -> construction.nc
#   cuts       surface fit, cuts and ground pressure (history)     -> cuts.nc
#   exact      A ∩ C by LP (HiGHS): cut polygons, angle
#              ranges, ground-pressure bands, dip verdict   -> exact.nc
#   explore    zero-guess NLGS runs (random orders) of one shard of
#              the ensemble or of the tolerance study               -> shards/<name>_<k>-of-<n>.nc
#   warm       the same problem from the construction's last impulses (replayed: construction.nc
#              keeps the history forces, not that guess), other random orders
#                                                                   -> shards/warm_<k>-of-<n>.nc
#   merge      the shards, in member order                          -> ensemble.nc, tolerance.nc, warm.nc
#   notebook   notebooks/fig4_pile.ipynb (figure and sentences: ncd/figures/fig4_pile/plots.py)
#                                                                   -> results/figures/fig4_pile.png|pdf
FIG4 = "fig4_pile"
CFG4 = section(FIG4)
F4 = f"results/{FIG4}"
# each rule sees only the sections it uses (a cut parameter does not rerun the construction)
CFG4_SIM = {k: CFG4[k] for k in ("seed", "grains", "ground", "mu", "mu_ground", "gravity", "h", "source",
                                 "construction")}
CFG4_CUTS = {**CFG4_SIM, **{k: CFG4[k] for k in ("surface", "cut", "pressure")}}
CFG4_EXACT = {**CFG4_CUTS, "exact": CFG4["exact"]}
CFG4_EXP = {**CFG4_CUTS, **{k: CFG4[k] for k in ("ensemble", "tolerance_study")}}
# the warm runs: the pile's sections and the ensemble's solver settings (not its members)
CFG4_WARM = {**CFG4_CUTS, "warm_ensemble": CFG4["warm_ensemble"],
             "ensemble": {k: v for k, v in CFG4["ensemble"].items() if k not in ("runs", "shards", "root_seed")}}
F4_SHARDS = {"ensemble": CFG4["ensemble"]["shards"], "tolerance": CFG4["tolerance_study"]["shards"],
             "warm": CFG4["warm_ensemble"]["shards"]}


rule fig4_pile_simulate:
    priority: PRIORITY["fig4_pile"]
    input:
        code=code_of("fig4_pile_simulate"),
    output:
        f"{F4}/construction.nc",
    params:
        config=CFG4_SIM,
    log:
        log(FIG4, "simulate"),
    benchmark:
        bench(FIG4, "simulate")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_pile_simulate.py"


rule fig4_pile_cuts:
    priority: PRIORITY["fig4_pile"]
    input:
        construction=f"{F4}/construction.nc",
        code=code_of("fig4_pile_cuts"),
    output:
        f"{F4}/cuts.nc",
    params:
        config=CFG4_CUTS,
    log:
        log(FIG4, "cuts"),
    benchmark:
        bench(FIG4, "cuts")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_pile_cuts.py"


rule fig4_pile_exact:
    priority: PRIORITY["fig4_pile"]
    input:
        construction=f"{F4}/construction.nc",
        cuts=f"{F4}/cuts.nc",
        code=code_of("fig4_pile_exact"),
    output:
        f"{F4}/exact.nc",
    params:
        config=CFG4_EXACT,
    log:
        log(FIG4, "exact"),
    benchmark:
        bench(FIG4, "exact")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_pile_exact.py"


rule fig4_pile_explore:
    priority: PRIORITY["fig4_pile"]
    input:
        construction=f"{F4}/construction.nc",
        cuts=f"{F4}/cuts.nc",
        code=code_of("fig4_pile_explore"),
    output:
        temp(f"{F4}/shards/{{name}}_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        name="ensemble|tolerance",
        shard=r"\d+",
        n=r"\d+",
    threads: ENSEMBLE_THREADS
    params:
        config=without_shards(CFG4_EXP),
    log:
        log(FIG4, "explore_{name}_{shard}-of-{n}"),
    benchmark:
        bench(FIG4, "explore_{name}_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_pile_explore.py"


rule fig4_pile_warm:
    priority: PRIORITY["fig4_pile"]
    input:
        construction=f"{F4}/construction.nc",
        cuts=f"{F4}/cuts.nc",
        code=code_of("fig4_pile_warm"),
    output:
        temp(f"{F4}/shards/warm_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    threads: ENSEMBLE_THREADS
    params:
        config=without_shards(CFG4_WARM),
    log:
        log(FIG4, "warm_{shard}-of-{n}"),
    benchmark:
        bench(FIG4, "warm_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_pile_warm.py"


rule fig4_pile_merge:
    priority: PRIORITY["fig4_pile"]
    input:
        shards=lambda w: shard_files(FIG4, w.name, F4_SHARDS[w.name]),
        code=code_of("merge_shards"),
    output:
        f"{F4}/{{name}}.nc",
    wildcard_constraints:
        name="ensemble|tolerance|warm",
    params:
        dim="run",
    log:
        log(FIG4, "merge_{name}"),
    benchmark:
        bench(FIG4, "merge_{name}")
    conda:
        CONDA_ENV
    script:
        "../scripts/merge_shards.py"


rule fig4_pile_notebook:
    priority: PRIORITY["fig4_pile"]
    input:
        construction=f"{F4}/construction.nc",
        cuts=f"{F4}/cuts.nc",
        ensemble=f"{F4}/ensemble.nc",
        tolerance=f"{F4}/tolerance.nc",
        warm=f"{F4}/warm.nc",
        exact=f"{F4}/exact.nc",
        notebook=notebook_file(FIG4),
        notebook_py=notebook_file(FIG4, "py"),
        code=notebook_code("fig4_pile"),
    output:
        png=figure_output(FIG4, "png"),
        pdf=figure_output(FIG4, "pdf"),
        finding=f"results/figures/{FIG4}.finding.rst",   # included by the report's caption
    params:
        config=without_shards(CFG4),
    log:
        notebook=f"results/notebooks/{FIG4}.ipynb",
    benchmark:
        bench(FIG4, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_pile.ipynb"


rule fig4_pile:
    input:
        figure_targets(FIG4),
