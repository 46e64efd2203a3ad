"""Local exact solves where NLGS stalls (``SolverSettings(local_exact=True)``).

The problem is Figure 2's investigated step at the default configuration
(``tests/data/fig2_step50.nc``: the state before it, 355 discs, 552 contacts), started
from the previous step's impulses as the time stepping starts it.  There plain NLGS
stalls near a residual of 1e-7 for ~150,000 sweeps."""
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from step_checks import contact_velocities as _velocities
from step_checks import step_residual as _residual

import ncd
from ncd.dynamics.stepper import initial_guess
from ncd.shared.slope import scene_at_step
from ncd.solver import anderson, local_exact
from ncd.solver.finish import check_solution, global_delassus, natural_map

DATA = Path(__file__).parent / "data" / "fig2_step50.nc"


@pytest.fixture(scope="module")
def step():
    ds = xr.load_dataset(DATA)
    a = ds.attrs
    cfg = {"scene": {"density": a["density"], "mu": a["mu"], "restitution": a["restitution"]},
           "flow": {"overlap_tolerance": a["overlap_tolerance"]}}
    scene = scene_at_step(ds, cfg)
    problem = ncd.prepare_step(scene, float(a["h"]))
    warm = initial_guess(scene, problem, "warm")
    order = np.random.default_rng((1, 2005)).permutation(problem.contacts.n)
    return scene, problem, warm, order


@pytest.fixture(scope="module")
def plain_limit(step):
    """Plain NLGS from the warm guess to 1e-10: its end-of-step velocities."""
    scene, problem, warm, order = step
    r, vel, spin = ncd.solve_problem(scene, problem, warm.copy(), order,
                                     ncd.SolverSettings(tol=1e-10, max_sweeps=400000, check_every=10))
    assert r.converged
    return r, vel, spin


def _gap(problem, vel, spin, vel0, spin0, scene):
    """Largest end-of-step velocity difference over |g| h (an acceleration difference over g)."""
    u = np.column_stack([vel, spin * scene.radius])[:scene.n_mobile]
    u0 = np.column_stack([vel0, spin0 * scene.radius])[:scene.n_mobile]
    return float(np.abs(u - u0).max() / (np.linalg.norm(scene.gravity) * problem.h))


def test_plain_nlgs_stalls_from_the_warm_guess(step, plain_limit):
    """The premise: 20,000 sweeps leave plain NLGS above 1e-8; it needs > 100,000 to 1e-10."""
    scene, problem, warm, order = step
    r, _, _ = ncd.solve_problem(scene, problem, warm.copy(), order,
                                ncd.SolverSettings(tol=1e-10, max_sweeps=20000, check_every=10))
    assert not r.converged and r.residual > 1e-8
    assert plain_limit[0].sweeps > 100000


@pytest.mark.parametrize("accel, budget", [("none", 20000), ("anderson", 6000)])
def test_local_solves_finish_on_plain_nlgs_solution(step, plain_limit, accel, budget):
    """With local exact solves the run reaches 1e-10 within ``budget`` sweeps (measured:
    9,210 plain, 2,120 with Anderson, against plain NLGS's ~155,000); the end point
    passes the componentwise check to 1e-8, its residual is that of its velocities, and its
    accelerations are plain NLGS's own end point's to 1e-6 g (the same solution: the
    step's zero-guess solutions differ by 0.2 g or more)."""
    scene, problem, warm, order = step
    r, vel, spin = ncd.solve_problem(scene, problem, warm.copy(), order, ncd.SolverSettings(
        tol=1e-10, max_sweeps=budget, check_every=10, accel=accel, local_exact=True))
    assert r.converged and r.residual <= 1e-10 and r.local_solves >= 1
    assert r.sweeps < plain_limit[0].sweeps / 10
    assert _residual(problem, r.impulse, vel, spin) == pytest.approx(r.residual, rel=1e-6)
    # velocities over the largest |U| (the flow's; plain NLGS's end point at 1e-10 is at
    # 9e-10 there, and at 1.4e-8 over |g| h)
    chk = check_solution(r.impulse, _velocities(problem, vel, spin), problem.contacts.mu, tol=1e-8)
    assert chk["ok"], chk
    assert _gap(problem, vel, spin, plain_limit[1], plain_limit[2], scene) < 1e-6


def test_region_solve_is_exact_there_and_leaves_the_rest(step):
    """:func:`ncd.solver.local_exact.solve_region` on a region of the stalled iterate: the
    natural map vanishes on the region's contacts (to 1e-12 of the impulses), the other
    impulses are untouched."""
    scene, problem, warm, order = step
    r, _, _ = ncd.solve_problem(scene, problem, warm.copy(), order,
                                ncd.SolverSettings(tol=1e-14, max_sweeps=3000, check_every=10, keep_best=False))
    c = problem.contacts
    W, _, _ = global_delassus(scene, c)
    W = W.tocsr()
    q = _velocities(problem, problem.free_vel, problem.free_spin).ravel()    # U = W s + q
    moved = np.abs(r.impulse).sum(axis=1) * np.random.default_rng(0).random(c.n)
    idx = local_exact.region(moved, c.body_a, c.body_b, scene.n_mobile)
    assert local_exact.SEED <= len(idx) <= local_exact.SEED + local_exact.MAX_REGION
    s = r.impulse.ravel().copy()
    s_region = local_exact.solve_region(W, q, c.mu, s, idx)
    assert s_region is not None
    new = s.reshape(-1, 2).copy()
    new[idx] = s_region
    U = (W @ new.ravel() + q).reshape(-1, 2)
    F, _ = natural_map(new, U, c.mu, 1.0 / problem.W[:, 0, 0])
    scale = np.abs(new).max()
    assert np.abs(F[idx]).max() <= 1e-12 * scale
    rest = np.setdiff1d(np.arange(c.n), idx)
    assert np.array_equal(new[rest], r.impulse[rest])
    assert np.abs(s_region - r.impulse[idx]).max() > 0          # the stalled iterate was not a local solution


def test_no_stall_no_local_solve(step):
    """From the zero guess on this order plain NLGS converges at a steady rate: no local
    solve, and the run is plain NLGS's bit for bit."""
    scene, problem, warm, order = step
    plain, v0, w0 = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=1e-6, check_every=10))
    loc, v1, w1 = ncd.solve_problem(scene, problem, None, order,
                                    ncd.SolverSettings(tol=1e-6, check_every=10, local_exact=True))
    assert loc.local_solves == 0 and loc.sweeps == plain.sweeps
    assert np.array_equal(loc.impulse, plain.impulse) and np.array_equal(v1, v0) and np.array_equal(w1, w0)


def test_anderson_reset_forgets_the_history():
    aa = anderson.state((None, None, np.zeros(8), np.zeros(4)), 5)
    aa[8][:] = [3, 2, 1, 40, 30, 2, 1, 17]
    aa[9][0] = 0.5
    anderson.reset(aa)
    assert not aa[8].any() and aa[9][0] == np.inf


@pytest.mark.parametrize("value", [1, "yes", None])
def test_invalid_setting(value):
    with pytest.raises(ncd.InputError, match="local_exact"):
        ncd.SolverSettings(local_exact=value)


def test_local_form_refuses_local_solves():
    with pytest.raises(ncd.InputError, match="local_exact"):
        ncd.solve_local(np.eye(2), np.array([-1.0, 0.0]), 0.5, settings=ncd.SolverSettings(local_exact=True))


def test_chunked_runs_and_budget_end(step):
    """With an observable (calls of ``check_every`` sweeps) the stall test still runs every
    100 sweeps and the run finishes; a budget ending just after a stall returns a sweep's
    output (the solve waits for the next sweeps): its residual is that of its velocities,
    and its velocities those of its impulses."""
    scene, problem, warm, order = step
    gh = np.linalg.norm(scene.gravity) * problem.h
    r, vel, spin = ncd.solve_problem(scene, problem, warm.copy(), order, ncd.SolverSettings(
        tol=1e-10, max_sweeps=20000, check_every=10, local_exact=True), observe=lambda s, v, w: v[:, 0] / gh)
    assert r.converged and r.local_solves >= 1 and r.observable_change <= 1e-6
    W, Hm, minv = global_delassus(scene, problem.contacts)
    nm = scene.n_mobile
    free = np.column_stack([problem.free_vel[:nm], problem.free_spin[:nm]]).ravel()
    for budget in (2500, 2600, 2700):
        r, vel, spin = ncd.solve_problem(scene, problem, warm.copy(), order, ncd.SolverSettings(
            tol=1e-14, max_sweeps=budget, check_every=10, local_exact=True, keep_best=False))
        assert _residual(problem, r.impulse, vel, spin) == pytest.approx(r.residual, rel=1e-6)
        u = np.column_stack([vel[:nm], spin[:nm]]).ravel()
        assert np.abs(u - free - minv * (Hm @ r.impulse.ravel())).max() < 1e-13 * np.abs(u).max()   # round-off
