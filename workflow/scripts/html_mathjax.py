"""Copy MathJax beside the HTML pages (ncd.pages.render.copy_mathjax): the maths renders offline."""
from ncd.pages.render import copy_mathjax
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("MathJax copied to %s", copy_mathjax(snakemake.output[0]))  # noqa: F821
