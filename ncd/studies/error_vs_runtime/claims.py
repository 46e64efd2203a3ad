"""The work-precision study's row on the index: §2's warm start on several states.
"""


from ncd.shared.verdict import DIFFERS, REPRODUCED, judged, open_data


def warm_accelerates_states(results):
    nl = open_data(results, "error_vs_runtime/nlgs.nc").sel(criterion="residual")
    tight = float(nl.tol.where(nl.converged.all(("state", "init")), drop=True).min())
    r = nl.sweeps.sel(init="zero", tol=tight) / nl.sweeps.sel(init="warm", tol=tight)
    words = ", ".join(f"{s}: {float(v):.2g}" for s, v in zip(nl.state.values, r.values))
    return judged(f"plain NLGS, sweeps to a residual of {tight:g}, zero guess / warm start — {words} (slope: a flow down a "
              "slope like Figure 2's)",
              REPRODUCED if bool((r > 3).all()) else DIFFERS,
              "the warm start needs at least three times fewer sweeps on every state", "s2-warm-accelerates",
              "error_vs_runtime/nlgs.nc")


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-warm-accelerates": (warm_accelerates_states,),
}
