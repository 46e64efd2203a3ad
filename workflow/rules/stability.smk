# Stability of Contact Dynamics and of the MD baseline on stiff and extreme cases.
# One job runs every case (small scenes; a job's start-up costs more than most cases).
FIG = "stability"
CFG = section(FIG)


rule stability_simulate:
    """The stability table: one row per (case, method, h)."""
    input:
        figure_code(FIG),
    output:
        "results/stability/table.nc",
    params:
        config=CFG,
    log:
        log(FIG, "stability_simulate"),
    benchmark:
        bench(FIG, "stability_simulate")
    conda:
        CONDA_ENV
    script:
        "../scripts/stability_simulate.py"


rule stability_notebook:
    input:
        table="results/stability/table.nc",
        page=page_modules(FIG),
        notebook=notebook_file("stability"),
        notebook_py=notebook_file("stability", "py"),
        pages=page_sources("notebook"),
    output:
        png=figure_output("stability", "png"),
        pdf=figure_output("stability", "pdf"),
        caption=caption_output("stability"),
    log:
        notebook="results/notebooks/stability.ipynb",
    benchmark:
        bench(FIG, "stability_notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/stability.ipynb"


rule stability:
    input:
        figure_targets(FIG),
