# Work-precision diagrams: NLGS at one step on states built here, and time
# integration (incline, settled heap, slope flow), Contact Dynamics against MD.
FIG = "error_vs_runtime"
CFG = section(FIG)


rule error_vs_runtime_nlgs:
    """Build each state and run every NLGS setting on its next step."""
    input:
        code=code_of("error_vs_runtime_nlgs"),
    output:
        "results/error_vs_runtime/nlgs.nc",
    params:
        config={k: CFG[k] for k in ("root_seed", "solver", "nlgs")},
    log:
        log(FIG, "error_vs_runtime_nlgs"),
    benchmark:
        bench(FIG, "error_vs_runtime_nlgs")
    conda:
        CONDA_ENV
    script:
        "../scripts/error_vs_runtime_nlgs.py"


rule error_vs_runtime_integration:
    """CD over h and MD over h and stiffness, for each observable."""
    input:
        code=code_of("error_vs_runtime_integration"),
    output:
        "results/error_vs_runtime/integration.nc",
    params:
        config={k: CFG[k] for k in ("root_seed", "solver", "integration")},
    log:
        log(FIG, "error_vs_runtime_integration"),
    benchmark:
        bench(FIG, "error_vs_runtime_integration")
    conda:
        CONDA_ENV
    script:
        "../scripts/error_vs_runtime_integration.py"


rule error_vs_runtime_notebook:
    input:
        nlgs="results/error_vs_runtime/nlgs.nc",
        integration="results/error_vs_runtime/integration.nc",
        notebook=notebook_file("error_vs_runtime"),
        notebook_py=notebook_file("error_vs_runtime", "py"),
        code=notebook_code("error_vs_runtime"),
    output:
        png=figure_output("error_vs_runtime", "png"),
        pdf=figure_output("error_vs_runtime", "pdf"),
        caption=caption_output("error_vs_runtime"),
    log:
        notebook="results/notebooks/error_vs_runtime.ipynb",
    benchmark:
        bench(FIG, "error_vs_runtime_notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/error_vs_runtime.ipynb"


rule error_vs_runtime:
    input:
        figure_targets(FIG),
