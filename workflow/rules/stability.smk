# Stability of Contact Dynamics and of the MD baseline on stiff and extreme cases (issue 5).
# One job runs every case (small scenes; a job's start-up costs more than most cases).
FIG = "stability"
CFG = section(FIG)


rule stability_simulate:
    """The stability table: one row per (case, method, h)."""
    input:
        ncd_sources(FIG),
    output:
        "results/stability/table.nc",
    params:
        config=CFG,
    log:
        log(FIG, "stability_simulate"),
    benchmark:
        bench(FIG, "stability_simulate")
    script:
        "../scripts/stability_simulate.py"


rule stability_notebook:
    input:
        table="results/stability/table.nc",
        notebook=str(ROOT / "notebooks" / "stability.ipynb"),
    output:
        png="results/figures/stability.png",
        pdf="results/figures/stability.pdf",
    log:
        notebook="results/notebooks/stability.ipynb",
    benchmark:
        bench(FIG, "stability_notebook")
    notebook:
        "../../notebooks/stability.ipynb"


rule stability:
    input:
        figure_targets(FIG),
