"""Figure 5: the flow study's numbers (``flows.nc``) per parameter.

:func:`flow_measures` (per flow: fraction of indeterminate steps, mean spread, distance
between solutions), :func:`factor_table` (per setting of one factor, with a 95 % t-band
over seeds) and :func:`line_counts` (cloud ranks and how often the cluster hypothesis of
:mod:`ncd.figures.governing_line` holds).
"""
import numpy as np
from scipy import stats

from ncd.figures.governing_flow import FACTORS

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


__all__ = ["FACTOR_VAR", "flow_measures", "factor_table", "line_counts"]
