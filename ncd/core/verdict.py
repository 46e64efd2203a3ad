"""A claim's verdict: what the index page and a figure's page say about one sentence of the paper.

One record for both, so that a figure's page and the reproduction page can only agree:
the function that measures a claim returns a :class:`Verdict`, the page prints it, the
index prints the same object (``ncd.pages.claims`` maps claim ids to those functions).
``anchor`` is the id of the page section that holds the evidence; ``data`` the files the
number was read from, relative to ``results/``.
"""
from dataclasses import dataclass, field

REPRODUCED, DIFFERS, BEYOND, NOT_TESTED, NOT_COMPUTED = (
    "reproduced", "differs", "beyond the paper", "not tested", "not computed")
VERDICTS = (REPRODUCED, DIFFERS, BEYOND, NOT_TESTED, NOT_COMPUTED)


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
