# Figure 2 of Moreau (2005), section 3: dispersion of a grain's acceleration in a
# flow of discs down a 24° slope.
#   simulate   deposit, release, flow with warm starts    -> trajectory.nc
#   explore    zero-guess and warm-start NLGS runs of one
#              block of members, tolerance by tolerance   -> shards/ensemble_<k>-of-<n>.nc
#   merge      the shards, in member order                -> ensemble.nc
#   analyse    spreads, principal axes, solutions, verdict -> measures.nc
#   census     exact solutions: NLGS end points, Lemke,
#              status enumeration, basins, stability     -> census.nc
#   notebook   notebooks/fig2_slope.ipynb                  -> results/figures/fig2_slope.png|pdf
FIG2 = "fig2_slope"
CFG2 = section(FIG2)
F2 = f"results/{FIG2}"
# each rule sees only the sections it uses, so that e.g. an analysis
# threshold does not rerun the simulation
CFG2_SIM = {k: CFG2[k] for k in ("scene", "deposit", "flow", "scan")}
CFG2_EXP = {k: CFG2[k] for k in ("scene", "flow", "explore")}


rule fig2_slope_simulate:
    priority: PRIORITY["fig2_slope"]
    input:
        code=code_of("fig2_slope_simulate"),
    output:
        f"{F2}/trajectory.nc",
    params:
        config=CFG2_SIM,
    log:
        log(FIG2, "simulate"),
    benchmark:
        bench(FIG2, "simulate")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig2_slope_simulate.py"


rule fig2_slope_explore:
    priority: PRIORITY["fig2_slope"]
    input:
        trajectory=f"{F2}/trajectory.nc",
        code=code_of("fig2_slope_explore"),
    output:
        temp(f"{F2}/shards/ensemble_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    threads: ENSEMBLE_THREADS
    params:
        config=without_shards(CFG2_EXP),
    log:
        log(FIG2, "explore_{shard}-of-{n}"),
    benchmark:
        bench(FIG2, "explore_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig2_slope_explore.py"


rule fig2_slope_merge:
    priority: PRIORITY["fig2_slope"]
    input:
        shards=shard_files(FIG2, "ensemble", CFG2["explore"]["shards"]),
        code=code_of("merge_shards"),
    output:
        f"{F2}/ensemble.nc",
    params:
        dim="run",
    log:
        log(FIG2, "merge"),
    benchmark:
        bench(FIG2, "merge")
    conda:
        CONDA_ENV
    script:
        "../scripts/merge_shards.py"


rule fig2_slope_analyse:
    priority: PRIORITY["fig2_slope"]
    input:
        trajectory=f"{F2}/trajectory.nc",
        ensemble=f"{F2}/ensemble.nc",
        code=code_of("fig2_slope_analyse"),
    output:
        f"{F2}/measures.nc",
    params:
        config=without_shards(CFG2),
    log:
        log(FIG2, "analyse"),
    benchmark:
        bench(FIG2, "analyse")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig2_slope_analyse.py"


rule fig2_slope_census:
    priority: PRIORITY["fig2_slope"]
    input:
        trajectory=f"{F2}/trajectory.nc",
        ensemble=f"{F2}/ensemble.nc",
        measures=f"{F2}/measures.nc",
        code=code_of("fig2_slope_census"),
    output:
        f"{F2}/census.nc",
    # its random-guess NLGS runs, Lemke runs, status projections and perturbed restarts run
    # side by side on these threads (census.nc identical whatever the count)
    threads: ENSEMBLE_THREADS
    params:
        config={k: CFG2[k] for k in ("scene", "flow", "census")},
    log:
        log(FIG2, "census"),
    benchmark:
        bench(FIG2, "census")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig2_slope_census.py"


rule fig2_slope_notebook:
    priority: PRIORITY["fig2_slope"]
    input:
        trajectory=f"{F2}/trajectory.nc",
        ensemble=f"{F2}/ensemble.nc",
        measures=f"{F2}/measures.nc",
        census=f"{F2}/census.nc",
        notebook=notebook_file(FIG2),
        notebook_py=notebook_file(FIG2, "py"),
        code=notebook_code("fig2_slope"),
    output:
        png=figure_output(FIG2, "png"),
        pdf=figure_output(FIG2, "pdf"),
        caption=caption_output(FIG2),
    params:
        config=without_shards(CFG2),
    log:
        notebook=f"results/notebooks/{FIG2}.ipynb",
    benchmark:
        bench(FIG2, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig2_slope.ipynb"


rule fig2_slope:
    input:
        figure_targets(FIG2),
