"""Figure 5: the flow study's numbers (``flows.nc``) per parameter.

:func:`flow_measures` (per flow: fraction of indeterminate steps, mean spread, distance
between solutions), :func:`factor_table` (per setting of one factor, with a 95 % t-band
over seeds, for the continuous measures), :func:`fraction_table` (a fraction of scanned steps
per setting with its 95 % Wilson interval over the steps: two seeds give no usable t-band
of a fraction) and :func:`line_counts` (cloud ranks and how often the cluster hypothesis of
:mod:`ncd.figures.fig5_governing.line` holds).
"""
import numpy as np
from scipy import stats

from ncd.figures.fig5_governing.flow import FACTORS

FACTOR_VAR = {"mu": "mu", "h": "h", "slope": "slope_deg"}


def flow_measures(ds):
    """Dict of arrays over ``flow``: ``indeterminate`` (fraction of known steps), ``unknown``
    (fraction of scanned steps), ``spread`` (mean over known steps, / |g|), ``exact_spread``
    (mean over indeterminate steps, NaN without one), ``known`` (count)."""
    ind = ds.indeterminate.values
    known = ind >= 0
    n_known = known.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(n_known > 0, (ind == 1).sum(axis=1) / np.maximum(n_known, 1), np.nan)
        spread = np.where(n_known > 0, np.nansum(np.where(known, ds.spread.values, 0.0), axis=1)
                          / np.maximum(n_known, 1), np.nan)
        ex = np.where(ind == 1, ds.exact_spread.values, np.nan)
        exact = np.array([np.nanmean(r) if np.isfinite(r).any() else np.nan for r in ex])
    return {"indeterminate": frac, "unknown": 1.0 - n_known / ind.shape[1], "spread": spread,
            "exact_spread": exact, "known": n_known}


def _band(v):
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return np.nan, np.nan, 0
    half = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else np.nan
    return float(v.mean()), float(half), len(v)


def factor_table(ds, factor, measure):
    """Rows ``(value, mean, 95 % half-band, flows)`` of ``measure`` (a key of
    :func:`flow_measures`) for the settings varying ``factor`` ("mu", "h", "slope") and
    the base, sorted by the value."""
    m = flow_measures(ds)[measure]
    fac = ds.factor.values
    use = (fac == 0) | (fac == FACTORS.index(factor))
    x = ds[FACTOR_VAR[factor]].values
    rows = [(v, *_band(m[use & np.isclose(x, v)])) for v in np.unique(x[use])]
    return np.array(rows, float).reshape(-1, 4)


def wilson(k, n, z=1.959964):
    """``(lo, hi)``: the 95 % Wilson score interval of ``k`` successes in ``n`` trials (NaN for
    ``n = 0``); it stays inside [0, 1] and is not empty at ``k = 0`` or ``k = n``."""
    if n <= 0:
        return np.nan, np.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return float(max(centre - half, 0.0)), float(min(centre + half, 1.0))


def fraction_table(ds, factor, measure="indeterminate"):
    """Rows ``(value, fraction, 95 % Wilson lo, hi, steps counted k, of n, flows)`` for the settings
    varying ``factor`` and the base, sorted by the value, the steps of every seed pooled:
    ``indeterminate`` counts the indeterminate steps among those of known outcome,
    ``unknown`` the steps of unknown outcome among all scanned steps."""
    ind = ds.indeterminate.values
    fac = ds.factor.values
    use = (fac == 0) | (fac == FACTORS.index(factor))
    x = ds[FACTOR_VAR[factor]].values
    rows = []
    for v in np.unique(x[use]):
        f = use & np.isclose(x, v)
        if measure == "indeterminate":
            k, n = int((ind[f] == 1).sum()), int((ind[f] >= 0).sum())
        elif measure == "unknown":
            k, n = int((ind[f] == -1).sum()), int(ind[f].size)
        else:
            raise ValueError(f"fraction_table: measure {measure!r} is not a fraction of steps")
        rows.append((v, k / n if n else np.nan, *wilson(k, n), k, n, int(f.sum())))
    return np.array(rows, float).reshape(-1, 7)


def line_counts(ds):
    """Counts over the indeterminate steps of every flow: cloud ranks, predictions and agreement.

    ``predicted``: a cluster with one degree of freedom; ``holds``: the hypothesis agrees
    with the cloud; also solution counts, ``continuum`` and ``one_cluster``.  ``tested``
    repeats the counts over steps with three solutions or more, the only ones where the
    hypothesis can fail (two solutions always span one direction)."""
    ind = ds.indeterminate.values == 1
    rank = ds.cloud_rank.values[ind]
    pred = ds.predicted_line.values[ind] == 1
    line = rank == 1
    nex = ds.n_exact.values[ind]
    holds = ds.hypothesis_holds.values[ind] == 1
    k = nex >= 3
    tested = {"steps": int(k.sum()), "holds": int((holds & k).sum()),
              "line_and_predicted": int((line & pred & k).sum()), "line_not_predicted": int((line & ~pred & k).sum()),
              "predicted_not_line": int((~line & pred & k).sum()), "neither": int((~line & ~pred & k).sum())}
    return {"steps": int(ind.sum()), "rank": [int((rank == r).sum()) for r in (0, 1, 2)],
            "predicted": int(pred.sum()), "holds": int((ds.hypothesis_holds.values[ind] == 1).sum()),
            "line_and_predicted": int((line & pred).sum()), "line_not_predicted": int((line & ~pred).sum()),
            "solutions": [int((nex == 2).sum()), int((nex == 3).sum()), int((nex > 3).sum())],
            "continuum": int((ds.null_velocity.values[ind] > 0).sum()),
            "one_cluster": int((ds.n_clusters.values[ind] == 1).sum()),
            "switched_median": float(np.median(ds.n_switched.values[ind])) if ind.any() else np.nan,
            "moving_median": float(np.median(ds.n_moving.values[ind])) if ind.any() else np.nan,
            "tested": tested}


__all__ = ["FACTOR_VAR", "flow_measures", "factor_table", "wilson", "fraction_table", "line_counts"]


def flows_overview(flows, fc):
    """The flow scan in sentences: settings, scans, converged runs and the steps' outcomes
    (unknown outcomes counted apart: the fractions are lower bounds)."""
    n_set = len(np.unique(flows.setting.values))
    runs = fc["scan"]["runs"]
    n_scan = flows.sizes["scan"]
    ind = flows.indeterminate.values
    conv = (flows.converged_zero.values + flows.converged_warm.values).sum()
    return (
        f"{flows.sizes['flow']} flows: {n_set} settings × {fc['seeds']} seeds, one factor at a time around "
        f"μ = {fc['base']['mu']}, h = {fc['base']['h']:g} s, slope {fc['base']['slope_deg']:g}°. "
        f"Each flow is scanned {n_scan} times, every {fc['scan_every'] * 1e3:g} ms up to "
        f"{fc['duration'] * 1e3:g} ms after release, with {runs} zero-guess and {runs} warm-start runs: "
        f"{conv} of {2 * runs * ind.size} runs converged. Of the {ind.size} scanned steps, "
        f"{int((ind == 1).sum())} are indeterminate (two exact solutions or more), {int((ind == 0).sum())} "
        f"determinate and {int((ind == -1).sum())} unknown (no converged run, or end points that did not "
        f"polish to exact solutions: {int(((ind == -1) & (flows.n_solutions.values == 0)).sum())} without a "
        f"converged run). With {runs} + {runs} runs per step a solution reached rarely can be missed: the "
        f"fractions below are lower bounds of the fraction of steps with several solutions.")


def factor_text(flows):
    """The fraction of indeterminate steps against each factor, with its 95 % Wilson interval
    over the steps of known outcome (every seed's steps pooled)."""
    rows = []
    for factor, name, unit in (("mu", "μ", ""), ("h", "h", " s"), ("slope", "slope", "°")):
        ti, ts = fraction_table(flows, factor, "indeterminate"), factor_table(flows, factor, "spread")
        tu = fraction_table(flows, factor, "unknown")
        cells = "; ".join(f"{name} = {v:g}{unit}: {f:.2f} ({lo:.2f}–{hi:.2f}; {int(k)} of {int(n)} steps; spread "
                          f"{s:.2g} |g|, unknown {u:.2f}, {int(nf)} flows)"
                          for (v, f, lo, hi, k, n, nf), (_, s, _, _), (_, u, *_) in zip(ti, ts, tu))
        rows.append(f"**Against {name}** — fraction of indeterminate steps among those of known outcome (95 % "
                    f"Wilson interval over the steps, seeds pooled): {cells}.")
    return ("\n\n".join(rows))


def line_text(flows, line_ratio):
    """Why a cloud is a line, measured at the indeterminate steps (Moreau's open question)."""
    c = line_counts(flows)
    ratio = flows.cloud_minor.values / flows.cloud_major.values
    lr = line_ratio
    visual = int(((flows.indeterminate.values == 1) & (ratio <= lr)).sum())
    return (
        f"At the {c['steps']} indeterminate steps: {c['solutions'][0]} have two exact solutions, "
        f"{c['solutions'][1]} three and {c['solutions'][2]} more; a median of {c['switched_median']:.0f} "
        f"contacts change status and {c['moving_median']:.0f} grains accelerate differently between them "
        f"(one connected cluster at {c['one_cluster']} steps). The cloud of the grain of largest spread is a "
        f"point at {c['rank'][0]}, a line (rank 1, minor extent below the solution threshold) at {c['rank'][1]} "
        f"and spans an area at {c['rank'][2]} steps; by Figure 2's visual criterion (minor/major ≤ {lr}) it "
        f"is a line at {visual}. The grain's cluster has one degree of freedom (the solutions restricted to "
        f"it span one direction) at {c['predicted']} steps; the hypothesis — a line exactly when one isolated "
        f"one-degree-of-freedom cluster decides between the solutions — holds at {c['holds']} of "
        f"{c['steps']} steps ({c['line_and_predicted']} lines predicted, {c['line_not_predicted']} lines "
        f"not predicted). Two solutions always span one direction: with two exact solutions the line is "
        f"unavoidable, and the test has content only at the {c['tested']['steps']} steps with three or more. "
        f"There it holds at {c['tested']['holds']}: {c['tested']['line_and_predicted']} predicted lines and "
        f"{c['tested']['neither']} steps with neither a line nor a prediction; it fails at "
        f"{c['tested']['line_not_predicted']} lines not predicted and {c['tested']['predicted_not_line']} "
        f"predicted lines that are not. Keeping the statuses "
        f"of the most frequent solution leaves grain velocities free (a continuum of solutions) at "
        f"{c['continuum']} steps; elsewhere the solutions are isolated points and the impulses alone are "
        f"indeterminate (median dimension {np.nanmedian(flows.null_impulse.values[flows.indeterminate.values == 1]) if c['steps'] else np.nan:.0f}).")
