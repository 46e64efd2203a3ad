"""The paper's claims on the pages: the table of sentences, the lookup of their judging
functions and the block a page prints.

:data:`CLAIMS` is the table of every checkable sentence of Moreau (2005)
(``paper_claims.yaml``, one row per quoted sentence).  The functions that judge a claim
live with the figure whose data they read (``ncd/figures/<figure>/claims.py`` and
``ncd/studies/<study>/claims.py``, each a table ``JUDGES``: claim id -> functions taking
the ``results/`` folder and returning a :class:`~ncd.shared.verdict.Verdict`).  A figure's
page prints :func:`claim_markdown` with its own table and the index page
(:mod:`ncd.pages.report`) prints :func:`verdicts` over every figure's table
(:mod:`ncd.pages.registry`): the same functions, so the two cannot disagree.  A claim no
figure judges is listed as *not tested* with the reason in :data:`UNTESTED_REASONS`.

Criteria follow the paper's wording: a "may" is judged over the cases it ranges over
(cuts, steps, runs), a statement in R^2κ is tested in R^2κ, a claim about usable step
sizes counts only accurate runs.  One name, unit and sign per quantity: the *dip depth*
is the flank pressure minus the pressure under the apex (> 0 a dip) in units of the mean
ground stress W/2L, on both Figure 4 pages.
"""
from pathlib import Path

import yaml

from ncd.shared.verdict import BEYOND, CONSISTENT, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED, Verdict, anchor

TABLE = Path(__file__).with_name("paper_claims.yaml")


def load_claims(path=TABLE):
    """The claims table: a list of dicts ``id, section, quote, figures``."""
    rows = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    ids = [r["id"] for r in rows]
    if len(set(ids)) != len(ids):
        raise ValueError(f"duplicate claim ids in {path}")
    return rows


CLAIMS = load_claims()
CLAIM_BY_ID = {c["id"]: c for c in CLAIMS}

UNTESTED_REASONS = {
    "s2-md-forces-state": "the MD baseline (ncd/dynamics/md.py) is used for stability only; no exploration of "
                          "the plurality of its force states is run",
    "s5-cylindric-cuts": "a 3-D statement (cylindric cuts of a conical pile); the 2-D analogue is the vertical "
                         "cut of §5, and the end of the fig4_bank page says what a plane pile can say of it",
    "s6-incremental-coulomb": "a statement about theory (an incremental Coulomb law), not about a computation",
}


def measures_of(claim_id, judges_by_figure):
    """``[(figure, function)]`` judging ``claim_id`` in ``judges_by_figure`` ({figure: its
    ``JUDGES`` table}, in page order); empty: not tested."""
    if claim_id not in CLAIM_BY_ID:
        raise KeyError(f"unknown claim id {claim_id!r}")
    return [(fig, fn) for fig, judges in judges_by_figure.items() for fn in judges.get(claim_id, ())]


def evaluate(function, results, claim_id=""):
    """The claim's measurement, or ``not computed`` with the reason (missing file, variable, ...),
    so that a page builds while figures change."""
    try:
        return function(Path(results))
    except (FileNotFoundError, OSError, KeyError, IndexError, ValueError, AttributeError, TypeError) as exc:
        return Verdict(f"not computed ({type(exc).__name__}: {exc})", NOT_COMPUTED, "—", anchor(claim_id))


def verdicts(claim_id, results, judges_by_figure):
    """``[(figure, Verdict)]`` of a claim on this run; a claim no figure judges gives one
    ``not tested`` row (figure ``""``) with the reason."""
    rows = [(fig, evaluate(fn, results, claim_id)) for fig, fn in measures_of(claim_id, judges_by_figure)]
    if not rows:
        rows = [("", Verdict(UNTESTED_REASONS.get(claim_id, "not measured by any figure"), NOT_TESTED, "—",
                             anchor(claim_id)))]
    return rows


RULES = {
    "all": "every page's evidence must reproduce it",
    "any": "a \"may\": one page's evidence reproducing it suffices",
}


def rule_of(claim, figures):
    """``(counted figures, rule text)`` of a sentence: its table's ``rule`` (``all``, ``any``
    or the one figure whose evidence is the sentence's scope) over the ``figures`` that
    judged it; one page needs no rule."""
    rule = claim.get("rule", "all")
    if rule in RULES:
        return list(figures), (RULES[rule] if len(figures) > 1 else "")
    if rule not in figures:
        return list(figures), RULES["all"] if len(figures) > 1 else ""
    why = claim.get("rule_reason", "")
    return [rule], f"{rule}'s evidence is the sentence's scope" + (f" ({why})" if why else "") + "; the others are shown"


def sentence_verdict(claim, rows):
    """One verdict per sentence from its ``[(figure, Verdict)]`` rows, by the claim's rule:
    among the counted rows, any *differs* makes it differ under ``all`` (one reproducing
    row suffices under ``any``); rows that all hold by construction are *consistent*, all
    beyond the paper *beyond the paper*; a missing measurement leaves it *not computed*.
    Returns ``(verdict, rule text)``."""
    counted, text = rule_of(claim, [f for f, _ in rows])
    got = [v.verdict for f, v in rows if f in counted]
    if not got or got == [NOT_TESTED]:
        return NOT_TESTED, text
    any_rule = claim.get("rule") == "any"
    if any_rule and REPRODUCED in got:
        return REPRODUCED, text
    if DIFFERS in got:
        return DIFFERS, text
    if NOT_COMPUTED in got:
        return NOT_COMPUTED, text
    if REPRODUCED in got:
        return REPRODUCED, text
    for kind in (CONSISTENT, BEYOND, NOT_TESTED):
        if kind in got:
            return kind, text
    return got[0], text


def criterion_of(claim, verdict):
    """The criterion a page prints for a claim: the one stated beside the quote in the table
    (``criterion``: what is measured, over which set, the threshold and its reason), written
    before the data were looked at, else the judging function's own words."""
    return claim.get("criterion") or verdict.criterion


def claim_markdown(claim_id, results, judges):
    """The block a figure's page prints for one claim, judged by the page's own table
    ``judges`` (its package's ``JUDGES``): the anchor the index links to, the quote, the
    measured value and the verdict with its criterion (the index's own words)."""
    claim = CLAIM_BY_ID[claim_id]
    if claim_id not in judges:
        raise KeyError(f"claim {claim_id!r} is not judged by this page's table (its claims.py JUDGES)")
    rows = [evaluate(fn, results, claim_id) for fn in judges[claim_id]]
    own = anchor(claim_id)
    body = "\n\n".join((f'<a id="{v.anchor}"></a>' if v.anchor and v.anchor != own else "")
                       + f"**{v.verdict}** — {v.value}. *Criterion:* {criterion_of(claim, v).rstrip('.')}." for v in rows)
    return f'<a id="{own}"></a>\n\n> {claim["section"]}: “{claim["quote"]}”\n\n{body}\n'
