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


def test_unsynced_pair_is_noticed(tmp_path):
    """A .py edited without `jupytext --sync` stops the notebook with the command to run."""
    from ncd.pages.notebook import NotebookError, check_pair

    src = NOTEBOOKS[0]
    for f in ("Snakefile", "config.yaml"):
        (tmp_path / f).write_text("")
    (tmp_path / "notebooks").mkdir()
    for ext in (".py", ".ipynb"):
        (tmp_path / "notebooks" / f"x{ext}").write_bytes(src.with_suffix(ext).read_bytes())
    check_pair("x", tmp_path)
    py = tmp_path / "notebooks" / "x.py"
    py.write_text(py.read_text() + "\n# %%\nprint('edited')\n")
    with pytest.raises(NotebookError, match="jupytext --sync notebooks/x.py"):
        check_pair("x", tmp_path)


def test_paths_by_hand_from_root_and_from_notebooks(monkeypatch):
    """By hand, a notebook finds the repository from the root or from notebooks/ and
    writes only under results/."""
    from ncd.pages.notebook import paths

    root = NOTEBOOKS[0].parent.parent
    for cwd in (root, root / "notebooks"):
        monkeypatch.chdir(cwd)
        p = paths("stability", ["table"])
        assert p.input.table == str(root / "results" / "stability" / "table.nc")
        assert p.output.png == str(root / "results" / "figures" / "stability.png")
        assert isinstance(p.params.config, dict) and p.params.config


# measured-looking numbers in prose: decimals, percentages, angles, times, speeds, pressures
MEASURED = r"(?<![\w.^{/-])(\d+\.\d+|\d+\s*%|\d+\s*°|\d+\s*(?:ms|m/s|N/m)\b)"
# labelled values that are not measurements of the run: the paper's (fig2: Moreau's slope and
# friction) and analysis choices (fig4_history: bootstrap band and quartiles)
LABELLED = {"fig2_slope": {"24°", "0.5"}, "fig4_history": {"95 %", "75 %"}, "fig4_history_size": {"95 %"}}


def typed_numbers(nb, allowed=()):
    """Measured-looking numbers in the markdown cells past the introduction (outside maths and code)."""
    import re

    found = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "markdown" or i < 2:
            continue
        text = re.sub(r"\$\$.*?\$\$|\$[^$]*\$|`[^`]*`", "", cell.source, flags=re.S)
        found += [m for m in re.findall(MEASURED, text) if m not in allowed]
    return found


@pytest.mark.parametrize("py", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_hand_typed_numbers_in_prose(py):
    """Past the introduction, a markdown cell holds no hand-typed measured number: such numbers
    are written by Markdown(f"...") cells from the data at render time."""
    found = typed_numbers(jupytext.read(py), LABELLED.get(py.stem, set()))
    assert not found, f"{py.name}: numbers typed in prose {found}; compute them in a Markdown(f'...') cell"


def test_hand_typed_number_is_noticed():
    """The check fails on a stale sentence such as 'about 60 % and 95 %' (not in maths,
    and not in the introduction), and passes the same numbers inside maths or code."""
    text = ("# %% [markdown]\n# intro 60 %\n\n# %%\nx = 1\n\n# %% [markdown]\n"
            "# The clouds cover about 60 % and 95 %; $h = 0.3$ ms is `tol: 1.5`.\n")
    assert typed_numbers(jupytext.reads(text, fmt="py:percent")) == ["60 %", "95 %"]


CODE_LINES_MAX = 120


@pytest.mark.parametrize("py", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_narrates_and_the_package_computes(py):
    """A page reads like a paper section: its cells call tested package functions, so a
    notebook holds at most CODE_LINES_MAX lines of code (comments and blanks not counted)
    and prints no raw DataFrame."""
    cells = [c for c in jupytext.read(py).cells if c.cell_type == "code"]
    lines = [s for c in cells for s in c.source.splitlines() if s.strip() and not s.strip().startswith("#")]
    assert len(lines) <= CODE_LINES_MAX, f"{py.name}: {len(lines)} lines of code"
    assert not any(s.strip().startswith(("print(df", "display(df")) for s in lines)


# pages rewritten as paper sections: analysis and plots in the package, a few lines per cell
SECTION_PAGES = ("fig1_wedged", "fig2_slope", "stability", "error_vs_runtime", "bench")


@pytest.mark.parametrize("name", SECTION_PAGES)
def test_page_notebook_is_short_and_prints_no_log(name):
    nb = jupytext.read(Path(__file__).resolve().parent.parent / "notebooks" / f"{name}.py")
    code = [c.source for c in nb.cells if c.cell_type == "code"]
    lines = [ln for src in code for ln in src.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    assert len(lines) <= 120, f"{name}: {len(lines)} lines of code"
    body = [[ln for ln in src.splitlines() if ln.strip() and not ln.startswith(("import ", "from "))] for src in code]
    assert max(map(len, body)) <= 12, "a cell of more than 12 lines besides its imports"
    assert not any("print(" in src for src in code), f"{name} prints a log"


def notebook_defects(nb_path):
    """What an executed notebook shows wrongly: a figure shown twice (the cell that saves it
    with ``show=True`` holds more than one image) or a bare return value printed (an
    ``execute_result`` that is a plain number, e.g. the byte count of a file write)."""
    import json
    import re
    bad = []
    cells = json.loads(Path(nb_path).read_text(encoding="utf-8"))["cells"]
    for c in cells:
        if c["cell_type"] != "code":
            continue
        source, outputs = "".join(c.get("source", [])), c.get("outputs", [])
        images = sum("image/png" in o.get("data", {}) for o in outputs)
        if "show=True" in source and images != 1:
            bad.append(f"{Path(nb_path).name}: {images} images in the cell that saves the figure")
        for o in outputs:
            text = "".join(o.get("data", {}).get("text/plain", [])) if o.get("output_type") == "execute_result" else ""
            if re.fullmatch(r"\s*-?\d+(\.\d+)?\s*", text):
                bad.append(f"{Path(nb_path).name}: a bare value {text.strip()!r} printed")
    return bad


def test_the_defect_reader_finds_a_figure_shown_twice_and_a_bare_value(tmp_path):
    import json
    img = {"output_type": "display_data", "data": {"image/png": "x"}}
    cells = [{"cell_type": "code", "source": ["save(fig, out, show=True)"], "outputs": [img, img]},
             {"cell_type": "code", "source": ["path.write_text(s)"],
              "outputs": [{"output_type": "execute_result", "data": {"text/plain": ["601"]}}]},
             {"cell_type": "code", "source": ["save(fig, out, show=True)"], "outputs": [img]}]
    nb = tmp_path / "x.ipynb"
    nb.write_text(json.dumps({"cells": cells}))
    assert notebook_defects(nb) == ["x.ipynb: 2 images in the cell that saves the figure", "x.ipynb: a bare value '601' printed"]
    nb.write_text(json.dumps({"cells": cells[2:]}))
    assert notebook_defects(nb) == []


def test_each_figure_is_shown_once_and_no_bare_value_is_printed(results):
    """On the executed notebooks of the run (:func:`notebook_defects`)."""
    bad = [d for nb in sorted((results / "notebooks").glob("*.ipynb")) for d in notebook_defects(nb)]
    assert not bad, bad
