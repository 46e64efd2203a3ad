"""The reproduction page ``results/index.html``: every sentence of the paper, section by section.

The claims table and the rendering are in :mod:`ncd.pages.claims`, the functions that judge
them in each figure's ``claims.py`` (:mod:`ncd.pages.registry`); a figure's page prints the
same :class:`~ncd.shared.verdict.Verdict` for the same claim, and each row links to that
block (``html/<figure>.html#claim-<id>``) and to the data files it read.  One row per
sentence: where several pages hold evidence, the row shows each page's number and one
verdict by the sentence's rule, under the sentence's criterion stated before the data (the
table's) and how each judging function applied it.  The page opens with an abstract
generated from the verdicts.  A claim no figure measures is a *not tested* row with the
reason; a missing file gives *not computed*, never a crash, so the page builds while
figures change.
"""
import csv
import hashlib
import html
from pathlib import Path

import yaml

from ncd.io.netcdf import git_commit, versions
from ncd.pages.claims import CLAIMS, criterion_of, criterion_texts, how_judged, sentence_verdict, verdicts
from ncd.pages.registry import JUDGES_BY_FIGURE
from ncd.pages.runscale import banner_html
from ncd.pages.runscale import counts as counts_of
from ncd.pages.runscale import label as run_label
from ncd.shared.verdict import BEYOND, CONSISTENT, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED

UNGER = "unger2005"      # the source of the findings judged beyond the paper (Unger, Kertész & Wolf 2005)
GENG = "geng2001"        # the construction-history experiments (Geng et al. 2001; Vanel et al. 1999)
# the sources of the findings judged beyond the paper, each in a section of its own
SOURCES = {UNGER: "Beyond the paper: Unger, Kertész & Wolf (2005)",
           GENG: "Beyond the paper: construction history at matched shape (Geng et al. 2001; Vanel et al. 1999)"}


def run_times(results, figure):
    """(jobs, summed seconds) of the benchmark files results/benchmarks/<figure>/*.tsv."""
    total, jobs = 0.0, 0
    for tsv in sorted((Path(results) / "benchmarks" / figure).glob("*.tsv")):
        with open(tsv) as f:
            rows = list(csv.DictReader(f, delimiter="\t"))
        if rows and "s" in rows[0]:
            total += float(rows[-1]["s"])
            jobs += 1
    return jobs, total


def config_digest(config):
    return hashlib.sha256(yaml.safe_dump(config, sort_keys=True).encode()).hexdigest()[:16]


def provenance_rows(config):

    v = versions()
    return [("commit", git_commit()), ("Python", v["python_version"]), ("numpy", v["numpy_version"]),
            ("numba", v["numba_version"]), ("snakemake", v["snakemake_version"]),
            ("config digest (SHA-256 of the merged config)", config_digest(config))]


CSS = """body{font:15px/1.45 system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;width:100%;margin:1em 0}th,td{border:1px solid #ccc;padding:.4em .6em;vertical-align:top}
th{background:#f2f2f2;text-align:left}blockquote{margin:0;font-style:italic}
.v-reproduced{background:#e6f4e6}.v-differs{background:#fde8e0}.v-beyond{background:#e6eefa}.v-consistent{background:#f4f1e0}
.v-not{background:#eee;color:#666}.abstract{background:#f7f7f7;border:1px solid #ddd;padding:.2em 1em}
img.thumb{width:180px;border:1px solid #ddd}.small{font-size:13px;color:#555}"""

SECTIONS = (("§1", "Introductory example"), ("§2", "Time-stepping computation"), ("§3", "Granular flow on a slope"),
            ("§4", "An equilibrium state"), ("§5", "The messages from history"), ("§6", "Conclusion"),
            *SOURCES.items())
VERDICT_ORDER = (REPRODUCED, DIFFERS, CONSISTENT, BEYOND, NOT_TESTED, NOT_COMPUTED)


def _verdict_class(v):
    return {REPRODUCED: "v-reproduced", DIFFERS: "v-differs", BEYOND: "v-beyond",
            CONSISTENT: "v-consistent"}.get(v, "v-not")


def section_of(claim):
    """The section a claim is filed under: the last paper section (§1–§6) its label names,
    or the section of another source's findings (a claim whose ``source`` is in :data:`SOURCES`)."""
    if claim.get("source") in SOURCES:
        return claim["source"]
    found = [sec for sec, _ in SECTIONS if sec in claim["section"]]
    return found[-1] if found else SECTIONS[0][0]


def claim_rows(results, claims=CLAIMS):
    """``[(claim, figure, Verdict)]``: each page's evidence for each claim."""
    return [(c, fig, v) for c in claims for fig, v in verdicts(c["id"], results, JUDGES_BY_FIGURE)]


def sentence_rows(results, claims=CLAIMS):
    """``[(claim, [(figure, Verdict)], verdict, rule text)]``: one row per sentence, its
    pages' evidence and the one verdict its rule gives (:func:`ncd.pages.claims.sentence_verdict`)."""
    out = []
    for c in claims:
        rows = verdicts(c["id"], results, JUDGES_BY_FIGURE)
        out.append((c, rows, *sentence_verdict(c, rows)))
    return out


def tally(sentences, source=None):
    """``{verdict: count}`` over the sentences of the paper (``source`` None) or of another
    source (``UNGER``): one count per sentence, whatever the number of pages judging it."""
    counts = {v: 0 for v in VERDICT_ORDER}
    for c, _, verdict, _ in sentences:
        if c.get("source") == source:
            counts[verdict] += 1
    return counts


def _short(quote, words=12):
    w = quote.split()
    return " ".join(w[:words]) + (" …" if len(w) > words else "")


def unger_size(config):
    """The size Figure 5's verdicts on Unger et al.'s findings come from, in words, beside
    theirs (200 discs, 42 R wide, a 28 R slice, 100 walk samples); empty without the section."""
    f = config.get("fig5_governing") or {}
    p, w = f.get("packings") or {}, f.get("walk") or {}
    if "n_discs" not in p:
        return ""
    return (f"{p['n_discs']} discs, {p.get('width_radii')} R wide, a {p.get('slice_radii')} R slice, {p.get('per_mu')} "
            f"packings at each of {p.get('n_mu')} μ, {w.get('samples')} walk samples per analysis; Unger et al.: "
            "200 discs, 42 R, a 28 R slice, 100 samples")


def abstract(sentences, size=""):
    """The findings first, generated from the verdicts: how many sentences reproduce, which
    differ and by what measured value, how many hold by construction or are not tested, the
    pairs of sentences whose verdicts pull apart (the table's ``see``) with both measured
    values, and Unger et al.'s findings at this run's size (``size``: :func:`unger_size`)."""
    e = html.escape
    counts = tally(sentences)
    by_id = {c["id"]: (c, rows, v) for c, rows, v, _ in sentences}
    parts = [f"Of the {sum(counts.values())} checkable sentences of the paper, {counts[REPRODUCED]} reproduce, "
             f"{counts[DIFFERS]} differ, {counts[CONSISTENT]} hold by construction (consistent: illustrated, not "
             f"tested), {counts[BEYOND]} are questions the paper leaves open (measured, not judged), "
             f"{counts[NOT_TESTED]} are not tested and {counts[NOT_COMPUTED]} were not computed in this run."]
    differ = [(c, rows) for c, rows, v, _ in sentences if v == DIFFERS and c.get("source") is None]
    if differ:
        items = "".join(f"<li><a href='#{e(c['id'])}'>{e(c['section'])}</a> “{e(_short(c['quote']))}”: "
                        + "; ".join(e(v.value) for _, v in rows if v.verdict == DIFFERS) + "</li>"
                        for c, rows in differ)
        parts.append(f"<b>What differs, and the measured reason</b>:<ul>{items}</ul>")
    pulls = []
    for c, rows, v, _ in sentences:
        for other in c.get("see", []):
            if other in by_id and by_id[other][2] != v and other not in [p for p, _ in pulls]:
                o, orows, ov = by_id[other]
                pulls.append((c["id"], f"<li><a href='#{e(c['id'])}'>{e(c['section'])}</a> ({e(v)}) and "
                                       f"<a href='#{e(other)}'>{e(o['section'])}</a> ({e(ov)}): "
                                       + " — ".join(e(r.value) for _, r in rows + orows) + "</li>"))
    if pulls:
        parts.append(f"<b>Verdicts that pull apart</b>, with what each measured:<ul>{''.join(p for _, p in pulls)}</ul>")
    unger = tally(sentences, UNGER)
    if sum(unger.values()):
        parts.append("Beyond the paper, the findings of Unger, Kertész &amp; Wolf at this run's size"
                     + (f" ({e(size)})" if size else "") + ": "
                     + ", ".join(f"{k} {e(v)}" for v, k in unger.items() if k) + ".")
    geng = [(c, rows) for c, rows, v, _ in sentences if c.get("source") == GENG]
    for c, rows in geng:
        parts.append(f"Beyond the paper, the construction-history contrast of Geng et al. and Vanel et al. "
                     f"(<a href='#{e(c['id'])}'>{e(c['section'])}</a>): "
                     + "; ".join(f"{e(v.verdict)}, {e(v.value)}" for _, v in rows) + ".")
    return "<div class='abstract'><p>" + "</p><p>".join(parts) + "</p></div>"


def _row(c, evidence, verdict, rule):
    """One table row: a sentence, each page's evidence, the one verdict and its rule."""
    e = html.escape
    where = "<br>".join(f"<a href='html/{fig}.html#{e(m.anchor)}'>{e(fig)}</a>" for fig, m in evidence if fig) or "—"
    several = len(evidence) > 1
    measured = "<br><br>".join((f"<b>{e(fig)}</b>: " if several else "") + e(m.value) + "<br>"
                               + "<br>".join(f"<a class='small' href='{e(d)}'>{e(d)}</a>" for d in m.data)
                               for fig, m in evidence)
    rule_text = f"<br><span class='small'><i>rule:</i> {e(rule)}</span>" if rule else ""
    return (f"<tr class='{_verdict_class(verdict)}' id='{e(c['id'])}'><td>{where}<br>"
            f"<span class='small'>{e(c['section'])}</span></td><td><blockquote>“{e(c['quote'])}”</blockquote></td>"
            f"<td>{measured}</td><td><b>{e(verdict)}</b>{rule_text}<br>{criterion_cell(c, evidence)}</td></tr>")


def criterion_cell(c, evidence):
    """The criterion of a row: the table's, stated before the data (one text, or each page's
    where the row has one per page), then how each judging function judged it where its own
    words add to that (:func:`ncd.pages.claims.how_judged`)."""
    e = html.escape
    texts = criterion_texts(c)
    stated = ("<br>".join(f"{e(f)}: {e(t)}" for f, t in texts.items()) if len(set(texts.values())) > 1
              else e(criterion_of(c)))
    how = [(fig, m, how_judged(criterion_of(c, fig), m)) for fig, m in evidence]
    how = [(f"{e(fig)} ({e(m.verdict)}): " if len(evidence) > 1 else "") + e(h) for fig, m, h in how if h]
    return (f"<span class='small'><b>Criterion (stated before the data):</b> {stated}</span>"
            + (f"<br><span class='small'><i>How it was judged:</i> {'<br>'.join(how)}</span>" if how else ""))


def build_page(results, figures, config, claims=CLAIMS):
    """The HTML text of the reproduction page for the run in ``results`` (a folder)."""
    results = Path(results)
    e = html.escape

    def thumb(fig):
        if not fig or not (results / "figures" / f"{fig}.png").exists():
            return ""
        return f'<a href="html/{fig}.html"><img class="thumb" src="figures/{fig}.png" alt="{fig}"></a>'

    sentences = sentence_rows(results, claims)
    body = []
    for sec, title in SECTIONS:
        rows = [_row(*s) for s in sentences if section_of(s[0]) == sec]
        if rows:
            what = "the finding" if sec in SOURCES else "the paper says"
            body.append(f"<h2>{'' if sec in SOURCES else e(sec) + ' '}{e(title)}</h2><table><tr><th>page</th>"
                        f"<th>{what}</th><th>measured in this run (data)</th><th>verdict (criterion)</th></tr>"
                        f"{''.join(rows)}</table>")
    figs = []
    total = 0.0
    for fig in figures:
        jobs, secs = run_times(results, fig)
        total += secs
        n_claims = sum(any(f == fig for f, _ in evidence) for _, evidence, _, _ in sentences)
        scale = "<br>".join(f"{e(k.split('.', 1)[1])} = {v}" for k, v in counts_of(config, fig)) or "—"
        figs.append(f"<tr><td><a href='html/{fig}.html'>{e(fig)}</a></td><td class='small'>{scale}</td>"
                    f"<td>{n_claims}</td><td>{jobs}</td><td>{secs:.1f}</td><td>{thumb(fig)}</td></tr>")
    prov = "".join(f"<tr><th>{e(k)}</th><td><code>{e(str(v))}</code></td></tr>" for k, v in provenance_rows(config))
    counts = tally(sentences)
    summary = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    return f"""<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">
<title>ncd: reproduction of Moreau (2005), claim by claim</title><style>{CSS}</style></head><body>
<h1>Indetermination in the numerical simulation of granular systems — reproduced claim by claim</h1>
{banner_html(config, figures)}
<p>J. J. Moreau, <i>Indetermination in the numerical simulation of granular systems</i>, Powders and Grains
2005 (<a href="https://hal.science/hal-01824602">hal-01824602</a>). Every checkable sentence of the paper has one row
({sum(counts.values())} sentences, table <code>ncd/pages/paper_claims.yaml</code>). Every number is read from this
run's data when the page is built, by the same function that writes the claim on its figure's page; the page link
goes to that paragraph, the data links to the files read. Each row states its criterion as written in the table before
the data (what is measured, over which set, the threshold and its reason) and, where its words differ, how the judging
function applied it.</p>
{abstract(sentences, unger_size(config))}
<p><b>Verdicts, one per sentence of the paper:</b> {e(summary)}. <span class="small">reproduced: the paper's
statement holds by the criterion given; differs: it does not; consistent: it holds by construction of the method or
is a definition (illustrated, not tested); beyond the paper: a measurement the paper could not make (an open
question or an exact set); not tested: no figure measures it (the reason is given). Where several pages hold
evidence, the row shows each page's number and one verdict by the stated rule.</span></p>
{''.join(body)}
<h2>Figures and run time</h2>
<p class="small">Run time: the sum of the wall times of the figure's jobs
(<code>results/benchmarks/&lt;figure&gt;/*.tsv</code>), {total:.0f} s in all; with <code>-j2</code> two jobs run at once.</p>
<table><tr><th>figure</th><th>size and realizations of this run ({e(run_label(config))})</th><th>claims</th>
<th>jobs</th><th>s</th><th></th></tr>{''.join(figs)}</table>
<h2>Provenance</h2><table>{prov}</table>
</body></html>
"""


def write_page(results, figures, config, path=None):
    path = Path(path or Path(results) / "index.html")
    path.write_text(build_page(results, figures, config), encoding="utf-8")
    return path
