"""What a figure's notebook needs around the science: its inputs and outputs, wherever it runs.

Under Snakemake's ``notebook:`` directive the injected ``snakemake`` object names the
files; run by hand from anywhere in the checkout, :func:`paths` finds the repository root
and names what a finished ``snakemake -j2 <figure>`` left under ``results/``, so a
notebook writes only there.  :func:`check_pair` stops a run whose jupytext ``.py`` was
edited without ``jupytext --sync`` (the ``.ipynb`` that Snakemake runs would be stale).
:func:`save` records in the PNG the text layout of the figure (:func:`text_layout`: pairs
of overlapping texts, the smallest font), which the page check reads at the size the
page shows the figure (``tests/test_html.py``).
"""
import json
from pathlib import Path
from types import SimpleNamespace

import yaml

MARKERS = ("Snakefile", "config.yaml")
LAYOUT_KEY = "ncd-text-layout"   # the PNG text chunk holding text_layout's record
MIN_FONT_PT = 9.0                # the smallest font a reader should meet at the page's size
DENSE_POINTS = 2000              # markers or paths of one artist above which the PDF rasterizes it


class NotebookError(RuntimeError):
    """A notebook cannot find its repository or its pair is out of sync."""


def repo_root(start=None):
    """The nearest folder at or above ``start`` (default: the current one) holding the workflow."""
    here = Path(start or Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if all((folder / m).exists() for m in MARKERS) and (folder / "notebooks").is_dir():
            return folder
    pkg = Path(__file__).resolve().parents[2]  # an editable install: the checkout of ncd
    if all((pkg / m).exists() for m in MARKERS):
        return pkg
    raise NotebookError(f"no ncd checkout (a folder with {', '.join(MARKERS)}) at or above {here}")


def check_pair(figure, root=None):
    """Raise :class:`NotebookError` when ``notebooks/<figure>.py`` and ``.ipynb`` hold different cells."""
    import jupytext

    root = Path(root) if root is not None else repo_root()
    py, ipynb = root / "notebooks" / f"{figure}.py", root / "notebooks" / f"{figure}.ipynb"
    if not (py.exists() and ipynb.exists()):
        return
    cells = [[(c.cell_type, c.source.strip()) for c in jupytext.read(p).cells] for p in (py, ipynb)]
    # the executed copy Snakemake runs starts with its preamble cell: compare the rest
    b = [c for c in cells[1] if "snakemake preamble" not in c[1]]
    if cells[0] != b:
        raise NotebookError(f"notebooks/{figure}.py and notebooks/{figure}.ipynb differ: run "
                            f"`jupytext --sync notebooks/{figure}.py` (the .ipynb is the one Snakemake runs)")


def paths(figure, inputs, smk=None, data_dir=None):
    """The Snakemake object of the rule running this notebook, or by hand an object with the
    same fields: ``input.<name>`` = ``results/<data_dir>/<name>.nc`` (``data_dir`` defaults to
    ``figure``), ``output.png|pdf``, ``params.config`` and ``config`` (the figure's section)."""
    if smk is not None:
        try:
            root = repo_root()
        except NotebookError:  # a working directory outside the checkout: nothing to compare
            return smk
        check_pair(figure, root)
        return smk
    root = repo_root()
    check_pair(figure, root)
    results = root / "results"
    section = yaml.safe_load((root / "config.yaml").read_text()).get(figure, {})
    return SimpleNamespace(
        input=SimpleNamespace(**{n: str(results / (data_dir or figure) / f"{n}.nc") for n in inputs}),
        output=SimpleNamespace(png=str(results / "figures" / f"{figure}.png"),
                               pdf=str(results / "figures" / f"{figure}.pdf"),
                               finding=str(results / "figures" / f"{figure}.finding.rst")),
        params=SimpleNamespace(config=section), config={figure: section})


def write_finding(output, text):
    """Write the figure's finding (a paragraph computed from the data) to ``output.finding``:
    the Snakemake report's caption ``workflow/report/<figure>.rst`` includes it."""
    path = getattr(output, "finding", None)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(" ".join(text.split()) + "\n", encoding="utf-8")


def drawn_texts(fig):
    """The texts a draw of ``fig`` shows: visible, non-empty, and for tick labels only the
    ticks inside their axis's view (matplotlib keeps labels of ticks it does not draw), the
    ticks of inset axes (a colorbar's ``cax``, outside ``fig.axes``) included."""
    from matplotlib.axes import Axes
    from matplotlib.text import Text

    fig.canvas.draw()
    ticks, shown = set(), []
    for ax in fig.findobj(Axes):
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            pad = 1e-9 * max(abs(lo), abs(hi), 1.0)
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                labels = (tick.label1, tick.label2)
                ticks.update(id(t) for t in labels)
                loc = tick.get_loc()
                if loc is not None and lo - pad <= loc <= hi + pad and tick.get_visible():
                    shown += [t for t in labels if t.get_visible() and t.get_text().strip()]
    for t in fig.findobj(Text):
        if id(t) not in ticks and t.get_visible() and t.get_text().strip() and t.get_alpha() != 0:
            if all(a.get_visible() for a in (t.axes, t.get_figure(root=False)) if a is not None):
                shown.append(t)
    return shown


def text_layout(fig, tol_px=1.0):
    """What a reader meets in ``fig``'s texts: ``overlaps`` (pairs of texts whose boxes
    intersect by more than ``tol_px`` pixels each way at the figure's dpi), ``min_font_pt``,
    ``dpi`` and the figure's ``width_in``.  Text over data is not detected."""
    from matplotlib.text import Text

    texts = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    boxes = [Text.get_window_extent(t, renderer) for t in texts]       # an annotation's text, not its arrow
    over = []
    for i in range(len(texts)):
        for j in range(i + 1, len(texts)):
            a, b = boxes[i], boxes[j]
            w = min(a.x1, b.x1) - max(a.x0, b.x0)
            h = min(a.y1, b.y1) - max(a.y0, b.y0)
            if w > tol_px and h > tol_px:
                over.append([texts[i].get_text()[:40], texts[j].get_text()[:40]])
    return {"overlaps": over, "min_font_pt": min((t.get_fontsize() for t in texts), default=None),
            "dpi": float(fig.dpi), "width_in": float(fig.get_figwidth())}


def rasterize_dense(fig, limit=None):
    """Mark every artist of ``fig`` drawing more than ``limit`` (:data:`DENSE_POINTS`) points
    or paths as rasterized.  A cloud of 10^4-10^5 markers written as PDF
    vectors makes a large file that is slow to write and to view, and no reader zooms into
    single dots; axes, text, outlines and polygons stay vectors."""
    limit = DENSE_POINTS if limit is None else limit
    for ax in fig.axes:
        for artist in [*ax.collections, *ax.lines]:
            if hasattr(artist, "get_xdata"):
                n = len(artist.get_xdata()) if artist.get_marker() not in (None, "", "None", " ") else 0
            else:
                n = max(len(artist.get_offsets()), len(artist.get_paths()))
            if n > limit:
                artist.set_rasterized(True)


def save(fig, output, dpi=130, show=False, **kwargs):
    """Save ``fig`` to ``output.png`` and ``output.pdf`` (a PDF without creation date, so that
    reruns give the same bytes; its dense clouds rasterized at ``dpi``,
    :func:`rasterize_dense`); ``show`` also displays the PNG in the notebook.  The PNG
    carries :func:`text_layout` at the saved dpi (text chunk :data:`LAYOUT_KEY`)."""
    Path(output.png).parent.mkdir(parents=True, exist_ok=True)
    shown_dpi = fig.dpi                  # measured at the saved dpi, then displayed as before
    fig.set_dpi(dpi)
    layout = json.dumps(text_layout(fig), ensure_ascii=True)
    fig.set_dpi(shown_dpi)
    # the layout engine placed the axes in that draw at the saved dpi: keep those positions
    # for both files (the PNG is then the layout measured) instead of solving it in each savefig
    engine = fig.get_layout_engine()
    if engine is not None:
        fig.set_layout_engine("none")
    fig.savefig(output.png, dpi=dpi, metadata={LAYOUT_KEY: layout}, **kwargs)
    rasterize_dense(fig)
    fig.savefig(output.pdf, dpi=dpi, metadata={"CreationDate": None}, **kwargs)
    if engine is not None:
        fig.set_layout_engine(engine)
    if show:
        from IPython.display import Image, display

        display(Image(filename=str(output.png)))
        # the PNG shown is the figure: closed, the inline backend does not show it a second time
        import matplotlib.pyplot as plt

        plt.close(fig)


def results_dir(io):
    """The ``results/`` folder of a run, from the Snakemake object (or :func:`paths`' stand-in)
    of a notebook: the parent of its first input's figure folder."""
    inputs = io.input          # Snakemake's Namedlist is a list; the stand-in a namespace
    first = inputs[0] if isinstance(inputs, (list, tuple)) else next(iter(vars(inputs).values()))
    return Path(first).resolve().parents[1]
