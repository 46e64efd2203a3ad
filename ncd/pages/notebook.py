"""What a figure's notebook needs around the science: its inputs and outputs, wherever it runs.

Under Snakemake's ``notebook:`` directive the injected ``snakemake`` object names the
files; run by hand from anywhere in the checkout, :func:`paths` finds the repository root
and names what a finished ``snakemake -j2 <figure>`` left under ``results/``, so a
notebook writes only there.  :func:`check_pair` stops a run whose jupytext ``.py`` was
edited without ``jupytext --sync`` (the ``.ipynb`` that Snakemake runs would be stale).
"""
from pathlib import Path
from types import SimpleNamespace

import yaml

MARKERS = ("Snakefile", "config.yaml")


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
                               pdf=str(results / "figures" / f"{figure}.pdf")),
        params=SimpleNamespace(config=section), config={figure: section})


def save(fig, output, dpi=130, show=False, **kwargs):
    """Save ``fig`` to ``output.png`` and ``output.pdf`` (a PDF without creation date, so that
    reruns give the same bytes); ``show`` also displays the PNG in the notebook."""
    Path(output.png).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output.png, dpi=dpi, **kwargs)
    fig.savefig(output.pdf, metadata={"CreationDate": None}, **kwargs)
    if show:
        from IPython.display import Image, display

        display(Image(filename=str(output.png)))


def results_dir(io):
    """The ``results/`` folder of a run, from the Snakemake object (or :func:`paths`' stand-in)
    of a notebook: the parent of its first input's figure folder."""
    inputs = io.input          # Snakemake's Namedlist is a list; the stand-in a namespace
    first = inputs[0] if isinstance(inputs, (list, tuple)) else next(iter(vars(inputs).values()))
    return Path(first).resolve().parents[1]
