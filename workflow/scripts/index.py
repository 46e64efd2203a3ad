"""Write results/index.html, the reproduction page (ncd.report)."""
from pathlib import Path

from ncd.pipeline import start
from ncd.report import write_page

log = start(snakemake)  # noqa: F821 (snakemake is injected)
out = Path(snakemake.output[0])  # noqa: F821
log.info("wrote %s", write_page(out.parent, snakemake.params.figures, snakemake.params.config, out))  # noqa: F821
