"""Each notebook is a jupytext pair (.py percent + .ipynb) whose cells agree."""
from pathlib import Path

import jupytext
import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.py"))


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 1


@pytest.mark.parametrize("py", NOTEBOOKS, ids=lambda p: p.stem)
def test_pair_in_sync(py):
    ipynb = py.with_suffix(".ipynb")
    assert ipynb.exists(), f"{ipynb.name} missing: run jupytext --sync {py.name}"
    a = jupytext.read(py)
    b = jupytext.read(ipynb)
    src_a = [(c.cell_type, c.source.strip()) for c in a.cells]
    src_b = [(c.cell_type, c.source.strip()) for c in b.cells]
    assert src_a == src_b, f"{py.name} and {ipynb.name} differ: run jupytext --sync {py.name}"
    # Snakemake's notebook directive needs the language in the metadata
    assert b.metadata.get("language_info", {}).get("name") == "python"
    assert "ipynb" in b.metadata.get("jupytext", {}).get("formats", "")
