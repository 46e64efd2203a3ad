"""The HTML pages: no Snakemake preamble, code hidden behind a button, long tables
folded, maths typeset offline, every figure shown.  ``slow`` tests open the pages in
Debian's headless chromium (skipped without it) and keep screenshots under
``results/screenshots/``."""
import base64
import io
import json
import re
import shutil
import subprocess
from pathlib import Path

import nbformat
import numpy as np
import pytest
from bs4 import BeautifulSoup

from ncd.pages.render import LONG_TABLE, copy_mathjax, render

ROOT = Path(__file__).resolve().parent.parent

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


# ---- every page of the run: offline, navigated, legible (chromium) -------------------------------
PAGES = FIGURES + ("fig4_history", "fig4_history_size", "fig5_governing", "bench")
# identifiers, never fetched: XML namespaces and the SVG DTD of inline SVG figures
NAMESPACE = re.compile(r"https?://www\.w3\.org/(2000/svg|1999/xlink|1999/xhtml|Graphics/SVG/1\.1/DTD/svg11\.dtd)")
PROBE = """<script>window.addEventListener("load", function () {
  document.querySelectorAll("img").forEach(function (i) {
    i.setAttribute("data-w", i.getBoundingClientRect().width); i.setAttribute("data-nw", i.naturalWidth); });
  var n = 0;
  document.querySelectorAll("svg").forEach(function (svg) {
    var r = Array.from(svg.querySelectorAll("text")).map(function (t) { return t.getBoundingClientRect(); })
      .filter(function (b) { return b.width > 0 && b.height > 0; });
    for (var i = 0; i < r.length; i++) for (var j = i + 1; j < r.length; j++) {
      var w = Math.min(r[i].right, r[j].right) - Math.max(r[i].left, r[j].left);
      var h = Math.min(r[i].bottom, r[j].bottom) - Math.max(r[i].top, r[j].top);
      if (w > 1 && h > 1) n++; } });
  document.body.setAttribute("data-svg-overlaps", n);
  document.body.setAttribute("data-probe", "done"); });</script>"""


def figure_order():
    """The FIGURES list of workflow/rules/common.smk (the reading order of the pages)."""
    text = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    return re.findall(r'"(\w+)"', re.search(r"FIGURES = \[f for f in \((.*?)\)", text, re.S).group(1))


def external_urls(html):
    """Every http(s) URL of a page but the links (``<a href>``, not loaded) and XML namespaces."""
    soup = BeautifulSoup(html, "html.parser")
    links = {a["href"] for a in soup.find_all("a", href=True)}
    urls = re.findall(r"""https?://[^\s"'<>)`\\]+""", html)
    return sorted({u for u in urls if u not in links and not NAMESPACE.match(u)})


def probed_dom(page, tmp_path):
    """The DOM of ``page`` after chromium laid it out at 1280 px (images' rendered and natural widths)."""
    probe = page.parent / f".probe_{page.name}"
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>", 1), encoding="utf-8")
    try:
        out = chromium(probe, "--window-size=1280,2400", "--dump-dom").stdout
    finally:
        probe.unlink()
    dom = BeautifulSoup(out, "html.parser")
    assert dom.body is not None and dom.body.get("data-probe") == "done", f"{page.name}: the page did not load"
    return dom


def figure_layouts(dom):
    """(rendered / natural width, text layout) of every PNG of the page saved by ncd.pages.notebook.save."""
    from PIL import Image

    from ncd.pages.notebook import LAYOUT_KEY

    out = []
    for img in dom.find_all("img"):
        src = img.get("src", "")
        if not src.startswith("data:image/png;base64,") or not img.get("data-nw"):
            continue
        meta = Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1]))).text
        if LAYOUT_KEY in meta:
            out.append((float(img["data-w"]) / float(img["data-nw"]), json.loads(meta[LAYOUT_KEY])))
    return out


def test_external_urls_and_layout_record():
    """The URL scan sees a CDN import and ignores links and namespaces; ``save`` records overlapping titles."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncd.pages.notebook import text_layout

    html = ('<a href="https://hal.science/hal-01824602">paper</a><svg xmlns="http://www.w3.org/2000/svg"></svg>'
            '<script type="module">import("https://cdn.example.org/m.mjs")</script>')
    assert external_urls(html) == ["https://cdn.example.org/m.mjs"]
    fig, ax = plt.subplots(1, 2, figsize=(6, 3))
    ax[0].set_title("a long title running over the title of the next panel")
    ax[1].set_title("(b)", fontsize=8, loc="left")
    lay = text_layout(fig)
    assert lay["overlaps"] == [["a long title running over the title of t", "(b)"]] and lay["min_font_pt"] == 8
    ax[1].set_title("")
    ax[0].set_title("(a)")
    assert text_layout(fig)["overlaps"] == []
    plt.close(fig)


def page_layouts(results, name, dom):
    """The layouts of the page's figures; a page that shows its figure by ``plt.show()`` (no
    layout record on the page) is judged on its saved PNG, shown at the page's widest image."""
    from PIL import Image

    from ncd.pages.notebook import LAYOUT_KEY

    found = figure_layouts(dom)
    png = results / "figures" / f"{name}.png"
    if found or not png.exists():
        return found
    img = Image.open(png)
    if LAYOUT_KEY not in img.text:
        return []
    width = max((float(i["data-w"]) for i in dom.find_all("img") if i.get("data-w")), default=img.width)
    return [(width / img.width, json.loads(img.text[LAYOUT_KEY]))]


def built_page(results, name):
    page = results / "html" / f"{name}.html"
    if not page.exists():
        pytest.skip(f"{name} not built in this run")
    return page


_DOMS = {}


def laid_out(page):
    """:func:`probed_dom` of ``page``, once per test session."""
    if page not in _DOMS:
        _DOMS[page] = probed_dom(page, None)
    return _DOMS[page]


@pytest.mark.slow
@pytest.mark.pipeline
@needs_chromium
@pytest.mark.parametrize("name", PAGES)
def test_page_offline_navigated_legible(results, name):
    """Each page: no external URL, no Out[n] prompt, its human title, a header linking to the
    index, its neighbours in FIGURES' order (files that exist) and the paper; in chromium, no
    overlapping texts in its figures (PNG layout records of ncd.pages.notebook.save, inline SVG)."""
    from ncd.pages.render import INDEX, PAPER_URL, neighbours, title_of

    page = built_page(results, name)
    html = page.read_text(encoding="utf-8")
    assert external_urls(html) == [], f"{name}: external URLs"
    soup = BeautifulSoup(html, "html.parser")
    assert not [p for p in soup.select(".jp-OutputPrompt, .jp-InputPrompt") if "[" in p.get_text()]
    assert soup.title.get_text() == title_of(name) != name
    nav = soup.select_one("nav.ncd-nav")
    assert nav is not None, f"{name}: no navigation header"
    assert nav.select_one("a.ncd-index")["href"] == INDEX and (page.parent / INDEX).resolve() == results / "index.html"
    assert nav.select_one("a.ncd-paper")["href"] == PAPER_URL
    for cls, want in zip(("ncd-prev", "ncd-next"), neighbours(name, figure_order())):
        a = nav.select_one(f"a.{cls}")
        assert (a is None) == (want is None), f"{name}: {cls} link"
        if a is not None:
            assert a["href"] == f"{want}.html" and (page.parent / a["href"]).exists(), a["href"]
    dom = laid_out(page)
    assert dom.body["data-svg-overlaps"] == "0", f"{name}: overlapping SVG texts"
    for _, lay in page_layouts(results, name, dom):
        assert lay["overlaps"] == [], f"{name}: overlapping texts {lay['overlaps'][:5]}"


@pytest.mark.slow
@pytest.mark.pipeline
@needs_chromium
@pytest.mark.parametrize("name", PAGES)
def test_page_figure_fonts_at_page_width(results, name):
    """The smallest font of each figure saved by ncd.pages.notebook.save, at the size the page
    shows it in a 1280 px window, is at least MIN_FONT_PT."""
    from ncd.pages.notebook import MIN_FONT_PT

    for scale, lay in page_layouts(results, name, laid_out(built_page(results, name))):
        shown = lay["min_font_pt"] * lay["dpi"] / 96 * min(scale, 1.0) if lay["min_font_pt"] else MIN_FONT_PT
        assert shown >= MIN_FONT_PT - 0.05, f"{name}: smallest font {shown:.1f} pt at the page's width"


def test_neighbours_and_header():
    """Pages of the list link to their neighbours; a page outside it sits after the page it
    extends; the header names the pages by their titles and links the paper."""
    from ncd.pages.render import PAPER_URL, nav_header, neighbours

    order = ["fig1_wedged", "fig4_history", "fig5_governing"]
    assert neighbours("fig1_wedged", order) == (None, "fig4_history")
    assert neighbours("fig5_governing", order) == ("fig4_history", None)
    assert neighbours("fig4_history_size", order) == ("fig4_history", "fig5_governing")
    assert neighbours("bench", order) == ("fig5_governing", None)
    nav = BeautifulSoup(nav_header("fig4_history", order), "html.parser")
    assert nav.select_one("a.ncd-prev").get_text() == "← Figure 1 — a disc wedged between two discs"
    assert nav.select_one("a.ncd-next").get_text().startswith("Beyond the paper — governing parameters")
    assert nav.select_one("a.ncd-paper")["href"] == PAPER_URL and nav.select_one("a.ncd-index")["href"] == "../index.html"


def test_demo_page_offline_titled(page):
    html = page.read_text()
    assert external_urls(html) == [] and "import(" not in html
    assert BeautifulSoup(html, "html.parser").title.get_text() == "demo"


def test_report_captions_include_the_finding(tmp_path, monkeypatch):
    """No caption of the Snakemake report holds a ``<placeholder>``; a caption that includes its
    figure's finding (written by the notebook from the data) renders it, as Snakemake does
    (docutils, from the working directory)."""
    from docutils.core import publish_parts

    captions = sorted((ROOT / "workflow" / "report").glob("*.rst"))
    assert captions
    monkeypatch.chdir(tmp_path)
    for rst in captions:
        text = rst.read_text()
        assert not re.search(r"<[a-z_]+>", text), f"{rst.name}: a placeholder"
        for inc in re.findall(r"^\.\. include:: (\S+)$", text, flags=re.M):
            assert inc == f"results/figures/{rst.stem}.finding.rst", inc
            (tmp_path / inc).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / inc).write_text(f"Measured for {rst.stem}: 0.123 N.\n")
            html = publish_parts(text, writer="html")["body"]
            assert f"Measured for {rst.stem}: 0.123 N." in html


def test_save_records_the_layout_in_the_png(tmp_path):
    """The PNG written by ``save`` carries its text layout at the saved dpi; the figure keeps its
    own dpi for the notebook's display."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    from ncd.pages.notebook import LAYOUT_KEY, save

    fig, ax = plt.subplots(figsize=(4, 3), dpi=72)
    ax.set_title("(a) a title")
    ax.set_xlabel("x", fontsize=11)
    out = type("Out", (), {"png": str(tmp_path / "f.png"), "pdf": str(tmp_path / "f.pdf")})()
    save(fig, out, dpi=150)
    lay = json.loads(Image.open(out.png).text[LAYOUT_KEY])
    assert lay["dpi"] == 150 and lay["overlaps"] == [] and lay["width_in"] == 4 and fig.dpi == 72
    assert lay["min_font_pt"] == min(11, ax.xaxis.get_ticklabels()[0].get_fontsize())
    plt.close(fig)


def test_save_rasterizes_dense_clouds_in_the_pdf_only(tmp_path):
    """``save`` writes the PNG first, then rasterizes in the PDF the artists that draw more
    than DENSE_POINTS markers or paths (a scatter cloud, a line of dots); a line without
    markers, a few markers and the axes stay vectors.  The rasterized PDF is several times
    smaller than the all-vector one.  The layout engine, frozen while the files are written,
    is the figure's again afterwards."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncd.pages.notebook import DENSE_POINTS, save

    rng = np.random.default_rng(0)
    n = 20 * DENSE_POINTS

    def figure():
        fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
        cloud = ax.scatter(*rng.normal(size=(2, n)), s=1)
        dots, = ax.plot(*rng.normal(size=(2, n)), ".", ms=1)
        curve, = ax.plot(np.linspace(0, 1, n), np.linspace(0, 1, n) ** 2, "-")
        few, = ax.plot([0, 1], [0, 1], "o")
        return fig, (cloud, dots, curve, few)

    fig, artists = figure()
    engine = fig.get_layout_engine()
    out = type("Out", (), {"png": str(tmp_path / "f.png"), "pdf": str(tmp_path / "f.pdf")})()
    save(fig, out, dpi=100)
    assert [a.get_rasterized() for a in artists] == [True, True, False, False]
    assert fig.get_layout_engine() is engine            # frozen for the two files only
    plain, _ = figure()
    plain.savefig(tmp_path / "plain.pdf")
    assert (tmp_path / "f.pdf").stat().st_size < 0.25 * (tmp_path / "plain.pdf").stat().st_size
    plt.close("all")


def test_layout_skips_undrawn_ticks_of_an_inset_colorbar():
    """A colorbar in an inset axes (outside ``fig.axes``) keeps the labels of log ticks below
    its range, which it does not draw; the layout leaves them out like those of any axes, so
    they make no false overlap with the panel under the colorbar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from ncd.pages.notebook import drawn_texts, text_layout

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(5, 5), dpi=100, layout="constrained")
    sm = plt.cm.ScalarMappable(norm=LogNorm(vmin=9.8e-4, vmax=8e-3), cmap="viridis")
    cax = top.inset_axes([1.02, 0.06, 0.04, 0.88])
    fig.colorbar(sm, cax=cax)
    bottom.set_title("(b) below")
    texts = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    bar = cax.get_window_extent(renderer)
    beside = [t.get_window_extent(renderer) for t in texts if t.get_window_extent(renderer).x0 >= bar.x1]
    assert beside, "no label of the colorbar found"
    assert all(bar.y0 - 1 <= 0.5 * (b.y0 + b.y1) <= bar.y1 + 1 for b in beside), "a label outside the colorbar"
    assert text_layout(fig)["overlaps"] == []
    plt.close(fig)
