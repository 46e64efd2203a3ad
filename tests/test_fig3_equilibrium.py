"""Figure 3 (section 4): the polytope A ∩ C, exactly and by NLGS.

Unit tests of :mod:`ncd.exact.polytope` on problems with a known answer, then the
claims of the figure on the data of the DAG run (fixture ``results``).
"""
import numpy as np
import pytest
import scipy.sparse as sp
import xarray as xr
import yaml

import ncd
from ncd.core.contacts import external_load, h_matrix
from ncd.dynamics.explore import member_rng
from ncd.exact.polygon import boundary_distance, convex_hull, outside_distance, polygon_area
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.figures.fig3_equilibrium import measure as fe
from ncd.figures.fig3_equilibrium.packing import rest_problem


# ---------------------------------------------------------------- unit tests
def _shared_load(mu):
    """Two vertical supports share a unit load: r_n1 + r_n2 = 1 (one equation).

    A ∩ C = {r_n1 in [0, 1], |r_t1| <= mu r_n1, |r_t2| <= mu (1 - r_n1)}, of
    dimension 3; its projection on contact 1 is the triangle (0, 0), (1, ±mu).
    """
    return ForcePolytope(sp.csr_matrix([[1.0, 0.0, 1.0, 0.0]]), [-1.0], mu)


def test_projection_of_a_known_triangle():
    mu = 0.4
    P = _shared_load(mu)
    assert P.dimension() == (3, 3)
    assert P.is_bounded()
    for k in (0, 1):
        p = P.project(k, n_init=3)
        assert p["exact"]
        v = p["vertices"][np.lexsort(p["vertices"].T)]
        np.testing.assert_allclose(v, [[1.0, -mu], [0.0, 0.0], [1.0, mu]], atol=1e-9)
        assert p["inner_area"] == pytest.approx(mu, rel=1e-9)
        assert p["outer_area"] == pytest.approx(mu, rel=1e-6)


def test_projection_matches_dense_support_function():
    """Support values of the polygon equal direct LP support values in 90 directions."""
    rng = np.random.default_rng(3)
    H = rng.normal(size=(4, 12))
    H[0] = np.tile([1.0, 0.0], 6)                          # total normal force fixed: bounded
    F = -H @ np.tile([1.0, 0.1], 6)                        # a strictly feasible point
    P = ForcePolytope(sp.csr_matrix(H), F, 0.6)
    assert P.is_bounded() and P.dimension() == (8, 8)
    p = P.project(2, n_init=4)
    assert p["exact"] and len(p["vertices"]) >= 3
    for a in np.linspace(0, 2 * np.pi, 90, endpoint=False):
        u = np.array([np.cos(a), np.sin(a)])
        direct = u @ P.support(2, u)[4:6]
        assert (p["vertices"] @ u).max() == pytest.approx(direct, abs=1e-8 * P.scale)


def _wedge(beta_deg, mu):
    """Disc of weight W on two fixed discs, contact normals at beta above the horizontal."""
    R, Ro = 0.1, 0.15
    b = np.radians(beta_deg)
    d = (R + Ro) * np.array([np.cos(b), np.sin(b)])
    scene = ncd.make_scene([[0.0, 0.0]], R, 1.0, obstacle_pos=[-d, [d[0], -d[1]]], obstacle_radius=Ro, mu=mu)
    problem = rest_problem(scene, 1e-3)
    assert problem.contacts.n == 2
    F = external_load(scene)
    return ForcePolytope(h_matrix(scene, problem.contacts), F, problem.contacts.mu), -F[1], b


def test_wedged_disc_segment_and_unbounded_wedge():
    mu = 0.5
    P, W, b = _wedge(40.0, mu)                               # tan 40 deg > mu: bounded
    assert P.dimension() == (1, 1) and P.is_bounded()
    n_min = W / (2 * (np.sin(b) + mu * np.cos(b)))
    n_max = W / (2 * (np.sin(b) - mu * np.cos(b)))
    for k in (0, 1):
        p = P.project(k)
        assert p["exact"] and len(p["vertices"]) == 2 and p["inner_area"] == 0.0
        v = p["vertices"][np.argsort(p["vertices"][:, 0])]
        np.testing.assert_allclose(v[:, 0], [n_min, n_max], rtol=1e-8)
        np.testing.assert_allclose(np.abs(v[:, 1]), mu * v[:, 0], rtol=1e-8)
        assert np.sign(v[0, 1]) == -np.sign(v[1, 1])
    P2, _, _ = _wedge(20.0, mu)                              # tan 20 deg < mu: a self-stress
    assert not P2.is_bounded()
    with pytest.raises(PolytopeError, match="unbounded"):
        P2.uniform_samples(lambda k: member_rng(k, 0), 2, 10)


def test_uniform_sampler_is_uniform_on_the_triangle_problem():
    """r_n1 of a uniform point of A ∩ C has density ∝ r(1 - r) (Beta(2, 2): var 1/20, not 1/12)."""
    mu = 0.5
    P = _shared_load(mu)
    X, info = P.uniform_samples(lambda k: member_rng(k, 11), 4, 2000)
    assert info["dimension"] == 3 and info["rhat"] < 1.05
    eq, co = P.violations(X)
    assert eq.max() < 1e-12 and co.max() < 1e-12
    r = X[:, 0]
    assert r.mean() == pytest.approx(0.5, abs=0.02)
    assert r.var() == pytest.approx(1 / 20, abs=0.004)
    assert np.mean(X[:, 1] ** 2) == pytest.approx(mu ** 2 * 0.3 / 3, rel=0.08)


def test_active_faces_and_polygon_helpers():
    mu = 0.5
    P = _shared_load(mu)
    vertex = [1.0, mu, 0.0, 0.0]             # contact 1 sliding at full load, contact 2 unloaded
    inner = [0.5, 0.0, 0.5, 0.0]
    n_active, dims = P.active_faces(np.array([vertex, inner]))
    assert list(dims) == [0, 3] and list(n_active) == [1 + 3, 0]
    square = convex_hull([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [1, 0.5], [1 + 1e-13, 1]], tol=1e-9)
    assert len(square) == 4 and polygon_area(square) == pytest.approx(1.0)
    np.testing.assert_allclose(outside_distance([[0.5, 0.5], [2, 0.5], [2, 2]], square), [0, 1, np.sqrt(2)])
    np.testing.assert_allclose(boundary_distance([[0.5, 0.5], [0.9, 0.5], [2, 0.5]], square), [0.5, 0.1, -1.0])


def test_face_census_of_the_shared_load():
    """The triangle problem of _shared_load: a vertex (contact 1 sliding at full load,
    contact 2 without force), an interior point, and a point where both slide."""
    from ncd.figures.fig3_equilibrium import faces
    mu = 0.5
    P = _shared_load(mu)
    pts = np.array([[1.0, mu, 0.0, 0.0], [0.5, 0.0, 0.5, 0.0], [0.5, 0.25, 0.5, -0.25]])
    dims, free, slide = faces.face_census(P, pts)
    assert list(dims) == [0, 3, 1] and list(free) == [1, 0, 0] and list(slide) == [1, 0, 2]
    s = faces.face_summary(P, {"zero": pts[:2], "random": pts[1:2]})
    assert s["zero"]["interior"] == 1 and s["zero"]["with_free"] == 1 and s["random"]["interior"] == 1
    text = faces.face_text(s)
    assert "1 lie on a proper face" in text and "1 is interior" in text and "at most 1" in text


# ---------------------------------------------------------------- the figure data
@pytest.fixture(scope="module")
def fig3(results):
    d = results / "fig3_equilibrium"
    data = {name: xr.load_dataset(d / f"{name}.nc") for name in ("state", "ensemble", "projection", "uniform")}
    data["cfg"] = yaml.safe_load(data["ensemble"].attrs["config_yaml"])
    data["P"] = fe.polytope_of(data["state"])
    data["results"] = results
    return data


def test_packing_is_at_rest_and_polytope_is_exact(fig3):
    st, pr = fig3["state"], fig3["projection"]
    kappa, n = st.sizes["contact"], st.sizes["disc"]
    assert n == fig3["cfg"]["packing"]["n_discs"] and st.attrs["at_rest"] == 1
    assert st.attrs["rest_max_velocity"] <= fig3["cfg"]["packing"]["velocity_tol"]
    assert pr.attrs["dimension_moreau"] == 2 * kappa - 3 * n
    assert pr.attrs["dimension_A"] >= pr.attrs["dimension_moreau"] and pr.attrs["bounded"] == 1
    assert pr.exact.all() and pr.bounded.all()
    area = pr.area.values
    assert np.all(np.abs(pr.outer_area.values - area) <= 1e-6 * area.max())
    assert pr.displayed.sum() == fig3["cfg"]["projection"]["display"]
    assert (fig3["results"] / "figures" / "fig3_equilibrium.png").stat().st_size > 10_000


def test_converged_runs_are_equilibria_inside_the_exact_polygons(fig3):
    ens, pr, P = fig3["ensemble"], fig3["projection"], fig3["P"]
    for m in fe.MODES:
        assert (fe.mode_subset(ens, m).sizes["run"]) == fig3["cfg"]["modes"][m]["runs"]
    assert ens.converged.mean() >= 0.99
    conv = ens.isel(run=np.nonzero(ens.converged.values == 1)[0])
    assert conv.residual.max() <= fig3["cfg"]["solver"]["tol"]
    rho = np.stack([conv.force_n.values, conv.force_t.values], -1).reshape(conv.sizes["run"], -1)
    eq, co = P.violations(rho)
    assert eq.max() <= 1e-5           # |H r + F| relative to the largest weight (measured ~1e-6)
    assert co.max() <= 1e-12          # the local solver projects onto the sector exactly
    for k in range(conv.sizes["contact"]):
        pts = np.column_stack([conv.force_n.values[:, k], conv.force_t.values[:, k]])
        assert outside_distance(pts, fe.polygon(pr, k)).max() <= 1e-4 * P.scale, f"contact {k}"


def test_runs_are_classified(fig3):
    """outcome (ncd.solver.convergence): rest = converged and every grain slower than the stated
    bound; the clouds use the rest-state runs only."""
    ens = fig3["ensemble"]
    tol = fig3["cfg"]["packing"]["velocity_tol"]
    conv = ens.converged.values == 1
    np.testing.assert_array_equal(ens.outcome.values == 1, conv & (ens.max_speed.values <= tol))
    np.testing.assert_array_equal(ens.outcome.values == 0, ~conv)
    assert ens.outcome.attrs["flag_meanings"] == "unconverged rest motion"
    assert (ens.outcome.values == 1).mean() >= 0.99


def test_cloud_measures_of_the_displayed_contacts(fig3):
    ens, pr = fig3["ensemble"], fig3["projection"]
    shown = np.nonzero(pr.displayed.values)[0]
    rows = {(r["contact"], r["mode"]): r for r in fe.cloud_measures(ens, pr, fig3["uniform"], shown)}
    for k in shown:
        assert rows[k, "random"]["coverage"] >= rows[k, "zero"]["coverage"]
        assert rows[k, "warm"]["spread"] <= 1e-2 * rows[k, "zero"]["spread"]
        for m in ("zero", "random", "uniform"):
            assert 0 < rows[k, m]["coverage"] <= 1 + 1e-6


def test_face_statements_over_every_run(fig3):
    """The notebook's face statements are measured over all runs: every zero-guess run on a
    proper face, the warm runs interior, and the text says what the counts say."""
    from ncd.figures.fig3_equilibrium import faces
    ens, P = fig3["ensemble"], fig3["P"]
    modes = {m: np.stack([fe.mode_subset(ens, m).force_n.values, fe.mode_subset(ens, m).force_t.values],
                         -1).reshape(fe.mode_subset(ens, m).sizes["run"], -1) for m in fe.MODES}
    s = faces.face_summary(P, modes)
    assert sum(v["runs"] for v in s.values()) == ens.sizes["run"]
    assert s["zero"]["interior"] <= 0.01 * s["zero"]["runs"]
    assert s["warm"]["interior"] == s["warm"]["runs"]
    text = faces.face_text(s)
    for m in ("zero", "random"):
        assert f"{s[m]['runs']} {m}-guess runs" in text


def test_uniform_points_are_equilibria(fig3):
    uni, P = fig3["uniform"], fig3["P"]
    X = np.stack([uni.force_n.values, uni.force_t.values], -1).reshape(uni.sizes["sample"], -1)
    eq, co = P.violations(X)
    assert eq.max() <= 1e-9 and co.max() <= 1e-12
    assert uni.attrs["rhat_max"] < 1.1
    # interior points: every Coulomb row strictly satisfied (face of full dimension)
    _, dims = P.active_faces(X[:200], tol=1e-12)
    assert np.all(dims == fig3["projection"].attrs["dimension_AC"])


def test_members_do_not_depend_on_the_shard_count(fig3):
    st, ens, cfg = fig3["state"], fig3["ensemble"], fig3["cfg"]
    runs = cfg["modes"]["zero"]["runs"]
    n = runs // 2                       # shards of about two runs, not the DAG's shard count
    for shard in (0, n - 1):
        part = fe.run_ensemble(st, cfg, "zero", shard, n)
        ref = ens.sel(run=part.run.values)
        for v in ("force_n", "force_t", "sweeps", "residual", "converged", "mode"):
            np.testing.assert_array_equal(part[v].values, ref[v].values, err_msg=v)
    warm = fe.run_ensemble(st, cfg, "warm", 0, 1)
    np.testing.assert_array_equal(warm.force_n.values, ens.sel(run=warm.run.values).force_n.values)


# ------------------------------------------------------------------ the page (ncd.figures.fig3_equilibrium.plots)
@pytest.fixture(scope="module")
def page_run(fig3):
    from ncd.figures.fig3_equilibrium import plots as ep

    return ep.Fig3Run(fig3["state"], fig3["ensemble"], fig3["projection"], fig3["uniform"])


def test_page_figure_is_legible(page_run):
    """Panels lettered once each (a, b, then one per contact and exploration), no overlapping
    texts, fonts of at least 9 pt on a figure of at most 11.5 in."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncd.figures.fig3_equilibrium import plots as ep
    from ncd.pages.notebook import MIN_FONT_PT, text_layout

    fig = ep.figure(page_run)
    letters = [ax.get_title(loc="left").split(")")[0] + ")" for ax in fig.axes if ax.get_title(loc="left")]
    assert len(letters) == 2 + 4 * len(page_run.shown) == len(set(letters))
    lay = text_layout(fig)
    assert lay["overlaps"] == [] and lay["min_font_pt"] >= MIN_FONT_PT and lay["width_in"] <= 11.5
    plt.close(fig)


def test_page_sentences_follow_the_data(page_run, fig3):
    """The table and sentences of the page carry the measured numbers: converged counts, the
    coverage of each displayed contact, the face census (every uniform point interior)."""
    from ncd.figures.fig3_equilibrium import plots as ep

    r = page_run
    conv = ep.convergence_text(r)
    for m, ds in r.subsets.items():
        assert f"{m}: {int(ds.converged.sum())} of {ds.sizes['run']} converged" in conv
    table = ep.measures_table(r)
    assert table.count("\n") == 1 + len(r.rows)
    for x in r.rows:
        assert f"| {x['contact']} | {x['mode']} | {x['points']} | {x['coverage']:.1%} |" in table
    u = r.faces["uniform"]
    assert u["interior"] == u["runs"] and f"{u['runs']} points of the uniform sample, {u['runs']} are interior" \
        in ep.faces_text(r)
    pa = fig3["projection"].attrs
    assert f"$\\dim A \\cap C$ = {pa['dimension_AC']}" in ep.packing_text(r)
    assert "nan" not in (conv + table + ep.findings_text(r) + ep.packing_text(r)).lower()
