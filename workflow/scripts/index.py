"""Write results/index.html, the reproduction page (ncd.pages.report)."""
from pathlib import Path

from ncd.pages.report import write_page
from ncd.pipeline.workflow import start

log = start(snakemake)  # noqa: F821 (snakemake is injected)
out = Path(snakemake.output[0])  # noqa: F821
log.info("wrote %s", write_page(out.parent, snakemake.params.figures, snakemake.params.config, out))  # noqa: F821
