"""The work-precision study's row on the index: §2's warm start on several states.
"""

import numpy as np

from ncd.shared.verdict import DIFFERS, REPRODUCED, judged, open_data

CONSIDERABLY = 3.0     # zero-guess sweeps / warm-start sweeps: the bar of the Figure 3 page, so both parts are read alike


def warm_accelerates_states(results):
    """§2: "in case of dense collections of rigid bodies, one considerably accelerates
    convergence by starting from the values found for these impulsions at the antecedent
    step".  Every state of the study is a dense collection a step after its antecedent one
    (two settled packings and a flow down a slope); the saving is read at every tolerance
    where both starts converge, and summarised per state by its median."""
    nl = open_data(results, "error_vs_runtime/nlgs.nc").sel(criterion="residual")
    both = (nl.converged.sel(init="zero") == 1) & (nl.converged.sel(init="warm") == 1)
    r = (nl.sweeps.sel(init="zero") / nl.sweeps.sel(init="warm")).where(both)
    parts, medians = [], []
    for st in nl.state.values:
        v = r.sel(state=st).values
        v = v[np.isfinite(v)]
        med = float(np.median(v)) if len(v) else float("nan")
        medians.append(med)
        parts.append(f"{st}: {med:.2g} ({v.min():.2g}–{v.max():.2g} over {len(v)} tolerances)" if len(v)
                     else f"{st}: no tolerance where both converge")
    ok = len(medians) > 0 and all(np.isfinite(m) and m >= CONSIDERABLY for m in medians)
    return judged("plain NLGS, sweeps to a residual tolerance, zero guess / warm start, median over the tolerances "
                  f"{float(nl.tol.max()):g} to {float(nl.tol.min()):g} where both converge — " + "; ".join(parts)
                  + " (slope: a flow down a slope like Figure 2's)",
                  REPRODUCED if ok else DIFFERS,
                  "on every dense state, the median over the tolerances where both starts converge of zero-guess "
                  "sweeps over warm-start sweeps is at least 3 (\"considerably\": the bar of the Figure 3 page)",
                  "s2-warm-accelerates", "error_vs_runtime/nlgs.nc")


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-warm-accelerates": (warm_accelerates_states,),
}
