"""The reproduction page ``results/index.html``: the paper's claims, one row each.

Each claim is a quotation of Moreau (2005) and a small function that reads one known
variable of the run's data and returns the measured value, the verdict
(``reproduced``, ``differs``, ``beyond the paper``) and the criterion used.  A missing
file or variable gives ``not computed`` with the reason, never a crash, so that the
page builds while figures change.  Figures without a claim (and new figures) are
listed with their thumbnail and run time all the same.
"""
import csv
import hashlib
import html
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import xarray as xr
import yaml

from ncd.figures import equilibrium as fe
from ncd.figures.governing_summary import factor_table, line_counts
from ncd.io.netcdf import git_commit, versions
from ncd.solver.convergence import REST

REPRODUCED, DIFFERS, BEYOND, NOT_COMPUTED = "reproduced", "differs", "beyond the paper", "not computed"


@dataclass
class Measured:
    value: str
    verdict: str
    criterion: str


@dataclass
class Claim:
    figure: str
    section: str
    quote: str
    measure: Callable[[Path], Measured]


def _open(results, rel):
    path = Path(results) / rel
    if not path.exists():
        raise FileNotFoundError(f"{rel} absent")
    return xr.load_dataset(path)


def _pct(x):
    return f"{100 * x:.1f} %"


# --- figure 1 -----------------------------------------------------------------------------------

def fig1_two_evolutions(results):
    ens = _open(results, "fig1_wedged/ensemble.nc")
    outcome, zero = ens.outcome.values, ens.zero_guess.values.astype(bool)
    falls_zero = np.mean(outcome[zero] == 0)
    wedged_rand, falls_rand = np.mean(outcome[~zero] == 1), np.mean(outcome[~zero] == 0)
    both = (outcome == 0).any() and (outcome == 1).any()
    return Measured(f"zero guess: {_pct(falls_zero)} of {zero.sum()} runs fall; random guesses: "
                    f"{_pct(wedged_rand)} of {(~zero).sum()} wedge, {_pct(falls_rand)} fall",
                    REPRODUCED if both else DIFFERS, "both outcomes occur among converged runs")


def fig1_segment(results):
    ens = _open(results, "fig1_wedged/ensemble.nc")
    wedged = ens.outcome.values == 1
    if not wedged.any():
        return Measured("no wedged run", DIFFERS, "every wedged I on the closed-form vertical segment")
    R, lo, hi = float(ens.attrs["radius"]), float(ens.attrs["I_y_bottom"]), float(ens.attrs["I_y_top"])
    ix, iy = ens.I_x.values[wedged], ens.I_y.values[wedged]
    on = (np.abs(ix) <= 1e-6 * R) & (iy >= lo - 1e-6 * R) & (iy <= hi + 1e-6 * R)
    cover = (iy.max() - iy.min()) / (hi - lo)
    return Measured(f"{on.sum()} of {wedged.sum()} wedged I on the segment [{lo / R:.3f} R, {hi / R:.3f} R] "
                    f"(largest |x_I| {np.abs(ix).max() / R:.1e} R), covering {_pct(cover)} of it",
                    REPRODUCED if on.all() else DIFFERS,
                    "every wedged I within 10⁻⁶ R of the closed-form segment")


def fig1_threshold(results):
    swp = _open(results, "fig1_wedged/sweep.nc")
    gamma, frac = swp.gamma.values, swp.wedged_fraction.values
    beta = float(swp.attrs["threshold_gamma_deg"])
    below, above = frac[gamma < beta], frac[gamma > beta]
    ok = np.all(below == 0) and np.all(above > 0)
    first = gamma[frac > 0].min() if (frac > 0).any() else np.nan
    return Measured(f"wedged fraction 0 at all {len(below)} angles γ < β = {beta:.1f}°, > 0 at "
                    f"{np.sum(above > 0)} of {len(above)} angles γ > β (first at {first:.1f}°)",
                    REPRODUCED if ok else DIFFERS, "no wedging for γ < β, wedging for every γ > β")


# --- section 2 ----------------------------------------------------------------------------------

def stability_cd_md(results):
    tab = _open(results, "stability/table.nc")
    method, ratio = tab.method.values.astype(str), tab.h_over_hcrit.values
    cd, md = method == "CD", (method == "MD") & (ratio >= 2)
    cd_bounded = np.sum(tab.diverged.values[cd] == 0)
    md_unstable = np.sum(tab.stable.values[md] == 0)
    ok = cd_bounded == cd.sum() and md_unstable == md.sum()
    return Measured(f"CD bounded in {cd_bounded} of {cd.sum()} runs (h up to {ratio[cd].max():.3g} h_crit of MD); "
                    f"MD unstable in {md_unstable} of {md.sum()} runs at h ≥ 2 h_crit",
                    REPRODUCED if ok else DIFFERS, "every CD run bounded, every MD run at h ≥ 2 h_crit unstable")


def _grain_spreads(results):
    meas = _open(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    sp = meas.spread.sel(disc=grain)
    tight, loose = float(meas.tol.min()), float(meas.tol.max())
    return meas, grain, sp, tight, loose


def warm_start_little(results):
    meas, grain, sp, tight, _ = _grain_spreads(results)
    zero, warm = float(sp.sel(init="zero", tol=tight)), float(sp.sel(init="warm", tol=tight))
    return Measured(f"grain {grain} at tol {tight:g}: spread {zero:.3g} m/s² from the zero guess, "
                    f"{warm:.2g} m/s² warm-started",
                    REPRODUCED if warm < zero / 10 else DIFFERS, "warm spread below a tenth of the zero-guess one")


def fig2_dispersion(results):
    meas, grain, sp, tight, loose = _grain_spreads(results)
    z_tight, z_loose = float(sp.sel(init="zero", tol=tight)), float(sp.sel(init="zero", tol=loose))
    ok = z_tight > 0.5 * z_loose and z_tight > 0
    return Measured(f"grain {grain}: zero-guess spread {z_loose:.3g} m/s² at tol {loose:g}, {z_tight:.3g} m/s² "
                    f"at tol {tight:g}", REPRODUCED if ok else DIFFERS,
                    "a spread that does not shrink as the tolerance tightens (not iteration error)")


def fig2_line(results):
    meas, grain, _, tight, _ = _grain_spreads(results)
    ratio = float(meas.ratio.sel(init="zero", tol=tight, disc=grain))
    extra = f"; {int(meas.attrs['n_solutions'])} distinct solutions" if "n_solutions" in meas.attrs else ""
    return Measured(f"minor/major principal spread {ratio:.1e}{extra}", REPRODUCED if ratio < 0.05 else DIFFERS,
                    "minor axis below 5 % of the major one")


# --- figure 3 -----------------------------------------------------------------------------------

def _fig3_rows(results):

    proj = _open(results, "fig3_equilibrium/projection.nc")
    ens = _open(results, "fig3_equilibrium/ensemble.nc")
    uni = _open(results, "fig3_equilibrium/uniform.nc")
    shown = [int(k) for k in np.atleast_1d(proj.attrs["displayed_order"])]
    return fe.cloud_measures(ens, proj, uni, shown), proj


def fig3_outlines(results):
    rows, _ = _fig3_rows(results)
    cov = {m: [r["coverage"] for r in rows if r["mode"] == m] for m in ("zero", "random", "uniform")}
    txt = "; ".join(f"{m}: {', '.join(_pct(c) for c in v)}" for m, v in cov.items() if v)
    ok = min(cov["zero"]) >= 0.5
    return Measured(f"coverage of the exact projections (displayed contacts) — {txt}",
                    REPRODUCED if ok else DIFFERS, "zero-guess clouds cover at least half of each exact projection")


def fig3_boundary(results):
    rows, _ = _fig3_rows(results)
    contacts = sorted({r["contact"] for r in rows})
    near = {(r["contact"], r["mode"]): r["near_boundary"] for r in rows}
    denser = [k for k in contacts if near[(k, "zero")] > near[(k, "uniform")]]
    txt = "; ".join(f"contact {k}: NLGS zero guess {_pct(near[(k, 'zero')])}, uniform {_pct(near[(k, 'uniform')])}"
                    for k in contacts)
    return Measured(f"points within 5 % of √area of the boundary — {txt}",
                    REPRODUCED if len(denser) == len(contacts) else DIFFERS,
                    "at every displayed contact, NLGS points nearer the boundary than a uniform sample of A ∩ C")


def fig3_exact(results):
    proj = _open(results, "fig3_equilibrium/projection.nc")
    return Measured(f"κ = {proj.sizes['contact']} contacts, dim A ∩ C = {int(proj.attrs['dimension_AC'])}, "
                    f"bounded = {bool(proj.attrs['bounded'])}; exact LP projections "
                    f"({int(proj.attrs['n_lp_total'])} LPs)", BEYOND, "exact set computed, not in the paper")


# --- figure 4 -----------------------------------------------------------------------------------

def _default_cut(cuts):
    kinds = [str(k) for k in cuts.kind.values]
    return kinds.index("default"), kinds


def fig4_parallel(results):
    cuts = _open(results, "fig4_pile/cuts.nc")
    k, _ = _default_cut(cuts)
    dev = float(cuts.history_deviation.values[k])
    return Measured(f"resultant {float(cuts.history_angle.values[k]):.1f}° below the horizontal, "
                    f"{dev:+.1f}° from the free surface's slope", REPRODUCED if abs(dev) <= 10 else DIFFERS,
                    "within 10° of the free surface")


def fig4_cut_vs_cloud(results):
    cuts, ens = _open(results, "fig4_pile/cuts.nc"), _open(results, "fig4_pile/ensemble.nc")
    k, kinds = _default_cut(cuts)
    rest = ens.outcome.values == REST       # converged at rest: motion solutions are another outcome
    P = np.column_stack([ens.cut_force_x.values[rest, k], ens.cut_force_y.values[rest, k]])
    if len(P) < 2:
        return Measured(f"{len(P)} run(s) at rest: no cloud", NOT_COMPUTED, "—")
    diam = float(np.max(np.hypot(*(P[:, None] - P[None]).transpose(2, 0, 1))))
    H = np.column_stack([cuts.history_fx.values, cuts.history_fy.values])
    moves = [float(np.linalg.norm(H[kinds.index(m)] - H[k])) for m in ("minus", "plus") if m in kinds]
    ok = min(moves) > 2 * diam
    return Measured(f"cloud diameter {diam:.3g} N over the {len(P)} runs at rest; moving the cut by one diameter "
                    f"changes the resultant by {' and '.join(f'{m:.3g}' for m in moves)} N",
                    REPRODUCED if ok else DIFFERS, "change of the resultant more than twice the cloud's diameter")


def fig4_contacts(results):
    cuts = _open(results, "fig4_pile/cuts.nc")
    k, _ = _default_cut(cuts)
    n = int(cuts.n_loaded.values[k])
    return Measured(f"{n} loaded contacts across the default cut ({int(cuts.n_crossing.values[k])} crossing)",
                    REPRODUCED if 5 <= n <= 20 else DIFFERS, "same order as the paper's 10 (5 to 20)")


def fig4_dip(results):
    """The verdict of the fig4_pile page (:func:`ncd.scenes.pressure.dip_verdict`): a dip is
    called only when the history's depth exceeds the spread over analysis choices and the
    exact range over A ∩ C forces it."""
    ex = _open(results, "fig4_pile/exact.nc")
    a = ex.attrs
    m = [str(c) for c in ex.choice.values].index(a["dip_main_choice"])
    depth, lo, hi = (float(ex[v].values[m]) for v in ("depth_history", "depth_min", "depth_max"))
    called = bool(a["dip_called"])
    return Measured(f"history forces ({a['dip_main_choice']}): dip depth {depth:.3g} N/m, spread over the "
                    f"analysis choices {float(a['dip_binning_spread']):.3g} N/m, exact range over A ∩ C "
                    f"[{lo:.3g}, {hi:.3g}] N/m: a dip {a['dip_geometry']} by the geometry, "
                    f"{'called' if called else 'not called'}",
                    REPRODUCED if called else DIFFERS,
                    "a dip (depth < 0) beyond the analysis-choice spread, forced by the geometry")


def _history_analysis(results):
    """The ensemble analysis of fig4_history with the smallest pile size (the default 10^3)."""
    paths = sorted(Path(results).glob("fig4_history/analysis_n*.nc"), key=lambda q: int(q.stem.split("_n")[-1]))
    if not paths:
        raise FileNotFoundError("fig4_history/analysis_n*.nc absent")
    return xr.load_dataset(paths[0])


def fig4_history_dip(results):
    an = _history_analysis(results)
    s = an.isel(kernel=0)
    p, r = s.sel(history="point"), s.sel(history="rain")
    lo, hi = float(p.dip_lo), float(p.dip_hi)
    return Measured(f"dip of the mean profile over {an.sizes['pile']} point-source piles {float(p.dip_mean):.3f} "
                    f"[{lo:.3f}, {hi:.3f}] (rain {float(r.dip_mean):.3f}; difference p = {float(s.dip_diff_p):.2g})",
                    REPRODUCED if lo > 0 else DIFFERS,
                    "95 % basic bootstrap band over piles of the point-source dip depth above 0")


def fig4_history_arching(results):
    an = _history_analysis(results)
    p = an.sel(history="point")
    med = float(p.cut_deviation.median())
    lo, hi = float(p.deviation_median_lo.min()), float(p.deviation_median_hi.max())
    return Measured(f"cut resultant minus flank slope over {an.sizes['pile']} point-source piles: median {med:.1f}° "
                    f"(bootstrap bands of the per-cut medians within [{lo:.1f}°, {hi:.1f}°])",
                    REPRODUCED if abs(med) <= 10 else DIFFERS, "median deviation within 10° of the free surface")


# --- figure 5 (beyond the paper) ----------------------------------------------------------------

def fig5_governing_flows(results):
    flows = _open(results, "fig5_governing/flows.nc")
    t = factor_table(flows, "mu", "indeterminate")
    cells = ", ".join(f"μ = {v:g}: {_pct(m)}" for v, m, _, _ in t)
    return Measured(f"fraction of indeterminate scanned flow steps (mean over seeds) {cells}", BEYOND,
                    "two exact solutions or more at a scanned step (converged NLGS end points polished)")


def fig5_governing_line(results):
    c = line_counts(_open(results, "fig5_governing/flows.nc"))
    tc = c["tested"]
    return Measured(f"{c['steps']} indeterminate steps: grain cloud a line at {c['rank'][1]}, an area at "
                    f"{c['rank'][2]}; one-degree-of-freedom cluster hypothesis holds at {tc['holds']} of the "
                    f"{tc['steps']} steps with three solutions or more ({tc['line_and_predicted']} predicted "
                    f"lines; at two solutions a line is unavoidable)", BEYOND,
                    "cloud rank against the rank of the solutions over the grain's cluster")


CLAIMS = [
    Claim("fig1_wedged", "§1, Fig. 1", "a possible evolution consists in B losing contact and falling freely. "
          "But, if the friction angle γ is large enough, B may also remain wedged.", fig1_two_evolutions),
    Claim("fig1_wedged", "§1, Fig. 1", "Any position of I on some vertical segment corresponds to contact forces "
          "values balancing gravity and compatible with Coulomb friction.", fig1_segment),
    Claim("fig1_wedged", "§1", "if the friction angle γ is large enough, B may also remain wedged", fig1_threshold),
    Claim("stability", "§2", "such an implicit character secures numerical stability, allowing one to use "
          "considerably larger step-lengths than in MD methods.", stability_cd_md),
    Claim("fig2_slope", "§2–3", "if the same exploration is performed with the contact forces of antecedent step "
          "taken as initial guess, almost no dispersion is visible.", warm_start_little),
    Claim("fig2_slope", "§3, Fig. 2", "The acceleration vector of a grain center is affected by a dispersion shown "
          "on the figure.", fig2_dispersion),
    Claim("fig2_slope", "§3", "explain why the dispersion produces a line, not an extended cloud.", fig2_line),
    Claim("fig3_equilibrium", "§4, Fig. 3", "The resulting clouds provide outlines of the projections of A ∩ C.",
          fig3_outlines),
    Claim("fig3_equilibrium", "§4", "in R^2κ the points are a little denser in the vicinity of the boundary of "
          "A ∩ C.", fig3_boundary),
    Claim("fig3_equilibrium", "§4", "the set of the possible values of contact forces is similarly investigated.",
          fig3_exact),
    Claim("fig4_pile", "§5, Fig. 4", "The vector obtained, approximately parallel to the free surface, confirms the "
          "arching trend of force transmission throughout the lateral bank.", fig4_parallel),
    Claim("fig4_pile", "§5", "varying slightly the cut position may produce changes in transmitted force of "
          "definitely larger amplitude than the above indetermination.", fig4_cut_vs_cloud),
    Claim("fig4_pile", "§5", "in the example shown only 10 contacts are involved in the force transmission across "
          "the segment.", fig4_contacts),
    Claim("fig4_pile", "§5", "A local minimum of pressure may even be found at the vertical of the apex.",
          fig4_dip),
    Claim("fig4_history", "§5", "A local minimum of pressure may even be found at the vertical of the apex.",
          fig4_history_dip),
    Claim("fig4_history", "§5", "The vector obtained, approximately parallel to the free surface, confirms the "
          "arching trend of force transmission throughout the lateral bank.", fig4_history_arching),
    Claim("fig5_governing", "§3", "Further study is thus needed to discover the governing parameters",
          fig5_governing_flows),
    Claim("fig5_governing", "§3", "and to explain why the dispersion produces a line", fig5_governing_line),
]


def evaluate(claim, results):
    """The claim's measurement, or ``not computed`` with the reason (missing file, variable, ...)."""
    try:
        return claim.measure(Path(results))
    except (FileNotFoundError, OSError, KeyError, IndexError, ValueError, AttributeError, TypeError) as exc:
        return Measured(f"not computed ({type(exc).__name__}: {exc})", NOT_COMPUTED, "—")


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


def _verdict_class(v):
    return {REPRODUCED: "v-reproduced", DIFFERS: "v-differs", BEYOND: "v-beyond"}.get(v, "v-not")


def build_page(results, figures, config, claims=CLAIMS):
    """The HTML text of the reproduction page for the run in ``results`` (a folder)."""
    results = Path(results)
    e = html.escape

    def thumb(fig):
        if not (results / "figures" / f"{fig}.png").exists():
            return "<span class='small'>no figure</span>"
        return f'<a href="html/{fig}.html"><img class="thumb" src="figures/{fig}.png" alt="{fig}"></a>'

    measured = [(c, evaluate(c, results)) for c in claims]
    rows = []
    for c, m in measured:
        rows.append(f"<tr class='{_verdict_class(m.verdict)}'><td><a href='html/{c.figure}.html'>{e(c.figure)}</a>"
                    f"<br><span class='small'>{e(c.section)}</span></td><td><blockquote>“{e(c.quote)}”</blockquote></td>"
                    f"<td>{e(m.value)}</td><td><b>{e(m.verdict)}</b><br><span class='small'>{e(m.criterion)}</span>"
                    f"</td><td>{thumb(c.figure)}</td></tr>")
    figs = []
    total = 0.0
    for fig in figures:
        jobs, secs = run_times(results, fig)
        total += secs
        n_claims = sum(c.figure == fig for c in claims)
        figs.append(f"<tr><td><a href='html/{fig}.html'>{e(fig)}</a></td><td>{n_claims}</td><td>{jobs}</td>"
                    f"<td>{secs:.1f}</td><td>{thumb(fig)}</td></tr>")
    prov = "".join(f"<tr><th>{e(k)}</th><td><code>{e(str(v))}</code></td></tr>" for k, v in provenance_rows(config))
    counts = {v: 0 for v in (REPRODUCED, DIFFERS, BEYOND, NOT_COMPUTED)}
    for _, m in measured:
        counts[m.verdict] += 1
    summary = ", ".join(f"{n} {v}" for v, n in counts.items() if n)
    return f"""<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">
<title>ncd: reproduction of Moreau (2005), claim by claim</title><style>{CSS}</style></head><body>
<h1>Indetermination in the numerical simulation of granular systems — reproduced claim by claim</h1>
<p>J. J. Moreau, <i>Indetermination in the numerical simulation of granular systems</i>, Powders and Grains
2005 (hal-01824602). Every number below is read from this run's data (<code>results/&lt;figure&gt;/*.nc</code>)
when the page is built; each figure's page says how it was computed.</p>
<p><b>Claims:</b> {e(summary)}.</p>
<table><tr><th>figure</th><th>the paper says</th><th>measured in this run</th><th>verdict (criterion)</th>
<th>figure</th></tr>{''.join(rows)}</table>
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
