"""Figure 5: exact measures of A ∩ C across friction, Unger et al.'s eta_U on their walk
and on a uniform sample, the mobile plate, the flows.

Unit tests on problems with a known answer (a shared load, a uniform segment, a frictionless
packing built between two plates), then the figure's data from the DAG run (fixture ``results``).
"""
import numpy as np
import pytest
import scipy.sparse as sp
import xarray as xr
import yaml

import ncd
from ncd.core.contacts import external_load, h_matrix
from ncd.dynamics.explore import shard_members
from ncd.exact.polytope import ForcePolytope
from ncd.figures.fig5_governing import claims as gc
from ncd.figures.fig5_governing import exact as ge
from ncd.figures.fig5_governing import line as gl
from ncd.figures.fig5_governing import measure as fg
from ncd.figures.fig5_governing import plates
from ncd.figures.fig5_governing import unger as gu


# ---------------------------------------------------------------- unit tests
def test_ranges_of_a_shared_load():
    """Two supports share a unit load (r_n1 + r_n2 = 1): every range and eta known."""
    mu = 0.4
    m = ge.exact_measures(sp.csr_matrix([[1.0, 0.0, 1.0, 0.0]]), [-1.0], mu)
    assert (m["dim_A"], m["dim_AC_rank"], m["dim_AC_lp"]) == (3, 3, 3)
    np.testing.assert_allclose(m["force_min"], [[0.0, -mu], [0.0, -mu]], atol=1e-9)
    np.testing.assert_allclose(m["force_max"], [[1.0, mu], [1.0, mu]], atol=1e-9)
    assert m["n_fixed"] == 0
    # widths (1, 2 mu), box centres (0.5, 0) on both contacts
    assert m["eta_exact"] == pytest.approx(np.hypot(1.0, 2 * mu) / 0.5, rel=1e-9)


def test_single_support_without_friction_is_determinate():
    """One support, mu = 0: A is a line (r_t free), A ∩ C a point found by LP."""
    m = ge.exact_measures(sp.csr_matrix([[1.0, 0.0]]), [-1.0], 0.0)
    assert m["dim_A"] == 1
    assert (m["dim_AC_rank"], m["dim_AC_lp"]) == (0, 0)
    assert m["n_fixed"] == 1 and m["eta_exact"] == 0.0
    assert m["implicit_sliding"][0]


def small_plates(**kw):
    """Packing parameters of a 24-disc cell between two plates (the top one mobile), no gravity."""
    p = dict(n_discs=24, radius_min=0.01, width_radii=12, slice_radii=6, density=1.0, load=9.81, plate_mass=0.2,
             mu_min=0.01, mu_max=1.0, n_mu=2, per_mu=1, control=1, root_seed=3, h=2e-4, max_steps=20000,
             check_every=50, speed_tol=1.0, velocity_tol=1e-6, solver=dict(tol=1e-3, max_sweeps=1000, check_every=10),
             rest_solver=dict(tol=1e-8, max_sweeps=20000, check_every=10, finish="active_set", finish_tol=1e-12))
    p.update(kw)
    return p


WALK = dict(samples=6, noise=1.0, point_tol=1e-12,
            solver=dict(tol=1e-8, max_sweeps=20000, check_every=10, finish="active_set", finish_tol=1e-12))


@pytest.fixture(scope="module")
def frictionless_cell():
    p = small_plates()
    cell, forces, contacts, info = fg.build(p, 0.0, member=0)
    return p, cell, forces, contacts, info


def test_mobile_plate_is_balanced_and_moves_along_its_normal(frictionless_cell):
    """At rest the plate's contacts carry exactly its load (its row of H r + F = 0), with no
    tangential force; it has not moved sideways; the whole cell's A ∩ C is bounded."""
    p, cell, forces, contacts, info = frictionless_cell
    top = contacts.body_b == cell.n
    assert top.sum() >= 2
    assert forces[top, 0].sum() == pytest.approx(cell.force, rel=1e-9)
    assert np.abs(forces[top, 1]).max() == 0.0
    assert cell.scene.vel[cell.n, 0] == 0.0 and cell.scene.pos[cell.n, 0] == pytest.approx(0.5 * cell.scene.period)
    H = h_matrix(cell.scene, contacts)
    r = np.abs(H @ forces.ravel() + external_load(cell.scene, plates.plate_load(cell))).max()
    assert r <= 1e-9 * cell.force
    assert fg.plates_bounded(cell, contacts)
    assert info["max_penetration"] < 0.2


def test_frictionless_packing_is_isostatic_and_determinate(frictionless_cell):
    """A packing built frictionless has no self-stress: its slice (boundary forces fixed) has
    dim (A ∩ C) = 0, every contact fixed, eta_U = 0 on the uniform sample (one point) and on
    the random walk (every relaxation returns the history state to round-off)."""
    p, cell, forces, contacts, _ = frictionless_cell
    exact_forces, exact = fg.exact_rest(cell, contacts, forces, 0.0)
    assert exact and np.abs(exact_forces - forces).max() <= 1e-8 * cell.force
    sl = fg.slice_of(cell, contacts, exact_forces, p, exact)
    assert len(sl.mu) >= 5 and (sl.mu == 0).all()
    m = ge.exact_measures(sl.H, sl.F, sl.mu, feas_tol=1e-9)
    assert (m["dim_AC_rank"], m["dim_AC_lp"]) == (0, 0) and m["n_fixed"] == m["n_contacts"]
    walk = gu.random_walk(sl, WALK, np.random.default_rng(0))
    assert walk["ok"].all()
    assert gu.eta_u(walk["samples"]) <= 1e-9
    uni = gu.uniform_sample(sl, m, dict(per_chain=20, rounds=0), lambda k: np.random.default_rng(k), 1e-9)
    assert uni["dimension"] == 0 and uni["eta"] == 0.0


def test_slice_balanced_by_its_reference_forces(frictionless_cell):
    """Rest forces balanced to ~1e-10 only (a refinement not taken, as in thin cones): with
    ``balance`` the slice's loads are those its reference forces balance, to round-off, and its
    exact set is the same single point; the boundary forces' loads miss by the perturbation."""
    p, cell, forces, contacts, _ = frictionless_cell
    rough = forces * (1.0 + 1e-9 * np.random.default_rng(3).uniform(-1.0, 1.0, forces.shape))
    mid, half = 0.5 * cell.plate_y, 0.5 * p["slice_radii"] * p["radius_min"]
    plain = plates.slice_problem(cell, contacts, rough, mid - half, mid + half, p["h"])
    sl = fg.slice_of(cell, contacts, rough, p, exact=False)
    scale = np.abs(sl.F).max()
    assert np.abs(sl.H @ sl.reference.ravel() + sl.F).max() <= 1e-14 * scale
    assert np.abs(plain.H @ plain.reference.ravel() + plain.F).max() >= 1e-12 * scale
    np.testing.assert_allclose(sl.F, plain.F, rtol=0, atol=1e-8 * scale)
    m = ge.exact_measures(sl.H, sl.F, sl.mu, feas_tol=1e-9)
    assert m["dim_AC_rank"] == 0 and m["n_fixed"] == m["n_contacts"]
    np.testing.assert_allclose(0.5 * (m["force_min"] + m["force_max"]), sl.reference, rtol=0, atol=1e-7 * scale)


def test_eta_u_of_a_uniform_segment():
    """Two frictionless supports share a unit load: A ∩ C is the segment r_n1 + r_n2 = 1, each
    r_n uniform on [0, 1] under the uniform law, so eta_U = (1 / sqrt 12) / (1 / 2) exactly.
    Hit-and-run's two chains (dispersed starts) give it within sampling error, and agree."""
    P = ForcePolytope(sp.csr_matrix([[1.0, 0.0, 1.0, 0.0]]), [-1.0], 0.0)
    x, info = P.uniform_samples(lambda k: np.random.default_rng((k, 1)), 2, 4000, dispersed=True)
    assert info["dimension"] == 1 and info["rhat"] < 1.02
    f = x.reshape(2, 4000, 2, 2)
    exact = gu.closed_form_segment_eta()
    assert exact == pytest.approx(0.57735, abs=1e-5)
    # 4000 thinned points per chain: the relative standard error of a standard deviation ~ 1 / sqrt(2 n) ~ 1 %
    for chain in f:
        assert gu.eta_u(chain) == pytest.approx(exact, rel=0.05)
    assert gu.eta_u(f.reshape(-1, 2, 2)) == pytest.approx(exact, rel=0.03)


def elongated_slice(n=5, mu=0.003, decades=4):
    """``n`` contacts share a unit load with coefficients ``a_i`` spread over ``decades``
    (``sum a_i r_n,i = 1``), friction ``mu``, and two more contacts whose normal forces sum
    to zero (both carry nothing: implicit equalities).  Uniform on A ∩ C, ``a_i r_n,i`` is
    Dirichlet(2, ..., 2) (the tangential range 2 mu r_n weights each), so eta_U has a closed
    form (:func:`elongated_eta`) whatever the ``a_i``; the set is a simplex-like body whose
    widths span ``decades`` decades, with far vertices."""
    from types import SimpleNamespace
    a = np.logspace(0.0, -decades, n)
    H = np.zeros((2, 2 * (n + 2)))
    H[0, 0:2 * n:2] = a
    H[1, 2 * n] = H[1, 2 * n + 2] = 1.0
    return SimpleNamespace(H=sp.csr_matrix(H), F=np.array([-1.0, 0.0]), mu=np.full(n + 2, mu))


def elongated_eta(n, mu):
    """eta_U of :func:`elongated_slice`: with ``u = a r_n`` Dirichlet(2, ..., 2) and ``r_t``
    uniform in ``[-mu r_n, mu r_n]``, ``dF = sqrt((n - 1 + n mu^2) / (2n + 1)) / (a n)`` and
    ``E|F| = g(mu) / (a n)``, ``g = (sqrt(1 + mu^2) + asinh(mu) / mu) / 2``; the two
    unloaded contacts add 0 to both means."""
    g = 0.5 * (np.sqrt(1.0 + mu ** 2) + np.arcsinh(mu) / mu)
    return np.sqrt((n - 1 + n * mu ** 2) / (2 * n + 1)) / g


@pytest.mark.parametrize("directions", ["random", "coordinate"])
@pytest.mark.parametrize("mu", [0.003, 0.5])
def test_uniform_sample_of_an_elongated_set_with_implicit_equalities(mu, directions):
    """Widths over 4 decades, far vertices as dispersed starts, two contacts fixed at zero by
    implicit equalities: the sampler works in the 2n - 1 dimensions the exact LPs count, its
    two chains agree at the first length, and eta_U matches the closed form, with random
    directions and with coordinate ones in the rounded frame.  (One pilot from an isotropic
    start, chains burnt in for 50 dim steps: R-hat 24 here.)"""
    n = 5
    sl = elongated_slice(n, mu)
    m = ge.exact_measures(sl.H, sl.F, sl.mu)
    assert (m["dim_AC_rank"], m["dim_AC_lp"]) == (2 * n - 1, 2 * n - 1)
    u = dict(per_chain=2000, max_per_chain=2000, rounds=1, burn=20, directions=directions)
    uni = gu.uniform_sample(sl, m, u, lambda k: np.random.default_rng((k, 5)))
    assert uni["dimension"] == 2 * n - 1 and uni["per_chain"] == 2000
    assert gu.chains_agree(uni["gap"], uni["rhat"]) and uni["rhat"] < 1.1, (uni["gap"], uni["rhat"])
    f = uni["samples"]
    assert np.abs(f[:, n:]).max() <= 1e-9             # the unloaded contacts stay at zero
    # 2 x 2000 thinned points: the relative standard error of eta_U is a few percent
    assert uni["eta"] == pytest.approx(elongated_eta(n, mu), rel=0.06)
    for chain in f.reshape(2, -1, n + 2, 2):
        assert gu.eta_u(chain) == pytest.approx(elongated_eta(n, mu), rel=0.1)


def test_uniform_samples_reject_points_of_another_space():
    P = ForcePolytope(sp.csr_matrix([[1.0, 0.0, 1.0, 0.0]]), [-1.0], 0.5)
    with pytest.raises(ncd.InputError, match="points"):
        P.uniform_samples(lambda k: np.random.default_rng(k), 2, 10, points=np.zeros((3, 3)))
    with pytest.raises(ncd.InputError, match="directions = 'gibbs'"):
        P.uniform_samples(lambda k: np.random.default_rng(k), 2, 10, directions="gibbs")


def test_coordinate_directions_keep_the_uniform_law_on_the_segment():
    """The frictionless segment r_n1 + r_n2 = 1 (each r_n uniform on [0, 1]) sampled by
    coordinate hit-and-run: mean 1/2 and variance 1/12 within sampling error, both chains."""
    P = ForcePolytope(sp.csr_matrix([[1.0, 0.0, 1.0, 0.0]]), [-1.0], 0.0)
    x, info = P.uniform_samples(lambda k: np.random.default_rng((k, 2)), 2, 4000, dispersed=True,
                                directions="coordinate")
    assert info["dimension"] == 1 and info["rhat"] < 1.02
    for chain in x.reshape(2, 4000, 4):
        assert chain[:, 0].mean() == pytest.approx(0.5, abs=0.02)
        assert chain[:, 0].var() == pytest.approx(1 / 12, rel=0.06)
        np.testing.assert_allclose(chain[:, 0] + chain[:, 2], 1.0, atol=1e-12)


def test_eta_u_is_a_standard_deviation_over_mean_force():
    """Known samples: contact 0 alternates t = ±0.5 at n = 1, contact 1 is fixed at 3."""
    f = np.array([[[1.0, 0.5], [3.0, 0.0]], [[1.0, -0.5], [3.0, 0.0]]] * 2)
    sd = np.std([0.5, -0.5, 0.5, -0.5], ddof=1)
    mag = (np.hypot(1.0, 0.5) + 3.0) / 2
    assert gu.eta_u(f) == pytest.approx(sd / 2 / mag, rel=1e-12)
    assert np.isnan(gu.eta_u(f[:1]))


def test_study_tables_and_bad_friction():
    p = small_plates(n_mu=3, per_mu=2, control=2)
    b, a = fg.build_table(p), fg.analysis_table(p)
    assert len(b["mu"]) == 8 and len(set(b["member"].tolist())) == 8
    assert (b["mu"][b["kind"] == 1] == 0.0).all()
    assert len(a["mu"]) == 6 + 2 * 3
    np.testing.assert_allclose(np.unique(a["mu"]), [0.01, 0.1, 1.0])
    with pytest.raises(ncd.InputError, match="mu_min"):
        fg.mu_values(dict(mu_min=0.0, mu_max=1.0, n_mu=3))


def test_ballistic_start_has_no_overlap():
    rng = np.random.default_rng(0)
    radius = rng.uniform(1.0, 2.0, 60)
    pos = fg.ballistic(radius, 42.0, rng)
    d = pos[:, None] - pos[None]
    d[..., 0] -= 42.0 * np.round(d[..., 0] / 42.0)
    gap = np.hypot(d[..., 0], d[..., 1]) - (radius[:, None] + radius[None])
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= -1e-9 and (pos[:, 1] >= radius - 1e-12).all()


# ---------------------------------------------------------------- figure data (DAG run)
@pytest.fixture(scope="module")
def packings(results):
    return xr.load_dataset(results / "fig5_governing" / "packings.nc")


CHAIN_GAP, RHAT = gu.MIXED_GAP, gu.MIXED_RHAT     # eta_U within 30 %, R-hat below 1.2
MU_THIN = 0.01     # below, the LPs may find directions narrower than the width tolerance


def test_two_uniform_chains_agree_on_every_packing(packings):
    """The mixing check: on every analysis with a bounded, non-trivial A ∩ C the two
    hit-and-run chains (dispersed starts) give eta_U within CHAIN_GAP and R-hat below RHAT,
    in the hull of the rank count (dim_uniform = dim_AC_rank: no direction is dropped, thin
    or not); the flag ``mixed`` says so."""
    bounded = packings.bounded.values == 1
    assert np.isfinite(packings.eta_uniform.values[bounded]).all()
    good = (packings.eta_uniform_gap.values <= CHAIN_GAP) & (packings.rhat.values <= RHAT)
    np.testing.assert_array_equal(packings.mixed.values[bounded] == 1, good[bounded])
    sel = bounded & (packings.dim_AC_rank.values > 0)
    assert (packings.eta_uniform_gap.values[sel] <= CHAIN_GAP).all(), packings.eta_uniform_gap.values[sel]
    assert (packings.rhat.values[sel] <= RHAT).all(), packings.rhat.values[sel]
    np.testing.assert_array_equal(packings.dim_uniform.values[sel], packings.dim_AC_rank.values[sel])


def test_lp_dimension_agrees_with_rank_count(packings):
    """The affine rank of LP points equals the rank count at mu >= MU_THIN; in thinner sectors
    the LPs may find directions narrower than the width tolerance (in r, where r_t spans
    2 mu r_n) that the rank count keeps (default run: 2 of 88 analyses), never the other way
    round.  The uniform sample keeps them: it works in r_t / mu, where they are as wide as
    the set's other narrow directions."""
    assert packings.sizes["packing"] >= 6
    wide = packings.mu.values >= MU_THIN
    np.testing.assert_array_equal(packings.dim_AC_lp.values[wide], packings.dim_AC_rank.values[wide])
    assert (packings.dim_AC_lp.values <= packings.dim_AC_rank.values).all()
    assert (packings.dim_AC_rank.values <= packings.dim_A.values).all()


def test_walk_samples_are_inside_the_exact_ranges(packings):
    """Every accepted random-walk state lies within the exact range of each force component,
    up to 1e-5 of the largest walk force.  That margin is conditioning, not sampling: on a
    nearly determinate slice at mu = 1 of the default run a walk state with an equilibrium
    residual of 2e-13 and a cone violation of 6e-14 lies 4e-6 (relative) below the LP
    minimum of one r_n, which a direct LP on the same slice confirms to 1e-9."""
    ok = packings.walk_point.values == 1
    assert ok[:, 0].all() and ok.sum() >= 2 * packings.sizes["packing"]
    for j in range(packings.sizes["packing"]):
        k = int(packings.n_contacts[j])
        tol = 1e-5 * np.nanmax(np.abs(packings.walk_n.values[j]))
        for comp in ("n", "t"):
            lo = np.nan_to_num(packings[f"force_min_{comp}"].values[j, :k], nan=-np.inf)
            hi = np.nan_to_num(packings[f"force_max_{comp}"].values[j, :k], nan=np.inf)
            f = packings[f"walk_{comp}"].values[j][ok[j]][:, :k]
            assert (f >= lo - tol).all() and (f <= hi + tol).all(), (j, comp)


def test_claims_are_measured(results):
    from ncd.shared.verdict import BEYOND, CONSISTENT, NOT_TESTED, VERDICTS
    for claim_id, claim in gc.UNGER_CLAIMS.items():
        v = claim(results)
        assert v.verdict in VERDICTS[:2] + (NOT_TESTED, BEYOND) and v.anchor == f"claim-{claim_id}", (claim_id, v)
        assert "nan" not in v.value
    assert gc.claim_unger_citation(results).verdict == CONSISTENT


def test_wedged_disc_is_unbounded():
    """A disc held by friction between two walls facing each other (rows: F_x, F_y,
    torque; unit weight): r_t = ±1/2, r_n1 = r_n2 >= 1 / (2 mu), unbounded above."""
    mu = 0.5
    H = sp.csr_matrix([[1.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, -1.0], [0.0, -1.0, 0.0, -1.0]])
    m = ge.exact_measures(H, [0.0, -1.0, 0.0], mu)
    assert not m["bounded"] and np.isnan(m["eta_exact"])
    assert (m["dim_A"], m["dim_AC_rank"], m["dim_AC_lp"]) == (1, 1, 1)
    np.testing.assert_allclose(m["force_min"][:, 0], 0.5 / mu, rtol=1e-9)
    assert np.isinf(m["force_max"][:, 0]).all()
    np.testing.assert_allclose([m["force_min"][0, 1], m["force_max"][0, 1]], [0.5, 0.5], atol=1e-9)


# ---------------------------------------------------------------------------- why a line


def _chain_case():
    """Six grains in a chain 0-1-2-3-4-5 (contacts k: k-(k+1)) and a ground contact on 0.
    Solution 1 differs from solution 0 on grains 1, 2 only, along (1, 0.5) (one free
    cluster, one degree of freedom); solution 2 differs on grains 4, 5 along (0, 1)."""
    body_a = np.array([0, 1, 2, 3, 4, 0])
    body_b = np.array([1, 2, 3, 4, 5, -1])
    a0 = np.zeros((6, 2))
    a1 = a0.copy()
    a1[[1, 2]] = [[1.0, 0.5], [2.0, 1.0]]
    a2 = a0.copy()
    a2[[4, 5]] = [[0.0, 1.0], [0.0, 3.0]]
    s0 = np.array([1, 1, 1, 1, 1, 1])
    s1 = s0.copy()
    s1[1] = 2                    # the contact 1-2 slides in solution 1
    s2 = s0.copy()
    s2[4] = 0                    # the contact 4-5 opens in solution 2
    return body_a, body_b, (a0, a1, a2), (s0, s1, s2)


def test_cluster_test_on_one_known_free_cluster():
    """Two solutions differing on one cluster (grains 1, 2, one direction): the contacts
    switched, the differing grains, their cluster and its one degree of freedom are found
    exactly, and the line is predicted and observed."""
    body_a, body_b, a, s = _chain_case()
    rng = np.random.default_rng(0)
    pick = rng.integers(0, 2, 40)
    cloud = np.array([a[k][2] for k in pick]) + rng.normal(0, 1e-6, (40, 2))   # grain 2's cloud
    out = gl.line_analysis(np.array(a[:2]), np.array(s[:2]), body_a, body_b, cloud, 2, 1e-3)
    assert out["n_switched"] == 1 and out["n_moving"] == 2 and out["n_clusters"] == 1
    assert (out["field_rank"], out["cluster_size"], out["cluster_rank"], out["cloud_rank"]) == (1, 2, 1, 1)
    assert out["predicted_line"] == 1 and out["hypothesis_holds"] == 1
    moving, labels = gl.moving_clusters(np.array([a[1] - a[0]]), body_a, body_b, np.ones(6, bool), 1e-3)
    np.testing.assert_array_equal(np.nonzero(moving)[0], [1, 2])
    np.testing.assert_array_equal(labels, [-1, 0, 0, -1, -1, -1])


def test_cluster_test_on_two_independent_clusters():
    """A third solution moves another cluster (grains 4, 5) in another direction: two
    clusters, the whole field spans two directions, yet grain 2's cluster keeps one
    degree of freedom and its cloud a line; a grain moved by both would not."""
    body_a, body_b, a, s = _chain_case()
    pick = np.arange(30) % 3
    cloud2 = np.array([a[k][2] for k in pick])
    out = gl.line_analysis(np.array(a), np.array(s), body_a, body_b, cloud2, 2, 1e-3)
    assert (out["n_switched"], out["n_moving"], out["n_clusters"], out["field_rank"]) == (2, 4, 2, 2)
    assert (out["cluster_rank"], out["cloud_rank"], out["predicted_line"], out["hypothesis_holds"]) == (1, 1, 1, 1)
    # one cluster with two degrees of freedom: grain 2 moves along (1, 0.5) or (0, 1)
    a3 = np.array(a)
    a3[2, 2] = [0.0, 1.0]
    a3[2, [4, 5]] = 0.0
    cloud3 = np.array([a3[k][2] for k in pick])
    out = gl.line_analysis(a3, np.array(s), body_a, body_b, cloud3, 2, 1e-3)
    assert (out["n_clusters"], out["cluster_rank"], out["cloud_rank"], out["predicted_line"]) == (1, 2, 2, 0)
    assert out["hypothesis_holds"] == 1


def test_status_dimension_of_a_disc_in_a_corner():
    """A disc resting in a corner (floor and wall), both contacts sticking: 4 impulse
    unknowns, 3 equations of motion, the Delassus matrix has rank 3 -> the impulses keeping
    the statuses form a line (a self-stress pushing the disc into the corner) along which
    no grain moves; with the wall open the floor's impulse is fixed."""
    from ncd.dynamics.stepper import prepare_step
    from ncd.solver.finish import global_delassus

    scene = ncd.make_scene([[1.0, 1.0]], [1.0], walls=[((0.0, 0.0), (0.0, 1.0)), ((0.0, 0.0), (1.0, 0.0))],
                           gravity=(-1.0, -9.81), mu=0.5)
    problem = prepare_step(scene, 1e-3)
    assert problem.contacts.n == 2
    W, H, _ = global_delassus(scene, problem.contacts)
    assert gl.status_dimension(W, H, problem.contacts.mu, np.array([1, 1])) == (1, 0)
    assert gl.status_dimension(W, H, problem.contacts.mu, np.array([1, 0])) == (0, 0)
    assert gl.status_dimension(W, H, problem.contacts.mu, np.array([2, 0])) == (0, 0)


def test_cloud_and_field_rank():
    t = np.linspace(0, 1, 9)
    assert gl.cloud_rank(t, 2 * t, 1e-3)[0] == 1
    assert gl.cloud_rank(np.zeros(5), np.zeros(5), 1e-3)[0] == 0
    assert gl.cloud_rank(np.cos(7 * t), np.sin(7 * t), 1e-3)[0] == 2
    f = np.zeros((3, 4, 2))
    f[1, 0] = [1, 0]
    f[2, 0] = [2, 0]
    assert gl.field_rank(f, 1e-6) == 1
    f[2, 3] = [0, 1]
    assert gl.field_rank(f, 1e-6) == 2


# ---------------------------------------------------------------- flows (DAG run)
def yaml_config(ds):
    """The config a dataset was computed with (its provenance)."""
    return yaml.safe_load(ds.attrs["config_yaml"])


@pytest.fixture(scope="module")
def flows(results):
    return xr.load_dataset(results / "fig5_governing" / "flows.nc")


def test_flow_study_design(flows):
    """Every setting of the one-factor-at-a-time design has its seeds, and every scan
    is accounted for (indeterminate, determinate or unknown)."""
    from ncd.figures.fig5_governing import flow as gf
    cfg = yaml_config(flows)["flows"]
    tab = gf.settings_table(cfg)
    assert flows.sizes["flow"] == len(tab["mu"]) * cfg["seeds"]
    np.testing.assert_allclose(np.sort(flows.mu.values), np.sort(np.repeat(tab["mu"], cfg["seeds"])))
    assert set(np.unique(flows.indeterminate.values)) <= {-1, 0, 1}
    runs = cfg["scan"]["runs"]
    assert (flows.converged_zero.values <= runs).all() and (flows.converged_warm.values <= runs).all()
    none = flows.converged_zero.values + flows.converged_warm.values == 0
    assert (flows.indeterminate.values[none] == -1).all()
    assert (flows.n_solutions.values[~none] >= 1).all()


def test_indeterminate_steps_have_distinct_exact_solutions(flows):
    """At an indeterminate step at least two exact solutions differ by more than the
    threshold; the ranks are consistent (a cluster spans no more directions than the
    field, the field no more than the solutions allow), and a cluster with one degree of
    freedom makes the grain's cloud a line (or a point) whatever the iteration error."""
    cfg = yaml_config(flows)["flows"]
    ind = flows.indeterminate.values == 1
    if not ind.any():
        pytest.skip("no indeterminate step in this run")
    assert (flows.n_exact.values[ind] >= 2).all()
    assert (flows.exact_spread.values[ind] > cfg["scan"]["threshold"]).all()
    nex, fr, cr = flows.n_exact.values[ind], flows.field_rank.values[ind], flows.cluster_rank.values[ind]
    assert (fr <= nex - 1).all() and (cr <= fr).all() and (fr >= 1).all()
    assert (flows.cloud_rank.values[ind][cr == 1] <= 1).all()
    assert (flows.null_velocity.values[ind] <= flows.null_impulse.values[ind]).all()
    assert np.isnan(flows.field_rank.values[~ind]).all()


def test_flow_tables(flows):
    from ncd.figures.fig5_governing import summary as gs
    m = gs.flow_measures(flows)
    ok = np.isfinite(m["indeterminate"])
    assert ((m["indeterminate"][ok] >= 0) & (m["indeterminate"][ok] <= 1)).all()
    for factor in ("mu", "h", "slope"):
        t = gs.factor_table(flows, factor, "indeterminate")
        assert len(t) >= 2 and t[:, 3].sum() >= 2 * yaml_config(flows)["flows"]["seeds"]
    c = gs.line_counts(flows)
    assert c["steps"] == int((flows.indeterminate.values == 1).sum()) == sum(c["rank"])
    assert c["holds"] <= c["steps"] and c["line_and_predicted"] + c["line_not_predicted"] == c["rank"][1]


def test_flow_settings_one_factor_at_a_time():
    from ncd.figures.fig5_governing import flow as gf
    f = dict(base={"mu": 0.5, "h": 5e-4, "slope_deg": 24.0}, mu=[0.1, 0.3, 0.8], h=[2e-4, 2e-3], slope_deg=[20.0],
             duration=0.05, scan_every=0.005)
    t = gf.settings_table(f)
    assert len(t["mu"]) == 7 and t["factor"].tolist() == [0, 1, 1, 1, 2, 2, 3]
    # each extra setting changes exactly one parameter of the base
    changed = (t["mu"] != 0.5).astype(int) + (t["h"] != 5e-4) + (t["slope_deg"] != 24.0)
    assert changed.tolist() == [0, 1, 1, 1, 1, 1, 1]
    assert gf.deposit_mu(f) == 0.5
    np.testing.assert_allclose(gf.scan_times(f), 0.005 * np.arange(1, 11))
    with pytest.raises(ncd.InputError, match="flows.h"):
        gf.settings_table(dict(f, h=[5e-4]))
    with pytest.raises(ncd.InputError, match="duration"):
        gf.scan_times(dict(f, duration=0.001))


def test_mean_settling_compares_means_over_packings():
    """The walk's convergence in the means over packings: packing A moves only in its second
    half ([1, 1, 1, 3, 3]: eta_U 0 then 0.6086), B oscillates ([2, 4, 2, 4, 2]: 0.4330 then
    0.3912), a determinate C counts 0; (0 + 0.4330 + 0) / (0.6086 + 0.3912 + 0) - 1 = -0.567."""
    n = np.array([[1, 1, 1, 3, 3], [2, 4, 2, 4, 2], [5, 5, 5, 5, 5]], float)[:, :, None]
    ds = xr.Dataset({"walk_n": (("packing", "sample", "contact"), n),
                     "walk_t": (("packing", "sample", "contact"), np.zeros_like(n)),
                     "walk_point": (("packing", "sample"), np.ones((3, 5), np.int8)),
                     "n_contacts": ("packing", [1, 1, 1]), "dim_AC_rank": ("packing", [1.0, 1.0, 0.0]),
                     "kind": ("packing", [0, 0, 0]), "mu_index": ("packing", [0, 0, 0])})
    assert gc.walk_eta_at(ds, 0, 2) == 0.0 and gc.walk_eta_at(ds, 2, 4) == 0.0
    assert gc.walk_eta_at(ds, 0, 4) == pytest.approx(np.sqrt(1.2) / 1.8, rel=1e-12)
    assert gc.walk_eta_at(ds, 1, 2) == pytest.approx(np.sqrt(4 / 3) / (8 / 3), rel=1e-12)
    full = (np.sqrt(1.2) / 1.8 + np.sqrt(1.2) / 2.8) / 3
    assert gc.mean_settling(ds) == pytest.approx(1 - np.sqrt(4 / 3) / (8 / 3) / 3 / full, rel=1e-12)
    assert gc.mean_settling(ds, kind=1) == 0.0


def test_analysis_shards_interleave_and_partition_the_table():
    """Each shard holds every n-th analysis (so every shard spans the mu grid, whose small
    values cost most), and the shards together hold each analysis once."""
    parts = [shard_members(104, k, 8, interleaved=True) for k in range(8)]
    np.testing.assert_array_equal(np.sort(np.concatenate(parts)), np.arange(104))
    np.testing.assert_array_equal(parts[1][:3], [1, 9, 17])
    with pytest.raises(ValueError, match="shard 8 is outside 0..7"):
        shard_members(104, 8, 8, interleaved=True)
