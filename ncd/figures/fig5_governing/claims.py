"""Figure 5: Unger, Kertész & Wolf's findings, measured on ``packings.nc`` and judged.

Each ``claim_unger_*`` takes the results folder and returns a
:class:`ncd.shared.verdict.Verdict` under its claim's anchor (``unger-peak``,
``unger-vanishes``, ``unger-control``, ``unger-centrality``; Moreau's citation of them is
``s4-unger``), so that the page and the index page print the same verdict.  The measures
behind them (:func:`peak_test`, :func:`slope_band`, :func:`vanishing`, :func:`control_trend`,
:func:`centrality_summary`) are bootstrapped over the packings at each mu.  The series
compared is ``plates`` (built at mu), analysed by ``eta_walk`` (their statistic on their
sampling) unless a claim says otherwise.
"""
from pathlib import Path

import numpy as np
import xarray as xr
from scipy import stats

from ncd.figures.fig5_governing.measure import eta_table, mixed_only
from ncd.figures.fig5_governing.summary import fraction_table, line_counts
from ncd.figures.fig5_governing.unger import eta_u
from ncd.shared.verdict import (
    BEYOND,
    CONSISTENT,
    DIFFERS,
    NOT_COMPUTED,
    NOT_TESTED,
    REPRODUCED,
    judged,
    open_data,
    pct,
    span,
)

DATA = "fig5_governing/packings.nc"
PEAK_MU = 0.1              # Unger et al.: maximum near mu = 0.1
Z_ISOSTATIC = 4.0          # frictionless discs, 2-D
Z_FRICTIONAL = 3.0         # isostatic for mu -> infinity, 2-D
Z_TOL = 0.3                # z "still frictionless": at most three tenths of the way from 4 to 3
SLOPE_TOL = 0.5            # eta ∝ mu: slope band inside 1 ± 0.5, half-way to constant (0) and ∝ mu² (2)
SMALL_MU_POINTS = 3        # the smallest mu of the grid with eta > 0: "small mu" (a decade by default)
N_BOOT = 2000


def _boot_means(ds, var, kind, n_boot=N_BOOT, seed=0):
    """``(mus, means, boots)``: per mu of series ``kind`` the mean of ``var`` over its packings
    and ``n_boot`` means over resamples of those packings (columns: mu)."""
    rng = np.random.default_rng(seed)
    sel = ds.kind.values == kind
    mus, vals = [], []
    for i in np.unique(ds.mu_index.values[sel]):
        rows = sel & (ds.mu_index.values == i)
        v = ds[var].values[rows]
        mus.append(float(ds.mu.values[rows][0]))
        vals.append(v[np.isfinite(v)])
    means = np.array([v.mean() if len(v) else np.nan for v in vals])
    boots = np.column_stack([rng.choice(v, (n_boot, len(v))).mean(axis=1) if len(v) else np.full(n_boot, np.nan)
                             for v in vals]) if vals else np.zeros((n_boot, 0))
    return np.array(mus), means, boots


def peak(ds, var="eta_walk", kind=0, n_boot=N_BOOT, seed=0):
    """``(mu of the largest mean, 2.5 %, 97.5 % of that mu over bootstrap resamples of the
    packings at each mu)``: where the curve peaks, with a band over packings."""
    t = peak_test(ds, var, kind, n_boot, seed)
    return t["mu"], t["lo"], t["hi"]


def peak_test(ds, var="eta_walk", kind=0, n_boot=N_BOOT, seed=0):
    """The peak of the mean of ``var`` against mu, bootstrapped over the packings at each mu.

    Keys: ``mu`` (argmax of the means), ``lo``/``hi`` (2.5 % / 97.5 % of the argmax over the
    resamples, grid points), ``step`` (grid step in decades), ``ends`` (the argmax is interior
    and its mean exceeds both ends' beyond noise: the 2.5 % point of the resampled difference
    is above 0), ``neighbours`` (the same against its two grid neighbours), ``resolved`` (the
    argmax band lies within one grid step of the argmax on each side), ``near`` (the argmax
    within one grid step of 0.1), ``compatible`` (a grid point within one step of 0.1 lies in
    the argmax band)."""
    mus, means, boots = _boot_means(ds, var, kind, n_boot, seed)
    ok = np.isfinite(means)
    mus, means, boots = mus[ok], means[ok], boots[:, ok]
    nan = dict(mu=np.nan, lo=np.nan, hi=np.nan, step=np.nan, ends=False, neighbours=False, resolved=False,
               near=False, compatible=False, means=means, mus=mus)
    if len(mus) < 3:
        return nan
    i, n = int(np.argmax(means)), len(mus)
    step = float(np.mean(np.diff(np.log10(mus))))
    tol = 1.0 + 1e-6

    def above(j):
        return bool(np.quantile(boots[:, i] - boots[:, j], 0.025) > 0)

    interior = 0 < i < n - 1
    at = mus[np.argmax(boots, axis=1)]
    lo, hi = float(np.quantile(at, 0.025, method="lower")), float(np.quantile(at, 0.975, method="higher"))
    window = mus[np.abs(np.log10(mus / PEAK_MU)) <= step * tol]
    return dict(mu=float(mus[i]), lo=lo, hi=hi, step=step, mus=mus, means=means,
                ends=interior and above(0) and above(n - 1),
                neighbours=interior and above(i - 1) and above(i + 1),
                resolved=bool(np.log10(hi / mus[i]) <= step * tol and np.log10(mus[i] / lo) <= step * tol),
                near=bool(abs(np.log10(mus[i] / PEAK_MU)) <= step * tol),
                compatible=bool(((window >= lo) & (window <= hi)).any()))


def _small_mu(ds, var, kind, points):
    t = eta_table(ds, var, kind)
    return t[np.isfinite(t[:, 1]) & (t[:, 1] > 0)][:points]


def small_mu_slope(ds, var="eta_walk", kind=0, points=SMALL_MU_POINTS):
    """Least-squares slope of log mean eta against log mu over the ``points`` smallest mu
    with a positive mean (Unger et al.: 1)."""
    t = _small_mu(ds, var, kind, points)
    if len(t) < 2:
        return np.nan
    return float(np.polyfit(np.log(t[:, 0]), np.log(t[:, 1]), 1)[0])


def slope_band(ds, var="eta_walk", kind=0, points=SMALL_MU_POINTS, n_boot=N_BOOT, seed=0):
    """``(slope, 2.5 %, 97.5 %)``: :func:`small_mu_slope` and its band over resamples of the
    packings at each of those mu (a resample with a zero mean there counts as an unbounded
    slope: the band then stays open on that side)."""
    t = _small_mu(ds, var, kind, points)
    if len(t) < 2:
        return np.nan, np.nan, np.nan
    mus, _, boots = _boot_means(ds, var, kind, n_boot, seed)
    cols = [int(np.argmin(np.abs(mus - m))) for m in t[:, 0]]
    b = boots[:, cols]
    x = np.log(t[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        slopes = np.polyfit(x, np.log(np.where(b > 0, b, 1.0)).T, 1)[0]
    zero = (b <= 0).any(axis=1)
    slopes[zero & (b[:, 0] <= 0)] = np.inf       # nothing at the smallest mu: steeper than any slope
    slopes[zero & (b[:, 0] > 0)] = -np.inf       # nothing above it: a fall
    return (small_mu_slope(ds, var, kind, points), float(np.quantile(slopes, 0.025, method="lower")),
            float(np.quantile(slopes, 0.975, method="higher")))


def vanishing(ds, var="eta_walk", kind=0):
    """``(mu_min, mean eta at mu_min / largest mean eta)``: small when eta -> 0 as mu -> 0."""
    t = eta_table(ds, var, kind)
    if not (np.nan_to_num(t[:, 1]) > 0).any():
        return np.nan, np.nan
    return float(t[0, 0]), float(t[0, 1] / np.nanmax(t[:, 1]))


def control_trend(ds, var="eta_walk"):
    """Spearman rank correlation of mean eta against mu in the control series, and the
    number of mu steps where the mean falls."""
    t = eta_table(ds, var, 1)
    t = t[np.isfinite(t[:, 1])]
    if len(t) < 3:
        return np.nan, 0
    return float(stats.spearmanr(t[:, 0], t[:, 1])[0]), int((np.diff(t[:, 1]) < 0).sum())


def centrality_summary(ds, kind=0):
    """Over packings with a uniform sample that mixed and dim(A ∩ C) > 0 (series ``kind``): how many, in how many the
    history state is closer to the centre than the mean uniform sample, and the median
    fraction of uniform samples closer than it."""
    sel = np.isfinite(ds.history_distance.values) & (ds.dim_AC_rank.values > 0)
    if kind is not None:
        sel &= ds.kind.values == kind
    closer = ds.history_distance.values[sel] < ds.uniform_distance.values[sel]
    rank = ds.history_rank.values[sel]
    return int(sel.sum()), int(closer.sum()), float(np.median(rank)) if sel.any() else np.nan


def walk_settling(ds):
    """Per analysis with eta_U > 0 on the walk: |eta_U over the first half of the accepted
    samples / eta_U over all - 1|; returns (median, largest, count)."""
    out = []
    for j in np.nonzero(np.nan_to_num(ds.eta_walk.values) > 0)[0]:
        f = walk_forces(ds, j)
        if len(f) >= 6:
            out.append(abs(eta_u(f[: len(f) // 2]) / eta_u(f) - 1.0))
    return (float(np.median(out)), float(np.max(out)), len(out)) if out else (np.nan, np.nan, 0)


def walk_forces(ds, j, count=None):
    """Accepted random-walk states of analysis ``j`` (samples, contacts, 2), over its first
    ``count`` rounds (all by default), the contact padding left out."""
    stop = None if count is None else count + 1
    ok = ds.walk_point.values[j, :stop] == 1
    k = int(ds.n_contacts[j])
    return np.stack([ds.walk_n.values[j, :stop][ok][:, :k], ds.walk_t.values[j, :stop][ok][:, :k]], axis=-1)


def walk_eta_at(ds, j, count):
    """eta_U of analysis ``j`` over its first ``count`` walk rounds (accepted samples only; 0 on a
    determinate slice, as in :func:`ncd.figures.fig5_governing.measure.analyse`)."""
    if int(ds.dim_AC_rank[j]) == 0:
        return 0.0
    f = walk_forces(ds, j, count)
    return eta_u(f) if len(f) > 1 else np.nan


def mean_settling(ds, kind=0):
    """Largest ``|mean eta_U over half the walk rounds / mean over all - 1|`` over the mu of
    series ``kind`` with a positive mean: the walk's convergence in the quantity the verdicts
    use (means over packings), not packing by packing."""
    rounds = ds.sizes["sample"] - 1
    sel = ds.kind.values == kind
    worst = 0.0
    for i in np.unique(ds.mu_index.values[sel]):
        rows = np.nonzero(sel & (ds.mu_index.values == i))[0]
        half = np.nanmean([walk_eta_at(ds, j, rounds // 2) for j in rows])
        full = np.nanmean([walk_eta_at(ds, j, rounds) for j in rows])
        if full > 0:
            worst = max(worst, abs(half / full - 1.0))
    return float(worst)


def _open(results):
    path = Path(results) / DATA
    return mixed_only(xr.load_dataset(path)) if path.exists() else None


def _missing(claim_id):
    return judged("packings.nc not computed", NOT_COMPUTED, "", claim_id, DATA)


def _too_few(ds, claim_id):
    """None, or the verdict of a plates series with fewer than 2 packings at some mu: a band
    over one packing has no width and would measure nothing."""
    counts = eta_table(ds, "eta_walk", 0)[:, 3]
    if len(counts) and counts.min() >= 2:
        return None
    return judged(f"{int(counts.min()) if len(counts) else 0} packing(s) at some μ: no band over packings in this run",
                  NOT_TESTED, "needs 2 packings or more at each μ (bootstrap over packings)", claim_id, DATA)


def _flat(ds, kind, claim_id):
    """None, or the verdict of a series whose every slice is determinate (nothing to compare)."""
    if (np.nan_to_num(ds.eta_walk.values[ds.kind.values == kind]) > 0).any():
        return None
    return judged("every analysed slice of this series is determinate (dim(A ∩ C) = 0, η_U = 0): no curve to "
                  "compare in this run", NOT_TESTED, "needs indeterminate slices", claim_id, DATA)


def claim_unger_peak(results):
    """Unger et al.: eta_U is not monotonous in mu, with its maximum near mu = 0.1.

    An interior maximum beyond noise (the argmax's mean above both ends' beyond the bootstrap
    band of the difference) whose position is resolved (the argmax band within one grid step of
    it) and near 0.1 (within one grid step) reproduces it; no interior maximum, or a resolved one
    elsewhere, or an unresolved one whose band holds no grid point near 0.1, differs; an
    interior maximum whose band is too wide but holds a point near 0.1 leaves the position
    (what the sentence is about) not tested at this size."""
    ds = _open(results)
    if ds is None:
        return _missing("unger-peak")
    if (flat := _flat(ds, 0, "unger-peak") or _too_few(ds, "unger-peak")) is not None:
        return flat
    t = peak_test(ds)
    if not np.isfinite(t["mu"]):
        return judged("fewer than 3 values of μ with η_U", NOT_TESTED, "needs 3 values of μ or more", "unger-peak",
                      DATA)
    if not t["ends"]:
        verdict, why = DIFFERS, "no interior maximum beyond noise"
    elif t["resolved"]:
        verdict, why = (REPRODUCED, "resolved, near 0.1") if t["near"] else (DIFFERS, "resolved, not near 0.1")
    elif t["compatible"]:
        verdict, why = NOT_TESTED, "an interior maximum, its position unresolved at this size"
    else:
        verdict, why = DIFFERS, "an interior maximum, its band holding no grid point near 0.1"
    grid = f"{t['mus'][0]:.3g}–{t['mus'][-1]:.3g}"
    return judged(f"η_U (their statistic, their random walk) is largest at μ = {t['mu']:.3g} (95 % bootstrap band of "
                  f"the argmax over packings {t['lo']:.3g}–{t['hi']:.3g}; grid {grid}, step {t['step']:.2f} decade); "
                  f"above both ends beyond noise: {'yes' if t['ends'] else 'no'}, above both grid neighbours: "
                  f"{'yes' if t['neighbours'] else 'no'}: {why}; Unger et al.: near 0.1",
                  verdict, "an interior maximum (mean η_U at the argmax above both ends beyond the 95 % bootstrap "
                  "band of the difference, packings resampled at each μ) whose argmax band lies within one grid "
                  "step of it (resolved) and which lies within one grid step of 0.1 (the grid's resolution); "
                  "unresolved with a point near 0.1 in its band: not tested", "unger-peak", DATA)


def claim_unger_vanishes(results):
    """Unger et al.: eta_U -> 0 as mu -> 0 with eta_U ∝ mu, z still at its frictionless value.

    eta_U ∝ mu is eta_U / mu constant over the smallest mu: the log-log slope's bootstrap band
    must contain 1 and lie inside 1 ± 0.5 (half-way to a constant eta, slope 0, and to
    eta ∝ mu², slope 2); a band excluding 1 differs, a band holding 1 but wider leaves the
    power not tested at this size."""
    ds = _open(results)
    if ds is None:
        return _missing("unger-vanishes")
    if (flat := _flat(ds, 0, "unger-vanishes") or _too_few(ds, "unger-vanishes")) is not None:
        return flat
    mu0, ratio = vanishing(ds)
    slope, lo, hi = slope_band(ds)
    z0 = eta_table(ds, "z", 0)[0, 1]
    if not np.isfinite(slope):
        return judged(f"fewer than two μ with η_U > 0 at the small-μ end (η_U at μ = {mu0:.3g} is {ratio:.2g} of "
                      f"its largest value; z = {z0:.2f} there)", NOT_TESTED, "needs a small-μ slope",
                      "unger-vanishes", DATA)
    pts = _small_mu(ds, "eta_walk", 0, SMALL_MU_POINTS)
    r = pts[:, 1] / pts[:, 0]
    others = ratio < 0.05 and abs(z0 - Z_ISOSTATIC) <= Z_TOL
    has_one, narrow = lo <= 1.0 <= hi, 1.0 - SLOPE_TOL <= lo and hi <= 1.0 + SLOPE_TOL
    verdict = (REPRODUCED if others and has_one and narrow else
               NOT_TESTED if others and has_one else DIFFERS)
    return judged(f"at μ = {mu0:.3g} η_U is {ratio:.2g} of its largest value; over μ = {pts[0, 0]:.3g}–"
                  f"{pts[-1, 0]:.3g} the log-log slope is {slope:.2f} (95 % bootstrap band over packings "
                  f"{lo:.2f}–{hi:.2f}; η_U/μ from {r.min():.3g} to {r.max():.3g}); z = {z0:.2f} at μ = {mu0:.3g} "
                  "(isostatic: 4 frictionless, 3 for μ → ∞)", verdict,
                  f"η_U(μ_min) below 5 % of its maximum; over the {SMALL_MU_POINTS} smallest μ the slope's 95 % "
                  f"band holds 1 and lies inside 1 ± {SLOPE_TOL} (half-way to a constant η, 0, and η ∝ μ², 2; a band "
                  f"holding 1 but wider: not tested); z within {Z_TOL} of 4 (at most 30 % of the way to 3)",
                  "unger-vanishes", DATA)


def claim_unger_control(results):
    """Unger et al.'s control (a frictionless packing, friction switched on for the sampling):
    eta_U rises with mu.  Measured, not judged: with the contacts fixed, raising mu only widens
    every Coulomb cone, so the sets A ∩ C are nested and a rise is near-automatic (only the
    sampler's noise can make eta_U fall); what the series carries is the contrast with the
    packings built at mu, whose contact network thins as mu grows."""
    ds = _open(results)
    if ds is None or not (ds.kind.values == 1).any():
        return _missing("unger-control")
    if (flat := _flat(ds, 1, "unger-control")) is not None:
        return flat
    rho, falls = control_trend(ds)
    rho_u, falls_u = control_trend(ds, "eta_uniform")
    if not np.isfinite(rho):
        return judged("fewer than 3 values of μ with a walk that moved in the control series", NOT_TESTED,
                      "needs η_U of the walk at 3 values of μ or more", "unger-control", DATA)
    uni = f"; uniform sample ρ = {rho_u:.2f}, {falls_u} falls" if np.isfinite(rho_u) else ""
    c, p = eta_table(ds, "eta_walk", 1), eta_table(ds, "eta_walk", 0)
    zc, zp = eta_table(ds, "z", 1)[:, 1], eta_table(ds, "z", 0)[:, 1]
    c, p = c[np.isfinite(c[:, 1])], p[np.isfinite(p[:, 1])]
    rise = c[-1, 1] / c[0, 1] if c[0, 1] > 0 else np.inf
    fall = (f"η_U at μ = {p[-1, 0]:.3g} is {pct(p[-1, 1] / np.max(p[:, 1]))} of its largest mean"
            if len(p) and np.max(p[:, 1]) > 0 else "every slice determinate")
    return judged(f"control series (built frictionless, z = {span(zc[np.isfinite(zc)], '.2f')} at every μ): "
                  f"η_U of the walk from {c[0, 1]:.2g} at μ = {c[0, 0]:.3g} to {c[-1, 1]:.2g} at μ = {c[-1, 0]:.3g} "
                  f"(×{rise:.3g}; Spearman ρ = {rho:.2f}, {falls} falls between neighbouring μ{uni}); built at μ (z {zp[0]:.2f} → {zp[-1]:.2f}): {fall}", BEYOND,
                  "measured, not judged: at fixed contacts a larger μ only widens the cones, the sets are nested "
                  "and a rise is near-automatic; the contrast with the series built at μ is the content",
                  "unger-control", DATA)


def claim_unger_centrality(results):
    """Unger et al.: the history force state lies closer to the centre of A ∩ C than random samples."""
    ds = _open(results)
    if ds is None:
        return _missing("unger-centrality")
    n, closer, rank = centrality_summary(ds)
    if n == 0:
        return judged("no indeterminate built-at-μ slice whose uniform chains agree in this run", NOT_TESTED,
                      "needs a mixed uniform sample of an indeterminate slice", "unger-centrality", DATA)
    ok = closer >= 0.8 * n
    return judged(f"history state closer to the centre than the mean uniform sample in {closer} of {n} "
                  f"indeterminate packings (median fraction of uniform samples closer than it: {rank:.2f})",
                  REPRODUCED if ok else DIFFERS, "closer in at least 80 % of the packings with dim(A ∩ C) > 0 (a "
                  "typical-case finding: a few exceptions allowed, while a state placed at random in the set "
                  "would be closer in about half)", "unger-centrality", DATA)


UNGER_CLAIMS = {"unger-peak": claim_unger_peak, "unger-vanishes": claim_unger_vanishes,
                "unger-control": claim_unger_control, "unger-centrality": claim_unger_centrality}


def claim_unger_citation(results):
    """Moreau's pointer to Unger et al.: a citation, which no data can contradict (consistent);
    the value says where their findings are judged and what this run gives (read from
    ``packings.nc``: without it the row is not computed, as every row of a run not made)."""
    open_data(results, DATA)
    got = {k: f(results).verdict for k, f in UNGER_CLAIMS.items()}
    return judged("a pointer to Unger, Kertész & Wolf (PRL 94, 178001, 2005; arXiv 2004): rigid discs with Coulomb "
                  "friction in equilibrium, the set A ∩ C sampled statistically (their η_U over a random walk), "
                  "as in Figure 3 (Moreau: 28 discs under gravity; theirs: 200 discs compressed between plates, "
                  "no gravity); their findings, judged on their terms in this run: "
                  + ", ".join(f"{k} {v}" for k, v in got.items()), CONSISTENT,
                  "a citation: no data can make it false; the four findings it points to are judged in their own "
                  "rows", "s4-unger", DATA)


# --- the slope flows of Figure 2 across parameters (§3) ---

FLOWS = "fig5_governing/flows.nc"


def fig5_other_experiments(results):
    """"In other numerical experiments of the same sort, no indetermination was visible": an
    existence claim over flows of Figure 2's kind; one flow whose scanned steps of known outcome
    are all determinate suffices, and every flow having an indeterminate step makes it differ."""
    flows = open_data(results, FLOWS)
    ind = flows.indeterminate.values
    known = ind >= 0
    none = [(ind[f][known[f]] == 0).all() and known[f].any() for f in range(flows.sizes["flow"])]
    frac = float(np.mean(ind[known] == 1)) if known.any() else np.nan
    return judged(f"{sum(none)} of {flows.sizes['flow']} flows show no indeterminate scanned step; over all flows "
                  f"{pct(frac)} of the {known.sum()} steps of known outcome are indeterminate "
                  f"({(~known).sum()} of unknown outcome left out)", REPRODUCED if any(none) else DIFFERS,
                  "some flow of the same kind with no indeterminate step among its scanned steps of known outcome "
                  "(an existence claim over other experiments: one such flow suffices)", "s3-other-experiments",
                  FLOWS)


def fig5_governing_flows(results):
    flows = open_data(results, FLOWS)
    t = fraction_table(flows, "mu", "indeterminate")
    cells = ", ".join(f"μ = {v:g}: {pct(f)} ({int(k)} of {int(n)} steps, 95 % Wilson {pct(lo)}–{pct(hi)})"
                      for v, f, lo, hi, k, n, _ in t)
    return judged(f"fraction of indeterminate scanned flow steps among those of known outcome (seeds pooled): "
                  f"{cells}", BEYOND, "two exact solutions or more at a scanned step (converged NLGS end points "
                  "polished)", "s3-governing-parameters", FLOWS)


def fig5_governing_line(results):
    c = line_counts(open_data(results, FLOWS))
    tc = c["tested"]
    return judged(f"{c['steps']} indeterminate steps: grain cloud a line at {c['rank'][1]}, an area at {c['rank'][2]}; "
              f"the one-degree-of-freedom cluster hypothesis holds at {tc['holds']} of the {tc['steps']} steps with "
              f"three solutions or more ({tc['line_and_predicted']} predicted lines; at two solutions a line is "
              "unavoidable)", BEYOND, "an open question of the paper: cloud rank against the rank of the solutions "
              "over the grain's cluster", "s3-line", FLOWS)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them);
# Moreau's citation of Unger et al. (s4-unger) is a pointer; each of Unger, Kertész & Wolf's
# findings has its own row (unger-*), judged on their terms (their statistic and packings)
JUDGES = {
    "s3-other-experiments": (fig5_other_experiments,),
    "s3-governing-parameters": (fig5_governing_flows,),
    "s3-line": (fig5_governing_line,),
    "s4-unger": (claim_unger_citation,),
    **{claim_id: (f,) for claim_id, f in UNGER_CLAIMS.items()},
}


__all__ = ["walk_settling", "walk_forces", "walk_eta_at", "mean_settling", "peak", "peak_test", "small_mu_slope",
           "slope_band", "vanishing", "control_trend", "centrality_summary", "claim_unger_peak",
           "claim_unger_vanishes", "claim_unger_control", "claim_unger_centrality", "claim_unger_citation",
           "fig5_other_experiments", "fig5_governing_flows", "fig5_governing_line", "PEAK_MU", "Z_ISOSTATIC",
           "Z_FRICTIONAL", "Z_TOL", "SLOPE_TOL", "SMALL_MU_POINTS", "UNGER_CLAIMS", "JUDGES"]
