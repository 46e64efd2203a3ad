"""Criteria stated before the data: every row of the claims table carries its criterion
beside the quote, in a form that can fail (a threshold, or the kind of row that has none
and what that kind must say); the table refuses a row without one; on a run, the
criterion's kind agrees with the verdict its judging function gives."""
import pytest

from ncd.pages import claims as C
from ncd.pages.report import UNGER
from ncd.shared.verdict import BEYOND, CONSISTENT, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED

JUDGED = ["fig1_wedged"]


def test_every_row_has_a_criterion_that_names_a_threshold_or_says_why_none():
    problems = {c["id"]: C.criterion_problems(c) for c in C.CLAIMS}
    assert not {k: p for k, p in problems.items() if p}
    for c in C.CLAIMS:
        texts = C.criterion_texts(c)
        assert texts and all(t.strip() for t in texts.values()), c["id"]
        assert set(texts) == set(c["figures"] or [""]), c["id"]      # one text per page that judges it


def test_every_unger_row_has_its_criterion():
    unger = [c for c in C.CLAIMS if c.get("source") == UNGER]
    assert len(unger) >= 4
    for c in unger:
        assert c.get("criterion") and not C.criterion_problems(c), c["id"]
        assert "beyond the paper" in C.criterion_of(c).lower(), c["id"]      # judged on their terms, not Moreau's


@pytest.mark.parametrize("row, expected", [
    ({"id": "x", "figures": JUDGED}, "no criterion"),
    ({"id": "x", "figures": JUDGED, "criterion": ""}, "no criterion"),
    ({"id": "x", "figures": JUDGED, "criterion": "   "}, "empty criterion"),
    ({"id": "x", "figures": JUDGED, "criterion": "the wedged runs look right"}, "names no threshold"),
    ({"id": "x", "figures": JUDGED, "criterion": "Consistent: it holds by construction."}, "no control"),
    ({"id": "x", "figures": JUDGED, "criterion": "Not tested: nothing measures it."}, "would"),
    ({"id": "x", "figures": JUDGED, "criterion": "Not judged: measured."}, "open question"),
    ({"id": "x", "figures": [], "criterion": "at least 1 run falls"}, "Not tested:"),
    ({"id": "x", "figures": ["fig4_pile", "fig4_history"], "criterion": {"fig4_pile": "within 10°"}},
     "are not its figures"),
    ({"id": "x", "figures": ["fig4_pile", "fig4_history"], "criterion": {"fig4_pile": "within 10°",
                                                                          "fig4_history": "looks parallel"}},
     "names no threshold (fig4_history)"),
    ({"id": "x", "figures": JUDGED, "criterion": ["a list"]}, "a text or a mapping"),
])
def test_the_checker_refuses_a_row_without_a_usable_criterion(row, expected):
    """Negative controls: each made-up row fails the checker, with the reason named."""
    problems = C.criterion_problems(row)
    assert problems and any(expected in p for p in problems), problems


@pytest.mark.parametrize("row", [
    {"id": "x", "figures": JUDGED, "criterion": "every wedged I within 10⁻⁶ R of the segment"},
    {"id": "x", "figures": JUDGED, "criterion": "Consistent: by construction; no control can be built since ..."},
    {"id": "x", "figures": [], "criterion": "Not tested: a 3-D statement; a 3-D pile would test it."},
    {"id": "x", "figures": JUDGED, "criterion": "Not judged: an open question of the paper, measured."},
    {"id": "x", "figures": ["fig4_pile", "fig4_history"], "criterion": {"fig4_pile": "within 10°",
                                                                          "fig4_history": "band within 10°"}},
])
def test_the_checker_passes_a_usable_criterion(row):
    """Positive controls: the same rows written with a threshold or with what their kind needs."""
    assert C.criterion_problems(row) == []


def test_the_table_refuses_a_row_without_a_criterion(tmp_path):
    good = ('- id: a-row\n  section: "§1"\n  quote: "q"\n  criterion: "at least 1 run"\n  figures: [fig1_wedged]\n')
    path = tmp_path / "claims.yaml"
    path.write_text(good, encoding="utf-8")
    assert C.load_claims(path)[0]["criterion"] == "at least 1 run"
    path.write_text(good + '- id: no-criterion\n  section: "§2"\n  quote: "r"\n  figures: [fig1_wedged]\n',
                    encoding="utf-8")
    with pytest.raises(ValueError, match="no-criterion: no criterion"):
        C.load_claims(path)


def test_criterion_of_gives_each_page_its_own_text():
    row = {"id": "x", "figures": ["a", "b"], "criterion": {"a": "within 1", "b": "within 2"}}
    assert C.criterion_of(row, "a") == "within 1" and C.criterion_of(row, "b") == "within 2"
    assert C.criterion_of(row) == "a: within 1; b: within 2"
    one = {"id": "y", "figures": ["a", "b"], "criterion": "within 3"}
    assert C.criterion_of(one, "b") == C.criterion_of(one) == "within 3"


def kind_disagrees(text, verdict):
    """True when a criterion's kind contradicts its verdict: a row its function finds
    consistent must state "Consistent:", one beyond the paper "Not judged:", one not tested
    must say so; a reproduced or differing row names a threshold, not one of these kinds.
    A measurement not computed says nothing."""
    low = text.strip().lower()
    kinds = [k for k in C.NO_THRESHOLD if low.startswith(k)]
    expected = {CONSISTENT: "consistent:", BEYOND: "not judged:"}.get(verdict)
    if verdict == NOT_COMPUTED:
        return False
    if expected:
        return kinds != [expected]
    if verdict == NOT_TESTED:
        return "not tested" not in low
    return bool(kinds)


@pytest.mark.parametrize("text, verdict, disagrees", [
    ("Consistent: by construction; no control can be built", CONSISTENT, False),
    ("every I within 10⁻⁶ R", CONSISTENT, True),                 # a consistent row written as a test
    ("Not judged: an open question", BEYOND, False),
    ("below 5 %", BEYOND, True),
    ("a band holding 1 but wider is not tested", NOT_TESTED, False),
    ("within 10°", NOT_TESTED, True),
    ("within 10°", REPRODUCED, False),
    ("Consistent: no control can be built", REPRODUCED, True),   # a judged verdict under a criterion that judges nothing
    ("Not judged: an open question", DIFFERS, True),
    ("anything", NOT_COMPUTED, False),
])
def test_the_kind_check_has_controls(text, verdict, disagrees):
    assert kind_disagrees(text, verdict) == disagrees


def test_the_criterion_kind_agrees_with_the_verdict_on_the_run(results):
    """On a run, every page's verdict against the criterion stated for that page."""
    from ncd.pages.report import claim_rows

    wrong = [(c["id"], fig, v.verdict) for c, fig, v in claim_rows(results)
             if kind_disagrees(C.criterion_of(c, fig), v.verdict)]
    assert not wrong, wrong
