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
Every row carries its ``criterion``, the test stated before the data (what is measured, over
which set, the threshold and its reason); the pages print it under "Criterion (stated before
the data)" and the judging function's own words under "How it was judged", so that a reader
can hold the one against the other.

Criteria follow the paper's wording: a "may" is judged over the cases it ranges over
(cuts, steps, runs), a statement in R^2κ is tested in R^2κ, a claim about usable step
sizes counts only accurate runs.  One name, unit and sign per quantity: the *dip depth*
is the flank pressure minus the pressure under the apex (> 0 a dip) in units of the mean
ground stress W/2L, on both Figure 4 pages.
"""
import re
from pathlib import Path

import yaml

from ncd.shared.verdict import BEYOND, CONSISTENT, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED, Verdict, anchor

TABLE = Path(__file__).with_name("paper_claims.yaml")


def load_claims(path=TABLE):
    """The claims table: a list of dicts ``id, section, quote, criterion, figures``.  A row
    without a criterion, or with one per page that misses a page of its ``figures``, is
    refused here (naming the row), so that no page prints a verdict without its test."""
    rows = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    ids = [r["id"] for r in rows]
    if len(set(ids)) != len(ids):
        raise ValueError(f"duplicate claim ids in {path}")
    bad = [f"{r['id']}: {p}" for r in rows for p in criterion_problems(r, form_only=True)]
    if bad:
        raise ValueError(f"claims table {path}: " + "; ".join(bad))
    return rows


# The kinds of criterion that name no number, by their opening words, and what each must
# then say: why no control can be built, what would test it, why it is not judged.
NO_THRESHOLD = {
    "consistent:": ("no control",),
    "not tested:": ("would",),
    "not judged:": ("open question", "beyond the paper"),
}


def criterion_texts(claim):
    """``{figure: criterion}`` of a row: one text for every page of its ``figures`` (``""``
    for a row no page judges), or the row's own mapping figure -> text."""
    c = claim.get("criterion")
    if isinstance(c, dict):
        return dict(c)
    return {f: c for f in claim.get("figures") or [""]}


def criterion_problems(claim, form_only=False):
    """What is wrong with a row's ``criterion`` (an empty list: nothing).  The form: present,
    non-empty text, one per page where it is a mapping.  Then the content (unless
    ``form_only``): a judged text names a threshold (a number), else it opens with one of
    :data:`NO_THRESHOLD` and says what that kind needs; a row no page judges is
    "Not tested:"."""
    c = claim.get("criterion")
    figures = list(claim.get("figures") or [])
    if not c:
        return ["no criterion"]
    if isinstance(c, dict):
        if set(c) != set(figures):
            return [f"criterion pages {sorted(c)} are not its figures {sorted(figures)}"]
    elif not isinstance(c, str):
        return [f"criterion must be a text or a mapping figure -> text, got {type(c).__name__}"]
    texts = criterion_texts(claim)
    problems = [f"empty criterion for {f or 'the row'}" for f, t in texts.items() if not isinstance(t, str) or not t.strip()]
    if problems or form_only:
        return problems
    for fig, text in texts.items():
        where = f" ({fig})" if fig else ""
        low = text.strip().lower()
        kind = next((k for k in NO_THRESHOLD if low.startswith(k)), None)
        if not figures and kind != "not tested:":
            problems.append("a row no page judges must open with \"Not tested:\"")
        elif kind is None and not re.search(r"\d", text):
            problems.append(f"names no threshold{where}: no number, and it does not open with one of "
                            f"{', '.join(repr(k) for k in NO_THRESHOLD)}")
        elif kind is not None and not any(w in low for w in NO_THRESHOLD[kind]):
            problems.append(f"a {kind!r} criterion{where} must say " + " or ".join(repr(w) for w in NO_THRESHOLD[kind]))
    return problems


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


def criterion_of(claim, figure=""):
    """The criterion stated beside the quote in the table, written before the data were looked
    at (what is measured, over which set, the threshold and its reason): the text for
    ``figure``'s evidence where the row has one per page, else the row's text."""
    texts = criterion_texts(claim)
    if figure in texts:
        return texts[figure]
    if len(set(texts.values())) == 1:
        return next(iter(texts.values()))
    return "; ".join(f"{f}: {t}" for f, t in texts.items())


def figure_of(function):
    """The page whose package holds a judging function (``ncd.figures.<figure>.claims`` or
    ``ncd.studies.<study>.claims``), ``""`` for a function elsewhere."""
    parts = getattr(function, "__module__", "").split(".")
    return parts[2] if len(parts) > 3 and parts[:2] in (["ncd", "figures"], ["ncd", "studies"]) else ""


def _same(a, b):
    return " ".join(a.split()).rstrip(".").casefold() == " ".join(b.split()).rstrip(".").casefold()


def how_judged(stated, verdict):
    """The judging function's own criterion where it adds to the ``stated`` one: ``""`` when
    it is empty (a measurement not computed) or says the same."""
    own = (verdict.criterion or "").strip()
    return "" if own in ("", "—") or _same(own, stated) else own


def claim_markdown(claim_id, results, judges):
    """The block a figure's page prints for one claim, judged by the page's own table
    ``judges`` (its package's ``JUDGES``): the anchor the index links to, the quote, the
    criterion stated before the data (the table's, the text for this page), then per judging
    function the measured value, the verdict and how the function judged it (the index's
    own words)."""
    claim = CLAIM_BY_ID[claim_id]
    if claim_id not in judges:
        raise KeyError(f"claim {claim_id!r} is not judged by this page's table (its claims.py JUDGES)")
    own = anchor(claim_id)
    blocks = []
    for fn in judges[claim_id]:
        v = evaluate(fn, results, claim_id)
        stated = criterion_of(claim, figure_of(fn))
        how = how_judged(stated, v)
        blocks.append((f'<a id="{v.anchor}"></a>' if v.anchor and v.anchor != own else "")
                      + f"*Criterion (stated before the data):* {stated.rstrip('.')}.\n\n"
                      + f"**{v.verdict}** — {v.value}." + (f" *How it was judged:* {how.rstrip('.')}." if how else ""))
    body = "\n\n".join(blocks)
    return f'<a id="{own}"></a>\n\n> {claim["section"]}: “{claim["quote"]}”\n\n{body}\n'
