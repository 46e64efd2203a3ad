"""Figure 5 (issue 15): exact measures of A ∩ C across friction, and Unger et al.'s eta.

Unit tests of :mod:`ncd.figures.governing_exact` on problems with a known answer and on
a frictionless packing, then the claims of the figure on the data of the DAG run
(fixture ``results``).
"""
import numpy as np
import pytest
import scipy.sparse as sp
import xarray as xr

import ncd
from ncd.contacts import h_matrix
from ncd.figures import governing as fg
from ncd.figures import governing_exact as ge
from ncd.figures.equilibrium import external_force, rest_problem


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


def test_frictionless_packing_is_determinate():
    """A packing built by contact dynamics at mu = 0: every contact force fixed, eta = 0."""
    p = dict(n_discs=14, radius_min=0.01, width_radii=14, density=1.0, gravity=9.81, root_seed=3, h=2e-4,
             max_steps=20000, check_every=100, speed_tol=1.0, velocity_tol=1e-6,
             solver=dict(tol=1e-4, max_sweeps=1000, check_every=10),
             rest_solver=dict(tol=1e-9, max_sweeps=50000, check_every=10))
    scene, info = fg.build(p, "box", 0.0, member=0)
    problem = rest_problem(scene, p["h"])
    m = ge.exact_measures(h_matrix(scene, problem.contacts), external_force(scene), problem.contacts.mu)
    assert m["n_contacts"] >= 14
    assert (m["dim_AC_rank"], m["dim_AC_lp"]) == (0, 0)
    assert m["n_fixed"] == m["n_contacts"]
    assert m["eta_exact"] <= 1e-6
    np.testing.assert_allclose(m["force_min"][:, 1], 0.0, atol=1e-9 * m["scale"])


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


def test_unger_eta_of_known_samples():
    f0 = np.array([[1.0, 0.0], [3.0, 0.0]])
    f1 = f0 + np.array([[0.0, 0.5], [0.0, -0.5]])
    assert ge.unger_eta([f0, f1, f0]) == pytest.approx((0.5 + 0.0) / 2 / 2.0)


def test_packing_table_and_bad_friction():
    p = dict(mu_min=0.01, mu_max=1.0, n_mu=3, kinds={"plates": 2, "box": 1})
    t = fg.packing_table(p)
    assert len(t["mu"]) == 9 and len(set(t["member"].tolist())) == 9
    np.testing.assert_allclose(np.unique(t["mu"]), [0.01, 0.1, 1.0])
    with pytest.raises(ncd.InputError, match="mu_min"):
        fg.mu_values(dict(mu_min=0.0, mu_max=1.0, n_mu=3))
    with pytest.raises(ncd.InputError, match="kinds"):
        fg.packing_table(dict(p, kinds={"lid": 1}))


def test_ballistic_start_has_no_overlap():
    rng = np.random.default_rng(0)
    radius = rng.uniform(1.0, 2.0, 60)
    pos = fg.ballistic(radius, 42.0, True, rng)
    d = pos[:, None] - pos[None]
    d[..., 0] -= 42.0 * np.round(d[..., 0] / 42.0)
    gap = np.hypot(d[..., 0], d[..., 1]) - (radius[:, None] + radius[None])
    np.fill_diagonal(gap, np.inf)
    assert gap.min() >= -1e-9 and (pos[:, 1] >= radius - 1e-12).all()


# ---------------------------------------------------------------- figure data (DAG run)
@pytest.fixture(scope="module")
def packings(results):
    return xr.load_dataset(results / "fig5_governing" / "packings.nc")


def test_lp_dimension_agrees_with_rank_count(packings):
    assert packings.sizes["packing"] >= 6
    np.testing.assert_array_equal(packings.dim_AC_lp.values, packings.dim_AC_rank.values)
    assert (packings.dim_AC_rank.values <= packings.dim_A.values).all()
    assert (packings.dim_AC_rank.values > 0).all()      # frictional packings: indeterminate


def test_exact_ranges_contain_every_relaxed_solution(packings):
    ok = packings.relaxed_ok.values == 1
    assert ok.sum() >= packings.sizes["packing"]
    for j in range(packings.sizes["packing"]):
        k = int(packings.n_contacts[j])
        tol = 1e-6 * np.nanmax(np.abs(packings.relaxed_n.values[j]))
        for comp in ("n", "t"):
            lo = np.nan_to_num(packings[f"force_min_{comp}"].values[j, :k], nan=-np.inf)  # NaN: unbounded
            hi = np.nan_to_num(packings[f"force_max_{comp}"].values[j, :k], nan=np.inf)
            f = packings[f"relaxed_{comp}"].values[j][ok[j]][:, :k]
            assert (f >= lo - tol).all() and (f <= hi + tol).all(), (j, comp)


def test_eta_small_friction_below_peak(packings):
    for k in set(packings.kind.values.tolist()):
        t = fg.eta_table(packings, "eta_exact", k)
        assert t[0, 1] < 0.8 * np.nanmax(t[:, 1])
