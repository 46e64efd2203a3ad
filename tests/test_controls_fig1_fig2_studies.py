"""Every judging function of Figures 1 and 2 and of the stability and work-precision studies on
a positive control (data where the sentence holds: *reproduced*) and a negative one (the
physics changed so that the sentence is false: *differs*); sentences that hold by
construction give *consistent* with the value read from the data, open questions *beyond
the paper* with a value that follows the data."""
import numpy as np
import xarray as xr

from ncd.figures.fig1_wedged import claims as fig1
from ncd.figures.fig2_slope import claims as fig2
from ncd.shared.verdict import BEYOND, CONSISTENT, DIFFERS, NOT_COMPUTED, REPRODUCED
from ncd.studies.error_vs_runtime import claims as evr
from ncd.studies.stability import claims as stab


def _write(tmp_path, rel, ds):
    path = tmp_path / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path)


# ---------------------------------------------------------------- Figure 1
R, LO, HI = 0.1, 0.0342, 0.0627


def _ensemble(tmp_path, outcome, iy=None, ix=None, gamma=26.6, beta=20.0):
    outcome = np.asarray(outcome, np.int8)
    n = len(outcome)
    wedged = outcome == 1
    if iy is None:
        iy = np.linspace(LO + 0.01 * (HI - LO), HI, max(wedged.sum(), 1))[: wedged.sum()]
    y, x = np.full(n, np.nan), np.full(n, np.nan)
    y[wedged] = iy
    x[wedged] = 0.0 if ix is None else ix
    zero = np.zeros(n, np.int8)
    zero[: n // 4] = 1
    ds = xr.Dataset({"outcome": ("run", outcome), "zero_guess": ("run", zero), "I_x": ("run", x), "I_y": ("run", y)},
                    coords={"run": np.arange(n)},
                    attrs={"radius": R, "I_y_bottom": LO, "I_y_top": HI, "gamma_deg": gamma, "beta_deg": beta})
    _write(tmp_path, fig1.F1_ENS, ds)


def test_two_evolutions_needs_both_outcomes_above_the_threshold(tmp_path):
    _ensemble(tmp_path, [0] * 10 + [1, 0] * 15)
    v = fig1.fig1_two_evolutions(tmp_path)
    assert v.verdict == REPRODUCED and "of 10 runs fall" in v.value
    _ensemble(tmp_path, [0] * 40)                                   # B always falls: no wedged evolution
    assert fig1.fig1_two_evolutions(tmp_path).verdict == DIFFERS
    _ensemble(tmp_path, [0] * 10 + [1, 0] * 15, gamma=15.0)         # wedged below the threshold: not the paper's B
    assert fig1.fig1_two_evolutions(tmp_path).verdict == DIFFERS


def _sweep(tmp_path, gamma, fractions, beta=20.0):
    ds = xr.Dataset({"wedged_fraction": ("gamma", np.asarray(fractions, float))},
                    coords={"gamma": np.asarray(gamma, float)}, attrs={"threshold_gamma_deg": beta})
    _write(tmp_path, fig1.F1_SWEEP, ds)


def test_threshold_controls(tmp_path):
    g = [5.0, 15.0, 25.0, 35.0]
    _sweep(tmp_path, g, [0.0, 0.0, 0.3, 0.5])
    assert fig1.fig1_threshold(tmp_path).verdict == REPRODUCED
    _sweep(tmp_path, g, [0.0, 0.2, 0.3, 0.5])                     # wedging below β
    assert fig1.fig1_threshold(tmp_path).verdict == DIFFERS
    _sweep(tmp_path, g, [0.0, 0.0, 0.0, 0.5])                     # no wedging just above β
    assert fig1.fig1_threshold(tmp_path).verdict == DIFFERS
    _sweep(tmp_path, [25.0, 35.0], [0.3, 0.5])                    # no angle below β: the threshold is not tested
    assert fig1.fig1_threshold(tmp_path).verdict == DIFFERS


def test_segment_controls(tmp_path):
    _ensemble(tmp_path, [0, 1] * 20)
    assert fig1.fig1_segment(tmp_path).verdict == REPRODUCED
    _ensemble(tmp_path, [0, 1] * 20, ix=0.01 * R)                 # I off the vertical through B's centre
    assert fig1.fig1_segment(tmp_path).verdict == DIFFERS
    _ensemble(tmp_path, [0, 1] * 20, iy=np.full(20, HI + 0.05 * R))   # I above the closed-form top
    assert fig1.fig1_segment(tmp_path).verdict == DIFFERS
    _ensemble(tmp_path, [0] * 20)
    assert fig1.fig1_segment(tmp_path).verdict == DIFFERS


def test_forces_undetermined_controls(tmp_path):
    _ensemble(tmp_path, [0, 1] * 20)
    v = fig1.fig1_undetermined(tmp_path)
    assert v.verdict == REPRODUCED and "20 wedged runs" in v.value
    _ensemble(tmp_path, [0, 1] * 20, iy=np.full(20, HI))           # every wedged run in one force state
    assert fig1.fig1_undetermined(tmp_path).verdict == DIFFERS


def _evolutions(tmp_path, drop_zero, drop_warm):
    t = np.linspace(0.0, 1.0, 11)
    y = np.stack([-drop_zero * t ** 2, -drop_warm * t ** 2])
    ds = xr.Dataset({"y": (("evolution", "step"), y)}, coords={"evolution": ["zero_guess", "wedged_warm"],
                                                              "step": np.arange(11)},
                    attrs={"radius": R, "duration": 1.0,
                           "evolutions": "zero_guess: zero initial guess at every step; wedged_warm: warm"})
    _write(tmp_path, fig1.F1_EVOL, ds)


def test_forces_as_state_controls(tmp_path):
    _evolutions(tmp_path, 4.9, 0.0)
    assert fig1.fig1_forces_as_state(tmp_path).verdict == REPRODUCED
    _evolutions(tmp_path, 4.9, 4.9)                   # the carried forces do not hold B: no memory in them
    assert fig1.fig1_forces_as_state(tmp_path).verdict == DIFFERS
    _evolutions(tmp_path, 0.0, 0.0)                   # nothing falls from the zero guess either
    assert fig1.fig1_forces_as_state(tmp_path).verdict == DIFFERS


# ---------------------------------------------------------------- Figure 2
TOLS = np.array([1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8])


def _measures(tmp_path, zero, warm, n_solutions=2, ratio=1e-5, sticking=True):
    sp = np.zeros((2, len(TOLS), 3))
    sp[0, :, 1], sp[1, :, 1] = zero, warm
    ds = xr.Dataset({"spread": (("init", "tol", "disc"), sp),
                     "ratio": (("init", "tol", "disc"), np.full(sp.shape, ratio))},
                    coords={"init": ["zero", "warm"], "tol": TOLS, "disc": [0, 1, 2]},
                    attrs={"grain": 1, "g": 9.81, "n_solutions": n_solutions, "verdict": "indeterminacy"})
    if sticking:
        ds["switch_distance"] = ("disc", np.array([0, 1, -1]))
        ds["delta_x"] = ("disc", np.array([1.0, 0.5, 0.1]))
        ds["delta_y"] = ("disc", np.zeros(3))
    _write(tmp_path, "fig2_slope/measures.nc", ds)


ZERO = [0.5, 2.9, 5.4, 5.6, 5.6, 5.6]
WARM = [0.4, 0.2, 0.05, 0.01, 2e-4, 2e-5]


def test_dispersion_controls(tmp_path):
    _measures(tmp_path, ZERO, WARM)
    v = fig2.fig2_dispersion(tmp_path)
    assert v.verdict == REPRODUCED and "5.6 m/s²" in v.value
    _measures(tmp_path, [0.5 * 10.0 ** -k for k in range(6)], WARM)          # iteration error: shrinks with tol
    assert fig2.fig2_dispersion(tmp_path).verdict == DIFFERS
    _measures(tmp_path, [1e-6] * 6, WARM)             # flat but invisible: the grain is not affected
    assert fig2.fig2_dispersion(tmp_path).verdict == DIFFERS
    _measures(tmp_path, ZERO, WARM, n_solutions=1)    # one solution: no dispersion between solutions
    assert fig2.fig2_dispersion(tmp_path).verdict == DIFFERS


def test_warm_start_controls_for_both_sentences(tmp_path):
    for judge in (fig2.warm_little, fig2.warm_little_s2):
        _measures(tmp_path, ZERO, WARM)
        assert judge(tmp_path).verdict == REPRODUCED
        _measures(tmp_path, ZERO, ZERO)               # the warm start disperses as much as the zero guess
        assert judge(tmp_path).verdict == DIFFERS
        _measures(tmp_path, ZERO, [0.4, 0.2, 0.9, 0.01, 2e-4, 2e-5])   # visible at a settled tolerance
        assert judge(tmp_path).verdict == DIFFERS
    assert fig2.warm_little_s2(tmp_path).anchor == "claim-s2-warm-little-indeterminacy"


def test_line_is_measured_not_judged(tmp_path):
    _measures(tmp_path, ZERO, WARM, ratio=6.2e-6)
    v = fig2.fig2_line(tmp_path)
    assert v.verdict == BEYOND and "6.2e-06" in v.value
    _measures(tmp_path, ZERO, WARM, ratio=0.4, n_solutions=3)
    v = fig2.fig2_line(tmp_path)
    assert v.verdict == BEYOND and "4.0e-01" in v.value and "3 distinct solutions" in v.value


def _census(tmp_path, status, switching, n_random=None, n_zero=None):
    status = np.asarray(status, np.int8)
    n = status.shape[0]
    ds = xr.Dataset({"status": (("solution", "contact"), status),
                     "switching": ("switching_contact", np.asarray(switching, np.int64)),
                     "n_random": ("solution", np.asarray(n_random if n_random is not None else [1] * n)),
                     "n_zero": ("solution", np.asarray(n_zero if n_zero is not None else [1] * n))},
                    coords={"solution": np.arange(n)},
                    attrs={"random_converged": int(np.sum(n_random)) if n_random is not None else n,
                           "random_guess_scale": 2e-5, "random_plain_runs": 4, "random_plain_same": 4})
    _write(tmp_path, "fig2_slope/census.nc", ds)


def _statuses(switch_pairs, base_stick=50, base_slide=50):
    """Two solutions: ``base_stick`` contacts sticking and ``base_slide`` sliding in both, then the
    switching contacts with the status pairs ``switch_pairs``."""
    same = [1] * base_stick + [2] * base_slide
    a = same + [p[0] for p in switch_pairs]
    b = same + [p[1] for p in switch_pairs]
    return np.array([a, b]), np.arange(len(same), len(same) + len(switch_pairs))


def test_sticking_determinant_controls(tmp_path):
    _measures(tmp_path, ZERO, WARM)
    st, sw = _statuses([(1, 2)] * 10 + [(3, 1)] * 10)              # every switch involves a sticking contact
    _census(tmp_path, st, sw)
    v = fig2.fig2_sticking(tmp_path)
    assert v.verdict == REPRODUCED and "20 of which (100 %)" in v.value
    st, sw = _statuses([(1, 2)] * 10 + [(2, 3)] * 10)              # sticking at the base rate of the step
    _census(tmp_path, st, sw)
    assert fig2.fig2_sticking(tmp_path).verdict == DIFFERS
    st, sw = _statuses([(1, 2)] * 14 + [(2, 3)] * 6, base_stick=80, base_slide=20)   # most stick, as everywhere
    _census(tmp_path, st, sw)
    assert fig2.fig2_sticking(tmp_path).verdict == DIFFERS
    _census(tmp_path, st[:1], [])
    assert fig2.fig2_sticking(tmp_path).verdict == NOT_COMPUTED


def test_random_guesses_reach_every_solution_controls(tmp_path):
    st, sw = _statuses([(1, 2)] * 3)
    _census(tmp_path, st, sw, n_random=[60, 40], n_zero=[200, 300])
    v = fig2.random_guess_any_solution(tmp_path)
    assert v.verdict == REPRODUCED and "solution 1: 40" in v.value
    _census(tmp_path, st, sw, n_random=[100, 0], n_zero=[187, 313])    # a solution outside every random basin
    v = fig2.random_guess_any_solution(tmp_path)
    assert v.verdict == DIFFERS and "never reached: solution(s) 1" in v.value
    _census(tmp_path, st[:1], [], n_random=[100])
    assert fig2.random_guess_any_solution(tmp_path).verdict == NOT_COMPUTED


def _trajectory(tmp_path, accel, noise=1e-4, v0=0.02, step=50, n=60, h=5e-4):
    steps = np.arange(1, n + 1)
    t = h * steps
    vx = v0 + accel * t + noise * np.random.default_rng(3).standard_normal(n)
    ds = xr.Dataset({"time": ("step", t), "mean_vx": ("step", vx)}, coords={"step": steps},
                    attrs={"investigated_step": step, "gravity_x": 3.99})
    _write(tmp_path, "fig2_slope/trajectory.nc", ds)


def test_overall_acceleration_controls(tmp_path):
    _trajectory(tmp_path, 0.94)
    v = fig2.overall_acceleration(tmp_path)
    assert v.verdict == REPRODUCED and "0.9" in v.value
    _trajectory(tmp_path, 0.0)                        # a steady flow: the mean velocity only fluctuates
    assert fig2.overall_acceleration(tmp_path).verdict == DIFFERS
    _trajectory(tmp_path, -0.94)                      # a decelerating flow
    assert fig2.overall_acceleration(tmp_path).verdict == DIFFERS
    _trajectory(tmp_path, 0.05, noise=2e-3)           # a drift lost in the fluctuation
    assert fig2.overall_acceleration(tmp_path).verdict == DIFFERS


# ---------------------------------------------------------------- stability study
def _table(tmp_path, rows):
    keys = ("case", "method", "h", "h_over_hcrit", "diverged", "stable", "max_penetration", "tunnelled",
            "unconverged_steps", "energy_drift", "observable")
    data = {k: ("run", np.array([r.get(k, d) for r in rows])) for k, d in
            zip(keys, ("case", "CD", 1e-3, 1.0, 0, 1, 0.01, 0, 0, -0.1, 0.0))}
    _write(tmp_path, stab.STAB, xr.Dataset(data, coords={"run": np.arange(len(rows))}))


def _stability_rows(**change):
    rows = [dict(method="CD", h_over_hcrit=0.5), dict(method="CD", h_over_hcrit=5.0),
            dict(method="MD", h_over_hcrit=0.2, stable=1), dict(method="MD", h_over_hcrit=2.0, stable=0, diverged=1),
            dict(method="MD", h_over_hcrit=10.0, stable=0, diverged=1)]
    for k, upd in change.items():
        rows[int(k[1:])].update(upd)
    return rows


def test_stability_controls(tmp_path):
    _table(tmp_path, _stability_rows())
    v = stab.stability_cd_md(tmp_path)
    assert v.verdict == REPRODUCED and "MD unstable in 2 of 2 runs" in v.value
    _table(tmp_path, _stability_rows(r3=dict(stable=1, diverged=0)))       # MD stable at 2 h_crit
    assert stab.stability_cd_md(tmp_path).verdict == DIFFERS
    _table(tmp_path, _stability_rows(r1=dict(max_penetration=0.5)))        # no accurate CD run at h >= 2 h_crit
    assert stab.stability_cd_md(tmp_path).verdict == DIFFERS
    _table(tmp_path, _stability_rows(r1=dict(stable=0, max_penetration=0.5)))   # CD's energy grows there
    assert stab.stability_cd_md(tmp_path).verdict == DIFFERS
    _table(tmp_path, _stability_rows(r1=dict(stable=0)))                   # an energy-growing run is not accurate
    assert stab.stability_cd_md(tmp_path).verdict == DIFFERS
    _table(tmp_path, _stability_rows()[:3])                                # no MD run beyond its critical step
    assert stab.stability_cd_md(tmp_path).verdict == DIFFERS


def _collision(tmp_path, e, ratio):
    ds = xr.Dataset({"velocity_ratio": ("restitution", np.asarray(ratio, float))},
                    coords={"restitution": np.asarray(e, float)}, attrs={"h": 1e-3})
    _write(tmp_path, stab.COLLISION, ds)


def _chain(tmp_path, drift, diverged=0):
    _table(tmp_path, [dict(case="e1_chain", method="CD", h=h, energy_drift=drift, observable=0.4, diverged=diverged)
                      for h in (1e-4, 1e-3, 5e-3)] + [dict(case="e1_chain", method="MD", energy_drift=-0.5)])


def test_restitution_controls(tmp_path):
    _collision(tmp_path, [0.0, 0.5], [0.0, -0.5])
    _chain(tmp_path, -7e-8)
    v = stab.restitution(tmp_path)
    assert v.verdict == REPRODUCED and "U_f/U_i = -0.500000" in v.value and "3 CD runs" in v.value
    _chain(tmp_path, -0.3)                            # the multicontact impact loses energy at e = 1
    assert stab.restitution(tmp_path).verdict == DIFFERS
    _chain(tmp_path, -7e-8, diverged=1)               # the chain does not run through
    assert stab.restitution(tmp_path).verdict == DIFFERS
    _chain(tmp_path, -7e-8)
    _collision(tmp_path, [0.0, 0.5], [0.0, -0.3])     # Newton's law broken in the binary collision
    assert stab.restitution(tmp_path).verdict == DIFFERS
    # the file of one collision written before the e = 0 one was added
    _write(tmp_path, stab.COLLISION, xr.Dataset({"velocity_ratio": ((), -0.5)}, attrs={"restitution": 0.5}))
    assert stab.restitution(tmp_path).verdict == REPRODUCED


def test_inelastic_is_consistent_with_its_value(tmp_path):
    _collision(tmp_path, [0.0, 0.5], [1e-17, -0.5])
    v = stab.inelastic(tmp_path)
    assert v.verdict == CONSISTENT and "1.0e-17" in v.value
    _collision(tmp_path, [0.0, 0.5], [-0.2, -0.5])    # a scheme that bounces at e = 0 is broken
    assert stab.inelastic(tmp_path).verdict == DIFFERS


def test_binary_collision_file_holds_both_restitutions(tmp_path):
    from ncd.studies.stability.measure import binary_collision

    ds = binary_collision()
    assert list(ds.restitution.values) == [0.0, 0.5]
    assert ds.velocity_ratio.attrs["units"] == "1" and ds.restitution.attrs["long_name"]
    np.testing.assert_allclose(ds.velocity_ratio.values, [0.0, -0.5], atol=1e-9)
    _write(tmp_path, stab.COLLISION, ds)
    assert stab.inelastic(tmp_path).verdict == CONSISTENT


# ---------------------------------------------------------------- work-precision study
NL_TOLS = np.array([1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8])


def _nlgs(tmp_path, zero, warm, converged=None):
    """Sweeps per state (rows) and tolerance (columns), residual criterion."""
    zero, warm = np.asarray(zero, float), np.asarray(warm, float)
    sweeps = np.stack([zero, warm], 1)[:, :, None, :].astype(np.int64)          # state, init, criterion, tol
    conv = np.ones(sweeps.shape, np.int8) if converged is None else converged
    ds = xr.Dataset({"sweeps": (("state", "init", "criterion", "tol"), sweeps),
                     "converged": (("state", "init", "criterion", "tol"), conv)},
                    coords={"state": ["packing28", "slope"][: len(zero)], "init": ["zero", "warm"],
                            "criterion": ["residual"], "tol": NL_TOLS})
    _write(tmp_path, "error_vs_runtime/nlgs.nc", ds)


def test_warm_accelerates_controls(tmp_path):
    zero = [[40, 200, 400, 600, 900, 1200]] * 2
    _nlgs(tmp_path, zero, [[4, 20, 40, 60, 90, 120]] * 2)              # ten times fewer sweeps everywhere
    v = evr.warm_accelerates_states(tmp_path)
    assert v.verdict == REPRODUCED and "packing28: 10" in v.value
    _nlgs(tmp_path, zero, zero)                                        # the warm start saves nothing
    assert evr.warm_accelerates_states(tmp_path).verdict == DIFFERS
    # a saving at the loosest tolerances only (a fixed number of sweeps saved): the median is below 3
    _nlgs(tmp_path, zero, [[1, 20, 300, 500, 800, 1100]] * 2)
    v = evr.warm_accelerates_states(tmp_path)
    assert v.verdict == DIFFERS and "1.3" in v.value
    # one dense state where it saves nothing: the sentence speaks of every dense collection
    _nlgs(tmp_path, zero, [[4, 20, 40, 60, 90, 120], [40, 200, 400, 600, 900, 1200]])
    assert evr.warm_accelerates_states(tmp_path).verdict == DIFFERS
    # tolerances where a start did not converge are left out
    conv = np.ones((2, 2, 1, 6), np.int8)
    conv[:, 1, 0, 3:] = 0
    _nlgs(tmp_path, zero, [[4, 20, 40, 1200, 1200, 1200]] * 2, converged=conv)
    v = evr.warm_accelerates_states(tmp_path)
    assert v.verdict == REPRODUCED and "over 3 tolerances" in v.value
