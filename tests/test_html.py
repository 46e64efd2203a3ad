"""The HTML pages: no Snakemake preamble, code hidden behind a button, long tables
folded, maths typeset offline, every figure shown.  ``slow`` tests open the pages in
Debian's headless chromium (skipped without it) and keep screenshots under
``results/screenshots/``."""
import re
import shutil
import subprocess

import nbformat
import pytest
from bs4 import BeautifulSoup

from ncd.pages.render import LONG_TABLE, copy_mathjax, render

CHROMIUM = next((shutil.which(c) for c in ("chromium", "chromium-browser", "google-chrome") if shutil.which(c)), None)
needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="chromium absent (apt-get install -y chromium)")
FIGURES = ("fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile", "fig4_bank", "stability", "error_vs_runtime")


def executed_notebook(path):
    """A small executed notebook: Snakemake's preamble, maths, a long table, a figure."""
    from nbclient import NotebookClient

    nb = nbformat.v4.new_notebook(metadata={"kernelspec": {"name": "python3", "display_name": "Python 3",
                                                           "language": "python"}})
    nb.cells = [
        nbformat.v4.new_code_cell("######## snakemake preamble start (automatically inserted, do not edit) ########\n"
                                  "import pickle\nsecret_path = '/home/someone/machine'\n"
                                  "######## snakemake preamble end #########"),
        nbformat.v4.new_markdown_cell(r"The friction angle $\gamma = \arctan\mu$ and $$\int_0^h r\,dt = s.$$"),
        nbformat.v4.new_code_cell("import pandas as pd\npd.DataFrame({'a': range(60), 'b': range(60)})"),
        nbformat.v4.new_code_cell("import matplotlib.pyplot as plt\nfig, ax = plt.subplots(figsize=(3, 2))\n"
                                  "ax.plot([0, 1], [1, 0])\nplt.show()"),
        nbformat.v4.new_code_cell("from IPython.display import Markdown\nMarkdown(r'measured: $h = 10^{-3}$ s')"),
    ]
    NotebookClient(nb, timeout=120).execute()
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    d = tmp_path_factory.mktemp("html")
    copy_mathjax(d / "mathjax")
    return render(executed_notebook(d / "executed.ipynb"), d / "demo.html")


def test_page_is_clean(page):
    html = page.read_text()
    soup = BeautifulSoup(html, "html.parser")
    assert "snakemake preamble" not in html and "/home/someone" not in html
    assert soup.find(id="ncd-toggle") is not None and "ncd-show-code" in html
    assert re.search(r"body:not\(\.ncd-show-code\) \.jp-CodeCell \.jp-Cell-inputWrapper \{ display: none", html)
    folded = soup.select("details.ncd-table")
    assert len(folded) == 1 and "60 rows" in folded[0].summary.text and LONG_TABLE < 60
    srcs = [s.get("src", "") for s in soup.find_all("script")]
    assert "mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full,Safe" in srcs
    assert not [s for s in srcs if s.startswith("http")], srcs
    assert len(soup.select(".jp-OutputArea-output img")) == 1


def chromium(page, *args):
    cmd = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=30000", *args,
           page.resolve().as_uri()]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=180)


def check_in_browser(page, screenshot, min_figures=1):
    """Open ``page`` in chromium: maths typeset (no raw $...$), figures present; a screenshot."""
    dom = BeautifulSoup(chromium(page, "--dump-dom").stdout, "html.parser")
    body = dom.find("body")
    assert body is not None and body.get("data-mathjax") == "done", f"{page.name}: MathJax did not finish"
    assert not dom.select(".MathJax_Error"), f"{page.name}: MathJax errors"
    figures = dom.select(".jp-OutputArea-output img, .jp-OutputArea-output svg")
    assert len(figures) >= min_figures, f"{page.name}: {len(figures)} figures shown"
    for tag in dom.select("script, style, pre, code, .jp-InputArea, .MathJax_Preview"):
        tag.decompose()
    raw = re.findall(r"\$[^$\s][^$]{0,80}\$", dom.get_text(" "))
    assert raw == [], f"{page.name}: untypeset maths {raw[:5]}"
    screenshot.parent.mkdir(parents=True, exist_ok=True)
    chromium(page, f"--screenshot={screenshot}", "--window-size=1280,2400")
    assert screenshot.exists() and screenshot.stat().st_size > 10_000


@pytest.mark.slow
@needs_chromium
def test_demo_page_in_chromium(page, tmp_path):
    check_in_browser(page, tmp_path / "demo.png")


@pytest.mark.slow
@pytest.mark.pipeline
@needs_chromium
@pytest.mark.parametrize("figure", FIGURES)
def test_figure_pages_in_chromium(results, figure):
    page = results / "html" / f"{figure}.html"
    if not page.exists():
        pytest.skip(f"{figure} not built in this run")
    check_in_browser(page, results / "screenshots" / f"{figure}.png")


def test_folded_table_counts_data_rows_only():
    """A long table is folded with its count of data rows, whatever its header rows (a
    two-level column index writes two)."""
    import numpy as np
    import pandas as pd

    from ncd.pages.render import fold_long_tables

    n = LONG_TABLE + 5
    flat = pd.DataFrame({"a": np.arange(n), "b": np.arange(n)})
    two = pd.DataFrame(np.zeros((n, 2)), columns=pd.MultiIndex.from_tuples([("x", "p"), ("x", "q")]))
    for df in (flat, two):
        nb = nbformat.v4.new_notebook()
        cell = nbformat.v4.new_code_cell("df")
        cell.outputs = [nbformat.v4.new_output("execute_result", data={"text/html": df.to_html()}, execution_count=1)]
        nb.cells = [cell]
        html = fold_long_tables(nb).cells[0].outputs[0]["data"]["text/html"]
        assert f"table of {n} rows" in html, re.search(r"table of \d+ rows", html)
