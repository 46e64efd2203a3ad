"""Physically invalid input raises ncd.InputError naming the offending key and
value; a state that goes non-finite or diverges while stepping raises
ncd.SimulationError instead of returning NaN."""
import re

import numpy as np
import pytest

import ncd

FLOOR = [((0.0, 0.0), (0.0, 1.0))]
POS = [[0.0, 0.5], [2.0, 0.5]]


def scene(**kw):
    args = dict(pos=POS, radius=0.5, density=1.0, walls=FLOOR)
    args.update(kw)
    return ncd.make_scene(**args)


def test_input_error_is_a_value_error():
    assert issubclass(ncd.InputError, ValueError)
    assert issubclass(ncd.SimulationError, RuntimeError)


@pytest.mark.parametrize("kw, pattern", [
    (dict(pos=[[0.0, 0.5], [0.9, 0.5]]), r"overlap between disc 0 and disc 1 .*overlap_tolerance = 0\.01"),
    (dict(pos=[[0.0, 0.3]]), r"overlap between disc 0 and wall 0 .*overlap_tolerance"),
    (dict(pos=[[0.0, 0.5]], obstacle_pos=[[0.95, 0.5]], obstacle_radius=0.5),
     r"overlap between disc 0 and disc 1 is 0\.05"),
    (dict(radius=[0.5, 0.0]), r"radius must be > 0; radius\[1\] = 0\.0"),
    (dict(radius=[-0.5, 0.5]), r"radius must be > 0; radius\[0\] = -0\.5"),
    (dict(obstacle_pos=[[5.0, 0.5]], obstacle_radius=-1.0), r"obstacle_radius must be > 0; obstacle_radius\[0\] = -1\.0"),
    (dict(density=[1.0, 0.0]), r"density must be > 0; density\[1\] = 0\.0"),
    (dict(density=-2.0), r"density must be > 0; density\[0\] = -2\.0"),
    (dict(mu=-0.1), r"mu = -0\.1 is outside"),
    (dict(mu_obstacle=-1.0), r"mu_obstacle = -1\.0 is outside"),
    (dict(mu=np.nan), r"mu = nan is outside"),
    (dict(e_n=1.5), r"e_n = 1\.5 is outside \[0\.0, 1\.0\]"),
    (dict(e_n=-0.2), r"e_n = -0\.2 is outside \[0\.0, 1\.0\]"),
    (dict(e_t=2.0), r"e_t = 2\.0 is outside"),
    (dict(e_n_obstacle=1.01), r"e_n_obstacle = 1\.01 is outside"),
    (dict(pos=[[0.0, 0.5], [np.nan, 0.5]]), r"pos must be finite; pos\[1, 0\] = nan"),
    (dict(pos=[[0.0, np.inf], [2.0, 0.5]]), r"pos must be finite; pos\[0, 1\] = inf"),
    (dict(gravity=(0.0, np.inf)), r"gravity must be finite; gravity\[1\] = inf"),
    (dict(gravity=(np.nan, -9.81)), r"gravity must be finite; gravity\[0\] = nan"),
    (dict(vel=[[0.0, 0.0], [np.nan, 0.0]]), r"vel must be finite"),
    (dict(radius=[0.5, np.inf]), r"radius must be finite"),
    (dict(period=-1.0), r"period = -1\.0 is outside"),
    (dict(period=2.0), r"period = 2\.0 must be at least three largest diameters"),
    (dict(walls=[((0.0, 0.0), (0.0, 0.0))]), r"walls\[0\]\.normal is zero"),
])
def test_make_scene_rejects(kw, pattern):
    with pytest.raises(ncd.InputError, match=pattern):
        scene(**kw)


def test_overlap_tolerance_is_honoured():
    """An overlap of 5% of the radius passes with overlap_tolerance = 0.1 only."""
    pos = [[0.0, 0.5], [0.975, 0.5]]
    with pytest.raises(ncd.InputError, match=r"overlap between disc 0 and disc 1 is 0\.025"):
        scene(pos=pos)
    assert scene(pos=pos, overlap_tolerance=0.1).n_mobile == 2


@pytest.mark.parametrize("h", [0.0, -1e-3, np.nan, np.inf])
def test_step_rejects_bad_h(h):
    s = scene()
    with pytest.raises(ncd.InputError, match=re.escape(f"time step h = {h!r} must be > 0")):
        ncd.step(s, h)
    with pytest.raises(ncd.InputError, match="time step h"):
        ncd.equilibrium_test(s, h)
    assert s.time == 0.0 and np.all(np.isfinite(s.pos))


@pytest.mark.parametrize("theta", [0.0, 1.5, -0.5])
def test_step_rejects_bad_theta(theta):
    with pytest.raises(ncd.InputError, match=re.escape(f"theta = {theta!r} must be in (0, 1]")):
        ncd.step(scene(), 1e-3, theta=theta)


def test_step_rejects_bad_init():
    with pytest.raises(ncd.InputError, match="init = 'hot'"):
        ncd.step(scene(), 1e-3, init="hot")


def test_speed_limit_raises_simulation_error():
    """A disc falling freely from rest reaches g t; a speed limit of 0.5 m/s is
    exceeded at the step where g t > 0.5 (t = 0.051 s) and the step raises
    instead of returning; the scene keeps its last valid state."""
    s = ncd.make_scene([[0.0, 10.0]], 0.5)
    h = 1e-3
    with pytest.raises(ncd.SimulationError, match=r"speed 0\.5\d* exceeds speed_limit = 0\.5"):
        for _ in range(1000):
            ncd.step(s, h, speed_limit=0.5)
    assert s.time == pytest.approx(0.050, abs=1e-12)
    assert np.all(np.isfinite(s.vel)) and abs(s.vel[0, 1]) <= 0.5


def test_state_going_non_finite_raises_simulation_error():
    """A velocity that overflows the position update (1e308 * h) must not
    reach the contact detection or come back as NaN."""
    s = scene()
    s.vel[0] = [1e308, 0.0]
    with np.errstate(over="ignore", invalid="ignore"):
        with pytest.raises(ncd.SimulationError, match="non-finite"):
            ncd.step(s, 10.0)
    s = scene()
    s.spin[1] = np.nan
    with pytest.raises(ncd.SimulationError, match="non-finite"):
        ncd.step(s, 1e-3)
    s = scene()
    s.vel[1, 1] = np.inf
    with np.errstate(invalid="ignore"):
        with pytest.raises(ncd.SimulationError, match="non-finite"):
            ncd.step(s, 1e-3)


def test_solver_settings_and_local_form_reject():
    for kw, pattern in [(dict(tol=-1.0), r"settings\.tol = -1\.0 is outside \(0\.0, inf\]"),
                        (dict(tol=np.nan), r"settings\.tol = nan"),
                        (dict(max_sweeps=2.5), r"settings\.max_sweeps = 2\.5 must be an integer"),
                        (dict(max_sweeps=0), r"settings\.max_sweeps = 0 is outside \[1, 1000000000\]"),
                        (dict(check_every=True), r"settings\.check_every = True must be an integer"),
                        (dict(criterion="energy"), r"settings\.criterion = 'energy'")]:
        with pytest.raises(ncd.InputError, match=pattern):
            ncd.SolverSettings(**kw)
    with pytest.raises(ncd.InputError, match=r"mu must be >= 0; mu\[0\] = -0\.5"):
        ncd.solve_local(np.eye(2), [-1.0, 0.0], -0.5)
    with pytest.raises(ncd.InputError, match=r"positive definite .*block 0 = \[\[1\.0, 0\.0\], \[0\.0, -1\.0\]\]"):
        ncd.solve_local(np.diag([1.0, -1.0]), [-1.0, 0.0], 0.5)
    with pytest.raises(ncd.InputError, match=r"W has shape \(2, 2\), q has length 4"):
        ncd.solve_local(np.eye(2), np.zeros(4), 0.5)


# ------------------------------------------ regressions of faults that crashed the interpreter
def run_isolated(code):
    """Run ``code`` in a fresh interpreter: a segfault or abort is a failure of the
    test, not of the runner.  Returns its stdout (rc 0 asserted)."""
    import subprocess
    import sys
    proc = subprocess.run([sys.executable, "-c", "import numpy as np, ncd\n" + code],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"interpreter died with rc {proc.returncode}:\n{proc.stderr[-2000:]}"
    return proc.stdout


ISOLATED = {
    # a segfault (rc 139) without the check: index 10**6 read by the NLGS sweep
    "review_order_local": "ncd.solve_local(2.0 * np.eye(6), -np.ones(6), 0.5, review_order=[0, 1, 10**6])",
    "review_order_problem": ("s = ncd.make_scene([[0.0, 0.5], [1.0, 0.5], [2.0, 0.5]], 0.5, walls=[((0, 0), (0, 1))])\n"
                             "p = ncd.prepare_step(s, 1e-3)\n"
                             "assert p.contacts.n == 5\n"
                             "ncd.solve_problem(s, p, review_order=[0, 1, 10**6, 2, 3])"),
    # heap corruption (rc 134/139) without the check: a guess of 3 values for 3 contacts
    "guess": "ncd.solve_local(2.0 * np.eye(6), -np.ones(6), 0.5, guess=np.ones(3))",
}
MESSAGES = {
    "review_order_local": r"review_order\[2\] = 1000000 is outside range\(3\)",
    "review_order_problem": r"review_order\[2\] = 1000000 is outside range\(5\)",
    "guess": r"guess has shape \(3,\), expected \(3, 2\)",
}


@pytest.mark.parametrize("case", sorted(ISOLATED))
def test_crash_regressions_raise_input_error(case):
    """Each crashing call, in a subprocess: an InputError naming the argument."""
    code = ("try:\n" + "".join(f"    {line}\n" for line in ISOLATED[case].splitlines())
            + "except ncd.InputError as err:\n    print('InputError:', err)\nelse:\n    print('accepted')\n")
    out = run_isolated(code)
    assert out.startswith("InputError:"), out
    assert re.search(MESSAGES[case], out), out


def test_review_order_of_right_length_but_out_of_range():
    with pytest.raises(ncd.InputError, match=r"review_order\[2\] = 1000000 is outside range\(3\)"):
        ncd.solve_local(2.0 * np.eye(6), -np.ones(6), 0.5, review_order=[0, 1, 10**6])


@pytest.mark.parametrize("order, pattern", [
    ([0, 0], r"not a permutation of range\(2\): 0 appears 2 times and 1 is missing"),
    ([1, -1], r"review_order\[1\] = -1 is outside range\(2\)"),
    ([0.0, 1.0], r"must hold integers.*float64"),
    ([0, 1, 2, 3], r"got shape \(4,\)"),
    ([[0, 1]], r"got shape \(1, 2\)"),
    ("01", r"got shape \(\)"),
])
def test_review_order_must_be_a_permutation(order, pattern):
    """An order such as [0, 0] would skip contact 1 silently: it is refused."""
    W, q = 2.0 * np.eye(4), -np.ones(4)
    with pytest.raises(ncd.InputError, match=pattern):
        ncd.solve_local(W, q, 0.5, review_order=order)
    s = scene(pos=[[0.0, 0.5], [1.0, 0.5]])
    p = ncd.prepare_step(s, 1e-3)
    assert p.contacts.n == 3
    with pytest.raises(ncd.InputError, match="review_order"):
        ncd.solve_problem(s, p, review_order=order)


@pytest.mark.parametrize("where", ["W", "q"])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_non_finite_local_problem_refused_up_front(where, value):
    """NaN in W or q is refused before any sweep (unchecked, it runs every sweep and returns NaN)."""
    W, q = 2.0 * np.eye(6), -np.ones(6)
    (W if where == "W" else q)[(0, 3) if where == "W" else 1] = value
    with pytest.raises(ncd.InputError, match=rf"{where} must be finite; {where}\[.*\] = {value}"):
        ncd.solve_local(W, q, 0.5)
    with pytest.raises(ncd.InputError, match=rf"{where} must be finite"):
        ncd.solve_local(__import__("scipy.sparse").sparse.csr_matrix(W), q, 0.5)


@pytest.mark.parametrize("mu", [np.inf, np.nan, -1.0, [0.5, np.inf, 0.5]])
def test_mu_must_be_finite_and_non_negative(mu):
    with pytest.raises(ncd.InputError, match=r"mu must be"):
        ncd.solve_local(2.0 * np.eye(6), -np.ones(6), mu)
    with pytest.raises(ncd.InputError, match=r"mu"):
        ncd.solve_single_contact_py(np.eye(2), [-1.0, 0.0], np.asarray(mu).ravel()[np.size(mu) // 2])
    if np.ndim(mu) == 0:
        with pytest.raises(ncd.InputError, match=r"mu = "):
            scene(mu=mu)
        with pytest.raises(ncd.InputError, match=r"mu = "):
            ncd.project_cone(1.0, 0.0, mu)


def test_gap_tolerance_nan_is_refused():
    """step(gap_tolerance=nan) is refused: it would drop every contact and report converged=True."""
    s = scene()
    for tol in (np.nan, -1e-3, np.inf):
        with pytest.raises(ncd.InputError, match=rf"gap_tolerance = {tol} is outside \[0\.0, inf\]"):
            ncd.step(s, 1e-3, gap_tolerance=tol)
    assert s.time == 0.0
    rep = ncd.step(s, 1e-3, gap_tolerance=0.0)      # the contacts with the floor are kept
    assert rep.n_contacts == 2 and rep.converged


@pytest.mark.parametrize("pos", [np.zeros((2, 3)), np.zeros(4), np.zeros((1, 2, 2)), [[0.0, 0.5], [1.0]]])
def test_pos_must_have_shape_n_by_2(pos):
    """pos of shape (2, 3) is not read as 3 discs."""
    with pytest.raises(ncd.InputError, match=r"pos (has shape|= ).*"):
        ncd.make_scene(pos, 0.1)


def test_empty_local_problem_returns_an_empty_converged_result():
    """An empty problem is solved trivially, not an AttributeError."""
    for W in (np.zeros((0, 0)), __import__("scipy.sparse").sparse.csr_matrix((0, 0))):
        r = ncd.solve_local(W, np.zeros(0), 0.5)
        assert r.impulse.shape == (0, 2) and r.status.shape == (0,)
        assert r.converged and r.sweeps == 0 and r.residual == 0.0


def test_guess_of_wrong_shape_or_non_finite():
    W, q = 2.0 * np.eye(6), -np.ones(6)
    for guess, pattern in [(np.ones(3), r"guess has shape \(3,\), expected \(3, 2\)"),
                           (np.ones((2, 2)), r"guess has shape \(2, 2\)"),
                           (np.full((3, 2), np.nan), r"guess must be finite; guess\[0, 0\] = nan")]:
        with pytest.raises(ncd.InputError, match=pattern):
            ncd.solve_local(W, q, 0.5, guess=guess)
    r = ncd.solve_local(W, q, 0.5, guess=np.ones(6))       # the flat layout of q is accepted
    assert r.converged and np.allclose(r.impulse[:, 0], 0.5)


def test_non_symmetric_block_policy():
    """A non-symmetric diagonal block is accepted when x.Bx > 0 (its symmetric part
    is positive definite) and solved; refused otherwise, with the block's values."""
    W = np.array([[2.0, 0.5], [-0.5, 1.0]])        # symmetric part diag(2, 1)
    r = ncd.solve_local(W, [-1.0, 0.2], 0.3)
    assert r.converged
    (rn, rt), (un, ut) = r.impulse[0], W @ r.impulse[0] + [-1.0, 0.2]
    assert rn > 0 and un == pytest.approx(0.0, abs=1e-12)          # closed contact
    assert abs(rt) <= 0.3 * rn * (1 + 1e-12)
    assert abs(rt) == pytest.approx(0.3 * rn) and ut * rt < 0 or ut == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ncd.InputError, match=r"block 0 = \[\[1\.0, 3\.0\], \[0\.0, 1\.0\]\] is not"):
        ncd.solve_local(np.array([[1.0, 3.0], [0.0, 1.0]]), [-1.0, 0.0], 0.3)   # det 1 > 0 but x.Bx < 0 somewhere


def test_diverging_nlgs_is_a_simulation_error_not_nan():
    """An indefinite coupling (the diagonal blocks are fine) makes NLGS blow up;
    the result is refused instead of coming back non-finite."""
    W = np.array([[1.0, 0.0, -50.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-50.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    with np.errstate(all="ignore"):
        try:
            r = ncd.solve_local(W, [-1.0, 0.0, -1.0, 0.0], 0.0, settings=ncd.SolverSettings(max_sweeps=2000))
        except ncd.SimulationError as err:
            assert "non-finite" in str(err)
        else:
            assert np.all(np.isfinite(r.impulse)) and not r.converged


@pytest.mark.parametrize("call, pattern", [
    (lambda s, p: ncd.detect_contacts(s, alert=np.nan), r"alert = nan"),
    (lambda s, p: ncd.detect_contacts(s, pos=np.zeros((3, 2))), r"pos has shape \(3, 2\), expected \(2, 2\)"),
    (lambda s, p: ncd.detect_contacts("scene"), r"scene must be an ncd.Scene"),
    (lambda s, p: ncd.prepare_step(s, 1e-3, vel=np.zeros((3, 2))), r"vel has shape \(3, 2\)"),
    (lambda s, p: ncd.solve_problem(s, "problem"), r"problem must be an ncd.StepProblem"),
    (lambda s, p: ncd.solve_problem(s, p, guess=np.ones((5, 2))), r"guess has shape \(5, 2\), expected \(2, 2\)"),
    (lambda s, p: ncd.solve_problem(s, p, settings={"tol": 1e-8}), r"settings must be an ncd.SolverSettings"),
    (lambda s, p: ncd.step(s, 1e-3, init=np.ones(3)), r"init has shape \(3,\), expected \(2, 2\)"),
    (lambda s, p: ncd.step(s, 1e-3, speed_limit=np.nan), r"speed_limit = nan"),
    (lambda s, p: ncd.equilibrium_test(s, 1e-3, velocity_tol=-1.0), r"velocity_tol = -1\.0"),
    (lambda s, p: ncd.kinetic_energy(None), r"scene must be an ncd.Scene"),
    (lambda s, p: ncd.solve_single_contact_py(np.eye(3), [0.0, 0.0], 0.5), r"W has shape \(3, 3\), expected \(2, 2\)"),
    (lambda s, p: ncd.project_cone(np.nan, 0.0, 0.5), r"zn = nan"),
])
def test_entry_points_name_the_argument(call, pattern):
    s = scene()
    p = ncd.prepare_step(s, 1e-3)
    with pytest.raises(ncd.InputError, match=pattern):
        call(s, p)
    assert s.time == 0.0


def test_inconsistent_scene_and_problem_never_reach_a_kernel():
    """A scene edited by hand (a wrong vel shape) or a problem of another scene."""
    s = scene()
    s.vel = np.zeros((5, 2))
    with pytest.raises(ncd.InputError, match=r"scene\.vel has shape \(5, 2\), expected \(2, 2\)"):
        ncd.step(s, 1e-3)
    big = scene(pos=[[0.0, 0.5], [1.0, 0.5], [2.0, 0.5]])
    p = ncd.prepare_step(big, 1e-3)
    with pytest.raises(ncd.InputError, match=r"problem\.contacts\.body_a|problem\.free_vel|body_b"):
        ncd.solve_problem(scene(), p)
    p.contacts.body_b[0] = 99
    with pytest.raises(ncd.InputError, match=r"contacts\.body_b must be another disc"):
        ncd.solve_problem(big, p)


@pytest.mark.parametrize("kw, pattern", [
    (dict(members=[0, -1]), r"members must be >= 0"),
    (dict(members=[0.5]), r"members must be a 1-D array of integers"),
    (dict(root_seed=-3), r"root_seed = -3 is outside"),
    (dict(root_seed=1.5), r"root_seed = 1\.5 must be an integer"),
    (dict(init="random"), r"needs guess_scale > 0, got None"),
    (dict(init="random", guess_scale=np.inf), r"guess_scale = inf is outside"),
    (dict(init="hot"), r"init = 'hot'"),
    (dict(review="sorted"), r"review = 'sorted'"),
    (dict(threads=0), r"threads = 0 is outside"),
    (dict(progress=3), r"progress = 3 must be callable"),
])
def test_explore_rejects(kw, pattern):
    from ncd.dynamics.explore import explore
    s = scene()
    p = ncd.prepare_step(s, 1e-3)
    args = dict(members=[0, 1], root_seed=7)
    args.update(kw)
    with pytest.raises(ncd.InputError, match=pattern):
        explore(s, p, **args)


def test_mass_ratio_1e12_and_tiny_discs():
    """A mass ratio of 1e12 steps without error; a mass that underflows is refused."""
    s = ncd.make_scene([[0.0, 0.5], [0.0, 1.5]], 0.5, [1.0, 1e12], walls=FLOOR)
    for _ in range(5):
        rep = ncd.step(s, 1e-3)
    assert np.all(np.isfinite(s.vel)) and rep.n_contacts == 2
    with pytest.raises(ncd.InputError, match=r"disc 0: mass 0 .* must be finite and > 0"):
        ncd.make_scene([[0.0, 0.5]], 1e-200, 1.0)
    with pytest.raises(ncd.InputError, match=r"disc 0: mass inf"):
        ncd.make_scene([[0.0, 0.5]], 1e200, 1e200)


def test_overlap_tolerance_inf_skips_the_overlap_check():
    """``overlap_tolerance = inf`` (the peer side by side rebuilds scenes mid-run) is no check,
    while NaN and negative values are refused."""
    pos = [[0.0, 0.0], [0.1, 0.0]]                    # overlap of half a radius
    scene = ncd.make_scene(pos, 0.1, 1.0, overlap_tolerance=np.inf)
    assert scene.n_disc == 2
    with pytest.raises(ncd.InputError, match="overlap between disc 0 and disc 1"):
        ncd.make_scene(pos, 0.1, 1.0, overlap_tolerance=0.5)
    for bad in (np.nan, -1.0):
        with pytest.raises(ncd.InputError, match="overlap_tolerance"):
            ncd.make_scene(pos, 0.1, 1.0, overlap_tolerance=bad)
