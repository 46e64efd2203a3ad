"""Figure 5: Unger, Kertész & Wolf's findings, measured on ``packings.nc`` and judged.

Each ``claim_unger_*`` takes the results folder and returns a
:class:`ncd.shared.verdict.Verdict` (value: a sentence of the data; anchor: the section of
the figure's page that holds the evidence), so that the page and the index page print the
same verdict.  The measures behind them (:func:`peak`, :func:`small_mu_slope`,
:func:`vanishing`, :func:`control_trend`, :func:`centrality_summary`) are what the page
prints too.  The series compared is ``plates`` (built at mu), analysed by ``eta_walk``
(their statistic on their sampling) unless a claim says otherwise.
"""
from pathlib import Path

import numpy as np
import xarray as xr
from scipy import stats

from ncd.figures.fig5_governing.measure import eta_table, mixed_only
from ncd.figures.fig5_governing.summary import factor_table, line_counts
from ncd.figures.fig5_governing.unger import eta_u
from ncd.shared.verdict import BEYOND, DIFFERS, NOT_COMPUTED, NOT_TESTED, REPRODUCED, Verdict, judged, open_data, pct

DATA = "fig5_governing/packings.nc"
PEAK_MU = 0.1              # Unger et al.: maximum near mu = 0.1
Z_ISOSTATIC = 4.0          # frictionless discs, 2-D


def peak(ds, var="eta_walk", kind=0, n_boot=2000, seed=0):
    """``(mu of the largest mean, 2.5 %, 97.5 % of that mu over bootstrap resamples of the
    packings at each mu)``: where the curve peaks, with a band over packings."""
    rng = np.random.default_rng(seed)
    sel = ds.kind.values == kind
    mus = np.unique(ds.mu.values[sel])
    vals = [ds[var].values[sel & (ds.mu.values == m)] for m in mus]
    vals = [v[np.isfinite(v)] for v in vals]
    means = np.array([v.mean() if len(v) else np.nan for v in vals])
    if not np.isfinite(means).any():
        return np.nan, np.nan, np.nan
    at = []
    for _ in range(n_boot):
        b = np.array([rng.choice(v, len(v)).mean() if len(v) else np.nan for v in vals])
        at.append(mus[np.nanargmax(b)])
    return float(mus[np.nanargmax(means)]), float(np.quantile(at, 0.025)), float(np.quantile(at, 0.975))


def small_mu_slope(ds, var="eta_walk", kind=0, points=3):
    """Least-squares slope of log mean eta against log mu over the ``points`` smallest mu
    with a positive mean (Unger et al.: 1)."""
    t = eta_table(ds, var, kind)
    t = t[np.isfinite(t[:, 1]) & (t[:, 1] > 0)][:points]
    if len(t) < 2:
        return np.nan
    return float(np.polyfit(np.log(t[:, 0]), np.log(t[:, 1]), 1)[0])


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


def _missing():
    return Verdict("packings.nc not computed", NOT_COMPUTED, "", "unger-peak", (DATA,))


def _flat(ds, kind, anchor):
    """None, or the verdict of a series whose every slice is determinate (nothing to compare)."""
    if (np.nan_to_num(ds.eta_walk.values[ds.kind.values == kind]) > 0).any():
        return None
    return Verdict("every analysed slice of this series is determinate (dim(A ∩ C) = 0, η_U = 0): no curve to "
                   "compare in this run", NOT_TESTED, "needs indeterminate slices", anchor, (DATA,))


def claim_unger_peak(results):
    """eta_U peaks near mu = 0.1: the peak's bootstrap band over packings contains the
    grid point nearest 0.1, and the peak is not at an end of the grid."""
    ds = _open(results)
    if ds is None:
        return _missing()
    if (flat := _flat(ds, 0, "unger-peak")) is not None:
        return flat
    m, lo, hi = peak(ds)
    grid = np.unique(ds.mu.values)
    near = grid[np.argmin(np.abs(np.log(grid / PEAK_MU)))]
    interior = grid.min() < m < grid.max()
    ok = interior and lo <= near <= hi
    return Verdict(f"η_U (their statistic, their random walk) is largest at μ = {m:.3g} (95 % bootstrap band over "
                   f"packings {lo:.3g}–{hi:.3g}); Unger et al.: near 0.1",
                   REPRODUCED if ok else DIFFERS,
                   f"peak inside the grid and its band over packings containing μ = {near:.3g}, the grid point "
                   "nearest 0.1", "unger-peak", (DATA,))


def claim_unger_vanishes(results):
    """eta_U -> 0 as mu -> 0 with eta_U ∝ mu, z still at its frictionless value."""
    ds = _open(results)
    if ds is None:
        return _missing()
    if (flat := _flat(ds, 0, "unger-vanishes")) is not None:
        return flat
    mu0, ratio = vanishing(ds)
    slope = small_mu_slope(ds)
    z0 = eta_table(ds, "z", 0)[0, 1]
    if not np.isfinite(slope):
        return Verdict(f"fewer than two μ with η_U > 0 at the small-μ end (η_U at μ = {mu0:.3g} is {ratio:.2g} of "
                       f"its largest value; z = {z0:.2f} there)", NOT_TESTED, "needs a small-μ slope",
                       "unger-vanishes", (DATA,))
    ok = ratio < 0.05 and 0.5 <= slope <= 1.5 and abs(z0 - Z_ISOSTATIC) <= 0.3
    return Verdict(f"at μ = {mu0:.3g} η_U is {ratio:.2g} of its largest value; log-log slope over the smallest μ "
                   f"{slope:.2f}; z = {z0:.2f} there (isostatic frictionless: 4)",
                   REPRODUCED if ok else DIFFERS,
                   "η_U(μ_min) below 5 % of its maximum, slope within 0.5–1.5 (Unger et al.: 1), z within 0.3 of 4",
                   "unger-vanishes", (DATA,))


def claim_unger_control(results):
    """The control series (built frictionless) gives eta_U rising monotonically with mu."""
    ds = _open(results)
    if ds is None or not (ds.kind.values == 1).any():
        return _missing()
    if (flat := _flat(ds, 1, "unger-control")) is not None:
        return flat
    rho, falls = control_trend(ds)
    rho_u, falls_u = control_trend(ds, "eta_uniform")
    if not np.isfinite(rho):
        return Verdict("fewer than 3 values of μ with a walk that moved in the control series", NOT_TESTED,
                       "needs η_U of the walk at 3 values of μ or more", "unger-control", (DATA,))
    ok = rho >= 0.9 and falls == 0
    return Verdict(f"control series: Spearman ρ(μ, η_U) = {rho:.2f} on the walk ({falls} falls between "
                   f"neighbouring μ), {rho_u:.2f} on the uniform sample ({falls_u} falls)",
                   REPRODUCED if ok else DIFFERS, "mean η_U of the walk never falls as μ grows (ρ ≥ 0.9)",
                   "unger-control", (DATA,))


def claim_unger_centrality(results):
    """The history force state lies closer to the centre of A ∩ C than random samples."""
    ds = _open(results)
    if ds is None:
        return _missing()
    n, closer, rank = centrality_summary(ds)
    if n == 0:
        return Verdict("no indeterminate built-at-μ slice whose uniform chains agree in this run", NOT_TESTED,
                       "needs a mixed uniform sample of an indeterminate slice", "unger-centrality", (DATA,))
    ok = closer >= 0.8 * n
    return Verdict(f"history state closer to the centre than the mean uniform sample in {closer} of {n} "
                   f"indeterminate packings (median fraction of uniform samples closer than it: {rank:.2f})",
                   REPRODUCED if ok else DIFFERS, "closer in at least 80 % of the packings with dim(A ∩ C) > 0",
                   "unger-centrality", (DATA,))


# --- the slope flows of Figure 2 across parameters (§3) ---

FLOWS = "fig5_governing/flows.nc"


def fig5_other_experiments(results):
    flows = open_data(results, FLOWS)
    ind = flows.indeterminate.values
    known = ind >= 0
    none = [(ind[f][known[f]] == 0).all() and known[f].any() for f in range(flows.sizes["flow"])]
    frac = float(np.mean(ind[known] == 1))
    return judged(f"{sum(none)} of {flows.sizes['flow']} flows show no indeterminate scanned step; over all flows "
              f"{pct(frac)} of the {known.sum()} steps of known outcome are indeterminate "
              f"({(~known).sum()} of unknown outcome left out)", REPRODUCED if any(none) else DIFFERS,
              "some flows of the same kind with no indeterminate step", "s3-other-experiments", FLOWS)


def fig5_governing_flows(results):
    flows = open_data(results, FLOWS)
    t = factor_table(flows, "mu", "indeterminate")
    cells = ", ".join(f"μ = {v:g}: {pct(m)}" for v, m, _, _ in t)
    return judged(f"fraction of indeterminate scanned flow steps among those of known outcome (mean over seeds): "
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
# Unger, Kertész & Wolf's findings are judged on their terms (their statistic and packings)
JUDGES = {
    "s3-other-experiments": (fig5_other_experiments,),
    "s3-governing-parameters": (fig5_governing_flows,),
    "s3-line": (fig5_governing_line,),
    "s4-unger": (claim_unger_peak, claim_unger_vanishes, claim_unger_control, claim_unger_centrality),
}


__all__ = ["walk_settling", "walk_forces", "walk_eta_at", "mean_settling", "peak", "small_mu_slope", "vanishing",
           "control_trend", "centrality_summary", "claim_unger_peak", "claim_unger_vanishes", "claim_unger_control",
           "claim_unger_centrality", "fig5_other_experiments", "fig5_governing_flows", "fig5_governing_line",
           "PEAK_MU", "Z_ISOSTATIC", "JUDGES"]
