"""Finishing stage: NLGS, then the projection on its statuses' polyhedron (LP)."""
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from step_checks import contact_velocities as _velocities
from step_checks import step_residual as _residual

import ncd
from ncd.core.scene import make_scene
from ncd.solver import convergence, finish, finish_lp
from ncd.solver.finish import check_solution
from ncd.solver.single_contact import NO_CONTACT, SLIDE_BACKWARD, SLIDE_FORWARD, STICK
from ncd.studies import cases as scenes

H = 1e-3


def _rest_problem(scene):
    return ncd.prepare_step(scene, H, 1.0, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin))


def _check(scene, problem, result, vel, spin):
    return check_solution(result.impulse, _velocities(problem, vel, spin), problem.contacts.mu, tol=1e-9,
                          velocity_scale=np.linalg.norm(scene.gravity) * H)


@pytest.fixture
def lp_now(monkeypatch):
    """Project at once (no NLGS sweeps to measure its rate, none while its rate looks good)."""
    monkeypatch.setattr(finish, "LP_SWEEPS", 0)
    monkeypatch.setattr(finish, "FIRST_CHUNK", 0)


@pytest.fixture(scope="module")
def column():
    scene = scenes.hexagonal(12, 12)
    return scene, _rest_problem(scene)


@pytest.fixture(scope="module")
def heavy_lid():
    """A hexagonal packing 12 x 12 at rest whose top row is 1000 times denser: plain NLGS
    is left at a residual ~6e-8 after 50,000 sweeps, grains moving at ~6e-4 g h."""
    base = scenes.hexagonal(12, 12)
    y = base.pos[:base.n_mobile, 1]
    scene = make_scene(base.pos[:base.n_mobile], 0.01, np.where(y > y.max() - 1e-3, 1000.0, 1.0),
                       walls=scenes.box_walls(0.24), mu=0.5)
    return scene, _rest_problem(scene)


def test_projection_single_disc():
    """A disc on the floor under gravity: with the contact sticking, the polyhedron is the
    single point s = (m g h, 0); with it open, it is empty and the elastic LP puts the
    violation on that contact."""
    scene = make_scene([[0.0, 0.01]], 0.01, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))], mu=0.5)
    problem = _rest_problem(scene)
    W, Hm, minv = finish.global_delassus(scene, problem.contacts)
    free = np.column_stack([problem.free_vel[:1], problem.free_spin[:1]]).ravel()
    lp = finish_lp.StatusLP.discs(Hm, minv, free, problem.bias, problem.contacts.mu, scene.radius[:1],
                                  1e-3, 1e-2)
    mgh = scene.mass[0] * 9.81 * H
    s, u, info = finish_lp.project(lp, np.array([[0.5 * mgh, 0.1 * mgh]]), np.array([STICK], np.int8))
    np.testing.assert_allclose(s, [[mgh, 0.0]], rtol=0, atol=1e-12 * mgh)
    np.testing.assert_allclose(u, 0.0, atol=1e-12)
    assert info["correction"] == pytest.approx(0.6 * mgh, rel=1e-9)
    s, _, info = finish_lp.project(lp, np.zeros((1, 2)), np.array([NO_CONTACT], np.int8))
    assert s is None and info["status"] == "Infeasible"
    s, _, info = finish_lp.project(lp, np.zeros((1, 2)), np.array([NO_CONTACT], np.int8), elastic=1e3)
    assert info["slack"][0] == pytest.approx(9.81 * H / 1e-2, rel=1e-9)     # U_n = -g h, over V


def test_polish_reaches_exact_solution(column, lp_now):
    """From an NLGS iterate stopped at 1e-4 (grains still moving at ~1e-2 g h), the
    projection reaches residual <= 1e-10 and a state at rest that passes the componentwise
    check, by a correction of about 1 % of the impulses."""
    scene, problem = column
    order = np.random.default_rng(3).permutation(problem.contacts.n)
    plain, vel0, spin0 = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=1e-4))
    assert plain.residual > 1e-5 and convergence.max_speed(vel0, spin0, scene, H) > 1e-3
    fin, vel, spin = ncd.solve_problem(scene, problem, None, order,
                                       ncd.SolverSettings(tol=1e-4, finish="active_set", finish_tol=1e-10))
    assert fin.converged and fin.residual <= 1e-10 and fin.finish_rounds >= 1
    assert convergence.max_speed(vel, spin, scene, H) < 1e-10
    chk = _check(scene, problem, fin, vel, spin)
    assert chk["ok"], chk
    assert 0 < fin.finish_correction < 0.05
    assert np.linalg.norm(fin.impulse - plain.impulse) < 0.05 * np.linalg.norm(plain.impulse)


def test_polish_agrees_with_nlgs_limit(column, lp_now):
    """Where NLGS converges (to 1e-13 here), the projection of its iterates (same review
    order) lands next to the same solution although the forces are indeterminate: closer
    to the limit than the iterate it started from (2.5e-7 against 4.9e-7 from the 1e-8
    iterate, 2.7e-9 against 4.9e-9 from the 1e-10 one)."""
    scene, problem = column
    order = np.random.default_rng(5).permutation(problem.contacts.n)
    limit, _, _ = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=1e-13, max_sweeps=200000))
    assert limit.converged
    def dist(s):
        return np.linalg.norm(s - limit.impulse) / np.linalg.norm(limit.impulse)
    for tol in (1e-8, 1e-10):
        start, _, _ = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(tol=tol))
        fin, _, _ = ncd.solve_problem(scene, problem, None, order,
                                      ncd.SolverSettings(tol=tol, finish="active_set", finish_tol=1e-12))
        assert fin.converged and fin.residual <= 1e-12 and fin.finish_rounds >= 1
        assert dist(fin.impulse) < 0.6 * dist(start.impulse)      # measured: 0.51 (1e-8), 0.54 (1e-10)


def test_finish_where_nlgs_stalls(heavy_lid):
    """On the heavy-lid packing plain NLGS does not reach 1e-10 in 40,000 sweeps; with the
    same budget the finishing stage (default settings) reaches it, at rest, checked."""
    scene, problem = heavy_lid
    order = np.random.default_rng(2).permutation(problem.contacts.n)
    plain, vel0, spin0 = ncd.solve_problem(scene, problem, None, order,
                                           ncd.SolverSettings(tol=1e-10, max_sweeps=40000, check_every=10))
    assert not plain.converged and plain.residual > 1e-8
    assert convergence.max_speed(vel0, spin0, scene, H) > 1e-5
    fin, vel, spin = ncd.solve_problem(scene, problem, None, order, ncd.SolverSettings(
        tol=1e-6, max_sweeps=40000, check_every=10, finish="active_set", finish_tol=1e-10))
    assert fin.converged and fin.residual <= 1e-10 and fin.finish_rounds >= 1
    assert convergence.max_speed(vel, spin, scene, H) < 1e-8
    chk = _check(scene, problem, fin, vel, spin)
    assert chk["ok"], chk
    assert fin.finish_correction < 1e-2


def test_best_iterate_when_budget_runs_out(heavy_lid):
    """A budget too small for NLGS and the projection: the result is flagged unconverged and
    carries the best iterate seen (its residual is that of its impulses, and no worse than
    where plain NLGS stopped with the same budget)."""
    scene, problem = heavy_lid
    settings = dict(tol=1e-10, max_sweeps=300, check_every=10)
    plain, _, _ = ncd.solve_problem(scene, problem, settings=ncd.SolverSettings(**settings))
    fin, vel, spin = ncd.solve_problem(scene, problem, settings=ncd.SolverSettings(
        **settings, finish="active_set", finish_tol=1e-10))
    assert not fin.converged and fin.sweeps <= 600
    assert _residual(problem, fin.impulse, vel, spin) == pytest.approx(fin.residual, rel=1e-6)
    assert fin.residual <= plain.residual


def test_polish_local_form_unique_solution(lp_now):
    """A positive definite local W and a small mu (unique solution): the projection of a
    loose NLGS iterate equals NLGS driven to 1e-14."""
    rng = np.random.default_rng(11)
    n = 12
    A = rng.normal(size=(2 * n, 2 * n))
    W = A @ A.T / (2 * n) + np.eye(2 * n)
    q = rng.normal(size=2 * n)
    ref = ncd.solve_local(W, q, 0.3, settings=ncd.SolverSettings(tol=1e-14, max_sweeps=100000))
    assert ref.converged
    fin = ncd.solve_local(W, q, 0.3, settings=ncd.SolverSettings(tol=1e-3, finish="active_set", finish_tol=1e-12))
    assert fin.converged and fin.residual <= 1e-12 and fin.finish_rounds >= 1
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


def test_rest_polyhedron_is_the_equilibrium_set():
    """finish.rest_status: every contact sticking (none has a positive gap velocity at rest).
    Its polyhedron is A ∩ C times h: the projection of a non-admissible guess lands on
    equilibrium forces inside the Coulomb cones (ForcePolytope.violations ~ round-off), with
    the bodies at rest: an exact one-step solution (natural-map residual ~ round-off)."""
    from ncd.core.contacts import h_matrix
    from ncd.exact.polytope import ForcePolytope
    R, h3 = 1.0, np.sqrt(3.0)
    ground = np.array([[-4.0, 0.0], [-2.0, 0.0], [0.0, 0.0], [2.0, 0.0], [4.0, 0.0]])
    pos = np.array([[-1.0, h3], [1.0, h3], [0.0, 2 * h3], [-3.0, h3], [3.0, h3]])
    scene = make_scene(pos, np.full(5, R), 1.0, obstacle_pos=ground, obstacle_radius=np.full(5, R),
                       gravity=(0.0, -10.0), mu=0.4)
    problem = _rest_problem(scene)
    c = problem.contacts
    W, Hm, minv = finish.global_delassus(scene, c)
    free = np.column_stack([problem.free_vel[:5], problem.free_spin[:5]]).ravel()
    mgh = float(scene.mass[0]) * 10.0 * H
    lp = finish_lp.StatusLP.discs(Hm, minv, free, problem.bias, c.mu, scene.radius[:5], mgh, 10.0 * H)
    status = finish.rest_status(lp)
    assert (status == STICK).all()
    guess = np.tile([[mgh, 0.3 * mgh]], (c.n, 1))              # tangential impulses beyond some cones
    s, u, info = finish_lp.project(lp, guess, status)
    assert s is not None
    np.testing.assert_allclose(u, 0.0, atol=1e-12)
    F = np.zeros((5, 3))
    F[:, :2] = scene.mass[:5, None] * scene.gravity[None, :]
    fp = ForcePolytope(h_matrix(scene, c), F.ravel(), c.mu)
    eq, co = fp.violations((s / H).ravel()[None, :])
    assert eq.max() <= 1e-12 and co.max() <= 1e-12
    assert info["correction"] > 0.01 * mgh                      # the guess was not admissible
    residual = finish.relative_residual(s, (W @ s.ravel() + (Hm.T @ free + problem.bias.ravel())).reshape(-1, 2),
                                        c.mu, 1.0 / W.diagonal()[0::2], mgh)
    assert residual <= 1e-12


def test_shared_delassus_is_built_once_and_changes_nothing(column, lp_now):
    """The global Delassus matrix of a problem is built at its first finished run and kept
    for every later run on it (ensembles); a run with it is bit-identical to a run that
    builds its own, with the finishing stage and with local exact solves.  A ``delassus``
    of the wrong shape is an InputError naming it."""
    scene, problem = column
    order = np.random.default_rng(7).permutation(problem.contacts.n)
    fresh = ncd.prepare_step(scene, H, 1.0, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin))
    first = fresh.delassus(scene)
    assert fresh.delassus(scene) is first
    for settings in (ncd.SolverSettings(tol=1e-4, finish="active_set", finish_tol=1e-10),
                     ncd.SolverSettings(tol=1e-9, max_sweeps=3000, check_every=10, local_exact=True)):
        shared, vel_a, spin_a = ncd.solve_problem(scene, fresh, None, order, settings)
        vel, spin = fresh.free_vel.copy(), fresh.free_spin.copy()
        own = ncd.solve_discs(scene, fresh.contacts, vel, spin, None, order, settings, bias=fresh.bias, W=fresh.W)
        assert fresh.delassus(scene) is first
        assert np.array_equal(shared.impulse, own.impulse) and np.array_equal(vel_a, vel)
        assert np.array_equal(spin_a, spin) and shared.sweeps == own.sweeps
    W, Hm, minv = first
    vel, spin = fresh.free_vel.copy(), fresh.free_spin.copy()
    with pytest.raises(ncd.InputError, match="delassus"):
        ncd.solve_discs(scene, fresh.contacts, vel, spin, settings=ncd.SolverSettings(finish="active_set"),
                        delassus=(W, Hm[:-3], minv))
    for bad in ((W, Hm, list(minv)[:-1]), (W, Hm, np.where(np.arange(len(minv)) == 0, np.nan, minv))):
        with pytest.raises(ncd.InputError, match="delassus"):
            ncd.solve_discs(scene, fresh.contacts, vel, spin, settings=ncd.SolverSettings(local_exact=True),
                            delassus=bad)


def test_status_system_and_min_norm_solve_match_their_plain_definitions():
    """``status_system`` (vectorized) builds, entry for entry, the matrices of its plain
    per-contact definition (stick: two unknowns and rows; slide: ``s_t = -+mu s_n``, the
    row ``U_n``; open: none), and ``min_norm_solve`` gives bit for bit the answer of the
    system assembled by ``scipy.sparse.bmat``: the census's patterns stay the same."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    def plain(mu, status):
        prow, pcol, pval, srow, col = [], [], [], [], 0
        for c, st in enumerate(status):
            if st == STICK or st > SLIDE_BACKWARD:
                prow += [2 * c, 2 * c + 1]
                pcol += [col, col + 1]
                pval += [1.0, 1.0]
                srow += [2 * c, 2 * c + 1]
                col += 2
            elif st in (SLIDE_FORWARD, SLIDE_BACKWARD):
                prow += [2 * c, 2 * c + 1]
                pcol += [col, col]
                pval += [1.0, (-1.0 if st == SLIDE_FORWARD else 1.0) * mu[c]]
                srow.append(2 * c)
                col += 1
        n = len(status)
        return (sp.csr_matrix((pval, (prow, pcol)), shape=(2 * n, col)),
                sp.csr_matrix((np.ones(col), (srow, np.arange(col))), shape=(2 * n, col)))

    rng = np.random.default_rng(5)
    for n in (0, 1, 7, 40):
        status = rng.choice([NO_CONTACT, STICK, SLIDE_FORWARD, SLIDE_BACKWARD, SLIDE_BACKWARD + 1], n).astype(np.int8)
        mu = rng.uniform(0.1, 1.0, n)
        for got, want in zip(finish.status_system(mu, status), plain(mu, status)):
            assert got.shape == want.shape
            for a in ("indptr", "indices", "data"):
                np.testing.assert_array_equal(getattr(got, a), getattr(want, a))
        if n < 7:
            continue
        P, S = finish.status_system(mu, status)
        A = sp.random(2 * n, 2 * n, density=0.2, random_state=n)
        K = (S.T @ (A @ A.T) @ P).tocsr()
        r = K @ rng.normal(size=K.shape[1])
        m = K.shape[0]
        eps = 1e-10 * abs(K).sum(axis=1).max() ** 2
        lu = spla.splu(sp.bmat([[sp.identity(m), K.T], [K, -eps * sp.identity(m)]], format="csc"),
                       permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        d, prev = np.zeros(m), np.inf                  # min_norm_solve's refinements, on bmat's system
        for _ in range(finish.REFINE):
            e = r - K @ d
            if np.linalg.norm(e) <= 1e-15 * np.linalg.norm(r) or np.linalg.norm(e) > 0.5 * prev:
                break
            prev = np.linalg.norm(e)
            d += lu.solve(np.concatenate([np.zeros(m), e]))[:m]
        got = finish.min_norm_solve(K, r)
        np.testing.assert_array_equal(got, d)
        np.testing.assert_allclose(K @ got, r, atol=1e-8 * np.abs(r).max())


def _l1_reference(W, q, mu, s0, status):
    """min sum |s - s0| over the polyhedron of ``status`` written out row by row (the cone
    and each status as inequality and equality rows on ``(s, d)``, ``|s - s0| <= d``), by
    scipy's HiGHS: a formulation independent of finish_lp's sector columns."""
    from scipy.optimize import linprog

    n = len(mu)
    m = 2 * n
    I = np.eye(m)
    A_eq, b_eq, A_ub, b_ub = [], [], [], []
    for c in range(n):
        sn, st = np.zeros(2 * m), np.zeros(2 * m)
        sn[2 * c], st[2 * c + 1] = 1.0, 1.0
        Un, Ut = np.concatenate([W[2 * c], np.zeros(m)]), np.concatenate([W[2 * c + 1], np.zeros(m)])
        qn, qt = q[2 * c], q[2 * c + 1]
        if status[c] == NO_CONTACT:
            A_eq += [sn, st]
            b_eq += [0.0, 0.0]
            A_ub.append(-Un)
            b_ub.append(qn)                                  # U_n >= 0
            continue
        A_eq.append(Un)
        b_eq.append(-qn)                                     # U_n = 0
        A_ub += [-sn, -(mu[c] * sn + st), -(mu[c] * sn - st)]
        b_ub += [0.0, 0.0, 0.0]                              # s_n >= 0, |s_t| <= mu s_n
        if status[c] == STICK:
            A_eq.append(Ut)
            b_eq.append(-qt)
        elif status[c] == SLIDE_FORWARD:                     # s_t = -mu s_n, U_t >= 0
            A_eq.append(mu[c] * sn + st)
            b_eq.append(0.0)
            A_ub.append(-Ut)
            b_ub.append(qt)
        else:                                                # SLIDE_BACKWARD: s_t = mu s_n, U_t <= 0
            assert status[c] == SLIDE_BACKWARD
            A_eq.append(mu[c] * sn - st)
            b_eq.append(0.0)
            A_ub.append(Ut)
            b_ub.append(-qt)
    A_ub += list(np.hstack([I, -I])) + list(np.hstack([-I, -I]))
    b_ub += list(s0) + list(-s0)
    res = linprog(np.concatenate([np.zeros(m), np.ones(m)]), A_ub=np.array(A_ub), b_ub=np.array(b_ub),
                  A_eq=np.array(A_eq), b_eq=np.array(b_eq), bounds=[(None, None)] * m + [(0, None)] * m,
                  method="highs")
    return res.fun if res.status == 0 else None


def test_projection_matches_a_row_by_row_formulation():
    """finish_lp.project carries the cone and the sliding statuses as bounds on sector
    columns (ncd.solver.cone); its L1 distance must be that of the same polyhedron written
    with explicit rows, for every status (open, stick, slide either way), frictionless
    contacts included, on polyhedra built non-empty around a known solution and on
    random, mostly empty, ones."""
    rng = np.random.default_rng((0, 2005))
    found = {True: 0, False: 0}
    for trial in range(40):
        n = int(rng.integers(3, 7))
        J = rng.normal(size=(2 * n, 3 * n - 2))
        W = J @ J.T                                           # semi-definite, rank-deficient
        mu = np.where(rng.random(n) < 0.25, 0.0, rng.uniform(0.1, 1.0, n))
        status = rng.choice(np.array([NO_CONTACT, STICK, SLIDE_FORWARD, SLIDE_BACKWARD], np.int8), n)
        sn = rng.uniform(0.5, 2.0, n)
        st = np.select([status == STICK, status == SLIDE_FORWARD, status == SLIDE_BACKWARD],
                       [rng.uniform(-1, 1, n) * mu * sn, -mu * sn, mu * sn], 0.0)
        s_star = np.column_stack([np.where(status == NO_CONTACT, 0.0, sn), st]).ravel()
        U = np.column_stack([np.where(status == NO_CONTACT, rng.uniform(0.1, 1, n), 0.0),
                             np.select([status == SLIDE_FORWARD, status == SLIDE_BACKWARD,
                                        status == NO_CONTACT], [rng.uniform(0.1, 1, n), -rng.uniform(0.1, 1, n),
                                                                rng.normal(size=n)], 0.0)]).ravel()
        q = U - W @ s_star if trial % 2 == 0 else rng.normal(size=2 * n)
        s0 = s_star + 0.3 * rng.normal(size=2 * n)
        lp = finish_lp.StatusLP.local(W, q, mu, 1.0, 1.0)
        ref = _l1_reference(W, q, mu, s0, status)
        for presolve in (True, False):          # presolve changes HiGHS's route, not the polyhedron
            s, _, info = finish_lp.project(lp, s0.reshape(n, 2), status, presolve=presolve)
            assert (s is None) == (ref is None), (trial, presolve, info["status"])
            assert presolve or info["presolve"] == "off"
            if s is not None:
                assert abs(info["correction"] - ref) <= 1e-7 * max(ref, 1.0), (trial, info["correction"], ref)
                assert np.abs(s.ravel() - s0).sum() == pytest.approx(info["correction"], rel=1e-12)
        found[s is not None] += 1
    assert found[True] >= 20 and found[False] >= 5


def test_thin_cone_projection_needs_no_presolve():
    """One projection LP of the random walk of Figure 5 on a thin-cone slice (mu = 0.0027,
    built at that mu: the default run's build member 1000, the walk's second LP; the
    arrays ``solve_lp`` received), stored in tests/data.  With HiGHS's presolve the interior
    point stops without progress and the dual simplex from scratch stops at the iteration
    cap, so the round gets no vertex; without presolve the LP ends optimal at a point that
    meets its rows and bounds to the feasibility tolerance (measured: 5e-10).  This is why
    the walk's solver has ``finish_presolve: false`` (docs/governing.md)."""
    d = np.load(Path(__file__).parent / "data" / "fig5_thin_cone_lp.npz")
    M = sp.csc_matrix((d["data"], d["indices"], d["indptr"]), shape=tuple(d["shape"]))
    args = (M, d["row_lo"], d["row_hi"], d["col_lo"], d["col_hi"], d["cost"])
    x, info = finish_lp.solve_lp(*args)
    assert x is None and info["status"] == "Iteration limit reached" and info["iterations"] == finish_lp.SIMPLEX_LIMIT
    x, info = finish_lp.solve_lp(*args, presolve=False)
    assert info["status"] == "Optimal" and info["presolve"] == "off", info
    r = M @ x
    viol = max((d["row_lo"] - r).max(), (r - d["row_hi"]).max(), (d["col_lo"] - x).max(), (x - d["col_hi"]).max())
    assert viol <= finish_lp.FEASIBILITY


def test_finish_presolve_must_be_a_bool():
    with pytest.raises(ncd.InputError, match="finish_presolve"):
        ncd.SolverSettings(finish_presolve="off")
    assert ncd.SolverSettings().finish_presolve is True


def _single_disc_lp():
    scene = make_scene([[0.0, 0.01]], 0.01, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))], mu=0.5)
    problem = _rest_problem(scene)
    W, Hm, minv = finish.global_delassus(scene, problem.contacts)
    free = np.column_stack([problem.free_vel[:1], problem.free_spin[:1]]).ravel()
    lp = finish_lp.StatusLP.discs(Hm, minv, free, problem.bias, problem.contacts.mu, scene.radius[:1], 1e-3, 1e-2)
    return lp, scene.mass[0] * 9.81 * H


def test_a_projection_is_skipped_only_where_it_must_be_a_jump(monkeypatch):
    """The L1 distance to a set is 1-Lipschitz: from an iterate whose projection moved it by
    ``d``, one ``e`` away is at least ``d - e`` from the set.  On the single disc, whose
    sticking polyhedron is the point ``(m g h, 0)``, a projection is skipped where that bound
    exceeds the jump threshold (and the LP confirms a jump there), and solved where it does
    not, both where the LP then finds a jump and where it finds none."""
    lp, mgh = _single_disc_lp()
    stick = np.array([STICK], np.int8)
    calls = []
    monkeypatch.setattr(finish, "project", lambda *a, **k: calls.append(1) or finish_lp.project(*a, **k))

    def distance(s):
        return finish_lp.project(lp, s, stick)[2]["correction"]

    seen = {}
    far = np.array([[0.5 * mgh, 0.1 * mgh]])                  # 0.6 m g h away: a jump
    cand, info = finish.project_unless_jump(lp, far, stick, True, seen)
    assert cand is not None and len(calls) == 1
    near_far = far + [[0.01 * mgh, 0.0]]                       # bound 0.59 m g h > 0.05 |s|: skipped
    cand, info = finish.project_unless_jump(lp, near_far, stick, True, seen)
    assert cand is None and info["status"].startswith("skipped") and len(calls) == 1
    assert distance(near_far) > finish.MAX_CORRECTION * np.abs(near_far).sum()
    close = np.array([[0.99 * mgh, 0.0]])                     # bound negative: solved, not a jump
    cand, info = finish.project_unless_jump(lp, close, stick, True, seen)
    assert cand is not None and len(calls) == 2
    assert info["correction"] <= finish.MAX_CORRECTION * np.abs(close).sum()
    # a jump the bound cannot see: from the close iterate's record, a far one is solved
    cand, info = finish.project_unless_jump(lp, far, stick, True, seen)
    assert cand is not None and len(calls) == 3


def test_skipping_jumps_leaves_the_finishing_stage_as_it_was(lp_now, monkeypatch):
    """An iterate that stalls on its statuses (one contact sliding) far from their
    polyhedron, here the point ``P``, while the states at rest are the point ``Q`` nearby:
    every projection on its statuses is a jump, and since the polyhedron is not empty the
    stage never tries the rest polyhedron.  It projects after each chunk, as many as
    ``MAX_ATTEMPTS``; skipping those the distance bound rules out must leave its result
    unchanged bit for bit and call the LP on a subsequence of the same polyhedra: here one
    LP instead of three, and never the rest polyhedron (a skipped projection is a rejected
    candidate, not an empty polyhedron)."""
    P, Q = np.array([[3.0, -1.5]]), np.array([[1.0, 0.01]])
    slide = np.array([SLIDE_FORWARD], np.int8)

    class OneContactLP:                            # what rest_status reads of a StatusLP: b_n < 0, closed
        b = np.array([-1.0, 0.0])

    def project(lp, s0, status, presolve=True):
        point = P if np.array_equal(status, slide) else Q
        calls.append(int(status[0]))
        return point.copy(), None, {"status": "Optimal", "iterations": 0,
                                    "correction": float(np.abs(point - s0).sum())}
    monkeypatch.setattr(finish, "project", project)
    W, mu = sp.identity(2, format="csr"), np.array([0.5])
    s0 = np.array([[1.0, -0.5]])                    # on the sliding edge, U = (1e-9, 0): residual ~ 1e-9
    q = -s0.ravel() + [1e-9, 0.0]
    runs = []
    for margin in (np.inf, finish.JUMP_MARGIN):               # inf: nothing skipped
        monkeypatch.setattr(finish, "JUMP_MARGIN", margin)
        calls = []
        s = s0.copy()

        def creep(k, s=s):
            s += [[1e-12, 0.0]]
            return s.copy(), slide.copy()
        out = finish.polish(OneContactLP, W, q, mu, np.array([1.0]), 1.0, s0.copy(), slide.copy(), 1e-300, creep, 400, 100)
        runs.append((out, calls))
    (a, calls_all), (b, calls_skip) = runs
    assert 1e-300 < a[2] <= finish.REST_GATE and a[3] == b[3] == finish.MAX_ATTEMPTS
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and a[2] == b[2]
    assert a[4] is b[4] is False and a[5] == b[5]
    assert calls_all == [SLIDE_FORWARD] * finish.MAX_ATTEMPTS and calls_skip == [SLIDE_FORWARD]
