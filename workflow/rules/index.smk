# The reproduction page results/index.html (ncd/pages/report.py): the paper's claims, one row
# each, with the number measured in this run, the verdict and a thumbnail linking to the
# figure's page; the run's provenance; the run time of each figure.  Built by the default
# target after every figure.


rule index:
    input:
        figures=[figure_targets(f) for f in FIGURES],
        code=code_of("index"),
    output:
        "results/index.html",
    params:
        figures=FIGURES,
        config=config,
    log:
        "results/logs/index.log",
    benchmark:
        "results/benchmarks/index.tsv"
    conda:
        CONDA_ENV
    script:
        "../scripts/index.py"
