"""Angle ranges of ExactSet by the Charnes-Cooper model against plain Dinkelbach iterations
and against the exact polygon, on a pile of a few tens of discs."""
import numpy as np
import pytest
from test_pile_exact import balanced

import ncd
from ncd.exact.exact_set import ExactSet
from ncd.figures.fig4_pile.exact import resultant_angle
from ncd.shared import cuts as cm


def lattice_pile(n_base=7, mu=0.3):
    """A triangular pile of n_base (n_base + 1) / 2 touching discs (radius 1) on n_base + 1
    fixed discs: hyperstatic with friction, so A ∩ C is a polytope of many dimensions."""
    h = np.sqrt(3.0)
    ground = np.column_stack([2.0 * np.arange(n_base + 1) - n_base, np.zeros(n_base + 1)])
    pos = np.array([[2.0 * i - (n_base - 1 - j), (j + 1) * h] for j in range(n_base) for i in range(n_base - j)])
    return ncd.make_scene(pos, np.ones(len(pos)), 1.0, obstacle_pos=ground, obstacle_radius=np.ones(len(ground)),
                          gravity=(0.0, -10.0), mu=mu)


def dinkelbach(es, L, outer, ref, tol=1e-12):
    """The angle range by Dinkelbach's iteration alone on A ∩ C from the ``min p`` point
    (the route without the homogenised model): ``(lo, hi, p_min)``, degrees."""
    M = np.diag([float(outer), -1.0]) @ L
    t = np.radians(ref)
    a, b = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
    p_min, r0 = es.minimize(M.T @ a)
    ends = []
    for sign in (-1.0, 1.0):
        r = r0
        lam = sign * (b @ M @ r) / (a @ M @ r)
        for _ in range(100):
            v, r_new = es.minimize(-(M.T @ (sign * b - lam * a)))
            lam_new = sign * (b @ M @ r_new) / (a @ M @ r_new)
            if -v <= tol * es.scale or lam_new <= lam:
                break
            lam, r = lam_new, r_new
        ends.append(ref + sign * np.degrees(np.arctan(lam)))
    return ends[0], ends[1], p_min


@pytest.fixture(scope="module")
def pile():
    scene = lattice_pile()
    c, H, F = balanced(scene)
    specs = [(s * x, s, -np.inf, np.inf) for s in (-1, 1) for x in (0.5, 1.5, 2.5, 3.5, 4.5)]
    C, counts = cm.cut_matrix(c, scene.pos, scene.n_mobile, specs)
    assert counts.min() >= 2
    outer = np.repeat([-1, 1], 5)
    return H, F, c.mu, C.toarray(), outer


def test_angle_range_equals_plain_dinkelbach_and_certifies_with_one_lp_per_end(pile):
    """The Charnes-Cooper ends, certified by one Dinkelbach LP each, against Dinkelbach's
    iteration alone (a separate model): the same angles to 1e-9 degree, the same p_min;
    five LPs per cut (min p, two ends, two certificates, whose LP starts at its optimum)."""
    H, F, mu, C, outer = pile
    es, plain = ExactSet(H, F, mu), ExactSet(H, F, mu)
    widths = []
    for k in range(len(outer)):
        L = C[2 * k: 2 * k + 2]
        g = L @ es.minimize(np.zeros(es.n))[1]
        ref = np.degrees(np.arctan2(-g[1], outer[k] * g[0])) + 3.0    # a separating reference, off centre
        r = es.angle_range(L, outer[k], ref=ref)
        assert es.highs.getInfo().simplex_iteration_count == 0
        lo, hi, p_min = dinkelbach(plain, L, outer[k], ref)
        assert abs(r["lo"] - lo) <= 1e-9 and abs(r["hi"] - hi) <= 1e-9
        assert abs(r["p_min"] - p_min) <= 1e-9 * es.scale and r["bound"] <= 1e-9
        assert r["n_lp"] == 5
        eq, co = es.fp.violations(r["points"])
        assert eq.max() <= 1e-9 and co.max() <= 1e-9
        widths.append(hi - lo)
    assert min(widths) > 1.0                                          # ranges worth comparing


def test_angle_range_equals_the_angles_of_the_exact_polygon(pile):
    """Against an independent computation: the angle range of the vertices of the exact
    image polygon (support LPs until every hull edge is confirmed)."""
    H, F, mu, C, outer = pile
    es = ExactSet(H, F, mu)
    for k in range(len(outer)):
        L = C[2 * k: 2 * k + 2]
        poly = es.polygon(L, n_dirs=90)
        assert poly["exact"]
        lo, hi = resultant_angle(poly["vertices"], outer[k])
        r = es.angle_range(L, outer[k])
        assert abs(r["lo"] - lo) <= 1e-8 and abs(r["hi"] - hi) <= 1e-8


def test_clp_simplex_gives_the_highs_angle_ranges_intervals_and_polygons(pile):
    """``simplex="clp"`` (HiGHS's first basis, then CLP from basis to basis, the route of the
    10^4-grain piles) against HiGHS alone on the same cuts and the same sequence of LPs: the
    same angle ranges to 1e-9 degree, p_min and the intervals of the resultants' components
    to 1e-9 of the force scale, the same exact polygon areas, and LP points in A ∩ C."""
    H, F, mu, C, outer = pile
    ref, clp = ExactSet(H, F, mu), ExactSet(H, F, mu, simplex="clp")
    assert clp.simplex == "clp" and clp._clp is None
    clp.minimize(np.zeros(clp.n))                                     # HiGHS's first LP, then CLP
    widths = []
    for k in range(len(outer)):
        L = C[2 * k: 2 * k + 2]
        g = L @ ref.minimize(np.zeros(ref.n))[1]
        phi = np.degrees(np.arctan2(-g[1], outer[k] * g[0])) + 3.0    # the same reference for both
        a, b = ref.angle_range(L, outer[k], ref=phi), clp.angle_range(L, outer[k], ref=phi)
        assert clp._clp is not None
        assert abs(a["lo"] - b["lo"]) <= 1e-9 and abs(a["hi"] - b["hi"]) <= 1e-9
        assert abs(a["p_min"] - b["p_min"]) <= 1e-9 * ref.scale and b["bound"] <= 1e-9
        eq, co = clp.fp.violations(b["points"])
        assert eq.max() <= 1e-9 and co.max() <= 1e-9
        assert np.abs(ref.intervals(L) - clp.intervals(L)).max() <= 1e-9 * ref.scale
        widths.append(a["hi"] - a["lo"])
    assert min(widths) > 1.0
    L = C[:2]
    pa, pb = ref.polygon(L, n_dirs=36), clp.polygon(L, n_dirs=36)
    assert pa["exact"] and pb["exact"]
    assert abs(pa["inner_area"] - pb["inner_area"]) <= 1e-9 * max(pa["inner_area"], 1e-300)


def test_clp_simplex_reports_an_empty_polytope_and_a_bad_choice():
    """An empty A ∩ C is a PolytopeError by either simplex, after the first LP too; an unknown
    ``simplex`` is an InputError naming the argument, before any model is built."""
    from ncd.core.errors import InputError
    from ncd.exact.polytope import PolytopeError
    scene = lattice_pile(n_base=3, mu=0.3)
    c, H, F = balanced(scene)
    es = ExactSet(H, F, c.mu, simplex="clp")
    es.minimize(np.zeros(es.n))
    with pytest.raises(PolytopeError, match="empty"):
        ExactSet(H, 1e3 * np.abs(F) + 1.0, c.mu, simplex="clp").minimize(np.zeros(es.n))
    with pytest.raises(InputError, match="simplex = 'cplex'"):
        ExactSet(H, F, c.mu, simplex="cplex")


def test_clp_model_refuses_arrays_of_the_wrong_length_before_clp_reads_them():
    """CLP reads bounds, basis and a new row by the model's sizes: a shorter array is a
    ValueError naming it, never a read past its end."""
    import scipy.sparse as sp

    from ncd.exact.clp_model import ClpModel
    A = sp.csr_matrix(np.array([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]]))
    one, zero = np.ones(2), np.zeros(3)
    with pytest.raises(ValueError, match="col_hi has shape"):
        ClpModel(A, one, one, zero, np.ones(2), 1e-10)
    with pytest.raises(ValueError, match="row_lo has shape"):
        ClpModel(A, np.ones(1), one, zero, np.ones(3), 1e-10)
    m = ClpModel(A, one, one, zero, np.ones(3), 1e-10)
    m.set_cost(np.array([1.0, 0.0, 1.0]))
    assert m.run() == "optimal"
    np.testing.assert_allclose(m.solution(), [0.0, 1.0, 0.0], atol=1e-12)
    with pytest.raises(ValueError, match="w has shape"):
        m.set_last_row(np.ones(2), 1.0, 1.0)
    with pytest.raises(ValueError, match="basis of shape"):
        m.set_basis(np.zeros(2, np.int8), np.zeros(2, np.int8))


def test_chord_bounds_bit_for_bit_as_the_branchy_loop():
    """The hit-and-run chord (``ncd.exact.polytope._chord``, branch-free) against the loop
    that divides only where a row bounds a side: the same bounds bit for bit, with zero
    slopes, zero slacks and rows of both signs; a direction that no row bounds gives
    infinite bounds on both sides."""
    from ncd.exact.polytope import _chord as chord

    def branchy(slack, g):
        lo, hi = -np.inf, np.inf
        for s, gi in zip(slack, g):
            if gi > 0.0:
                hi = min(hi, s / gi)
            elif gi < 0.0:
                lo = max(lo, s / gi)
        return lo, hi

    rng = np.random.default_rng((0, 51))
    for _ in range(200):
        m = int(rng.integers(1, 60))
        g = rng.normal(size=m) * 10.0 ** rng.uniform(-8, 8, m)
        g[rng.uniform(size=m) < 0.2] = 0.0
        slack = np.abs(rng.normal(size=m)) * 10.0 ** rng.uniform(-12, 2, m)
        slack[rng.uniform(size=m) < 0.1] = 0.0
        got, want = chord(slack, g), branchy(slack, g)
        assert np.array_equal(np.array(got).view(np.int64), np.array(want).view(np.int64)), (got, want)
    assert chord(np.ones(3), np.zeros(3)) == (-np.inf, np.inf)
    assert chord(np.array([2.0, 3.0]), np.array([1.0, -1.0])) == (-3.0, 2.0)
