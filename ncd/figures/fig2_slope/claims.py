"""Figure 2's rows on the index: §3 (the overall acceleration, the dispersion, the warm start,
the line, sticking contacts) and §2's little indeterminacy of warm starts and random guesses.
"""
from math import comb

import numpy as np

from ncd.shared.verdict import BEYOND, DIFFERS, NOT_COMPUTED, REPRODUCED, judged, open_data

VISIBLE = 0.01         # |g|: a grain's dispersion visible at the figure's scale (the census's "grains differ")
ACCEL_WINDOW = 20      # flow steps before the investigated step over which the acceleration is fitted
FLUCTUATION = 3.0      # the fitted rise of the mean velocity must exceed this many RMS residuals of the fit


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
    """§3: "The acceleration vector of a grain center is affected by a dispersion shown on the
    figure": the chosen grain's zero-guess spread at the tightest tolerance, visible and settled
    (not iteration error, which shrinks about tenfold per decade of tolerance), between distinct
    converged solutions."""
    meas = open_data(results, "fig2_slope/measures.nc")
    grain = int(meas.attrs["grain"])
    g = float(meas.attrs.get("g", 9.81))
    sp = meas.spread.sel(disc=grain, init="zero")
    tols = np.sort(meas.tol.values)[::-1]
    z = sp.sel(tol=tols).values
    z_tight, z_prev = float(z[-1]), float(z[-2]) if len(z) > 1 else float("nan")
    n_sol = int(meas.attrs["n_solutions"])
    ok = n_sol >= 2 and z_tight >= VISIBLE * g and z_tight >= 0.5 * z_prev
    return judged(f"grain {grain}: zero-guess RMS spread {float(z[0]):.3g} m/s² at tol {tols[0]:g}, {z_prev:.3g} at "
                  f"{tols[-2]:g}, {z_tight:.3g} m/s² ({z_tight / g:.2g} |g|) at tol {tols[-1]:g}; {n_sol} distinct "
                  f"solutions (verdict of the page: {meas.attrs.get('verdict', '—')})",
                  REPRODUCED if ok else DIFFERS,
                  "at the tightest tolerance the spread is visible (≥ 0.01 |g|, the census's threshold for grains "
                  "that differ), at least half its value one decade looser (iteration error shrinks about tenfold "
                  "per decade) and the runs reach at least two distinct solutions", "s3-dispersion",
                  "fig2_slope/measures.nc")


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


def _binomial_tail(k, n, p):
    """P(X >= k) for X binomial (n, p)."""
    return float(sum(comb(n, j) * p ** j * (1 - p) ** (n - j) for j in range(k, n + 1)))


def fig2_sticking(results):
    """Moreau's reason: at a sticking contact Coulomb's law leaves the force free in a cone,
    at a sliding one it fixes its direction.  Judged on the exact solutions of the step
    (the census): are the contacts where the solutions differ in status (the disposition of
    the sticking contacts changes there) sticking more often than the other active contacts?
    Without that, sticking among them is the base rate of the step, not a determinant."""
    census = open_data(results, "fig2_slope/census.nc")
    meas = open_data(results, "fig2_slope/measures.nc")
    if census.sizes["solution"] < 2 or "switch_distance" not in meas:
        return judged(f"the census finds {census.sizes['solution']} exact solution(s) at this step: no contact where "
                      "solutions differ", NOT_COMPUTED, "sticking contacts over-represented where the solutions "
                      "differ", "s3-sticking-determinant", "fig2_slope/census.nc")
    st = census.status.values
    switching = np.zeros(st.shape[1], bool)
    switching[census.switching.values] = True
    active = (st > 0).any(0)
    stick = (st == 1).any(0)
    n_sw, k = int(switching.sum()), int((stick & switching).sum())
    others = active & ~switching
    base = float(stick[others].mean()) if others.any() else float("nan")
    p = _binomial_tail(k, n_sw, base) if n_sw and np.isfinite(base) else float("nan")
    dist = meas.switch_distance.values
    dmag = np.hypot(meas.delta_x.values, meas.delta_y.values)
    linked = dist >= 0
    near = float(np.median(dmag[linked & (dist <= 1)])) if (linked & (dist <= 1)).any() else float("nan")
    apart = float(np.median(dmag[~linked])) if (~linked).any() else float("nan")
    ok = n_sw > 0 and k / n_sw > base and p < 0.05
    return judged(f"the {census.sizes['solution']} exact solutions of the step differ in status at {n_sw} contacts, "
                  f"{k} of which ({100 * k / max(n_sw, 1):.0f} %) stick (zero sliding velocity) in one of them, against "
                  f"{100 * base:.0f} % of the {int(others.sum())} other active contacts (chance of as many or more: "
                  f"{p:.2g}); the grain accelerations differ by {near:.2g} m/s² (median) within one sticking link of "
                  f"a switching contact and by {apart:.2g} for the {(~linked).sum()} grains not linked to one by "
                  "sticking contacts",
                  REPRODUCED if ok else DIFFERS,
                  "sticking over-represented where the solutions differ: the fraction of status-switching contacts "
                  "that stick in one solution exceeds that of the other active contacts, beyond chance (one-sided "
                  "binomial test at 5 %: the switching contacts are few)", "s3-sticking-determinant",
                  "fig2_slope/census.nc", "fig2_slope/measures.nc")


def random_guess_any_solution(results):
    """§2: "One possibility is to execute a large number of runs of the convergent iteration
    process, each time with initial guess drawn at random from some plausible range.  Any
    solution then has a chance to be approached."  A "may" over the step's exact solutions (the
    census: NLGS end points, Lemke, status enumeration): every one reached by some random-guess
    run of the census."""
    census = open_data(results, "fig2_slope/census.nc")
    n = census.sizes["solution"]
    runs = int(census.attrs["random_converged"])
    reached = census.n_random.values.astype(int)
    zero = census.n_zero.values.astype(int) if "n_zero" in census else np.zeros(n, int)
    if n < 2:
        return judged(f"the census finds {n} exact solution(s) at this step: nothing to choose between",
                      NOT_COMPUTED, "every exact solution of the census reached by some random-guess run",
                      "s2-random-guess-any-solution", "fig2_slope/census.nc")
    missed = np.nonzero(reached == 0)[0]
    per = ", ".join(f"solution {k}: {r} (zero guess, random orders: {z})" for k, (r, z) in enumerate(zip(reached, zero)))
    tail = (f"; never reached: solution(s) {', '.join(map(str, missed))} (a chance below {300 / max(runs, 1):.0f} % "
            "per run at 95 % confidence)" if len(missed) else "")
    a = census.attrs
    plain = (f"; {int(a['random_plain_same'])} of {int(a['random_plain_runs'])} rerun by plain NLGS end on the same "
             "solution" if int(a.get("random_plain_runs", 0)) else "")
    return judged(f"the census finds {n} exact solutions; its {runs} converged NLGS runs from random guesses (normal "
                  f"impulses uniform up to {float(a['random_guess_scale']):.2g} N s, the largest normal impulse of the "
                  f"solutions found before, tangential ones in the Coulomb cone{plain}) end on {per}{tail}",
                  REPRODUCED if runs > 0 and len(missed) == 0 else DIFFERS,
                  "a \"may\" over the step's exact solutions: every solution of the census (NLGS, Lemke, status "
                  "enumeration) is the end point of at least one random-guess run", "s2-random-guess-any-solution",
                  "fig2_slope/census.nc")


def overall_acceleration(results):
    """§3: "Flow is not in stationary regime but in a phase of overall acceleration": the mean
    velocity down the slope over the steps before the investigated one, fitted by a line; its
    rise over the window against the fluctuation about the fit."""
    traj = open_data(results, "fig2_slope/trajectory.nc")
    k = int(traj.attrs["investigated_step"])
    down = np.sign(float(traj.attrs["gravity_x"])) or 1.0
    steps = traj.step.values
    sel = (steps >= k - ACCEL_WINDOW) & (steps <= k - 1)
    if sel.sum() < 5:
        raise ValueError(f"only {int(sel.sum())} flow steps before the investigated step {k}")
    t, v = traj.time.values[sel], down * traj.mean_vx.values[sel]
    a, b = np.polyfit(t, v, 1)
    rms = float(np.sqrt(np.mean((v - (a * t + b)) ** 2)))
    rise = float(a * (t[-1] - t[0]))
    ok = rise > 0 and rise > FLUCTUATION * rms
    return judged(f"over the {int(sel.sum())} steps before the investigated step {k} the mean velocity down the slope "
                  f"goes from {v[0]:.3g} to {v[-1]:.3g} m/s: fitted acceleration {a:.3g} m/s² "
                  f"({a / abs(float(traj.attrs['gravity_x'])):.2f} g sin θ), a rise of {rise:.2g} m/s against "
                  f"{rms:.1g} m/s RMS fluctuation about the fit",
                  REPRODUCED if ok else DIFFERS,
                  "the mean downslope velocity, fitted by a line over the 20 steps before the investigated step, "
                  "rises by more than 3 times its RMS fluctuation about the fit (a steady flow rises by its "
                  "noise only)", "s3-overall-acceleration", "fig2_slope/trajectory.nc")


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-warm-little-indeterminacy": (warm_little_s2,),
    "s3-dispersion": (fig2_dispersion,),
    "s3-warm-no-dispersion": (warm_little,),
    "s3-line": (fig2_line,),
    "s3-sticking-determinant": (fig2_sticking,),
    "s2-random-guess-any-solution": (random_guess_any_solution,),
    "s3-overall-acceleration": (overall_acceleration,),
}
