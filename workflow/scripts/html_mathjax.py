"""Copy MathJax beside the HTML pages (ncd.render.copy_mathjax): the maths renders offline."""
from ncd.pipeline import start
from ncd.render import copy_mathjax

log = start(snakemake)  # noqa: F821 (snakemake is injected)
log.info("MathJax copied to %s", copy_mathjax(snakemake.output[0]))  # noqa: F821
