"""Physically invalid input raises ncd.InputError naming the offending key and
value; a state that goes non-finite or diverges while stepping raises
ncd.SimulationError instead of returning NaN (issue 2, "Bad input")."""
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
    with pytest.raises(ValueError, match=r"tol = -1\.0 must be > 0"):
        ncd.SolverSettings(tol=-1.0)
    with pytest.raises(ValueError, match="criterion = 'energy'"):
        ncd.SolverSettings(criterion="energy")
    with pytest.raises(ValueError, match=r"mu must be >= 0; got min -0\.5"):
        ncd.solve_local(np.eye(2), [-1.0, 0.0], -0.5)
    with pytest.raises(ValueError, match="positive definite"):
        ncd.solve_local(np.diag([1.0, -1.0]), [-1.0, 0.0], 0.5)
    with pytest.raises(ValueError, match=r"W has shape \(2, 2\), q has length 4"):
        ncd.solve_local(np.eye(2), np.zeros(4), 0.5)
