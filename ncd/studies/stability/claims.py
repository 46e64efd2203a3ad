"""The stability study's rows on the index: §2's implicit scheme (usable steps beyond MD's
critical step), perfectly inelastic collisions and restitution.
"""

import numpy as np

from ncd.shared.verdict import CONSISTENT, DIFFERS, REPRODUCED, judged, open_data, span
from ncd.studies.stability.page import inaccurate

STAB = "stability/table.nc"
COLLISION = "stability/collision.nc"
LARGE_STEP = 2.0         # h / h_crit: MD's explicit step is unstable above h_crit, so twice it is out of its reach
NEWTON_TOL = 1e-9        # |U_f/U_i + e| of one step: round-off, the law is built into the scheme
CHAIN_DRIFT = 1e-6       # |energy drift| / E_s of the e = 1 chain


def stability_cd_md(results):
    """§2: "such an implicit character secures numerical stability, allowing one to use
    considerably larger step-lengths than in MD methods"."""
    tab = open_data(results, STAB)
    method, ratio = tab.method.values.astype(str), tab.h_over_hcrit.values
    cd, md = method == "CD", method == "MD"
    stable = tab.stable.values == 1
    bounded = cd & (tab.diverged.values == 0)
    accurate = cd & stable & ~inaccurate(tab)
    md_big = md & (ratio >= LARGE_STEP)
    md_unstable = md_big & ~stable
    usable = accurate & (ratio >= LARGE_STEP)
    ok = (cd.any() and (stable[cd]).all() and md_big.any() and md_unstable.sum() == md_big.sum()
          and usable.any())
    return judged(f"CD stable in {(cd & stable).sum()} of {cd.sum()} runs (bounded in {bounded.sum()}), accurate in "
                  f"{accurate.sum()} (the others: penetration > 0.1 r, tunnelling or the sweep budget reached); "
                  f"accurate CD runs at h ≥ 2 h_crit of MD: {usable.sum()} (up to "
                  f"{ratio[usable].max() if usable.any() else float('nan'):.3g} h_crit); MD unstable in "
                  f"{md_unstable.sum()} of {md_big.sum()} runs at h ≥ 2 h_crit",
                  REPRODUCED if ok else DIFFERS,
                  "every CD run stable (not diverged, energy not growing), every MD run at h ≥ 2 h_crit unstable, "
                  "and some accurate CD run at h ≥ 2 h_crit (twice the step beyond which MD's explicit scheme "
                  "cannot run)", "s2-stability", STAB)


def _collisions(col):
    """``(e, U_f/U_i)`` arrays of the collision file (one collision per restitution)."""
    if "restitution" in col.dims:
        return col.restitution.values.astype(float), np.atleast_1d(col.velocity_ratio.values).astype(float)
    return np.array([float(col.attrs["restitution"])]), np.atleast_1d(col.velocity_ratio.values).astype(float)


def inelastic(results):
    """§2: the contact law on u_f alone (e = 0) makes every collision perfectly inelastic:
    by construction; one binary collision illustrates it."""
    e, ratio = _collisions(open_data(results, COLLISION))
    at0 = np.isclose(e, 0.0)
    if not at0.any():
        raise KeyError("no e = 0 collision in stability/collision.nc")
    r = float(ratio[at0][0])
    return judged(f"binary collision stepped once with the contact law on u_f (e = 0): U_f/U_i = {r:.1e}",
                  CONSISTENT if abs(r) <= NEWTON_TOL else DIFFERS,
                  "holds by construction (the impulse is connected with u_f alone, so the normal relative "
                  "velocity after a collision is zero); illustrated by a binary collision, U_f/U_i = 0 to 1e-9 "
                  "(otherwise the scheme is broken)", "s2-inelastic", COLLISION)


def restitution(results):
    """A binary collision at e > 0 stepped once by the stability rule (Newton's law: U_f = −e U_i),
    and the e = 1 chain of the stability study (energy kept; Newton's cradle would pass the whole
    speed to the last disc).  One verdict for the sentence: the binary part holds by construction
    (it is how the weights are chosen), so the verdict is the multicontact part's."""
    tab, col = open_data(results, STAB), open_data(results, COLLISION)
    e, ratio = _collisions(col)
    pos = e > 0
    if not pos.any():
        raise KeyError("no collision with e > 0 in stability/collision.nc")
    newton = bool(np.all(np.abs(ratio[pos] + e[pos]) <= NEWTON_TOL))
    chain = (tab.case.values.astype(str) == "e1_chain") & (tab.method.values.astype(str) == "CD")
    drift = float(np.max(np.abs(tab.energy_drift.values[chain]))) if chain.any() else float("nan")
    kept = chain.any() and bool(np.all(tab.diverged.values[chain] == 0)) and drift <= CHAIN_DRIFT
    last = tab.observable.values[chain]
    binary = ", ".join(f"e = {a:g}: U_f/U_i = {b:.6f}" for a, b in zip(e[pos], ratio[pos]))
    return judged(f"binary collision, {binary} (Newton: −e); multicontact e = 1 chain "
                  f"({chain.sum()} CD runs, h = {span(tab.h.values[chain], '.0e') if chain.any() else '—'} s): "
                  f"energy drift ≤ {drift:.1e} E_s, last disc leaves at {span(last, '.2f') if chain.any() else '—'} "
                  "of the striker's speed (Newton's cradle: 1)",
                  REPRODUCED if newton and kept else DIFFERS,
                  "one verdict for both parts: the binary part holds by construction (U_f/U_i = −e to 1e-9, else "
                  "the scheme is broken), the verdict is the multicontact part's: every CD run of the simultaneous "
                  "e = 1 chain impact bounded with |energy drift| ≤ 1e-6 E_s (far below the O(1) loss of an "
                  "inelastic impact, above the NLGS tolerance); Newton's cradle is not asked for",
                  "s2-restitution", STAB, COLLISION)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-stability": (stability_cd_md,),
    "s2-inelastic": (inelastic,),
    "s2-restitution": (restitution,),
}
