"""Finishing stage (issue 13 item 2): active-set polish of the NLGS iterate."""
import numpy as np
import pytest

import ncd
from ncd import convergence
from ncd.contacts import local_velocity
from ncd.finish import check_solution
from ncd.studies import scenes

H = 1e-3


def _rest_problem(scene):
    return ncd.prepare_step(scene, H, 1.0, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin))


def _velocities(problem, vel, spin):
    c = problem.contacts
    return local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((c.n, 2))) + problem.bias


@pytest.fixture(scope="module")
def column():
    scene = scenes.hexagonal(12, 12)
    return scene, _rest_problem(scene)


def test_polish_reaches_exact_solution(column):
    """From an NLGS iterate stopped at 1e-4 (grains still moving at ~1e-2 g h), the
    polish reaches residual <= 1e-10 and a state at rest that passes the componentwise check."""
    scene, problem = column
    order = np.random.default_rng(3).permutation(problem.contacts.n)
    plain, vel0, spin0 = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=1e-4))
    assert plain.residual > 1e-5 and convergence.max_speed(vel0, spin0, scene, H) > 1e-3
    fin, vel, spin = ncd.solve_problem(scene, problem, None, order,
                                       ncd.SolverSettings(tol=1e-4, finish="active_set", finish_tol=1e-10))
    assert fin.converged and fin.residual <= 1e-10 and fin.finish_rounds >= 1
    assert convergence.max_speed(vel, spin, scene, H) < 1e-10
    chk = check_solution(fin.impulse, _velocities(problem, vel, spin), problem.contacts.mu, tol=1e-9,
                         velocity_scale=np.linalg.norm(scene.gravity) * H)
    assert chk["ok"], chk
    # the correction is small: the polish stays next to the iterate it started from
    assert np.linalg.norm(fin.impulse - plain.impulse) < 0.05 * np.linalg.norm(plain.impulse)


def test_polish_agrees_with_nlgs_limit(column):
    """Where NLGS converges (to 1e-13 here), the polish of its iterates (same review
    order) lands next to the same solution, although the forces are indeterminate: the
    minimum-norm correction removes the iterate's error across the solution set, not
    along it, so the polished point is closer to the limit than the iterate (measured:
    2.0e-7 against 4.9e-7 from the 1e-8 iterate, 2.0e-9 from the 1e-10 one)."""
    scene, problem = column
    order = np.random.default_rng(5).permutation(problem.contacts.n)
    limit, _, _ = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=1e-13, max_sweeps=200000))
    assert limit.converged
    dist = lambda s: np.linalg.norm(s - limit.impulse) / np.linalg.norm(limit.impulse)
    for tol, bound in [(1e-8, 5e-7), (1e-10, 1e-8)]:
        start, _, _ = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=tol))
        fin, _, _ = ncd.solve_problem(scene, problem, None, order,
                                      ncd.SolverSettings(tol=tol, finish="active_set", finish_tol=1e-12))
        assert fin.converged and fin.residual <= 1e-12
        assert dist(fin.impulse) < min(bound, 0.6 * dist(start.impulse))


def test_polish_dense_packing_degenerate_contacts():
    """A dense packing under gravity has many degenerate contacts (force on the cone
    edge or zero, velocity at round-off).  Leaving them in their status, the polish of
    the 1e-4 NLGS iterate settles in two rounds without further sweeps (switching them
    too cycled for 9 rounds and 250 more sweeps)."""
    from ncd.studies.bench import dense_packing
    scene = dense_packing(100)
    problem = ncd.prepare_step(scene, H)
    plain, _, _ = ncd.solve_problem(scene, problem, settings=ncd.SolverSettings(tol=1e-4, check_every=10))
    fin, vel, spin = ncd.solve_problem(scene, problem, settings=ncd.SolverSettings(
        tol=1e-4, check_every=10, finish="active_set", finish_tol=1e-10))
    assert fin.converged and fin.residual <= 1e-10
    assert fin.finish_rounds <= 3 and fin.sweeps == plain.sweeps
    chk = check_solution(fin.impulse, _velocities(problem, vel, spin), problem.contacts.mu, tol=1e-9,
                         velocity_scale=np.linalg.norm(scene.gravity) * H)
    assert chk["ok"], chk


def test_polish_local_form_unique_solution():
    """A positive definite local W and a small mu (unique solution): the polish of a
    loose NLGS iterate equals NLGS driven to 1e-14."""
    rng = np.random.default_rng(11)
    n = 12
    A = rng.normal(size=(2 * n, 2 * n))
    W = A @ A.T / (2 * n) + np.eye(2 * n)
    q = rng.normal(size=2 * n)
    ref = ncd.solve_local(W, q, 0.3, settings=ncd.SolverSettings(tol=1e-14, max_sweeps=100000))
    assert ref.converged
    fin = ncd.solve_local(W, q, 0.3, settings=ncd.SolverSettings(tol=1e-3, finish="active_set", finish_tol=1e-12))
    assert fin.converged and fin.residual <= 1e-12
    np.testing.assert_allclose(fin.impulse, ref.impulse, rtol=0, atol=1e-10 * np.abs(ref.impulse).max())
    U = (W @ fin.impulse.ravel() + q).reshape(n, 2)
    assert check_solution(fin.impulse, U, np.full(n, 0.3), tol=1e-9, velocity_scale=np.abs(q).max())["ok"]


def test_check_solution_flags_violations():
    s = np.array([[1.0, 0.2], [1.0, -0.5], [0.0, 0.0]])
    U = np.array([[0.0, 0.0], [0.0, 0.3], [0.5, 0.1]])
    mu = np.full(3, 0.5)
    assert check_solution(s, U, mu)["ok"]
    bad = check_solution(s, np.array([[0.0, 1e-3], [0.0, 0.3], [0.5, 0.1]]), mu)
    assert not bad["ok"] and bad["sticking_velocity"] == pytest.approx(1e-3 / 0.5)
    assert check_solution(s, np.array([[0.0, 0.0], [0.0, -0.3], [0.5, 0.1]]), mu)["sliding_direction"] > 0.1
    assert check_solution(np.array([[1.0, 0.6]]), np.zeros((1, 2)), mu[:1])["cone_tangential"] == pytest.approx(0.1)
    assert check_solution(s, np.array([[-0.1, 0.0], [0.0, 0.3], [0.5, 0.1]]), mu)["gap_velocity"] > 0.1


def test_finish_none_is_default():
    assert ncd.SolverSettings().finish == "none"
    with pytest.raises(ValueError, match="finish"):
        ncd.SolverSettings(finish="newton")
