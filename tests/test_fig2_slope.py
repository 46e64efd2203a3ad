"""Figure 2 (section 3): spread measures on synthetic clouds, and the figure data.

The figure-data tests read ``results/fig2_slope`` of a DAG run (the reduced
configuration unless ``NCD_RESULTS_DIR`` points at a full run) and recompute
what they check from the raw ensemble, not from ``measures.nc``.
"""
import json

import numpy as np
import pytest
import xarray as xr
import yaml

import ncd
from ncd.figures.fig2_slope import census
from ncd.shared import slope
from ncd.shared import slope_analysis as sa


# ------------------------------------------------------------------ measures
def rotation(deg):
    t = np.radians(deg)
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def test_cloud_stats_exact_on_a_cross():
    # (+-a, 0), (0, +-b) rotated by 30°: covariance diag(a^2/2, b^2/2) in the rotated frame
    a, b = 3.0, 0.5
    pts = np.array([[a, 0], [-a, 0], [0, b], [0, -b]]) @ rotation(30.0).T + [1.0, -2.0]
    s = sa.cloud_stats(pts[:, 0], pts[:, 1])
    assert s["mean_x"] == pytest.approx(1.0) and s["mean_y"] == pytest.approx(-2.0)
    assert s["major"] == pytest.approx(a / np.sqrt(2), rel=1e-12)
    assert s["minor"] == pytest.approx(b / np.sqrt(2), rel=1e-12)
    assert s["ratio"] == pytest.approx(b / a, rel=1e-12)
    assert s["spread"] == pytest.approx(np.sqrt((a * a + b * b) / 2), rel=1e-12)
    assert s["angle"] == pytest.approx(30.0, abs=1e-9)


@pytest.mark.parametrize("deg", [-89.0, -45.0, 0.0, 24.0, 90.0])
def test_cloud_stats_principal_axes_of_a_gaussian_cloud(deg):
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(20000, 2)) * [2.0, 0.2] @ rotation(deg).T
    s = sa.cloud_stats(pts[:, 0], pts[:, 1])
    assert s["major"] == pytest.approx(2.0, rel=0.03)
    assert s["minor"] == pytest.approx(0.2, rel=0.03)
    assert s["ratio"] == pytest.approx(0.1, rel=0.05)
    diff = (s["angle"] - deg + 90.0) % 180.0 - 90.0   # an axis, defined modulo 180°
    assert abs(diff) < 1.0
    assert -90.0 < s["angle"] <= 90.0


def test_cloud_stats_vectorized_matches_numpy_cov():
    rng = np.random.default_rng(4)
    x, y = rng.normal(size=(2, 3, 5, 50))
    y = y + 0.7 * x
    s = sa.cloud_stats(x, y)
    for i in range(3):
        for j in range(5):
            c = np.cov(x[i, j], y[i, j], bias=True)
            w = np.linalg.eigvalsh(c)
            assert s["cov_xy"][i, j] == pytest.approx(c[0, 1], rel=1e-10)
            assert s["major"][i, j] == pytest.approx(np.sqrt(w[1]), rel=1e-10)
            assert s["minor"][i, j] == pytest.approx(np.sqrt(w[0]), rel=1e-9)


def test_cloud_stats_of_a_segment_and_of_a_point():
    t = np.linspace(-1, 1, 11)
    s = sa.cloud_stats(2 * t, -t)           # on the line y = -x/2
    assert s["minor"] < 1e-12 and s["ratio"] < 1e-12
    assert s["angle"] == pytest.approx(np.degrees(np.arctan2(-1, 2)), abs=1e-9)
    p = sa.cloud_stats(np.ones(5), np.ones(5))
    assert p["spread"] == 0.0 and np.isnan(p["ratio"])


def test_solutions_groups_runs_by_field():
    rng = np.random.default_rng(5)
    centres = rng.normal(size=(3, 40))
    pick = np.array([0] * 7 + [1] * 2 + [2] * 11)
    rng.shuffle(pick)
    fields = centres[pick] + rng.uniform(-1e-4, 1e-4, size=(len(pick), 40))
    labels, reps = sa.solutions(fields, 1e-3)
    assert np.bincount(labels).tolist() == [11, 7, 2]          # most frequent first
    for k in range(3):                                          # a label is one original group
        assert len(set(pick[labels == k])) == 1
        assert labels[reps[k]] == k
    one, _ = sa.solutions(fields, 100.0)
    assert (one == 0).all()


def test_verdict_rules():
    tol = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
    plateau = [0.9, 1.0, 1.0, 1.0, 1.0]
    shrinking = [1.0, 0.1, 0.01, 1e-3, 1e-4]
    assert sa.verdict(tol, plateau, shrinking, floor=0.1)[0] == "indeterminacy"
    assert sa.verdict(tol, shrinking, shrinking, floor=0.1)[0] == "iteration error"
    # a plateau that the warm-start runs share is not the paper's contrast
    assert sa.verdict(tol, plateau, plateau, floor=0.1)[0] == "undecided"
    # a plateau below the floor is not an indeterminacy
    assert sa.verdict(tol, [1e-3] * 5, shrinking, floor=0.1)[0] == "undecided"
    with pytest.raises(ValueError, match="decades"):
        sa.verdict([1e-6, 1e-7], [1, 1], [0, 0], floor=0.1)


def test_rigid_clusters_and_switch_distance():
    # grains 0-1-2 stick in a chain, 3-4 stick, 2-3 slides, 4 sticks to the ground (index 5)
    a = np.array([0, 1, 2, 3, 4])
    b = np.array([1, 2, 3, 4, 5])
    stick = np.array([True, True, False, True, True])
    labels = sa.rigid_clusters(5, a, b, stick)
    assert labels[0] == labels[1] == labels[2] != labels[3] == labels[4]
    dist = sa._switch_distance(5, a, b, stick, [0])
    assert dist.tolist() == [0, 1, 2, -1, -1]


def test_cluster_motion_fit_recovers_a_rigid_motion():
    rng = np.random.default_rng(6)
    pos = rng.uniform(0, 1, size=(6, 2))
    labels = np.array([0, 0, 0, 1, 1, 1])
    dv, dw = np.array([[0.3, -0.1], [1.0, 2.0]]), np.array([2.0, -1.0])
    delta = np.zeros_like(pos)
    for k in (0, 1):
        m = labels == k
        c = pos[m].mean(0)
        r = pos[m] - c
        delta[m] = dv[k] + dw[k] * np.column_stack([-r[:, 1], r[:, 0]])
    fit, size = sa.cluster_motion_fit(pos, delta, labels)
    np.testing.assert_allclose(fit, delta, atol=1e-12)
    assert size.tolist() == [3] * 6


# ------------------------------------------------------------------ figure data
@pytest.fixture(scope="module")
def data(results):
    base = results / "fig2_slope"
    traj = xr.load_dataset(base / "trajectory.nc")
    ens = xr.load_dataset(base / "ensemble.nc")
    meas = xr.load_dataset(base / "measures.nc")
    cfg = yaml.safe_load(ens.attrs["config_yaml"])
    an = yaml.safe_load(meas.attrs["config_yaml"])
    return traj, ens, meas, cfg, an


def raw_spread(ens, init, disc):
    """RMS distance to the mean of one grain's cloud, per tolerance, from the raw data."""
    e = ens.sel(init=init, disc=disc)
    return np.sqrt(e.accel_x.var("run") + e.accel_y.var("run")).values


def test_every_run_converged_to_its_tolerance(data):
    _, ens, _, cfg, _ = data
    assert ens.sizes["run"] == cfg["explore"]["runs"]
    assert list(ens.init.values) == ["zero", "warm"]
    assert bool(ens.converged.all()), "some runs did not converge: raise explore.max_sweeps"
    tol = ens.tol.broadcast_like(ens.residual)
    assert bool((ens.residual <= tol).all())
    assert bool((ens.sweeps.diff("tol") >= 0).all()) and bool((ens.wall_time.diff("tol") >= 0).all())
    np.testing.assert_array_equal(ens.run.values, np.arange(cfg["explore"]["runs"]))


def test_spread_against_tolerance_supports_the_verdict(data):
    _, ens, meas, _, an = data
    grain, verdict = int(meas.attrs["grain"]), meas.attrs["verdict"]
    g = float(meas.attrs["g"])
    tol = ens.tol.values
    zero, warm = raw_spread(ens, "zero", grain), raw_spread(ens, "warm", grain)
    np.testing.assert_allclose(meas.spread.sel(init="zero", disc=grain), zero, rtol=1e-9)
    window = tol <= tol.min() * 10 ** an["decades"] * (1 + 1e-9)
    assert np.log10(tol[window].max() / tol.min()) >= 2 - 1e-9, "the tolerances must span two decades"
    if verdict == "indeterminacy":
        assert (zero[window] >= an["floor"] * g).all(), zero
        assert zero[-1] >= 0.5 * zero[window][0], "the zero-guess spread must not shrink with the tolerance"
        assert zero[-1] >= 10 * warm[-1], (zero[-1], warm[-1])
        assert meas.attrs["n_solutions"] >= 2
    elif verdict == "iteration error":
        assert zero[-1] <= 0.1 * zero[window][0], zero
    else:
        pytest.fail(f"no decisive verdict ({verdict}): choose another step in config (flow.step)")
    # the rule that chose the grain
    if an["grain"] < 0:
        every = np.sqrt(ens.sel(init="zero", tol=tol.min()).accel_x.var("run")
                        + ens.sel(init="zero", tol=tol.min()).accel_y.var("run")).values
        assert grain == int(np.argmax(every))


def test_the_notebook_states_the_verdict_and_the_cloud_shape(data, results):
    _, ens, meas, _, an = data
    nb = json.loads((results / "notebooks" / "fig2_slope.ipynb").read_text())
    outputs = [o for c in nb["cells"] if c["cell_type"] == "code" for o in c.get("outputs", [])]
    md = "".join("".join(o.get("data", {}).get("text/markdown", "")) for o in outputs)
    html = "".join("".join(o.get("data", {}).get("text/html", "")) for o in outputs)
    assert not any(o.get("name") == "stdout" for o in outputs), "the page prints a log"
    assert f"Verdict of the rule below: **{meas.attrs['verdict']}**" in md
    grain = int(meas.attrs["grain"])
    ratio = float(meas.ratio.sel(init="zero", tol=ens.tol.min(), disc=grain))
    assert f"{ratio:.1e}" in html
    # the prose describes the cloud from the census (which solutions, how far from them)
    from ncd.figures.fig2_slope import census as cs
    cen = xr.load_dataset(results / "fig2_slope" / "census.nc")
    cloud = sa.cloud_against_census(ens, cen, grain, "zero")
    assert cs.cloud_text(cloud, grain, float(ens.tol.min()), an["line_ratio"]) in md
    assert "two isolated solutions" not in md and "line is made of two points" not in md


def test_spread_is_the_rms_distance_to_the_mean(data):
    """``spread`` (measures.nc) is what its long_name says: per init, tolerance and grain, the
    root mean square over the runs of the distance of the acceleration to its mean (not the
    largest distance, which is larger wherever a cloud has more than two points)."""
    _, ens, meas, _, _ = data
    ax, ay = ens.accel_x.transpose("init", "tol", "disc", "run"), ens.accel_y.transpose("init", "tol", "disc", "run")
    dist = np.hypot(ax - ax.mean("run"), ay - ay.mean("run")).values
    rms = np.sqrt((dist ** 2).mean(-1))
    np.testing.assert_allclose(meas.spread.transpose("init", "tol", "disc").values, rms, rtol=1e-9, atol=1e-12)
    assert meas.spread.attrs["long_name"].startswith("RMS distance of the acceleration to its mean")
    assert "largest" not in meas.spread.attrs["long_name"]
    largest = dist.max(-1)
    moving = rms > 1e-9
    assert np.all(largest[moving] >= rms[moving] * (1 - 1e-12))


def test_the_page_sentences_quote_the_files(data):
    """The page's sentences and tables count what the files hold; its figure is readable."""
    from figure_checks import problems

    from ncd.figures.fig2_slope import page

    traj, ens, meas, _, an = data
    cfg = {**yaml.safe_load(traj.attrs["config_yaml"]), "analysis": an}
    grain = int(meas.attrs["grain"])
    text = page.spread_sentence(ens, meas, cfg)
    assert f"grain {grain}" in text and f"**{meas.attrs['verdict']}**" in text
    n_conv = int(ens.sel(init="zero", tol=ens.tol.min()).converged.sum())
    assert f"zero {n_conv} of {ens.sizes['run']}" in text
    assert len(page.tolerance_table(ens, meas)) == ens.sizes["init"] * ens.sizes["tol"]
    sol = page.solutions_sentence(meas, cfg)
    assert f"reach {int(meas.attrs['n_solutions'])} distinct solution(s)" in sol
    if "scan_step" in traj.dims:
        several = int((traj.scan_zero_solutions.values > 1).sum())
        assert f"at {several} steps from the zero guess" in page.scan_sentence(traj, cfg)
    assert problems(page.plot(traj, ens, meas, cfg)) == []
    cap = page.caption(ens, meas)
    assert f"reach {int(meas.attrs['n_solutions'])} distinct solution(s)" in cap and meas.attrs["verdict"] in cap


def _ratio(x, y, weights=None):
    """minor/major axis of a 2-D cloud (square root of the covariance eigenvalue ratio)."""
    if len(x) < 2:
        return 0.0
    w = np.linalg.eigvalsh(np.cov(x, y, aweights=weights, bias=True))
    return float(np.sqrt(max(w[0], 0.0) / w[1])) if w[1] > 0 else 0.0


def test_the_cloud_is_the_census_solutions_plus_the_iteration_error(data, results):
    """The chosen grain's zero-guess cloud at the tightest tolerance, read through the census:
    every converged run sits within basin_tol |g| of one census solution (the census's own
    basin counts), and the cloud's principal axes are those of the solutions' points to within
    the runs' RMS distance to them (singular values are 1-Lipschitz).  One solution visited:
    the cloud is iteration error (its spread below that distance, no 'indeterminacy' verdict);
    several: the solutions' separation exceeds the iteration error."""
    _, ens, meas, _, an = data
    cen = xr.load_dataset(results / "fig2_slope" / "census.nc")
    ccfg = yaml.safe_load(cen.attrs["config_yaml"])
    grain, g = int(meas.attrs["grain"]), float(meas.attrs["g"])
    c = sa.cloud_against_census(ens, cen, grain, "zero")
    e = ens.sel(init="zero", tol=ens.tol.min(), disc=grain)
    ok = e.converged.values.astype(bool)
    assert c["n_converged"] == ok.sum() >= 1
    assert c["n_labelled"] == c["n_converged"] == int(cen.n_zero.sum())
    np.testing.assert_array_equal(c["counts"], cen.n_zero.values[c["visited"]])
    assert c["ratio"] == pytest.approx(_ratio(e.accel_x.values[ok], e.accel_y.values[ok]), rel=1e-6, abs=1e-9)
    if ok.all():
        assert c["ratio"] == pytest.approx(float(meas.ratio.sel(init="zero", tol=ens.tol.min(), disc=grain)),
                                           rel=1e-6, abs=1e-9)
    slack = 1e-9 * max(c["major"], 1e-300) + 1e-15
    assert abs(c["major"] - c["census_major"]) <= c["rms_offset"] + slack
    assert c["minor"] <= c["census_minor"] + c["rms_offset"] + slack
    assert c["max_offset"] <= ccfg["basin_tol"] * g
    if len(c["visited"]) == 1:
        assert c["spread"] <= c["rms_offset"] + slack
        assert meas.attrs["verdict"] != "indeterminacy"
    else:
        assert c["census_major"] > c["rms_offset"]
        assert meas.attrs["n_solutions"] >= 2


def test_cloud_against_census_on_a_synthetic_segment():
    """Runs on two of three solutions plus a small error: labels, counts and the axis bound."""
    rng = np.random.default_rng(7)
    sol = rng.normal(size=(3, 5, 2))                      # 3 solutions, 5 discs
    pick = np.array([0] * 7 + [2] * 13)
    err = 1e-6 * rng.normal(size=(20, 5, 2))
    runs = sol[pick] + err
    acc = np.stack([runs + 1.0, runs])                    # tol axis: loose (far off), tight
    ens = xr.Dataset({"accel_x": (("init", "tol", "run", "disc"), acc[None, ..., 0]),
                      "accel_y": (("init", "tol", "run", "disc"), acc[None, ..., 1]),
                      "converged": (("init", "tol", "run"), np.ones((1, 2, 20), bool))},
                     coords={"init": ["zero"], "tol": [1e-4, 1e-8]})
    cen = xr.Dataset({"accel_x": (("solution", "disc"), sol[..., 0]), "accel_y": (("solution", "disc"), sol[..., 1])},
                     attrs={"g": 9.81, "config_yaml": yaml.safe_dump({"basin_tol": 1e-3})})
    c = sa.cloud_against_census(ens, cen, 3, "zero")
    assert c["visited"].tolist() == [0, 2] and c["counts"].tolist() == [7, 13] and c["n_solutions"] == 3
    assert c["census_minor"] <= 1e-12 * c["census_major"]          # two points: a segment
    assert c["rms_offset"] == pytest.approx(np.sqrt(np.mean(np.sum(err[:, 3] ** 2, -1))), rel=1e-9)
    assert abs(c["major"] - c["census_major"]) <= c["rms_offset"] and c["minor"] <= c["rms_offset"]
    assert "2 of the census's 3 exact solutions, a segment" in census.cloud_text(c, 3, 1e-8, 0.05)


def test_status_patterns_combine_the_changes_cluster_by_cluster():
    """Three solutions on six contacts: contacts 1, 2 (grain 5 shared) and 4 switch; two
    clusters, all combinations of the statuses seen (2 x 2 at the pair, 3 at contact 4 = 12,
    less the 3 solutions' own); with a small budget, every single-cluster change first."""
    from types import SimpleNamespace
    st = np.array([[1, 1, 1, 0, 2, 1], [1, 2, 1, 0, 3, 1], [1, 1, 3, 0, 0, 1]], np.int8)
    contacts = SimpleNamespace(body_a=np.array([0, 5, 5, 7, 8, 9]), body_b=np.array([1, 6, 2, 10, 11, 12]))
    sw = sa.switching_contacts(st)
    assert sw.tolist() == [1, 2, 4]
    clusters = sa.contact_clusters(contacts, 10, sw)
    assert sorted(map(list, clusters)) == [[1, 2], [4]]
    pats, sw2, ncl = sa.status_patterns(st, contacts, 10, 100, np.random.default_rng(0))
    assert ncl == 2 and sw2.tolist() == [1, 2, 4]
    assert len(pats) == 12 - 3 and len({p.tobytes() for p in pats}) == len(pats)
    assert np.all(pats[:, [0, 3, 5]] == st[0, [0, 3, 5]])
    assert {tuple(p[[1, 2]]) for p in pats} == {(1, 1), (1, 3), (2, 1), (2, 3)}
    few, _, _ = sa.status_patterns(st, contacts, 10, 5, np.random.default_rng(0))
    assert len(few) <= 5
    single = {(int(p[1]), int(p[2]), int(p[4])) for p in few}
    assert (2, 1, 2) in single and (1, 1, 3) in single      # solution 0 with one cluster changed


def test_the_flow_is_accelerating_at_the_investigated_step(data):
    traj, _, _, _, _ = data
    k = int(traj.attrs["investigated_step"])
    i = k - 1
    vx = traj.mean_vx.values
    assert vx[i] > 0
    # a phase of overall acceleration: the mean velocity grows over +-10 steps (the
    # step itself may hold a collision) and so does the kinetic energy
    lo, hi = max(0, i - 10), min(len(vx), i + 11)
    slope_fit = np.polyfit(traj.time.values[lo:hi], vx[lo:hi], 1)[0]
    assert slope_fit > 0.01 * float(np.hypot(traj.attrs["gravity_x"], traj.attrs["gravity_y"]))
    assert traj.kinetic_energy.values[i] > traj.kinetic_energy.values[lo]
    assert vx[hi - 1] > vx[lo]


def test_the_restart_reproduces_the_trajectory_step(data):
    """Rebuilt state + previous impulses + the flow's settings give the trajectory's own step."""
    traj, _, _, cfg, _ = data
    scene = slope.scene_at_step(traj, cfg)
    problem = ncd.prepare_step(scene, float(traj.attrs["h"]))
    guess = ncd.dynamics.stepper.initial_guess(scene, problem, "warm")
    assert np.count_nonzero(guess[:, 0]) > 0.5 * problem.contacts.n
    settings = ncd.SolverSettings(**cfg["flow"]["solver"])
    result, vel, _ = ncd.solve_problem(scene, problem, guess, None, settings)
    acc = (vel[: scene.n_mobile] - scene.vel[: scene.n_mobile]) / problem.h
    np.testing.assert_allclose(acc[:, 0], traj.reference_accel_x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(acc[:, 1], traj.reference_accel_y, rtol=0, atol=1e-9)


def test_warm_runs_with_local_exact_solves_land_on_plain_nlgs_solution(data):
    """The warm runs use local exact solves; the first plain_check_runs members were also run by
    plain NLGS, and both end points are the same solution at the tightest tolerance (closer
    than the threshold that tells two solutions apart; at looser ones plain NLGS may still
    sit on its plateau); the other members are not checked (NaN)."""
    _, ens, _, cfg, an = data
    ecfg = cfg["explore"]
    assert int(ens.attrs["warm_local_exact"]) == int(ecfg["warm_local_exact"])
    dist = ens.warm_plain_distance
    checked = ens.run.values < ecfg["plain_check_runs"]
    assert checked.any() and np.isnan(dist.values[:, ~checked]).all()
    assert (dist.isel(tol=-1).values[checked] <= an["solution_threshold"]).all()
    text = sa.warm_check(ens, an["solution_threshold"])
    assert f"{int(checked.sum())} of them" in text and "same solution" in text


def test_warm_check_sentence_on_a_synthetic_ensemble():
    ens = xr.Dataset({"warm_plain_distance": (("tol", "run"), [[1e-6, np.nan, 3e-5], [2e-7, np.nan, 4e-6]])},
                     coords={"tol": [1e-6, 1e-8], "run": [0, 1, 2]}, attrs={"warm_local_exact": 1})
    text = sa.warm_check(ens, 1e-3)
    assert "2 of them" in text and "4.0e-06 |g|" in text and "same solution" in text
    assert "different solutions" in sa.warm_check(ens, 1e-6)
    assert sa.warm_check(ens.assign_attrs(warm_local_exact=0), 1e-3) is None


def test_a_member_does_not_depend_on_its_shard(data):
    traj, ens, _, cfg, _ = data
    member = int(ens.run.values[-1])
    alone = slope.run_ensemble(traj, cfg, [member])
    for v in ("accel_x", "accel_y", "sweeps", "residual", "converged", "impulse_n", "impulse_t", "status"):
        np.testing.assert_array_equal(alone[v].sel(run=member).values, ens[v].sel(run=member).values, err_msg=v)


def test_census_solutions_are_exact_and_contain_the_nlgs_end_points(data, results):
    """Every census solution is polished to a residual <= 1e-12 and satisfies the contact law
    componentwise; every converged NLGS run of the ensemble ends on one of them; the census
    recomputes its solutions' accelerations from its impulses."""
    from ncd.dynamics.stepper import prepare_step
    from ncd.shared.slope import scene_at_step
    from ncd.shared.step_solutions import StepSolutions
    traj, ens, meas, cfg, an = data
    cen = xr.load_dataset(results / "fig2_slope" / "census.nc")
    ccfg = yaml.safe_load(cen.attrs["config_yaml"])
    assert cen.sizes["solution"] >= meas.sizes["solution"] >= 1
    assert cen.residual.max() <= ccfg["polish_tol"] and cen.law_violation.max() <= 1e-10
    tight = ens.isel(tol=-1)
    ok = tight.converged.values.astype(bool)
    assert sum(int(cen[f"n_{i}"].sum()) for i in ens.init.values) == ok.sum()
    assert cen.by_nlgs.sum() >= meas.sizes["solution"]
    step = StepSolutions(scene_at_step(traj, {"scene": cfg["scene"], "flow": cfg["flow"]}),
                            prepare_step(scene_at_step(traj, {"scene": cfg["scene"], "flow": cfg["flow"]}),
                                         float(traj.attrs["h"])))
    for k in range(cen.sizes["solution"]):
        s = np.column_stack([cen.impulse_n.values[k], cen.impulse_t.values[k]])
        assert step.residual(s) <= ccfg["polish_tol"]
        a = step.accel(s)
        assert np.abs(a[:, 0] - cen.accel_x.values[k]).max() <= 1e-9 * step.g
    if cen.sizes["solution"] >= 2:               # the segment between the two most visited solutions, measured
        i, j = (int(v) for v in np.atleast_1d(cen.attrs["segment_pair"]))
        si, sj = (np.column_stack([cen.impulse_n.values[k], cen.impulse_t.values[k]]) for k in (i, j))
        for t, r in zip(cen.segment_t.values, cen.segment_residual.values):
            assert step.residual((1 - t) * si + t * sj) == pytest.approx(r, rel=1e-6)
    sw = np.nonzero((cen.status.values != cen.status.values[:1]).any(0))[0]
    np.testing.assert_array_equal(cen.switching.values, sw)
    for i in range(cen.sizes["solution"]):       # distinct: fields differ by more than same_tol |g|
        for j in range(i):
            d = max(np.abs(cen.accel_x.values[i] - cen.accel_x.values[j]).max(),
                    np.abs(cen.accel_y.values[i] - cen.accel_y.values[j]).max())
            assert d > ccfg["same_tol"] * step.g


def test_census_random_runs_by_local_exact_solves_end_where_plain_nlgs_ends(results):
    """The census's random-guess runs make local exact solves where NLGS stalls; the members
    rerun by plain NLGS (same guesses, same orders) all end on the same census solution, their
    accelerations within basin_tol |g| of the local route's, and the page says so."""
    cen = xr.load_dataset(results / "fig2_slope" / "census.nc")
    ccfg = yaml.safe_load(cen.attrs["config_yaml"])
    a = cen.attrs
    assert ccfg["random_local_exact"] and int(a["random_plain_runs"]) == min(ccfg["random_plain_check"],
                                                                          ccfg["random_runs"]) > 0
    assert int(a["random_plain_same"]) == int(a["random_plain_runs"])
    assert 0 <= float(a["random_plain_distance"]) <= ccfg["basin_tol"]
    assert f"{int(a['random_plain_same'])} of {int(a['random_plain_runs'])} of them rerun by plain NLGS" \
        in census.census_text(cen)


def test_angles_say_what_they_hold(data):
    """``trajectory.angle`` is the discs' rotation in radians (it was labelled degrees): at the
    investigated step it differs from the stored frame of that step by at most one step of spin.
    ``measures.angle`` is the direction of the cloud's major axis, in degrees."""
    traj, ens, meas, _, _ = data
    assert traj.angle.attrs["units"] == "rad"
    k = int(traj.attrs["investigated_step"])
    at = np.nonzero(traj.frame_step.values == k)[0]
    if len(at):
        step_turn = float(traj.attrs["h"]) * np.abs(traj.frame_spin.values[at[0]]).max()
        assert np.abs(traj.frame_angle.values[at[0]] - traj.angle.values).max() <= 2 * step_turn + 1e-12
    assert meas.angle.attrs["units"] == "degree" and "major principal axis" in meas.angle.attrs["long_name"]
    ax, ay = ens.accel_x.isel(tol=-1), ens.accel_y.isel(tol=-1)
    dx, dy = ax - ax.mean("run"), ay - ay.mean("run")
    expect = np.degrees(0.5 * np.arctan2(2 * (dx * dy).mean("run"), (dx * dx).mean("run") - (dy * dy).mean("run")))
    expect = xr.where(expect <= -90, expect + 180, expect)
    got = meas.angle.isel(tol=-1)
    elongated = (meas.ratio.isel(tol=-1) < 0.5) & (meas.major.isel(tol=-1) > 1e-9)
    assert bool(elongated.any())
    np.testing.assert_allclose(got.where(elongated).transpose("init", "disc").values,
                               expect.where(elongated).transpose("init", "disc").values, atol=1e-6)


def test_census_is_the_same_on_one_and_two_threads(data, results):
    """The census runs its NLGS runs, Lemke runs, projections and restarts side by side on
    the rule's threads, adding to the census in a fixed order: census.nc is the same
    bit for bit whatever the thread count."""
    import numba
    traj, ens, meas, cfg, _ = data
    ref = xr.load_dataset(results / "fig2_slope" / "census.nc")
    cfg = {**cfg, "census": yaml.safe_load(ref.attrs["config_yaml"])}
    before = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            ds = census.census_dataset(traj, ens, meas, cfg)
            for v in ref.data_vars:
                np.testing.assert_array_equal(ds[v].values, ref[v].values, err_msg=f"{v}, {threads} threads")
    finally:
        numba.set_num_threads(before)
