"""An executed notebook as a clean, offline HTML page (``rule render_html``).

Snakemake's injected preamble cell (a pickled object with the paths of the machine that
ran it) is dropped; code is hidden behind one button; a table longer than
:data:`LONG_TABLE` rows is folded in a ``<details>`` block; maths is typeset by MathJax 2
from ``mathjax/`` beside the page (:func:`copy_mathjax`, from ``jupyter-server-mathjax``):
no network.  The body gets ``data-mathjax="done"`` once typeset.
"""
import re
import shutil
from pathlib import Path

import nbformat

LONG_TABLE = 25
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


def copy_mathjax(dest):
    """Copy the MathJax 2 bundle of the ``jupyter-server-mathjax`` package into ``dest``."""
    import jupyter_server_mathjax

    src = Path(jupyter_server_mathjax.__file__).parent / "static"
    dest = Path(dest)
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(src, dest)
    return dest


def render(executed, html_path):
    """Write the clean HTML page of the executed notebook ``executed`` to ``html_path``."""
    from nbconvert import HTMLExporter

    nb = nbformat.read(executed, as_version=4)
    drop_preamble(nb)
    fold_long_tables(nb)
    exporter = HTMLExporter(template_name="lab")
    exporter.mathjax_url = MATHJAX_URL
    title = Path(html_path).stem
    body, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": title}})
    # no widgets on these pages: drop require.js, the one script the template loads from a CDN
    body = re.sub(r'<script src="https?://[^"]*require[^"]*"></script>', "", body)
    body = body.replace("</head>", STYLE + "</head>", 1)
    body = re.sub(r"(<body[^>]*>)", lambda m: m.group(1) + TOGGLE, body, count=1)
    html_path = Path(html_path)
    html_path.parent.mkdir(parents=True, exist_ok=True)
    html_path.write_text(body, encoding="utf-8")
    return html_path
