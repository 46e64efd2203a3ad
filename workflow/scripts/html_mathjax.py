"""Copy MathJax beside the HTML pages (ncd.pages.render.copy_mathjax): the maths renders offline."""
from ncd.pages.render import copy_mathjax
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
log.info("MathJax copied to %s", copy_mathjax(snakemake.output[0]))
