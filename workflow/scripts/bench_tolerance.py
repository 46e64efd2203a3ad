"""Time to tolerance (1e-6, 1e-8, 1e-10): plain NLGS and NLGS + finishing stage."""
from ncd.io import provenance, write_dataset
from ncd.pipeline import start
from ncd.studies.bench import environment, tolerance_table

log = start(snakemake)  # noqa: F821 (snakemake is injected)
cfg = snakemake.params.config  # noqa: F821
ds = tolerance_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output[0])  # noqa: F821
