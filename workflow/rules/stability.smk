# Stability of Contact Dynamics and of the MD baseline on stiff and extreme cases.
# One job runs every case (small scenes; a job's start-up costs more than most cases).
FIG = "stability"
CFG = section(FIG)


rule stability_simulate:
    """The stability table (one row per (case, method, h)) and one binary collision (restitution)."""
    input:
        code=code_of("stability_simulate"),
    output:
        table="results/stability/table.nc",
        collision="results/stability/collision.nc",
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
        collision="results/stability/collision.nc",
        notebook=notebook_file("stability"),
        notebook_py=notebook_file("stability", "py"),
        code=notebook_code("stability"),
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
