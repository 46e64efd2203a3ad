"""A claim's verdict: what the index page and a figure's page say about one sentence of the paper.

One record for both, so that a figure's page and the reproduction page can only agree:
the function that judges a claim (in its figure's ``claims.py``) returns a :class:`Verdict`,
the page prints it, the index prints the same object.  ``anchor`` is the id of the page
section that holds the evidence; ``data`` the files the number was read from, relative to
``results/``.  The helpers below are what every judging function needs: open a run's file,
format a fraction or a range, build the record under the claim's anchor.
"""
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

REPRODUCED, DIFFERS, BEYOND, CONSISTENT, NOT_TESTED, NOT_COMPUTED = (
    "reproduced", "differs", "beyond the paper", "consistent", "not tested", "not computed")
# consistent: the sentence holds by construction of the method or is a definition (no data
# where it is false can be built): illustrated by the run, not tested, and counted apart
VERDICTS = (REPRODUCED, DIFFERS, BEYOND, CONSISTENT, NOT_TESTED, NOT_COMPUTED)


@dataclass(frozen=True)
class Verdict:
    """``value``: the measured number in a sentence; ``verdict``: one of :data:`VERDICTS`;
    ``criterion``: the test applied, in the paper's terms (a "may" over cuts is judged over
    cuts, a statement in R^2κ in R^2κ)."""
    value: str
    verdict: str
    criterion: str
    anchor: str = ""
    data: tuple = field(default_factory=tuple)

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")


def anchor(claim_id):
    """The HTML id of a claim's block on its figure's page."""
    return f"claim-{claim_id}"


def judged(value, verdict, criterion, claim_id, *data):
    """The :class:`Verdict` of ``claim_id`` under its anchor, read from the files ``data``."""
    return Verdict(value, verdict, criterion, anchor(claim_id), tuple(data))


def open_data(results, rel):
    """The dataset ``results/<rel>``, or FileNotFoundError naming ``rel`` (the claim is then
    *not computed* on the pages, which still build)."""
    path = Path(results) / rel
    if not path.exists():
        raise FileNotFoundError(f"{rel} absent")
    return xr.load_dataset(path)


def pct(x):
    """A fraction as a percentage with one decimal."""
    return f"{100 * x:.1f} %"


def span(x, fmt):
    """``a–b`` of the range of ``x``, or ``a`` when both ends print the same."""
    lo, hi = format(np.min(x), fmt), format(np.max(x), fmt)
    return lo if lo == hi else f"{lo}–{hi}"
