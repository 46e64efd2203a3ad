"""The paper's claims measured on a run: one function per (claim, figure), used by both pages.

:data:`CLAIMS` is the table of every checkable sentence of Moreau (2005)
(``paper_claims.yaml``, one row per quoted sentence).  :data:`MEASURES` maps a claim id
to the functions that judge it on the data of a figure; each takes the ``results/``
folder and returns a :class:`~ncd.core.verdict.Verdict`.  A figure's page prints
:func:`claim_markdown` and the index page (:mod:`ncd.pages.report`) prints
:func:`evaluate` of the same function, so the two cannot disagree.  A claim no figure
measures is listed as *not tested* with the reason in :data:`UNTESTED_REASONS`.

Criteria follow the paper's wording: a "may" is judged over the cases it ranges over
(cuts, steps, runs), a statement in R^2κ is tested in R^2κ, a claim about usable step
sizes counts only accurate runs.  One name, unit and sign per quantity: the *dip depth*
is the flank pressure minus the pressure under the apex (> 0 a dip) in units of the mean
ground stress W/2L, on both Figure 4 pages.
"""
import math
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from ncd.core.scene import make_scene
from ncd.core.verdict import BEYOND, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED, Verdict
from ncd.dynamics.stepper import prepare_step, step
from ncd.figures import bank_claims as bank
from ncd.figures import equilibrium as fe
from ncd.figures import faces
from ncd.figures import governing_claims as unger
from ncd.figures.governing_summary import factor_table, line_counts
from ncd.figures.pile_exact import diameter
from ncd.solver.convergence import REST
from ncd.studies.stability_page import inaccurate

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


def anchor(claim_id):
    """The HTML id of a claim's block on its figure's page."""
    return f"claim-{claim_id}"


def _open(results, rel):
    path = Path(results) / rel
    if not path.exists():
        raise FileNotFoundError(f"{rel} absent")
    return xr.load_dataset(path)


def _pct(x):
    return f"{100 * x:.1f} %"


def _span(x, fmt):
    """``a–b`` of the range of ``x``, or ``a`` when both ends print the same."""
    lo, hi = format(np.min(x), fmt), format(np.max(x), fmt)
    return lo if lo == hi else f"{lo}–{hi}"


def _v(value, verdict, criterion, claim_id, *data):
    return Verdict(value, verdict, criterion, anchor(claim_id), tuple(data))


# --- §1, figure 1 -------------------------------------------------------------------------------

F1_ENS, F1_SWEEP, F1_EVOL = "fig1_wedged/ensemble.nc", "fig1_wedged/sweep.nc", "fig1_wedged/evolutions.nc"


def fig1_two_evolutions(results):
    ens = _open(results, F1_ENS)
    outcome, zero = ens.outcome.values, ens.zero_guess.values.astype(bool)
    falls_zero = np.mean(outcome[zero] == 0)
    wedged_rand, falls_rand = np.mean(outcome[~zero] == 1), np.mean(outcome[~zero] == 0)
    both = (outcome == 0).any() and (outcome == 1).any()
    return _v(f"zero guess: {_pct(falls_zero)} of {zero.sum()} runs fall; random guesses: "
              f"{_pct(wedged_rand)} of {(~zero).sum()} wedge, {_pct(falls_rand)} fall",
              REPRODUCED if both else DIFFERS, "both outcomes occur among converged runs of the same step",
              "s1-two-evolutions", F1_ENS)


def fig1_threshold(results):
    swp = _open(results, F1_SWEEP)
    gamma, frac = swp.gamma.values, swp.wedged_fraction.values
    beta = float(swp.attrs["threshold_gamma_deg"])
    below, above = frac[gamma < beta], frac[gamma > beta]
    ok = np.all(below == 0) and np.all(above > 0)
    first = gamma[frac > 0].min() if (frac > 0).any() else np.nan
    return _v(f"wedged fraction 0 at all {len(below)} angles γ < β = {beta:.1f}°, > 0 at "
              f"{np.sum(above > 0)} of {len(above)} angles γ > β (first at {first:.1f}°)",
              REPRODUCED if ok else DIFFERS, "no wedging for γ < β, wedging for every γ > β",
              "s1-wedging-threshold", F1_SWEEP)


def _wedged_on_segment(ens):
    wedged = ens.outcome.values == 1
    R, lo, hi = float(ens.attrs["radius"]), float(ens.attrs["I_y_bottom"]), float(ens.attrs["I_y_top"])
    ix, iy = ens.I_x.values[wedged], ens.I_y.values[wedged]
    on = (np.abs(ix) <= 1e-6 * R) & (iy >= lo - 1e-6 * R) & (iy <= hi + 1e-6 * R)
    return wedged, on, ix, iy, R, lo, hi


def fig1_segment(results):
    ens = _open(results, F1_ENS)
    wedged, on, ix, iy, R, lo, hi = _wedged_on_segment(ens)
    if not wedged.any():
        return _v("no wedged run", DIFFERS, "every wedged I on the closed-form vertical segment", "s1-segment", F1_ENS)
    return _v(f"{on.sum()} of {wedged.sum()} wedged I on the segment [{lo / R:.3f} R, {hi / R:.3f} R] "
              f"(largest |x_I| {np.abs(ix).max() / R:.1e} R)", REPRODUCED if on.all() else DIFFERS,
              "every wedged I within 10⁻⁶ R of the closed-form segment", "s1-segment", F1_ENS)


def fig1_undetermined(results):
    ens = _open(results, F1_ENS)
    wedged, on, ix, iy, R, lo, hi = _wedged_on_segment(ens)
    if wedged.sum() < 2:
        return _v(f"{wedged.sum()} wedged run(s)", DIFFERS, "wedged runs spread along the segment",
                  "s1-forces-undetermined", F1_ENS)
    cover = (iy.max() - iy.min()) / (hi - lo)
    return _v(f"the {wedged.sum()} wedged runs put I at {len(np.unique(np.round(iy / R, 6)))} distinct heights, "
              f"covering {_pct(cover)} of the segment", REPRODUCED if cover >= 0.5 else DIFFERS,
              "wedged runs of one step reach distinct force states over at least half the segment",
              "s1-forces-undetermined", F1_ENS)


def fig1_forces_as_state(results):
    ev = _open(results, F1_EVOL)
    names = [s.split(":")[0].strip() for s in str(ev.attrs["evolutions"]).split(";")]
    drop = ev.y.values[:, 0] - ev.y.values[:, -1]
    R = float(ev.attrs["radius"])
    zero, warm = names.index("zero_guess"), names.index("wedged_warm")
    ok = drop[zero] > R and abs(drop[warm]) < 1e-6 * R
    return _v(f"same position and velocity at t0: from the zero guess B falls {drop[zero] / R:.1f} R in "
              f"{float(ev.attrs['duration']):g} s; with the wedged contact forces carried from step to step it "
              f"moves {abs(drop[warm]) / R:.1e} R", REPRODUCED if ok else DIFFERS,
              "the contact forces at t0 alone decide between falling and staying wedged",
              "s1-forces-as-state", F1_EVOL)


def fig1_review_orders(results):
    ens = _open(results, F1_ENS)
    zero = ens.zero_guess.values.astype(bool) & ens.converged.values.astype(bool)
    kappa = ens.sizes["contact"]
    ends = np.unique(np.round(np.column_stack([ens.force_n.values[zero], ens.force_t.values[zero]]), 9), axis=0)
    bound = math.factorial(kappa - 1)
    return _v(f"κ = {kappa}: the {zero.sum()} converged zero-guess runs (both first-reviewed contacts) reach "
              f"{len(ends)} distinct solution(s), against at most (κ − 1)! = {bound}",
              REPRODUCED if len(ends) <= bound else DIFFERS, "distinct zero-guess limits ≤ (κ − 1)!",
              "s2-review-orders", F1_ENS)


# --- §2 -----------------------------------------------------------------------------------------

STAB = "stability/table.nc"


def stability_cd_md(results):
    tab = _open(results, STAB)
    method, ratio = tab.method.values.astype(str), tab.h_over_hcrit.values
    cd, md = method == "CD", method == "MD"
    bounded = cd & (tab.diverged.values == 0)
    accurate = bounded & ~inaccurate(tab)
    md_big = md & (ratio >= 2)
    md_unstable = md_big & (tab.stable.values == 0)
    usable = accurate & (ratio >= 2)
    ok = md_unstable.sum() == md_big.sum() and usable.any()
    return _v(f"CD bounded in {bounded.sum()} of {cd.sum()} runs, accurate in {accurate.sum()} (the others: "
              f"penetration > 0.1 r, tunnelling or the sweep budget reached); accurate CD runs at h ≥ 2 h_crit of "
              f"MD: {usable.sum()} (up to {ratio[usable].max() if usable.any() else float('nan'):.3g} h_crit); "
              f"MD unstable in {md_unstable.sum()} of {md_big.sum()} runs at h ≥ 2 h_crit",
              REPRODUCED if ok else DIFFERS,
              "accurate CD runs exist at steps where every MD run is unstable (h ≥ 2 h_crit)", "s2-stability", STAB)


def restitution(results):
    """A binary collision at e = 0.5 stepped once now (Newton's law: U_f = −e U_i), and the
    e = 1 chain of the stability study (energy kept; Newton's cradle would pass the whole
    speed to the last disc)."""
    tab = _open(results, STAB)
    e = 0.5
    scene = make_scene([[0.0, 0.0], [0.8, 0.0]], [0.5, 0.3], [1.0, 3.0], gravity=(0.0, 0.0),
                       vel=[[1.0, 0.0], [-0.5, 0.0]], e_n=e, mu=0.0)
    n = prepare_step(scene, 1e-3).contacts.normal[0]
    u_i = (scene.vel[0] - scene.vel[1]) @ n
    step(scene, 1e-3)
    ratio = float((scene.vel[0] - scene.vel[1]) @ n / u_i)
    chain = (tab.case.values.astype(str) == "e1_chain") & (tab.method.values.astype(str) == "CD")
    drift = float(np.max(np.abs(tab.energy_drift.values[chain]))) if chain.any() else float("nan")
    last = tab.observable.values[chain]
    ok = abs(ratio + e) < 1e-9 and chain.any() and drift < 1e-6
    return _v(f"binary collision, e = {e}: U_f/U_i = {ratio:.6f} (Newton: −{e}); multicontact e = 1 chain "
              f"({chain.sum()} CD runs): energy drift ≤ {drift:.1e}, last disc leaves at "
              f"{_span(last, '.2f')} of the striker's speed (Newton's cradle: 1)",
              REPRODUCED if ok else DIFFERS,
              "Newton's law in a binary collision; a multicontact impact handled with energy kept "
              "(not the sequence of binary collisions of Newton's cradle)", "s2-restitution", STAB)


def warm_accelerates_rest(results):
    ens = _open(results, "fig3_equilibrium/ensemble.nc")
    z, w = (np.median(fe.mode_subset(ens, m).sweeps.values) for m in ("zero", "warm"))
    return _v(f"equilibrium of Fig. 3 (N = 28 at rest, tol {float(ens.attrs['solver_tol']):g}): median {z:.0f} sweeps "
              f"from the zero guess, {w:.0f} warm-started ({z / w:.0f}× fewer)", REPRODUCED if z > 3 * w else DIFFERS,
              "the warm start needs at least three times fewer sweeps", "s2-warm-accelerates",
              "fig3_equilibrium/ensemble.nc")


def warm_accelerates_states(results):
    nl = _open(results, "error_vs_runtime/nlgs.nc").sel(criterion="residual")
    tight = float(nl.tol.where(nl.converged.all(("state", "init")), drop=True).min())
    r = nl.sweeps.sel(init="zero", tol=tight) / nl.sweeps.sel(init="warm", tol=tight)
    words = ", ".join(f"{s}: {float(v):.2g}" for s, v in zip(nl.state.values, r.values))
    return _v(f"plain NLGS, sweeps to a residual of {tight:g}, zero guess / warm start — {words} (slope: a flow down a "
              "slope like Figure 2's)",
              REPRODUCED if bool((r > 3).all()) else DIFFERS,
              "the warm start needs at least three times fewer sweeps on every state", "s2-warm-accelerates",
              "error_vs_runtime/nlgs.nc")


def warm_little(results, claim_id="s3-warm-no-dispersion"):
    """Judged at every tolerance where the zero-guess spread has settled (within 10 % of its
    value at the tightest tolerance): below that, both spreads are iteration error."""
    meas = _open(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    sp = meas.spread.sel(disc=grain)
    tols = np.sort(meas.tol.values)[::-1]
    zero, warm = sp.sel(init="zero", tol=tols).values, sp.sel(init="warm", tol=tols).values
    settled = np.abs(zero - zero[-1]) <= 0.1 * zero[-1]
    ok = settled.any() and np.all(warm[settled] < zero[settled] / 10)
    pairs = ", ".join(f"{t:g}: {z:.2g} / {w:.2g}" for t, z, w in zip(tols, zero, warm))
    return _v(f"grain {grain}, RMS spread of the acceleration (m/s²) zero guess / warm start at each tolerance — "
              f"{pairs}; the zero-guess spread has settled from tol {tols[settled][0]:g} on",
              REPRODUCED if ok else DIFFERS,
              "warm spread below a tenth of the zero-guess one at every tolerance where the latter has settled",
              claim_id, "fig2_slope/measures.nc")


def warm_little_s2(results):
    return warm_little(results, "s2-warm-little-indeterminacy")


def equilibrium_test(results):
    state = _open(results, "fig3_equilibrium/state.nc")
    proj = _open(results, "fig3_equilibrium/projection.nc")
    at_rest, dim = bool(state.attrs["at_rest"]), int(proj.attrs["dimension_AC"])
    ok = at_rest and dim >= 0
    return _v(f"one step from u_i = 0: |u_f| = {float(state.attrs['rest_max_velocity']):.1e} |g| h (at rest: "
              f"{at_rest}); the exact LP finds A ∩ C non-empty (dimension {dim})", REPRODUCED if ok else DIFFERS,
              "the one-step test and the exact feasibility of A ∩ C agree", "s2-equilibrium-test",
              "fig3_equilibrium/state.nc", "fig3_equilibrium/projection.nc")


# --- §3, figure 2 -------------------------------------------------------------------------------

def fig2_dispersion(results):
    meas = _open(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    sp = meas.spread.sel(disc=grain, init="zero")
    tight, loose = float(meas.tol.min()), float(meas.tol.max())
    z_tight, z_loose = float(sp.sel(tol=tight)), float(sp.sel(tol=loose))
    ok = z_tight > 0.5 * z_loose and z_tight > 0 and int(meas.attrs["n_solutions"]) >= 2
    return _v(f"grain {grain}: zero-guess RMS spread {z_loose:.3g} m/s² at tol {loose:g}, {z_tight:.3g} m/s² at tol "
              f"{tight:g}; {int(meas.attrs['n_solutions'])} distinct solutions (verdict of the page: "
              f"{meas.attrs['verdict']})", REPRODUCED if ok else DIFFERS,
              "a spread that does not shrink as the tolerance tightens, between distinct converged solutions",
              "s3-dispersion", "fig2_slope/measures.nc")


def fig2_line(results):
    meas = _open(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    ratio = float(meas.ratio.sel(init="zero", tol=float(meas.tol.min()), disc=grain))
    n_sol = int(meas.attrs["n_solutions"])
    why = ("one solution: no dispersion to shape" if n_sol < 2 else
           "two solutions: a line by construction, so this step cannot answer the question" if n_sol == 2
           else "more than two solutions")
    return _v(f"grain {grain}: minor/major principal spread {ratio:.1e}; {n_sol} distinct solutions ({why})",
              BEYOND, "an open question of the paper: measured, not judged", "s3-line", "fig2_slope/measures.nc")


def fig2_sticking(results):
    """Moreau's reason: at a sticking contact Coulomb's law leaves the force free in a cone,
    at a sliding one it fixes its direction.  Judged on the exact solutions of the step
    (the census): where do they differ?  And how the difference spreads from there."""
    census = _open(results, "fig2_slope/census.nc")
    meas = _open(results, "fig2_slope/measures.nc")
    if census.sizes["solution"] < 2 or "switch_distance" not in meas:
        return _v(f"the census finds {census.sizes['solution']} exact solution(s) at this step: no contact where "
                  "solutions differ", NOT_COMPUTED, "a \"may\": most contacts where the solutions differ stick in one "
                  "of them", "s3-sticking-determinant", "fig2_slope/census.nc")
    st = census.status.values[:, census.switching.values]
    stick = int(st.shape[0] and np.sum((st == 1).any(0)))
    n_sw = st.shape[1]
    dist = meas.switch_distance.values
    dmag = np.hypot(meas.delta_x.values, meas.delta_y.values)
    linked = dist >= 0
    near = float(np.median(dmag[linked & (dist <= 1)])) if (linked & (dist <= 1)).any() else float("nan")
    apart = float(np.median(dmag[~linked])) if (~linked).any() else float("nan")
    ok = n_sw > 0 and stick > n_sw / 2
    return _v(f"the {census.sizes['solution']} exact solutions of the step differ in status at {n_sw} contacts, "
              f"{stick} of which stick (zero sliding velocity) in one of them; the grain accelerations differ by "
              f"{near:.2g} m/s² (median) within one sticking link of a switching contact and by {apart:.2g} for "
              f"the {(~linked).sum()} grains not linked to one by sticking contacts",
              REPRODUCED if ok else DIFFERS,
              "a \"may\": most contacts where the solutions differ stick in one of them", "s3-sticking-determinant",
              "fig2_slope/census.nc", "fig2_slope/measures.nc")


# --- figure 5 (governing parameters) -------------------------------------------------------------

FLOWS = "fig5_governing/flows.nc"


def fig5_other_experiments(results):
    flows = _open(results, FLOWS)
    ind = flows.indeterminate.values
    known = ind >= 0
    none = [(ind[f][known[f]] == 0).all() and known[f].any() for f in range(flows.sizes["flow"])]
    frac = float(np.mean(ind[known] == 1))
    return _v(f"{sum(none)} of {flows.sizes['flow']} flows show no indeterminate scanned step; over all flows "
              f"{_pct(frac)} of the {known.sum()} steps of known outcome are indeterminate "
              f"({(~known).sum()} of unknown outcome left out)", REPRODUCED if any(none) else DIFFERS,
              "some flows of the same kind with no indeterminate step", "s3-other-experiments", FLOWS)


def fig5_governing_flows(results):
    flows = _open(results, FLOWS)
    t = factor_table(flows, "mu", "indeterminate")
    cells = ", ".join(f"μ = {v:g}: {_pct(m)}" for v, m, _, _ in t)
    return _v(f"fraction of indeterminate scanned flow steps among those of known outcome (mean over seeds): "
              f"{cells}", BEYOND, "two exact solutions or more at a scanned step (converged NLGS end points "
              "polished)", "s3-governing-parameters", FLOWS)


def fig5_governing_line(results):
    c = line_counts(_open(results, FLOWS))
    tc = c["tested"]
    return _v(f"{c['steps']} indeterminate steps: grain cloud a line at {c['rank'][1]}, an area at {c['rank'][2]}; "
              f"the one-degree-of-freedom cluster hypothesis holds at {tc['holds']} of the {tc['steps']} steps with "
              f"three solutions or more ({tc['line_and_predicted']} predicted lines; at two solutions a line is "
              "unavoidable)", BEYOND, "an open question of the paper: cloud rank against the rank of the solutions "
              "over the grain's cluster", "s3-line", FLOWS)


# --- §4, figure 3 -------------------------------------------------------------------------------

F3 = ("fig3_equilibrium/ensemble.nc", "fig3_equilibrium/projection.nc", "fig3_equilibrium/uniform.nc")


def _fig3_rows(results):
    proj = _open(results, F3[1])
    ens = _open(results, F3[0])
    uni = _open(results, F3[2])
    shown = [int(k) for k in np.atleast_1d(proj.attrs["displayed_order"])]
    return fe.cloud_measures(ens, proj, uni, shown), proj


def fig3_outlines(results):
    rows, _ = _fig3_rows(results)
    cov = {m: [r["coverage"] for r in rows if r["mode"] == m] for m in ("zero", "random", "uniform")}
    txt = "; ".join(f"{m}: {', '.join(_pct(c) for c in v)}" for m, v in cov.items() if v)
    ok = min(cov["zero"]) >= 0.5
    return _v(f"area of the cloud's convex hull / area of the exact projection (displayed contacts) — {txt}",
              REPRODUCED if ok else DIFFERS, "zero-guess clouds cover at least half of each exact projection",
              "s4-outlines", *F3)


def fig3_in_cones(results):
    ens, state = _open(results, F3[0]), _open(results, "fig3_equilibrium/state.nc")
    ok_run = ens.converged.values.astype(bool)
    rn, rt = ens.force_n.values[ok_run], ens.force_t.values[ok_run]
    scale = float(np.abs(rn).max())
    inside = (rn >= -1e-9 * scale) & (np.abs(rt) <= state.mu.values[None, :] * rn + 1e-9 * scale)
    worst = float(np.max(np.abs(rt) - state.mu.values[None, :] * rn) / scale)
    return _v(f"{inside.all(1).sum()} of {ok_run.sum()} converged runs have every contact force in its Coulomb "
              f"sector (largest excess {worst:.1e} of the largest force)", REPRODUCED if inside.all() else DIFFERS,
              "every force of every converged run in C_α within 10⁻⁹ of the force scale", "s4-in-cones",
              F3[0], "fig3_equilibrium/state.nc")


@lru_cache(maxsize=4)
def _face_summary(results):
    state = _open(results, "fig3_equilibrium/state.nc")
    ens, uni = _open(results, F3[0]), _open(results, F3[2])
    P = fe.polytope_of(state)
    modes = {m: np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)
             for m, ds in (("zero", fe.mode_subset(ens, "zero")), ("random", fe.mode_subset(ens, "random")),
                           ("uniform", uni))}
    return faces.face_summary(P, modes)


def fig3_boundary(results):
    s = _face_summary(str(results))
    z, r, u = s["zero"], s["random"], s["uniform"]
    frac = {m: 1 - d["interior"] / d["runs"] for m, d in s.items()}
    ok = frac["zero"] > frac["uniform"] and frac["random"] > frac["uniform"]
    return _v(f"in R^2κ (dim A ∩ C = {z['dimension']}): on a proper face of A ∩ C (its boundary) "
              f"{z['runs'] - z['interior']} of {z['runs']} zero-guess solutions, {r['runs'] - r['interior']} of "
              f"{r['runs']} random-guess ones, {u['runs'] - u['interior']} of {u['runs']} points of a uniform sample",
              REPRODUCED if ok else DIFFERS,
              "NLGS solutions lie on the boundary of A ∩ C more often than a uniform sample of A ∩ C (tested in "
              "R^2κ by the face holding each point)", "s4-denser-boundary", *F3, "fig3_equilibrium/state.nc")


def fig3_ghosts(results):
    s = _face_summary(str(results))
    r = s["random"]
    lo, med, hi = r["dims"]
    ok = r["interior"] < r["runs"] and lo < r["dimension"]
    return _v(f"random-guess solutions lie on faces of dimension {lo}–{hi} (median {med:g}) of the "
              f"{r['dimension']}-dimensional A ∩ C; {r['runs'] - r['interior']} of {r['runs']} on a proper face, "
              "whose projections draw the lines inside the clouds", REPRODUCED if ok else DIFFERS,
              "solutions concentrated on lower-dimensional faces (edges, vertices) of A ∩ C", "s4-ghost-images",
              *F3, "fig3_equilibrium/state.nc")


def fig3_dimension(results):
    proj = _open(results, F3[1])
    a, m = int(proj.attrs["dimension_A"]), int(proj.attrs["dimension_moreau"])
    N, kappa = int(proj.attrs["n_discs"]), int(proj.attrs["n_contacts"])
    rank = 2 * kappa - a
    return _v(f"N = {N}, κ = {kappa}: 2κ − 3N = {m}, measured dim A = 2κ − rank H = {a} (rank H = {rank}"
              f"{' < 3N' if rank < 3 * N else ''} = {3 * N})", REPRODUCED if a == m else DIFFERS,
              "dim A = 2κ − 3N (the 3N equations independent)", "s4-dimension-A", F3[1])


def fig3_exact(results):
    proj = _open(results, F3[1])
    return _v(f"κ = {proj.sizes['contact']} contacts, dim A ∩ C = {int(proj.attrs['dimension_AC'])}, "
              f"bounded = {bool(proj.attrs['bounded'])}; exact LP projections of every contact "
              f"({int(proj.attrs['n_lp_total'])} LPs)", BEYOND, "the exact set computed, not in the paper",
              "s4-force-set", F3[1])


# --- §5, figure 4 -------------------------------------------------------------------------------

F4 = ("fig4_pile/cuts.nc", "fig4_pile/ensemble.nc", "fig4_pile/exact.nc")


def _default_cut(cuts):
    kinds = [str(k) for k in cuts.kind.values]
    return kinds.index("default"), kinds


def _rest_cloud(cuts, ens, k):
    rest = ens.outcome.values == REST       # converged at rest: motion solutions are another outcome
    return np.column_stack([ens.cut_force_x.values[rest, k], ens.cut_force_y.values[rest, k]])


def fig4_parallel(results):
    cuts = _open(results, F4[0])
    k, _ = _default_cut(cuts)
    dev = float(cuts.history_deviation.values[k])
    return _v(f"history resultant across the default cut {float(cuts.history_angle.values[k]):.1f}° below the "
              f"horizontal, {dev:+.1f}° from the free surface's slope", REPRODUCED if abs(dev) <= 10 else DIFFERS,
              "within 10° of the free surface", "s5-parallel-to-surface", F4[0])


def fig4_cloud(results):
    cuts, ens = _open(results, F4[0]), _open(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if len(P) < 2:
        return _v(f"{len(P)} run(s) at rest: no cloud", DIFFERS, "a cloud of distinct resultants over runs at rest",
                  "s5-cloud", F4[1])
    n = len(np.unique(np.round(P / np.abs(P).max(), 6), axis=0))
    return _v(f"{len(P)} zero-guess runs at rest give {n} distinct resultants across the default cut, spanning "
              f"{diameter(P):.3g} N", REPRODUCED if n > 1 else DIFFERS,
              "distinct resultants over the runs at rest", "s5-cloud", F4[1])


def cut_pairs(cuts, d=None, rel=0.05):
    """Pairs (i, j) of scan cuts on the same flank whose positions differ by one mean
    diameter (within ``rel`` of it): "varying slightly the cut position"."""
    d = float(d or cuts.attrs["mean_diameter"])
    idx = np.flatnonzero(cuts.kind.values.astype(str) == "scan")
    x, o = cuts.cut_x.values, cuts.outer.values
    return [(i, j) for a, i in enumerate(idx) for j in idx[a + 1:]
            if o[i] == o[j] and abs(abs(x[i] - x[j]) - d) <= rel * d]


def fig4_cut_vs_cloud(results):
    """A "may" over cuts: the fraction of pairs of scan cuts one diameter apart whose
    history resultants differ by more than twice the default cut's cloud diameter."""
    cuts, ens = _open(results, F4[0]), _open(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if len(P) < 2:
        return _v(f"{len(P)} run(s) at rest: no cloud", NOT_COMPUTED, "—", "s5-cut-position", F4[1])
    diam = diameter(P)
    H = np.column_stack([cuts.history_fx.values, cuts.history_fy.values])
    pairs = cut_pairs(cuts)
    change = np.array([np.linalg.norm(H[i] - H[j]) for i, j in pairs])
    big2, big1 = float(np.mean(change > 2 * diam)), float(np.mean(change > diam))
    return _v(f"cloud diameter {diam:.3g} N over the {len(P)} runs at rest; over the {len(pairs)} pairs of scan cuts "
              f"one diameter apart the resultant changes by more than twice that at {_pct(big2)} of pairs, by more "
              f"than it at {_pct(big1)} (median change {np.median(change):.3g} N)",
              REPRODUCED if big2 > 0 else DIFFERS,
              "a \"may\" over cuts: some pairs of cuts one diameter apart change by more than twice the cloud",
              "s5-cut-position", F4[0], F4[1])


def fig4_contacts(results):
    cuts = _open(results, F4[0])
    k, _ = _default_cut(cuts)
    n = int(cuts.n_loaded.values[k])
    return _v(f"{n} loaded contacts across the default cut ({int(cuts.n_crossing.values[k])} crossing)",
              REPRODUCED if 5 <= n <= 20 else DIFFERS, "same order as the paper's 10 (5 to 20)", "s5-ten-contacts",
              F4[0])


def fig4_pressure_height(results):
    cuts = _open(results, F4[0])
    mid = 0.5 * (cuts.bin_lo.values + cuts.bin_hi.values)
    b = int(np.argmin(np.abs(mid)))
    p, w = float(cuts.history_pressure.values[b]), float(cuts.column_weight.values[b])
    loaded = cuts.column_weight.values > 0.5 * cuts.column_weight.values.max()
    dev = np.abs(cuts.history_pressure.values[loaded] / cuts.column_weight.values[loaded] - 1)
    ok = abs(p / w - 1) > 0.1
    return _v(f"under the apex the ground pressure is {p:.1f} N/m against a column weight of {w:.1f} N/m "
              f"({p / w:.0%}); over the {loaded.sum()} bins under more than half the apex column the ratio departs "
              f"from 1 by {np.median(dev):.0%} (median)", REPRODUCED if ok else DIFFERS,
              "the pressure under the apex differs from the weight of the column above it by more than 10 %",
              "s5-pressure-not-height", F4[0])


def fig4_dip(results):
    """The verdict of the fig4_pile page (:func:`ncd.scenes.pressure.dip_verdict`): a dip is
    called only when the history's dip depth exceeds the spread over analysis choices and
    the exact range over A ∩ C forces it."""
    ex = _open(results, F4[2])
    a = ex.attrs
    m = [str(c) for c in ex.choice.values].index(a["dip_main_choice"])
    depth, lo, hi = (float(ex[v].values[m]) for v in ("dip_history", "dip_min", "dip_max"))
    called = bool(a["dip_called"])
    return _v(f"dip depth (flank minus centre, > 0 a dip, units of the mean ground stress W/2L) of the history forces "
              f"({a['dip_main_choice']}): {depth:+.3f}; spread over the analysis choices "
              f"{float(a['dip_binning_spread']):.3f}; exact range over A ∩ C [{lo:+.3f}, {hi:+.3f}]: a dip "
              f"{a['dip_geometry']} by the geometry", REPRODUCED if called else DIFFERS,
              "a \"may\": a dip in this pile beyond the analysis-choice spread, forced by the geometry",
              "s5-dip", F4[2])


def fig4_geometry_enough(results):
    """"Whatever is the indeterminacy" judged on the exact set: the range of the resultant's
    angle over A ∩ C at the default cut, and the cuts where every admissible state arches."""
    cuts, ens, ex = (_open(results, f) for f in F4)
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    V = np.column_stack([ex.vertex_fx.values[k], ex.vertex_fy.values[k]])
    V = V[np.isfinite(V).all(1)]
    surf = float(cuts.surface_angle.values[k])
    lo, hi = float(ex.angle_min.values[k]), float(ex.angle_max.values[k])
    ok = abs(lo - surf) <= 10 and abs(hi - surf) <= 10
    hist = np.array([float(cuts.history_fx.values[k]), float(cuts.history_fy.values[k])])
    far = f"; the history resultant lies {np.linalg.norm(hist - P.mean(0)):.3g} N from its mean" if len(P) else ""
    exact = ex.exact.values.astype(bool)
    return _v(f"default cut: exact set of resultants {diameter(V):.3g} N across against a zero-guess cloud of "
              f"{diameter(P):.3g} N{far}; over A ∩ C the resultant's angle ranges over [{lo:.1f}°, {hi:.1f}°] below "
              f"the horizontal (free surface {surf:.1f}°); every admissible state arches at "
              f"{int(ex.all_arch.values[exact].sum())} of {exact.sum()} cuts", REPRODUCED if ok else DIFFERS,
              "\"whatever is the indeterminacy\": every admissible resultant at the default cut within 10° of the "
              "free surface", "s5-geometry-enough", *F4)


def fig4_reassuring(results):
    """"Not large enough to mask the feature": the cloud's angular width at the default cut
    against the angle between the free surface and the vertical (the direction of the
    force without arching)."""
    cuts, ens = _open(results, F4[0]), _open(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if not len(P):
        return _v("no run at rest", NOT_COMPUTED, "—", "s6-reassuring", F4[1])
    surf = float(cuts.surface_angle.values[k])
    dev = np.degrees(np.arctan2(-P[:, 1], np.abs(P[:, 0]))) - surf
    width, gap = float(dev.max() - dev.min()), 90.0 - surf
    return _v(f"the {len(P)} zero-guess runs at rest put the resultant {dev.min():+.1f}° to {dev.max():+.1f}° from "
              f"the free surface: a cloud {width:.1f}° wide, against {gap:.1f}° between the surface and the vertical "
              "(the exact set is judged in the §5 row on geometry)", REPRODUCED if width < gap / 10 else DIFFERS,
              "the NLGS cloud's angular width below a tenth of the angle between the free surface and the vertical",
              "s6-reassuring", *F4[:2])


def _history_analysis(results):
    """The ensemble analysis of fig4_history with the smallest pile size (the default 10^3)."""
    paths = sorted(Path(results).glob("fig4_history/analysis_n*.nc"), key=lambda q: int(q.stem.split("_n")[-1]))
    if not paths:
        raise FileNotFoundError("fig4_history/analysis_n*.nc absent")
    return xr.load_dataset(paths[0]), f"fig4_history/{paths[0].name}"


def fig4_history_dip(results):
    an, rel = _history_analysis(results)
    s = an.isel(kernel=0)
    p, r = s.sel(history="point"), s.sel(history="rain")
    lo, hi = float(p.dip_lo), float(p.dip_hi)
    return _v(f"dip depth of the mean profile (flank minus centre, > 0 a dip, units of the mean ground stress W/2L) "
              f"over {an.sizes['pile']} point-source piles {float(p.dip_mean):.3f} [{lo:.3f}, {hi:.3f}] "
              f"(rain {float(r.dip_mean):.3f}; difference p = {float(s.dip_diff_p):.2g})",
              REPRODUCED if lo > 0 else DIFFERS, "a \"may\" over piles: the 95 % bootstrap band over point-source "
              "piles of the dip depth above 0", "s5-dip", rel)


def fig4_history_arching(results):
    an, rel = _history_analysis(results)
    p = an.sel(history="point")
    med = float(p.cut_deviation.median())
    lo, hi = float(p.deviation_median_lo.min()), float(p.deviation_median_hi.max())
    return _v(f"cut resultant minus flank slope over {an.sizes['pile']} point-source piles: median {med:.1f}° "
              f"(bootstrap bands of the per-cut medians within [{lo:.1f}°, {hi:.1f}°])",
              REPRODUCED if abs(med) <= 10 else DIFFERS, "median deviation within 10° of the free surface",
              "s5-parallel-to-surface", rel)


# --- the table -------------------------------------------------------------------------------------

MEASURES = {
    "s1-two-evolutions": [("fig1_wedged", fig1_two_evolutions)],
    "s1-wedging-threshold": [("fig1_wedged", fig1_threshold)],
    "s1-forces-undetermined": [("fig1_wedged", fig1_undetermined)],
    "s1-segment": [("fig1_wedged", fig1_segment)],
    "s1-forces-as-state": [("fig1_wedged", fig1_forces_as_state)],
    "s2-stability": [("stability", stability_cd_md)],
    "s2-restitution": [("stability", restitution)],
    # (Figure 2's warm runs use local exact solves, so their sweeps do not measure plain NLGS: the
    # flow is judged on error_vs_runtime's slope state, where both starts run plain NLGS)
    "s2-warm-accelerates": [("fig3_equilibrium", warm_accelerates_rest), ("error_vs_runtime", warm_accelerates_states)],
    "s2-warm-little-indeterminacy": [("fig2_slope", warm_little_s2)],
    "s2-review-orders": [("fig1_wedged", fig1_review_orders)],
    "s2-equilibrium-test": [("fig3_equilibrium", equilibrium_test)],
    "s3-dispersion": [("fig2_slope", fig2_dispersion)],
    "s3-warm-no-dispersion": [("fig2_slope", warm_little)],
    "s3-other-experiments": [("fig5_governing", fig5_other_experiments)],
    "s3-governing-parameters": [("fig5_governing", fig5_governing_flows)],
    "s3-line": [("fig2_slope", fig2_line), ("fig5_governing", fig5_governing_line)],
    "s3-sticking-determinant": [("fig2_slope", fig2_sticking)],
    "s4-dimension-A": [("fig3_equilibrium", fig3_dimension)],
    "s4-outlines": [("fig3_equilibrium", fig3_outlines)],
    "s4-in-cones": [("fig3_equilibrium", fig3_in_cones)],
    "s4-ghost-images": [("fig3_equilibrium", fig3_ghosts)],
    "s4-denser-boundary": [("fig3_equilibrium", fig3_boundary)],
    "s4-force-set": [("fig3_equilibrium", fig3_exact)],
    "s5-pressure-not-height": [("fig4_pile", fig4_pressure_height)],
    "s5-dip": [("fig4_pile", fig4_dip), ("fig4_history", fig4_history_dip)],
    "s5-parallel-to-surface": [("fig4_pile", fig4_parallel), ("fig4_history", fig4_history_arching)],
    "s5-cloud": [("fig4_pile", fig4_cloud)],
    "s5-geometry-enough": [("fig4_pile", fig4_geometry_enough)],
    "s5-cut-position": [("fig4_pile", fig4_cut_vs_cloud)],
    "s5-ten-contacts": [("fig4_pile", fig4_contacts)],
    "s6-reassuring": [("fig4_pile", fig4_reassuring)],
    "s5-surface-parallel-vertical": [("fig4_bank", bank.claim_surface_force_vertical)],
    "s5-incipient-failure": [("fig4_bank", bank.claim_incipient_failure)],
    "s5-reciprocity": [("fig4_bank", bank.claim_reciprocity)],
    # Unger, Kertész & Wolf's findings, judged on their terms (their statistic and packings)
    "s4-unger": [("fig5_governing", unger.claim_unger_peak), ("fig5_governing", unger.claim_unger_vanishes),
                 ("fig5_governing", unger.claim_unger_control), ("fig5_governing", unger.claim_unger_centrality)],
}

UNTESTED_REASONS = {
    "s2-md-forces-state": "the MD baseline (ncd/dynamics/md.py) is used for stability only; no exploration of "
                          "the plurality of its force states is run",
    "s5-warm-construction": "the final step of a warm-started construction is not explored with random orders "
                            "from the warm guess (the zero-guess cloud is)",
    "s5-cylindric-cuts": "a 3-D statement (cylindric cuts of a conical pile); the 2-D analogue is the vertical "
                         "cut of §5, and the end of the fig4_bank page says what a plane pile can say of it",
    "s6-incremental-coulomb": "a statement about theory (an incremental Coulomb law), not about a computation",
}


def measures_of(claim_id):
    """``[(figure, function)]`` judging ``claim_id`` (empty: not tested)."""
    if claim_id not in CLAIM_BY_ID:
        raise KeyError(f"unknown claim id {claim_id!r}")
    return MEASURES.get(claim_id, [])


def evaluate(function, results, claim_id=""):
    """The claim's measurement, or ``not computed`` with the reason (missing file, variable, ...),
    so that a page builds while figures change."""
    try:
        return function(Path(results))
    except (FileNotFoundError, OSError, KeyError, IndexError, ValueError, AttributeError, TypeError) as exc:
        return Verdict(f"not computed ({type(exc).__name__}: {exc})", NOT_COMPUTED, "—", anchor(claim_id))


def verdicts(claim_id, results):
    """``[(figure, Verdict)]`` of a claim on this run; a claim no figure measures gives one
    ``not tested`` row (figure ``""``) with the reason."""
    rows = [(fig, evaluate(fn, results, claim_id)) for fig, fn in measures_of(claim_id)]
    if not rows:
        rows = [("", Verdict(UNTESTED_REASONS.get(claim_id, "not measured by any figure"), NOT_TESTED, "—",
                             anchor(claim_id)))]
    return rows


def claim_markdown(claim_id, results, figure=None):
    """The block a figure's page prints for one claim: the anchor the index links to, the
    quote, the measured value and the verdict with its criterion (the index's own words)."""
    claim = CLAIM_BY_ID[claim_id]
    rows = [(f, v) for f, v in verdicts(claim_id, results) if figure is None or f == figure]
    own = anchor(claim_id)
    body = "\n\n".join((f'<a id="{v.anchor}"></a>' if v.anchor and v.anchor != own else "")
                       + f"**{v.verdict}** — {v.value}. *Criterion:* {v.criterion}." for _, v in rows)
    return (f'<a id="{anchor(claim_id)}"></a>\n\n> {claim["section"]}: “{claim["quote"]}”\n\n{body}\n')
