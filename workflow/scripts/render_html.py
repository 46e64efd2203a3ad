"""An executed notebook as a clean offline HTML page (ncd.pages.render.render)."""
from ncd.pages.render import render
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
log.info("%s -> %s", snakemake.params.executed,
         render(snakemake.params.executed, snakemake.output.html,
                pages=snakemake.params.pages, banner=snakemake.params.banner))
