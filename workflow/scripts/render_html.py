"""An executed notebook as a clean offline HTML page (ncd.render.render)."""
from ncd.pipeline import start
from ncd.render import render

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("%s -> %s", snakemake.params.executed,  # noqa: F821
         render(snakemake.params.executed, snakemake.output.html))  # noqa: F821
