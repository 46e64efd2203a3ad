# Issue 16: Figure 4's claims as statistics over piles of two construction histories.
#   construct  one pile (history point or rain, member m, n grains); a rain pile reads the
#              point pile of its member (the rain falls over that pile's base width);
#              checkpoints in results/fig4_history/checkpoints (resumed after a kill,
#              removed at the end)                              -> piles/n<n>/<history>_<m>.nc
#   exact      exact angle ranges over A ∩ C at the arching cuts of the first exact.piles
#              members of each history (HiGHS LPs, ncd.figures.history_exact)
#                                                                -> exact/n<n>/<history>_<m>.nc
#   analyse    ground stress, dip, arching over the piles       -> analysis_n<n>.nc
#   notebook   notebooks/fig4_history.ipynb                     -> results/figures/fig4_history.png|pdf
FIGH = "fig4_history"
CFGH = section(FIGH)
FH = f"results/{FIGH}"
NH = CFGH["grains"]["n"]
# the construction sees only what builds a pile (an analysis parameter does not rebuild the piles)
CFGH_SIM = {k: CFGH[k] for k in ("root_seed", "grains", "ground", "mu", "mu_ground", "gravity", "h", "source",
                                 "rain", "construction", "surface")}
# the construction does not depend on the analysis, exact and plotting modules (editing them reruns
# the analysis only)
FH_AFTER = ("history_analysis.py", "history_exact.py", "history_plots.py", "pile_exact.py", "pressure.py")
FH_BUILD_SOURCES = [f for f in ncd_sources(FIGH) if not f.endswith(FH_AFTER)]
FH_PILES = [f"{FH}/piles/n{NH}/{h}_{m:03d}.nc" for h in ("point", "rain") for m in range(CFGH["piles"])]
FH_EXACT = [f"{FH}/exact/n{NH}/{h}_{m:03d}.nc" for h in ("point", "rain")
            for m in range(min(CFGH["exact"]["piles"], CFGH["piles"]))]
# the exact ranges (pile_exact: A ∩ C by HiGHS, through history_exact) do not depend on the plots
FH_EXACT_SOURCES = [f for f in ncd_sources(FIGH) if not f.endswith("history_plots.py")]


rule fig4_history_construct:
    input:
        FH_BUILD_SOURCES,
        point=lambda w: [] if w.history == "point" else f"{FH}/piles/n{w.n}/point_{w.member}.nc",
    output:
        f"{FH}/piles/n{{n}}/{{history}}_{{member}}.nc",
    wildcard_constraints:
        history="point|rain",
        member=r"\d+",
        n=r"\d+",
    params:
        config=CFGH_SIM,
        checkpoint=lambda w: f"{FH}/checkpoints/n{w.n}/{w.history}_{w.member}.npz",
    log:
        log(FIGH, "construct_n{n}_{history}_{member}"),
    benchmark:
        bench(FIGH, "construct_n{n}_{history}_{member}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_construct.py"


rule fig4_history_exact:
    input:
        FH_EXACT_SOURCES,
        pile=f"{FH}/piles/n{{n}}/{{history}}_{{member}}.nc",
    output:
        f"{FH}/exact/n{{n}}/{{history}}_{{member}}.nc",
    wildcard_constraints:
        history="point|rain",
        member=r"\d+",
        n=r"\d+",
    params:
        config={k: v for k, v in CFGH.items() if k != "piles"},   # one pile's ranges: not the pile count
    log:
        log(FIGH, "exact_n{n}_{history}_{member}"),
    benchmark:
        bench(FIGH, "exact_n{n}_{history}_{member}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_exact.py"


rule fig4_history_analyse:
    input:
        ncd_sources(FIGH),
        piles=FH_PILES,
        exact=FH_EXACT,
    output:
        f"{FH}/analysis_n{NH}.nc",
    params:
        config=CFGH,
    log:
        log(FIGH, f"analyse_n{NH}"),
    benchmark:
        bench(FIGH, f"analyse_n{NH}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_analyse.py"


rule fig4_history_notebook:
    input:
        analysis=f"{FH}/analysis_n{NH}.nc",
        point=f"{FH}/piles/n{NH}/point_000.nc",
        rain=f"{FH}/piles/n{NH}/rain_000.nc",
        plots=str(REL / "ncd" / "figures" / "history_plots.py"),
        notebook=notebook_file(FIGH),
        notebook_py=notebook_file(FIGH, "py"),
    output:
        png=figure_output(FIGH, "png"),
        pdf=figure_output(FIGH, "pdf"),
    params:
        config=CFGH,
    log:
        notebook=f"results/notebooks/{FIGH}.ipynb",
    benchmark:
        bench(FIGH, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_history.ipynb"


rule fig4_history:
    input:
        figure_targets(FIGH),
