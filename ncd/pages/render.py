"""An executed notebook as a clean, offline HTML page (``rule render_html``).

Snakemake's injected preamble cell (a pickled object with the paths of the machine that
ran it) is dropped; code is hidden behind one button; no ``In/Out [n]`` prompts; a table
longer than :data:`LONG_TABLE` rows is folded in a ``<details>`` block; maths is typeset
by MathJax 2 from ``mathjax/`` beside the page (:func:`copy_mathjax`, from
``jupyter-server-mathjax``).  Nothing is loaded from the network: the template's mermaid
loader (a CDN import; no page draws a diagram) and the URLs in its comments are removed.
The body gets ``data-mathjax="done"`` once typeset.  Each page is titled by its figure's
name (:data:`TITLES`: a reader must not take a study beyond the paper for one of the
paper's four figures) and opens with a header linking to the index, the previous and
next pages and the paper (:func:`nav_header`).
"""
import re
import shutil
from html import escape
from pathlib import Path

import nbformat

LONG_TABLE = 25
PAPER_URL = "https://hal.science/hal-01824602"
INDEX = "../index.html"   # the pages live in results/html/, the index is results/index.html
# the human name of every page (its <title> and its neighbours' links)
TITLES = {
    "fig1_wedged": "Figure 1 — a disc wedged between two discs",
    "fig2_slope": "Figure 2 — dispersion of a grain's acceleration in a flow down a slope",
    "fig3_equilibrium": "Figure 3 — indetermination clouds of discs at rest",
    "fig4_pile": "Figure 4 — a pile poured from a localized source",
    "fig4_history": "Beyond the paper — Figure 4's piles from a point source and from a rain",
    "fig4_history_size": "Beyond the paper — Figure 4's piles against their size",
    "fig4_bank": "End of §5 — the bank of the pile: surface-parallel cuts, stress and reciprocity",
    "fig5_governing": "Beyond the paper — governing parameters of indeterminacy",
    "stability": "§2 — stability of the implicit scheme on stiff and extreme cases, against MD",
    "error_vs_runtime": "§2 — error against run time, and the warm start",
    "bench": "Speed report",
}
# pages outside the default run's list, placed after the page they extend (their links
# point into the list; the list's pages never link to them, which a default run lacks)
EXTRA_AFTER = {"fig4_history_size": "fig4_history", "bench": None}
MATHJAX_URL = "mathjax/MathJax.js?config=TeX-AMS-MML_HTMLorMML-full,Safe"
PREAMBLE = "snakemake preamble start"

STYLE = """
<script type="text/x-mathjax-config">
MathJax.Hub.Config({"HTML-CSS": {availableFonts: ["STIX-Web"], preferredFont: "STIX-Web",
                                 webFont: "STIX-Web", imageFont: null}, messageStyle: "none"});
MathJax.Hub.Queue(function () { document.body.setAttribute("data-mathjax", "done"); });
</script>
<style>
body:not(.ncd-show-code) .jp-CodeCell .jp-Cell-inputWrapper { display: none; }
body:not(.ncd-show-code) .jp-CodeCell .jp-InputArea { display: none; }
#ncd-toggle { position: fixed; top: 0.6em; right: 0.8em; z-index: 100; padding: 0.3em 0.8em;
  font: 13px sans-serif; border: 1px solid #888; border-radius: 4px; background: #f6f6f6; cursor: pointer; }
.ncd-table { overflow-x: auto; max-width: 100%; }
.ncd-table summary { cursor: pointer; font: 13px sans-serif; color: #333; margin: 0.3em 0; }
.jp-RenderedHTMLCommon table { display: block; overflow-x: auto; max-width: 100%; }
.ncd-nav { font: 14px sans-serif; padding: 0.6em 8em 0.6em 1em; border-bottom: 1px solid #ccc;
  background: #fafafa; display: flex; flex-wrap: wrap; gap: 0.4em 1.4em; }
.ncd-nav a { color: #1a5fb4; text-decoration: none; }
.ncd-nav a:hover { text-decoration: underline; }
.ncd-nav .ncd-none { color: #999; }
</style>
"""
TOGGLE = """
<button id="ncd-toggle" type="button"
 onclick="document.body.classList.toggle('ncd-show-code');this.textContent=document.body.classList.contains('ncd-show-code')?'Hide code':'Show code';">Show code</button>
"""


def drop_preamble(nb):
    """Remove the cell Snakemake's ``notebook:`` directive inserts (returns the count removed)."""
    keep = [c for c in nb.cells if not (c.cell_type == "code" and PREAMBLE in c.source)]
    removed = len(nb.cells) - len(keep)
    nb.cells = keep
    return removed


def _rows(html):
    return len(re.findall(r"<tr[\s>]", html))


def _body_rows(html):
    """Data rows of an HTML table: the rows of its ``<tbody>`` (pandas writes one or
    two header rows in ``<thead>``), else all rows but the first."""
    bodies = re.findall(r"<tbody.*?</tbody>", html, flags=re.S)
    return sum(_rows(b) for b in bodies) if bodies else max(_rows(html) - 1, 0)


def fold_long_tables(nb, limit=LONG_TABLE):
    """Wrap every HTML table output with more than ``limit`` rows in a collapsed block."""
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            html = data.get("text/html")
            if html is None:
                continue
            html = "".join(html) if isinstance(html, list) else html
            n = _rows(html)
            if "<table" in html and n > limit:
                data["text/html"] = (f'<details class="ncd-table"><summary>table of {_body_rows(html)} rows '
                                     f"(click to show)</summary>{html}</details>")
                data.pop("text/plain", None)
    return nb


def title_of(name):
    """The human name of page ``name`` (the slug itself for a page without one)."""
    return TITLES.get(name, name)


def neighbours(name, pages):
    """(previous, next) page names of ``name`` in the order ``pages`` (None at an end).  A page
    outside ``pages`` (:data:`EXTRA_AFTER`) sits after the page it extends, or at the end."""
    pages = list(pages or [])
    if name in pages:
        i = pages.index(name)
        return (pages[i - 1] if i > 0 else None), (pages[i + 1] if i + 1 < len(pages) else None)
    after = EXTRA_AFTER.get(name)
    if after in pages:
        i = pages.index(after)
        return after, (pages[i + 1] if i + 1 < len(pages) else None)
    return (pages[-1] if pages else None), None


def nav_header(name, pages):
    """The ``<nav>`` opening a page: the index, the previous and next pages, the paper on HAL."""
    prev, nxt = neighbours(name, pages)

    def link(page, arrow):
        if page is None:
            return f'<span class="ncd-none">{arrow} (none)</span>'
        text = f"← {escape(title_of(page))}" if arrow == "←" else f"{escape(title_of(page))} →"
        return f'<a class="ncd-{"prev" if arrow == "←" else "next"}" href="{page}.html">{text}</a>'

    return (f'<nav class="ncd-nav" aria-label="pages"><a class="ncd-index" href="{INDEX}">Index of the '
            f'reproduction</a>{link(prev, "←")}{link(nxt, "→")}<a class="ncd-paper" href="{PAPER_URL}">'
            "The paper (Moreau 2005) on HAL</a></nav>")


def strip_external(body):
    """Remove what would reach the network: the template's mermaid loader (a module script
    importing from a CDN) and the URLs in the comments of its scripts and styles."""
    body = re.sub(r'<script type="module">(?:(?!</script>).)*mermaid(?:(?!</script>).)*</script>', "", body,
                  flags=re.S)
    body = re.sub(r'<script src="https?://[^"]*"></script>', "", body)
    body = re.sub(r"/\*(?:(?!\*/).)*?https?://(?:(?!\*/).)*\*/", "/* */", body, flags=re.S)
    return body


def copy_mathjax(dest):
    """Copy the MathJax 2 bundle of the ``jupyter-server-mathjax`` package into ``dest``."""
    import jupyter_server_mathjax

    src = Path(jupyter_server_mathjax.__file__).parent / "static"
    dest = Path(dest)
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(src, dest)
    return dest


def render(executed, html_path, pages=(), banner=""):
    """Write the clean HTML page of the executed notebook ``executed`` to ``html_path``;
    ``pages``: the page names in reading order (its header's previous and next links);
    ``banner``: HTML placed under the header (a quick run's notice, :mod:`ncd.pages.runscale`)."""
    from nbconvert import HTMLExporter

    nb = nbformat.read(executed, as_version=4)
    drop_preamble(nb)
    fold_long_tables(nb)
    exporter = HTMLExporter(template_name="lab", exclude_input_prompt=True, exclude_output_prompt=True)
    exporter.mathjax_url = MATHJAX_URL
    name = Path(html_path).stem
    body, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": title_of(name)}})
    body = strip_external(body)
    body = body.replace("</head>", STYLE + "</head>", 1)
    body = re.sub(r"(<body[^>]*>)", lambda m: m.group(1) + TOGGLE + nav_header(name, pages) + banner, body,
                  count=1)
    html_path = Path(html_path)
    html_path.parent.mkdir(parents=True, exist_ok=True)
    html_path.write_text(body, encoding="utf-8")
    return html_path
