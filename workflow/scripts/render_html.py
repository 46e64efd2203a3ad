"""An executed notebook as a clean offline HTML page (ncd.pages.render.render)."""
from ncd.pages.render import render
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("%s -> %s", snakemake.params.executed,  # noqa: F821
         render(snakemake.params.executed, snakemake.output.html,  # noqa: F821
                pages=snakemake.params.pages))  # noqa: F821
