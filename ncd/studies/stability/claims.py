"""The stability study's rows on the index: §2's implicit scheme (usable steps beyond MD's
critical step) and restitution.
"""

import numpy as np

from ncd.shared.verdict import DIFFERS, REPRODUCED, judged, open_data, span
from ncd.studies.stability.page import inaccurate

STAB = "stability/table.nc"
COLLISION = "stability/collision.nc"


def stability_cd_md(results):
    tab = open_data(results, STAB)
    method, ratio = tab.method.values.astype(str), tab.h_over_hcrit.values
    cd, md = method == "CD", method == "MD"
    bounded = cd & (tab.diverged.values == 0)
    accurate = bounded & ~inaccurate(tab)
    md_big = md & (ratio >= 2)
    md_unstable = md_big & (tab.stable.values == 0)
    usable = accurate & (ratio >= 2)
    ok = md_unstable.sum() == md_big.sum() and usable.any()
    return judged(f"CD bounded in {bounded.sum()} of {cd.sum()} runs, accurate in {accurate.sum()} (the others: "
              f"penetration > 0.1 r, tunnelling or the sweep budget reached); accurate CD runs at h ≥ 2 h_crit of "
              f"MD: {usable.sum()} (up to {ratio[usable].max() if usable.any() else float('nan'):.3g} h_crit); "
              f"MD unstable in {md_unstable.sum()} of {md_big.sum()} runs at h ≥ 2 h_crit",
              REPRODUCED if ok else DIFFERS,
              "accurate CD runs exist at steps where every MD run is unstable (h ≥ 2 h_crit)", "s2-stability", STAB)


def restitution(results):
    """A binary collision at e = 0.5 stepped once by the stability rule (Newton's law: U_f = −e U_i), and the
    e = 1 chain of the stability study (energy kept; Newton's cradle would pass the whole
    speed to the last disc)."""
    tab, col = open_data(results, STAB), open_data(results, COLLISION)
    e, ratio = float(col.attrs["restitution"]), float(col.velocity_ratio)
    chain = (tab.case.values.astype(str) == "e1_chain") & (tab.method.values.astype(str) == "CD")
    drift = float(np.max(np.abs(tab.energy_drift.values[chain]))) if chain.any() else float("nan")
    last = tab.observable.values[chain]
    ok = abs(ratio + e) < 1e-9 and chain.any() and drift < 1e-6
    return judged(f"binary collision, e = {e}: U_f/U_i = {ratio:.6f} (Newton: −{e}); multicontact e = 1 chain "
              f"({chain.sum()} CD runs): energy drift ≤ {drift:.1e}, last disc leaves at "
              f"{span(last, '.2f')} of the striker's speed (Newton's cradle: 1)",
              REPRODUCED if ok else DIFFERS,
              "Newton's law in a binary collision; a multicontact impact handled with energy kept "
              "(not the sequence of binary collisions of Newton's cradle)", "s2-restitution", STAB, COLLISION)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-stability": (stability_cd_md,),
    "s2-restitution": (restitution,),
}
