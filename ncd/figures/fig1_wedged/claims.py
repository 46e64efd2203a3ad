"""Figure 1's rows on the index: §1 (two evolutions, the wedging threshold, the segment of I,
forces as state).
"""

import numpy as np

from ncd.shared.verdict import DIFFERS, REPRODUCED, judged, open_data, pct

F1_ENS, F1_SWEEP, F1_EVOL = "fig1_wedged/ensemble.nc", "fig1_wedged/sweep.nc", "fig1_wedged/evolutions.nc"

def fig1_two_evolutions(results):
    """§1: B may fall freely, and (γ large enough) may also stay wedged: both outcomes among the
    converged runs of the same step, γ above the threshold β."""
    ens = open_data(results, F1_ENS)
    outcome, zero = ens.outcome.values, ens.zero_guess.values.astype(bool)
    falls_zero = np.mean(outcome[zero] == 0) if zero.any() else np.nan
    wedged_rand = np.mean(outcome[~zero] == 1) if (~zero).any() else np.nan
    falls_rand = np.mean(outcome[~zero] == 0) if (~zero).any() else np.nan
    both = bool((outcome == 0).any() and (outcome == 1).any())
    gamma, beta = float(ens.attrs["gamma_deg"]), float(ens.attrs["beta_deg"])
    return judged(f"γ = {gamma:.1f}°, β = {beta:.1f}°; zero guess: {pct(falls_zero)} of {zero.sum()} runs fall; "
                  f"random guesses: {pct(wedged_rand)} of {(~zero).sum()} wedge, {pct(falls_rand)} fall",
                  REPRODUCED if both and gamma > beta else DIFFERS,
                  "a \"may\" over the runs of one step at γ > β: at least one converged run falls freely and at "
                  "least one stays wedged", "s1-two-evolutions", F1_ENS)


def fig1_threshold(results):
    """§1: wedging needs γ large enough; closed form: γ > β."""
    swp = open_data(results, F1_SWEEP)
    gamma, frac = swp.gamma.values, swp.wedged_fraction.values
    beta = float(swp.attrs["threshold_gamma_deg"])
    below, above = frac[gamma < beta], frac[gamma > beta]
    ok = len(below) > 0 and len(above) > 0 and np.all(below == 0) and np.all(above > 0)
    first = gamma[frac > 0].min() if (frac > 0).any() else np.nan
    return judged(f"wedged fraction 0 at {np.sum(below == 0)} of {len(below)} angles γ < β = {beta:.1f}°, > 0 at "
                  f"{np.sum(above > 0)} of {len(above)} angles γ > β (first at {first:.1f}°)",
                  REPRODUCED if ok else DIFFERS, "angles sampled on both sides of β: no wedged run at any γ < β, "
                  "some wedged run at every γ > β", "s1-wedging-threshold", F1_SWEEP)


def _wedged_on_segment(ens):
    wedged = ens.outcome.values == 1
    R, lo, hi = float(ens.attrs["radius"]), float(ens.attrs["I_y_bottom"]), float(ens.attrs["I_y_top"])
    ix, iy = ens.I_x.values[wedged], ens.I_y.values[wedged]
    on = (np.abs(ix) <= 1e-6 * R) & (iy >= lo - 1e-6 * R) & (iy <= hi + 1e-6 * R)
    return wedged, on, ix, iy, R, lo, hi


def fig1_segment(results):
    """Fig. 1: the wedged states put I (where the lines of action of the two contact forces
    meet) on the closed-form vertical segment."""
    ens = open_data(results, F1_ENS)
    wedged, on, ix, iy, R, lo, hi = _wedged_on_segment(ens)
    if not wedged.any():
        return judged("no wedged run", DIFFERS, "every wedged I on the closed-form vertical segment", "s1-segment", F1_ENS)
    return judged(f"{on.sum()} of {wedged.sum()} wedged I on the segment [{lo / R:.3f} R, {hi / R:.3f} R] "
                  f"(largest |x_I| {np.abs(ix).max() / R:.1e} R)", REPRODUCED if on.all() else DIFFERS,
                  "every wedged I within 10⁻⁶ R of the closed-form segment (far above the solver's scatter, far "
                  "below the disc's scale)", "s1-segment", F1_ENS)


def fig1_undetermined(results):
    """§1: in the wedged case the contact forces are undetermined in some range: the wedged
    runs of one step spread their I along the segment."""
    ens = open_data(results, F1_ENS)
    wedged, on, ix, iy, R, lo, hi = _wedged_on_segment(ens)
    if wedged.sum() < 2:
        return judged(f"{wedged.sum()} wedged run(s)", DIFFERS, "wedged runs spread along the segment",
                      "s1-forces-undetermined", F1_ENS)
    cover = (iy.max() - iy.min()) / (hi - lo)
    return judged(f"the {wedged.sum()} wedged runs put I at {len(np.unique(np.round(iy / R, 6)))} distinct heights, "
                  f"covering {pct(cover)} of the segment", REPRODUCED if cover >= 0.5 else DIFFERS,
                  "the wedged runs of one step reach force states over at least half the closed-form segment (a "
                  "range of states, not a scatter about one)", "s1-forces-undetermined", F1_ENS)


def fig1_forces_as_state(results):
    """§1: the contact forces at t0 decide the evolution: same positions and velocities, two
    initial forces, two evolutions."""
    ev = open_data(results, F1_EVOL)
    names = [s.split(":")[0].strip() for s in str(ev.attrs["evolutions"]).split(";")]
    drop = ev.y.values[:, 0] - ev.y.values[:, -1]
    R = float(ev.attrs["radius"])
    zero, warm = names.index("zero_guess"), names.index("wedged_warm")
    ok = drop[zero] > R and abs(drop[warm]) < 1e-6 * R
    return judged(f"same position and velocity at t0: from the zero guess B falls {drop[zero] / R:.1f} R in "
                  f"{float(ev.attrs['duration']):g} s; with the wedged contact forces carried from step to step it "
                  f"moves {abs(drop[warm]) / R:.1e} R", REPRODUCED if ok else DIFFERS,
                  "the contact forces at t0 alone decide between falling (more than R) and staying wedged (less "
                  "than 10⁻⁶ R)", "s1-forces-as-state", F1_EVOL)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s1-two-evolutions": (fig1_two_evolutions,),
    "s1-wedging-threshold": (fig1_threshold,),
    "s1-forces-undetermined": (fig1_undetermined,),
    "s1-segment": (fig1_segment,),
    "s1-forces-as-state": (fig1_forces_as_state,),
}
