"""Shrink a figure to a README thumbnail (at most 640 x 400 pixels)."""
from PIL import Image

from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
with Image.open(snakemake.input[0]) as im:  # noqa: F821
    im = im.convert("RGB")
    im.thumbnail((640, 400), Image.LANCZOS)
    im = im.quantize(colors=256)        # a palette PNG: a few tens of kB
    im.save(snakemake.output[0], optimize=True)  # noqa: F821
    log.info("%s -> %s, %dx%d", snakemake.input[0], snakemake.output[0], *im.size)  # noqa: F821
