"""results/index.html and the claims table: every sentence of the paper has a row, the
verdicts follow the data, missing data give "not computed", run times come from the
benchmark files."""
import html
import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from ncd.figures.fig1_wedged import claims as fig1
from ncd.figures.fig2_slope import claims as fig2
from ncd.figures.fig4_pile import claims as fig4
from ncd.pages import claims as C
from ncd.pages.registry import JUDGES_BY_FIGURE
from ncd.pages.report import (
    SOURCES,
    UNGER,
    abstract,
    build_page,
    claim_rows,
    run_times,
    section_of,
    sentence_rows,
    tally,
)
from ncd.shared.verdict import CONSISTENT, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED, VERDICTS, Verdict, anchor

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT.parent / "shared" / "paper" / "moreau-2005-indetermination.txt"
MATH = (("\\mathbf{R}^{2\\kappa}", "R^2κ"), ("\\kappa", "κ"), ("\\gamma", "γ"), ("\\rho", "ρ"), ("\\alpha", "α"),
        ("\\cap", "∩"), ("t_0", "t0"), ("-", "−"), ("$", ""), ("*", ""), ("{", ""), ("}", ""), ("\\", ""))


def _normal(text):
    text = re.sub(r"-\s*\n\s*\n\s*", "", text)          # a word split over the paper's page break
    for a, b in MATH:
        text = text.replace(a, b)
    return re.sub(r"\s+", "", text)


def test_every_claim_is_judged_or_has_a_reason():
    ids = {c["id"] for c in C.CLAIMS}
    judged = {k for judges in JUDGES_BY_FIGURE.values() for k in judges}
    assert judged <= ids and set(C.UNTESTED_REASONS) <= ids
    for c in C.CLAIMS:
        figs = [f for f, _ in C.measures_of(c["id"], JUDGES_BY_FIGURE)]
        assert figs or c["id"] in C.UNTESTED_REASONS, c["id"]
        assert sorted(set(figs)) == sorted(c["figures"]), (c["id"], figs, c["figures"])
        assert section_of(c) in c["section"] or (c.get("source") in SOURCES and section_of(c) == c["source"])
    known = set(JUDGES_BY_FIGURE)
    assert {f for c in C.CLAIMS for f in c["figures"]} <= known


@pytest.mark.skipif(not PAPER.exists(), reason="the paper's text is not beside the checkout")
def test_every_quote_is_the_papers_wording():
    paper = _normal(PAPER.read_text(encoding="utf-8"))
    missing = [c["id"] for c in C.CLAIMS if c.get("source") not in SOURCES and _normal(c["quote"]) not in paper]
    assert not missing, f"quotes not found in the paper: {missing}"


def test_every_claim_has_one_row_on_the_index(tmp_path):
    page = build_page(tmp_path, ["fig1_wedged", "fig9_new"], {"fig1_wedged": {"mu": 0.75}})
    for c in C.CLAIMS:
        assert page.count(f"id='{c['id']}'") == 1, c["id"]
    rows = claim_rows(tmp_path)
    assert all(v.verdict in VERDICTS for _, _, v in rows)
    # without data every measured claim is "not computed", every other "not tested"; the page builds
    for c, fig, v in rows:
        assert v.verdict == (NOT_COMPUTED if fig else NOT_TESTED), (c["id"], v)
    assert "fig9_new" in page and "config digest" in page
    # the size and realizations each figure ran at, and the run's label, beside its run time
    page = build_page(tmp_path, ["fig4_pile"], {"run": {"label": "quick"}, "fig4_pile": {"ensemble": {"runs": 64}}})
    assert "ensemble.runs = 64" in page and "this run (quick)" in page and "A quick run" in page


def _sweep(tmp_path, fractions):
    gamma = np.array([10.0, 15.0, 25.0, 30.0])
    ds = xr.Dataset({"wedged_fraction": ("gamma", np.array(fractions))}, coords={"gamma": gamma},
                    attrs={"threshold_gamma_deg": 20.0})
    (tmp_path / "fig1_wedged").mkdir(exist_ok=True)
    ds.to_netcdf(tmp_path / "fig1_wedged" / "sweep.nc")


def test_threshold_verdict_follows_the_data(tmp_path):
    _sweep(tmp_path, [0.0, 0.0, 0.4, 0.6])
    m = fig1.fig1_threshold(tmp_path)
    assert m.verdict == REPRODUCED and "first at 25.0°" in m.value
    _sweep(tmp_path, [0.0, 0.1, 0.4, 0.6])  # wedging below the threshold: the claim fails
    assert fig1.fig1_threshold(tmp_path).verdict == DIFFERS


def _cuts(tmp_path, x, fx, cloud):
    """Scan cuts at ``x`` (one flank) with history resultants ``(fx, 0)``, a default cut at
    x[0], and zero-guess runs at rest whose resultants at the default cut are ``cloud``."""
    n = len(x) + 1
    kind = np.array(["default"] + ["scan"] * len(x))
    cuts = xr.Dataset({"kind": ("cut", kind), "cut_x": ("cut", np.r_[x[0], x]), "outer": ("cut", np.ones(n)),
                       "history_fx": ("cut", np.r_[fx[0], fx]), "history_fy": ("cut", np.zeros(n))},
                      attrs={"mean_diameter": 1.0})
    runs = len(cloud)
    fxr = np.zeros((runs, n))
    fxr[:, 0] = cloud
    ens = xr.Dataset({"outcome": ("run", np.ones(runs, int)), "cut_force_x": (("run", "cut"), fxr),
                      "cut_force_y": (("run", "cut"), np.zeros((runs, n)))})
    (tmp_path / "fig4_pile").mkdir(exist_ok=True)
    cuts.to_netcdf(tmp_path / "fig4_pile" / "cuts.nc")
    ens.to_netcdf(tmp_path / "fig4_pile" / "ensemble.nc")


def test_cut_position_is_a_may_over_pairs_of_cuts(tmp_path):
    # cuts one diameter apart: changes 1.0, 0.1, 0.1; the cloud is 0.2 across
    _cuts(tmp_path, [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 1.1, 1.2], [0.0, 0.2])
    v = fig4.fig4_cut_vs_cloud(tmp_path)
    assert v.verdict == REPRODUCED and "3 pairs" in v.value and "33.3 % of pairs" in v.value
    _cuts(tmp_path, [0.0, 1.0, 2.0, 3.0], [0.0, 0.3, 0.6, 0.9], [0.0, 0.2])   # every change below 0.4
    assert fig4.fig4_cut_vs_cloud(tmp_path).verdict == DIFFERS


def _measures(tmp_path, zero, warm):
    tol = np.array([1e-3, 1e-5, 1e-8])
    sp = np.zeros((2, 3, 1))
    sp[0, :, 0], sp[1, :, 0] = zero, warm
    ds = xr.Dataset({"spread": (("init", "tol", "disc"), sp)},
                    coords={"init": ["zero", "warm"], "tol": tol, "disc": [0]}, attrs={"grain": 0})
    (tmp_path / "fig2_slope").mkdir(exist_ok=True)
    ds.to_netcdf(tmp_path / "fig2_slope" / "measures.nc")


def test_warm_start_judged_where_the_zero_guess_spread_has_settled(tmp_path):
    _measures(tmp_path, [0.5, 5.4, 5.6], [0.4, 0.05, 1e-5])     # loose tolerance: both are iteration error
    assert fig2.warm_little(tmp_path).verdict == REPRODUCED
    _measures(tmp_path, [0.5, 5.4, 5.6], [0.4, 0.9, 1e-5])      # at 1e-5 the warm spread is not small
    assert fig2.warm_little(tmp_path).verdict == DIFFERS


def test_claim_markdown_carries_the_index_verdict_and_anchor(tmp_path):
    _sweep(tmp_path, [0.0, 0.0, 0.4, 0.6])
    text = C.claim_markdown("s1-wedging-threshold", tmp_path, fig1.JUDGES)
    assert '<a id="claim-s1-wedging-threshold"></a>' in text and f"**{REPRODUCED}**" in text
    rows = dict((c["id"], v) for c, _, v in claim_rows(tmp_path) if c["id"] == "s1-wedging-threshold")
    assert rows["s1-wedging-threshold"].value in text


def _index_row(page, claim_id):
    """The HTML of one sentence's row on the index page."""
    at = page.index(f"id='{claim_id}'")
    return page[at:page.index("</tr>", at)]


def test_the_index_row_states_the_criterion_before_the_data_and_how_it_was_judged(tmp_path):
    _sweep(tmp_path, [0.0, 0.0, 0.4, 0.6])
    claim = C.CLAIM_BY_ID["s1-wedging-threshold"]
    judged = fig1.fig1_threshold(tmp_path)
    row = _index_row(build_page(tmp_path, ["fig1_wedged"], {}), claim["id"])
    assert "Criterion (stated before the data)" in row and html.escape(claim["criterion"]) in row
    assert "How it was judged" in row and html.escape(judged.criterion) in row
    # a control: the row prints the table's text, whatever it says, and drops the function's when it says the same
    mine = dict(claim, criterion="a made-up criterion, 42 runs")
    row = _index_row(build_page(tmp_path, ["fig1_wedged"], {}, claims=[mine]), claim["id"])
    assert "a made-up criterion, 42 runs" in row and html.escape(claim["criterion"]) not in row
    same = dict(claim, criterion=judged.criterion)
    row = _index_row(build_page(tmp_path, ["fig1_wedged"], {}, claims=[same]), claim["id"])
    assert html.escape(judged.criterion) in row and "How it was judged" not in row


def test_every_index_row_prints_its_criterion_even_without_data(tmp_path):
    page = build_page(tmp_path, [], {})
    for c in C.CLAIMS:
        row = _index_row(page, c["id"])
        assert "Criterion (stated before the data)" in row, c["id"]
        for fig, text in C.criterion_texts(c).items():
            assert html.escape(text) in row, (c["id"], fig)
            if len(set(C.criterion_texts(c).values())) > 1:
                assert f"{fig}: {html.escape(text)}" in row, (c["id"], fig)


def test_the_page_block_states_its_own_pages_criterion(tmp_path):
    _sweep(tmp_path, [0.0, 0.0, 0.4, 0.6])
    text = C.claim_markdown("s1-wedging-threshold", tmp_path, fig1.JUDGES)
    crit = C.CLAIM_BY_ID["s1-wedging-threshold"]["criterion"]
    assert f"*Criterion (stated before the data):* {crit.rstrip('.')}." in text
    assert f"*How it was judged:* {fig1.fig1_threshold(tmp_path).criterion}" in text
    # a sentence judged by two pages: each page prints its own text, not the other's
    dip = C.CLAIM_BY_ID["s5-dip"]["criterion"]
    block = C.claim_markdown("s5-dip", tmp_path, fig4.JUDGES)
    assert dip["fig4_pile"].rstrip(".") in block and dip["fig4_history"].rstrip(".") not in block


def test_run_times_sum_the_benchmark_files(tmp_path):
    d = tmp_path / "benchmarks" / "fig1_wedged"
    d.mkdir(parents=True)
    for name, s in (("simulate", 2.5), ("notebook", 4.0)):
        (d / f"{name}.tsv").write_text(f"s\th:m:s\tmax_rss\n{s}\t0:00:0{int(s)}\t100\n")
    assert run_times(tmp_path, "fig1_wedged") == (2, 6.5)
    assert run_times(tmp_path, "absent") == (0, 0.0)


def test_each_page_states_the_index_verdict(results):
    """On the run's pages: every claim a figure judges is printed on that figure's page,
    under the anchor the index links to (up to the next anchor), with the same verdict and
    the same value."""
    import html as html_lib

    wrong = []
    for c, fig, v in claim_rows(results):
        if not fig:
            continue
        page = results / "html" / f"{fig}.html"
        text = page.read_text(encoding="utf-8") if page.exists() else ""
        at = text.find(f'id="{v.anchor}"')
        if at < 0:
            wrong.append((c["id"], fig, f"no anchor {v.anchor}"))
            continue
        end = at
        while True:        # the block runs to the next anchor that is not this claim's own
            end = text.find('<a id="', end + 10)
            if end < 0 or not text.startswith((f'<a id="{anchor(c["id"])}"', f'<a id="{v.anchor}"'), end):
                break
        block = html_lib.unescape(re.sub(r"<[^>]+>", "", text[at:end if end > 0 else at + 20000]))
        if v.verdict not in block or v.value[:60] not in block:
            wrong.append((c["id"], fig, v.verdict))
    assert not wrong, wrong


def _v(verdict, value="x"):
    return Verdict(value, verdict, "criterion")


@pytest.mark.parametrize("rule, verdicts, expected", [
    ("all", [REPRODUCED, REPRODUCED], REPRODUCED),
    ("all", [REPRODUCED, DIFFERS], DIFFERS),               # negative control: one page's evidence fails
    ("any", [DIFFERS, REPRODUCED], REPRODUCED),             # a "may": one page suffices
    ("any", [DIFFERS, DIFFERS], DIFFERS),
    ("b", [DIFFERS, REPRODUCED], REPRODUCED),               # page b is the sentence's scope
    ("b", [REPRODUCED, DIFFERS], DIFFERS),
    ("all", [CONSISTENT, CONSISTENT], CONSISTENT),
    ("all", [REPRODUCED, NOT_COMPUTED], NOT_COMPUTED),
])
def test_one_verdict_per_sentence_follows_its_rule(rule, verdicts, expected):
    claim = {"id": "x", "rule": rule}
    verdict, text = C.sentence_verdict(claim, [("a", _v(verdicts[0])), ("b", _v(verdicts[1]))])
    assert verdict == expected and text


def test_the_tally_counts_sentences_not_rows():
    sentences = [({"id": "a"}, [("f", _v(REPRODUCED)), ("g", _v(REPRODUCED))], REPRODUCED, ""),
                 ({"id": "b"}, [("f", _v(DIFFERS))], DIFFERS, ""),
                 ({"id": "c", "source": UNGER}, [("f", _v(REPRODUCED))], REPRODUCED, "")]
    assert tally(sentences)[REPRODUCED] == 1 and tally(sentences)[DIFFERS] == 1
    assert tally(sentences, UNGER)[REPRODUCED] == 1


def test_the_abstract_states_the_counts_what_differs_and_the_pairs_that_pull_apart():
    a = {"id": "s5-a", "section": "§5", "quote": "one two three", "see": ["s6-b"]}
    b = {"id": "s6-b", "section": "§6", "quote": "four five", "see": ["s5-a"]}
    sentences = [(a, [("f", _v(DIFFERS, "range 40° wide"))], DIFFERS, ""),
                 (b, [("f", _v(REPRODUCED, "cloud 3° wide"))], REPRODUCED, "")]
    text = abstract(sentences)
    assert "Of the 2 checkable sentences of the paper, 1 reproduce, 1 differ" in text
    assert "range 40° wide" in text and "pull apart" in text and "cloud 3° wide" in text
    same = [(a, [("f", _v(REPRODUCED))], REPRODUCED, ""), (b, [("f", _v(REPRODUCED))], REPRODUCED, "")]
    assert "pull apart" not in abstract(same)           # a control: agreeing verdicts are not flagged


def test_every_multi_page_sentence_has_a_rule_the_index_states(tmp_path):
    for c, rows, verdict, rule in sentence_rows(tmp_path):
        figs = {f for f, _ in rows if f}
        assert c.get("rule", "all") in ("all", "any") or c["rule"] in figs, c["id"]
        if len(figs) > 1:
            assert rule, c["id"]


def test_the_abstract_names_the_size_of_unger_et_al_s_verdicts():
    """Unger et al.'s findings are judged at the run's size, named beside theirs; a config
    without Figure 5 names none."""
    from ncd.pages.report import unger_size
    cfg = {"fig5_governing": {"packings": {"n_discs": 60, "width_radii": 23, "slice_radii": 16, "per_mu": 10,
                                           "n_mu": 8}, "walk": {"samples": 30}}}
    size = unger_size(cfg)
    assert size.startswith("60 discs, 23 R wide, a 16 R slice, 10 packings at each of 8 μ, 30 walk samples")
    assert "Unger et al.: 200 discs" in size and unger_size({}) == ""
    c = {"id": "unger-peak", "section": "Unger et al. 2005", "quote": "q", "source": UNGER}
    text = abstract([(c, [("f", _v(DIFFERS))], DIFFERS, "")], size)
    assert "at this run's size (60 discs, 23 R wide" in text
