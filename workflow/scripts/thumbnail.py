"""Shrink a figure to a README thumbnail (at most 640 x 400 pixels)."""
from PIL import Image

from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
with Image.open(snakemake.input[0]) as im:
    im = im.convert("RGB")
    im.thumbnail((640, 400), Image.LANCZOS)
    im = im.quantize(colors=256)        # a palette PNG: a few tens of kB
    im.save(snakemake.output[0], optimize=True)
    log.info("%s -> %s, %dx%d", snakemake.input[0], snakemake.output[0], *im.size)
