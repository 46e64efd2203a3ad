"""The reproduction page ``results/index.html``: every claim of the paper, section by section.

The claims and the functions that judge them are in :mod:`ncd.pages.claims`; a figure's
page prints the same :class:`~ncd.shared.verdict.Verdict` for the same claim, and each row
links to that block (``html/<figure>.html#claim-<id>``) and to the data files it read.
A claim no figure measures is a *not tested* row with the reason; a missing file gives
*not computed*, never a crash, so the page builds while figures change.  Figures
without a claim are listed with their thumbnail and run time all the same.
"""
import csv
import hashlib
import html
from pathlib import Path

import yaml

from ncd.io.netcdf import git_commit, versions
from ncd.pages.claims import CLAIMS, verdicts
from ncd.pages.registry import JUDGES_BY_FIGURE
from ncd.shared.verdict import BEYOND, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED


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
.v-reproduced{background:#e6f4e6}.v-differs{background:#fde8e0}.v-beyond{background:#e6eefa}.v-not{background:#eee;color:#666}
img.thumb{width:180px;border:1px solid #ddd}.small{font-size:13px;color:#555}"""

SECTIONS = (("§1", "Introductory example"), ("§2", "Time-stepping computation"), ("§3", "Granular flow on a slope"),
            ("§4", "An equilibrium state"), ("§5", "The messages from history"), ("§6", "Conclusion"))
VERDICT_ORDER = (REPRODUCED, DIFFERS, BEYOND, NOT_TESTED, NOT_COMPUTED)


def _verdict_class(v):
    return {REPRODUCED: "v-reproduced", DIFFERS: "v-differs", BEYOND: "v-beyond"}.get(v, "v-not")


def section_of(claim):
    """The paper section (§1–§6) a claim is filed under: the last one its label names."""
    found = [sec for sec, _ in SECTIONS if sec in claim["section"]]
    return found[-1] if found else SECTIONS[0][0]


def claim_rows(results, claims=CLAIMS):
    """``[(claim, figure, Verdict)]``: one row per claim and figure judging it."""
    return [(c, fig, v) for c in claims for fig, v in verdicts(c["id"], results, JUDGES_BY_FIGURE)]


def build_page(results, figures, config, claims=CLAIMS):
    """The HTML text of the reproduction page for the run in ``results`` (a folder)."""
    results = Path(results)
    e = html.escape

    def thumb(fig):
        if not fig or not (results / "figures" / f"{fig}.png").exists():
            return ""
        return f'<a href="html/{fig}.html"><img class="thumb" src="figures/{fig}.png" alt="{fig}"></a>'

    measured = claim_rows(results, claims)
    body = []
    for sec, title in SECTIONS:
        rows = []
        for c, fig, m in measured:
            if section_of(c) != sec:
                continue
            where = (f"<a href='html/{fig}.html#{e(m.anchor)}'>{e(fig)}</a>" if fig else "—")
            data = "<br>".join(f"<a class='small' href='{e(d)}'>{e(d)}</a>" for d in m.data)
            rows.append(f"<tr class='{_verdict_class(m.verdict)}' id='{e(c['id'])}'><td>{where}<br>"
                        f"<span class='small'>{e(c['section'])}</span></td>"
                        f"<td><blockquote>“{e(c['quote'])}”</blockquote></td><td>{e(m.value)}<br>{data}</td>"
                        f"<td><b>{e(m.verdict)}</b><br><span class='small'>{e(m.criterion)}</span></td>"
                        f"<td>{thumb(fig)}</td></tr>")
        if rows:
            body.append(f"<h2>{e(sec)} {e(title)}</h2><table><tr><th>page</th><th>the paper says</th>"
                        f"<th>measured in this run (data)</th><th>verdict (criterion)</th><th></th></tr>"
                        f"{''.join(rows)}</table>")
    figs = []
    total = 0.0
    for fig in figures:
        jobs, secs = run_times(results, fig)
        total += secs
        n_claims = sum(f == fig for _, f, _ in measured)
        figs.append(f"<tr><td><a href='html/{fig}.html'>{e(fig)}</a></td><td>{n_claims}</td><td>{jobs}</td>"
                    f"<td>{secs:.1f}</td><td>{thumb(fig)}</td></tr>")
    prov = "".join(f"<tr><th>{e(k)}</th><td><code>{e(str(v))}</code></td></tr>" for k, v in provenance_rows(config))
    counts = {v: 0 for v in VERDICT_ORDER}
    for _, _, m in measured:
        counts[m.verdict] += 1
    summary = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    return f"""<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">
<title>ncd: reproduction of Moreau (2005), claim by claim</title><style>{CSS}</style></head><body>
<h1>Indetermination in the numerical simulation of granular systems — reproduced claim by claim</h1>
<p>J. J. Moreau, <i>Indetermination in the numerical simulation of granular systems</i>, Powders and Grains
2005 (<a href="https://hal.science/hal-01824602">hal-01824602</a>). Every checkable sentence of the paper has a row
({len(claims)} sentences, table <code>ncd/pages/paper_claims.yaml</code>). Every number is read from this run's data
when the page is built, by the same function that writes the claim on its figure's page; the page link goes to that
paragraph, the data links to the files read.</p>
<p><b>Verdicts:</b> {e(summary)}. <span class="small">reproduced: the paper's statement holds by the criterion
given; differs: it does not; beyond the paper: a measurement the paper could not make (an open question or an exact
set); not tested: no figure measures it (the reason is given).</span></p>
{''.join(body)}
<h2>Figures and run time</h2>
<p class="small">Run time: the sum of the wall times of the figure's jobs
(<code>results/benchmarks/&lt;figure&gt;/*.tsv</code>), {total:.0f} s in all; with <code>-j2</code> two jobs run at once.</p>
<table><tr><th>figure</th><th>claims</th><th>jobs</th><th>s</th><th></th></tr>{''.join(figs)}</table>
<h2>Provenance</h2><table>{prov}</table>
</body></html>
"""


def write_page(results, figures, config, path=None):
    path = Path(path or Path(results) / "index.html")
    path.write_text(build_page(results, figures, config), encoding="utf-8")
    return path
