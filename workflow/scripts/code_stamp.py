"""The stamp of a set of sources (workflow/rules/common.smk, ``code``): one line per file, its
digest and its path from the package's parent (``ncd/...``, whatever the checkout's place, so
that a moved checkout plans nothing), and one input for a rule instead of the package's files.
Plain standard library: the package is not imported for this."""
import hashlib
import os
from pathlib import Path

files = list(snakemake.input)  # snakemake is injected
base = os.path.dirname(os.path.commonpath(files))          # every set holds ncd/__init__.py and ncd/core
algorithm = snakemake.params.algorithm
lines = [f"{hashlib.new(algorithm, Path(f).read_bytes()).hexdigest()}  {Path(os.path.relpath(f, base)).as_posix()}"
         for f in files]
Path(snakemake.output[0]).write_text("\n".join(lines) + "\n")
Path(snakemake.log[0]).write_text(f"{len(lines)} sources hashed ({algorithm}) into {snakemake.output[0]}\n")
