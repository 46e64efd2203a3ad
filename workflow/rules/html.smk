# Rules shared by every figure (included after common.smk, which holds only helpers):
from ncd.pages.runscale import banner_html

#   html_mathjax  MathJax copied beside the pages          -> results/html/mathjax/
#   render_html   executed notebook -> clean offline page, with links to the index and
#                 the neighbouring pages               -> results/html/<figure>.html
#   thumbnail(s)  README thumbnails                         -> docs/thumbnails/<figure>.png


rule html_mathjax:
    """MathJax, copied beside the pages from the jupyter-server-mathjax package (maths offline)."""
    input:
        code=code_of("html_mathjax"),
    output:
        directory("results/html/mathjax"),
    log:
        "results/logs/html/mathjax.log",
    benchmark:
        "results/benchmarks/html/mathjax.tsv"
    conda:
        CONDA_ENV
    script:
        "../scripts/html_mathjax.py"


rule render_html:
    """Render an executed notebook (written by its figure's notebook rule) to a clean HTML
    page: no Snakemake preamble, code hidden behind a button, long tables folded, maths
    typeset offline, nothing loaded from the network, a header linking to the index, the
    neighbouring pages (in the order of FIGURES) and the paper (ncd.pages.render)."""
    input:
        png="results/figures/{figure}.png",
        mathjax="results/html/mathjax",
        code=code_of("render_html"),
    output:
        html="results/html/{figure}.html",
    params:
        executed="results/notebooks/{figure}.ipynb",
        pages=FIGURES,
        banner=lambda w: banner_html(config, [w.figure]),   # a quick run's notice (ncd.pages.runscale)
    log:
        "results/logs/{figure}/render_html.log",
    benchmark:
        "results/benchmarks/{figure}/render_html.tsv"
    conda:
        CONDA_ENV
    script:
        "../scripts/render_html.py"


rule thumbnail:
    """A small copy of a figure for the README (docs/thumbnails, committed)."""
    input:
        "results/figures/{figure}.png",
        code=code_of("thumbnail"),
    output:
        "docs/thumbnails/{figure}.png",
    log:
        "results/logs/thumbnails/{figure}.log",
    benchmark:
        "results/benchmarks/thumbnails/{figure}.tsv"
    conda:
        CONDA_ENV
    script:
        "../scripts/thumbnail.py"


rule thumbnails:
    """`snakemake -j2 thumbnails`: refresh the README's thumbnails (not in the default target)."""
    input:
        [f"docs/thumbnails/{f}.png" for f in FIGURES],
