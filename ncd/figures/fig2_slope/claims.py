"""Figure 2's rows on the index: §3 (the dispersion, the warm start, the line, sticking contacts)
and §2's little indeterminacy of warm starts.
"""

import numpy as np

from ncd.shared.verdict import BEYOND, DIFFERS, NOT_COMPUTED, REPRODUCED, judged, open_data


def warm_little(results, claim_id="s3-warm-no-dispersion"):
    """Judged at every tolerance where the zero-guess spread has settled (within 10 % of its
    value at the tightest tolerance): below that, both spreads are iteration error."""
    meas = open_data(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    sp = meas.spread.sel(disc=grain)
    tols = np.sort(meas.tol.values)[::-1]
    zero, warm = sp.sel(init="zero", tol=tols).values, sp.sel(init="warm", tol=tols).values
    settled = np.abs(zero - zero[-1]) <= 0.1 * zero[-1]
    ok = settled.any() and np.all(warm[settled] < zero[settled] / 10)
    pairs = ", ".join(f"{t:g}: {z:.2g} / {w:.2g}" for t, z, w in zip(tols, zero, warm))
    return judged(f"grain {grain}, RMS spread of the acceleration (m/s²) zero guess / warm start at each tolerance — "
              f"{pairs}; the zero-guess spread has settled from tol {tols[settled][0]:g} on",
              REPRODUCED if ok else DIFFERS,
              "warm spread below a tenth of the zero-guess one at every tolerance where the latter has settled",
              claim_id, "fig2_slope/measures.nc")


def warm_little_s2(results):
    return warm_little(results, "s2-warm-little-indeterminacy")


def fig2_dispersion(results):
    meas = open_data(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    sp = meas.spread.sel(disc=grain, init="zero")
    tight, loose = float(meas.tol.min()), float(meas.tol.max())
    z_tight, z_loose = float(sp.sel(tol=tight)), float(sp.sel(tol=loose))
    ok = z_tight > 0.5 * z_loose and z_tight > 0 and int(meas.attrs["n_solutions"]) >= 2
    return judged(f"grain {grain}: zero-guess RMS spread {z_loose:.3g} m/s² at tol {loose:g}, {z_tight:.3g} m/s² at tol "
              f"{tight:g}; {int(meas.attrs['n_solutions'])} distinct solutions (verdict of the page: "
              f"{meas.attrs['verdict']})", REPRODUCED if ok else DIFFERS,
              "a spread that does not shrink as the tolerance tightens, between distinct converged solutions",
              "s3-dispersion", "fig2_slope/measures.nc")


def fig2_line(results):
    meas = open_data(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    ratio = float(meas.ratio.sel(init="zero", tol=float(meas.tol.min()), disc=grain))
    n_sol = int(meas.attrs["n_solutions"])
    why = ("one solution: no dispersion to shape" if n_sol < 2 else
           "two solutions: a line by construction, so this step cannot answer the question" if n_sol == 2
           else "more than two solutions")
    return judged(f"grain {grain}: minor/major principal spread {ratio:.1e}; {n_sol} distinct solutions ({why})",
              BEYOND, "an open question of the paper: measured, not judged", "s3-line", "fig2_slope/measures.nc")


def fig2_sticking(results):
    """Moreau's reason: at a sticking contact Coulomb's law leaves the force free in a cone,
    at a sliding one it fixes its direction.  Judged on the exact solutions of the step
    (the census): where do they differ?  And how the difference spreads from there."""
    census = open_data(results, "fig2_slope/census.nc")
    meas = open_data(results, "fig2_slope/measures.nc")
    if census.sizes["solution"] < 2 or "switch_distance" not in meas:
        return judged(f"the census finds {census.sizes['solution']} exact solution(s) at this step: no contact where "
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
    return judged(f"the {census.sizes['solution']} exact solutions of the step differ in status at {n_sw} contacts, "
              f"{stick} of which stick (zero sliding velocity) in one of them; the grain accelerations differ by "
              f"{near:.2g} m/s² (median) within one sticking link of a switching contact and by {apart:.2g} for "
              f"the {(~linked).sum()} grains not linked to one by sticking contacts",
              REPRODUCED if ok else DIFFERS,
              "a \"may\": most contacts where the solutions differ stick in one of them", "s3-sticking-determinant",
              "fig2_slope/census.nc", "fig2_slope/measures.nc")


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-warm-little-indeterminacy": (warm_little_s2,),
    "s3-dispersion": (fig2_dispersion,),
    "s3-warm-no-dispersion": (warm_little,),
    "s3-line": (fig2_line,),
    "s3-sticking-determinant": (fig2_sticking,),
}
