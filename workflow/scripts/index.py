"""Write results/index.html, the reproduction page (ncd.pages.report)."""
from pathlib import Path

from ncd.pages.report import write_page
from ncd.pipeline.jobs import start

log = start(snakemake)  # snakemake is injected
out = Path(snakemake.output[0])
log.info("wrote %s", write_page(out.parent, snakemake.params.figures, snakemake.params.config, out))
