"""The exact set A ∩ C of small piles (ncd.figures.fig4_pile.exact) and the ground-pressure maps."""
import numpy as np
import pytest

import ncd
from ncd.core.contacts import h_matrix
from ncd.exact.exact_set import ExactSet
from ncd.exact.polytope import ForcePolytope
from ncd.figures.fig4_pile import pressure as pm
from ncd.figures.fig4_pile.exact import resultant_angle


def balanced(scene):
    c = ncd.prepare_step(scene, 1e-3, 1.0, vel=np.zeros_like(scene.vel), spin=np.zeros_like(scene.spin)).contacts
    nm = scene.n_mobile
    F = np.zeros((nm, 3))
    F[:, :2] = scene.mass[:nm, None] * scene.gravity[None, :]
    return c, h_matrix(scene, c), F.ravel()


def disc_on_two(theta, mu, R=1.0):
    """One disc resting on two fixed discs at +-theta from the vertical."""
    obstacles = np.array([[-2 * R * np.sin(theta), -2 * R * np.cos(theta)],
                          [2 * R * np.sin(theta), -2 * R * np.cos(theta)]])
    return ncd.make_scene(np.zeros((1, 2)), [R], 1.0, obstacle_pos=obstacles, obstacle_radius=[R, R],
                          gravity=(0.0, -10.0), mu=mu)


@pytest.mark.parametrize("theta_deg, mu", [(30.0, 0.3), (45.0, 0.5), (20.0, 0.8)])
def test_disc_on_two_supports_by_hand(theta_deg, mu):
    """A ∩ C is the segment of the self-stress along the chord of the two contact points:
    both normal forces n0 + lam sin(theta), tangential |lam| cos(theta), so the horizontal
    force of the left support spans [n0 s - mu n0 / (c + mu s), n0 s + mu n0 / (c - mu s)]."""
    theta = np.radians(theta_deg)
    scene = disc_on_two(theta, mu)
    c, H, F = balanced(scene)
    assert c.n == 2
    es = ExactSet(H, F, c.mu)
    weight = scene.mass[0] * 10.0
    n0 = weight / (2 * np.cos(theta))
    s, co = np.sin(theta), np.cos(theta)
    left = int(np.argmin(c.point[:, 0]))
    fx = np.zeros(4)
    fx[2 * left], fx[2 * left + 1] = c.normal[left, 0], c.tangent[left, 0]
    lo, hi = es.interval(fx)
    assert abs(lo - (n0 * s - mu * n0 / (co + mu * s))) <= 1e-9 * weight
    assert abs(hi - (n0 * s + mu * n0 / (co - mu * s))) <= 1e-9 * weight
    # the projection on the left support's force plane is that segment, at f_y = n0 cos(theta)
    L = np.zeros((2, 4))
    L[0] = fx
    L[1, 2 * left], L[1, 2 * left + 1] = c.normal[left, 1], c.tangent[left, 1]
    poly = es.polygon(L, n_dirs=12)
    assert poly["exact"] and len(poly["vertices"]) == 2
    np.testing.assert_allclose(sorted(poly["vertices"][:, 0]), [lo, hi], atol=1e-9 * weight)
    np.testing.assert_allclose(poly["vertices"][:, 1], n0 * co, atol=1e-9 * weight)


def small_pile():
    """Five discs in a small triangular pile on five fixed discs (radii 1, touching)."""
    R = 1.0
    h = np.sqrt(3.0)
    ground = np.array([[-4.0, 0.0], [-2.0, 0.0], [0.0, 0.0], [2.0, 0.0], [4.0, 0.0]])
    pos = np.array([[-1.0, h], [1.0, h], [0.0, 2 * h], [-3.0, h], [3.0, h]])
    return ncd.make_scene(pos, np.full(len(pos), R), 1.0, obstacle_pos=ground,
                          obstacle_radius=np.full(len(ground), R), gravity=(0.0, -10.0), mu=0.4)


def test_small_pile_polygons_match_forcepolytope_and_vertices_are_admissible():
    scene = small_pile()
    c, H, F = balanced(scene)
    es = ExactSet(H, F, c.mu)
    fp = ForcePolytope(H, F, c.mu)
    assert fp.is_bounded()
    for k in range(c.n):
        L = np.zeros((2, 2 * c.n))
        L[0, 2 * k], L[1, 2 * k + 1] = 1.0, 1.0
        mine = es.polygon(L, n_dirs=24)
        ref = fp.project(k, n_init=16)
        assert mine["exact"] and ref["exact"]
        assert abs(mine["inner_area"] - ref["inner_area"]) <= 1e-8 * es.scale ** 2
        assert abs(mine["outer_area"] - mine["inner_area"]) <= 1e-6 * es.scale ** 2
        eq, co = fp.violations(mine["points"])
        assert eq.max() <= 1e-10 and co.max() <= 1e-10
        eq, co = fp.violations(np.array([es.refine(r) for r in mine["points"][:4]]))
        assert eq.max() <= 1e-13 and co.max() <= 1e-13


def test_resultant_angle_of_a_polygon():
    v = np.array([[1.0, -1.0], [2.0, -1.0], [2.0, -0.5]])       # outward right flank: 45 .. 14 deg
    lo, hi = resultant_angle(v, 1)
    assert abs(lo - np.degrees(np.arctan(0.25))) < 1e-12 and abs(hi - 45.0) < 1e-12
    assert np.isnan(resultant_angle(np.array([[-1.0, -1], [1, -1], [0, 1]]), 1)[0])   # contains 0


def test_ground_pressure_maps_integrate_to_the_ground_force():
    scene = small_pile()
    c, H, F = balanced(scene)
    r = ExactSet(H, F, c.mu).minimize(np.zeros(2 * c.n))[1]
    weight = float(scene.mass[:scene.n_mobile].sum() * 10.0)
    x = np.linspace(-20, 20, 4001)
    K = pm.kernel_matrix(c, scene.n_mobile, x, 1.5)
    assert abs((K @ r).sum() * (x[1] - x[0]) - weight) <= 1e-9 * weight
    e = pm.centred_edges(2.0, 0.5, 10.0)
    B = pm.bin_matrix(c, scene.n_mobile, e)
    assert abs((B @ r) @ np.diff(e) - weight) <= 1e-12 * weight
    depth = pm.dip_row(K, x, 4.0) @ r
    p = K @ r
    ref = 0.5 * (np.interp(-4.0, x, p) + np.interp(4.0, x, p)) - np.interp(0.0, x, p)   # > 0 a dip
    assert abs(depth[0] - ref) <= 1e-12 * weight
    assert pm.dip_verdict(1.0, 0.5, 0.2, 3.0) == ("forced", True)
    assert pm.dip_verdict(1.0, 1.5, 0.2, 3.0) == ("forced", False)
    assert pm.dip_verdict(1.0, 0.1, -0.2, 3.0) == ("allowed", False)
    assert pm.dip_verdict(-1.0, 0.1, -3.0, 0.0) == ("excluded", False)


def three_grain_pile(mu):
    """Two grains on three touching ground discs and one on top of them (radii 1)."""
    h = np.sqrt(3.0)
    ground = np.array([[-2.0, 0.0], [0.0, 0.0], [2.0, 0.0]])
    pos = np.array([[-1.0, h], [1.0, h], [0.0, 2 * h]])
    return ncd.make_scene(pos, np.ones(3), 1.0, obstacle_pos=ground, obstacle_radius=np.ones(3),
                          gravity=(0.0, -10.0), mu=mu)


def vertices_by_enumeration(H, F, mu):
    """Every vertex of {r : H r + F = 0, |r_t| <= mu r_n}: in the null-space coordinates
    r = r0 + Z y, each choice of d = dim Z Coulomb rows with an invertible system, kept
    when it satisfies every row (brute force, no LP)."""
    import itertools
    H = np.asarray(H.todense() if hasattr(H, "todense") else H, float)
    k = H.shape[1] // 2
    G = np.zeros((3 * k, 2 * k))
    for i in range(k):
        G[i, 2 * i + 1], G[i, 2 * i] = 1.0, -mu[i]          # r_t - mu r_n <= 0
        G[k + i, 2 * i + 1], G[k + i, 2 * i] = -1.0, -mu[i]  # -r_t - mu r_n <= 0
        G[2 * k + i, 2 * i] = -1.0                          # -r_n <= 0
    r0 = np.linalg.lstsq(H, -F, rcond=None)[0]
    _, s, vt = np.linalg.svd(H)
    Z = vt[int(np.sum(s > 1e-12 * s[0])):].T
    Gz, b = G @ Z, -G @ r0
    scale = np.abs(F).max()
    out = []
    for rows in itertools.combinations(range(len(G)), Z.shape[1]):
        M = Gz[list(rows)]
        if abs(np.linalg.det(M)) < 1e-10:
            continue
        y = np.linalg.solve(M, b[list(rows)])
        if np.all(Gz @ y <= b + 1e-10 * scale):
            out.append(r0 + Z @ y)
    return np.array(out)


def test_three_grain_pile_polygon_equals_the_hull_of_enumerated_vertices():
    """A ∩ C of a three-grain pile (7 contacts, dimension 14 - 9 = 5) by vertex enumeration
    (C(21, 5) row choices): the LP polygon of the left ground disc's force on grain 0 equals
    the hull of the projected vertices, vertex for vertex, to 1e-9 of the weight."""
    from scipy.spatial import ConvexHull
    scene = three_grain_pile(0.3)
    c, H, F = balanced(scene)
    assert c.n == 7
    weight = float(scene.mass[:scene.n_mobile].sum() * 10.0)
    V = vertices_by_enumeration(H, F, c.mu)
    assert len(V) >= 3
    es = ExactSet(H, F, c.mu)
    assert es.fp.is_bounded()
    eq, co = es.fp.violations(V)
    assert eq.max() <= 1e-12 and co.max() <= 1e-12
    left = int(np.nonzero((c.body_a == 0) & (c.body_b == 3))[0][0])     # grain 0 on the left ground disc
    L = np.zeros((2, 2 * c.n))
    for row in (0, 1):
        L[row, 2 * left], L[row, 2 * left + 1] = c.normal[left, row], c.tangent[left, row]
    P = V @ L.T
    hull = P[ConvexHull(P).vertices]
    poly = es.polygon(L, n_dirs=16)
    assert poly["exact"] and len(poly["vertices"]) == len(hull)
    d = np.hypot(*(poly["vertices"][:, None] - hull[None]).transpose(2, 0, 1))
    assert d.min(1).max() <= 1e-9 * weight and d.min(0).max() <= 1e-9 * weight
    assert abs(poly["inner_area"] - ConvexHull(P).volume) <= 1e-9 * weight ** 2
    # the exact range of the middle ground disc's vertical force on grain 0 equals the vertices' range
    mid = int(np.nonzero((c.body_a == 0) & (c.body_b == 4))[0][0])
    fy = np.zeros(2 * c.n)
    fy[2 * mid], fy[2 * mid + 1] = c.normal[mid, 1], c.tangent[mid, 1]
    lo, hi = es.interval(fy)
    assert hi - lo > 1e-3 * weight
    assert abs(lo - (V @ fy).min()) <= 1e-9 * weight and abs(hi - (V @ fy).max()) <= 1e-9 * weight


@pytest.mark.parametrize("outer", [1, -1])
def test_angle_range_equals_the_angles_of_the_enumerated_vertices(outer):
    """ExactSet.angle_range (Charnes-Cooper ends certified by Dinkelbach, a few LPs) against brute force: the
    angle range of the enumerated vertices of a three-grain pile's A ∩ C under the left
    ground disc's force, whatever the reference direction (the vertices' own angles, a
    direction 100 degrees off that does not separate the image from 0, none, NaN: the
    history angle of a cut crossing no contact)."""
    scene = three_grain_pile(0.3)
    c, H, F = balanced(scene)
    V = vertices_by_enumeration(H, F, c.mu)
    es = ExactSet(H, F, c.mu)
    left = int(np.nonzero((c.body_a == 0) & (c.body_b == 3))[0][0])
    L = np.zeros((2, 2 * c.n))
    for row in (0, 1):
        L[row, 2 * left], L[row, 2 * left + 1] = c.normal[left, row], c.tangent[left, row]
    P = V @ L.T
    phi = np.degrees(np.arctan2(-P[:, 1], outer * P[:, 0]))
    assert phi.max() - phi.min() > 5.0                       # a range worth testing
    for ref in (float(phi.mean()), float(phi.mean()) + 100.0, None, float("nan")):
        r = es.angle_range(L, outer, ref=ref)
        assert abs(r["lo"] - phi.min()) <= 1e-8 and abs(r["hi"] - phi.max()) <= 1e-8
        # a separating reference: min p, two ends, their certificates (and an LP point for
        # none); the one 100 degrees off: a 12-direction polygon first, then the same again
        assert r["bound"] <= 1e-8 and r["n_lp"] <= (40 if ref == float(phi.mean()) + 100.0 else 8)
        # the two extreme points are admissible and have the extreme angles
        eq, co = es.fp.violations(r["points"])
        assert eq.max() <= 1e-9 and co.max() <= 1e-9
        g = r["points"] @ L.T
        np.testing.assert_allclose(np.degrees(np.arctan2(-g[:, 1], outer * g[:, 0])), [r["lo"], r["hi"]], atol=1e-7)


def test_angle_range_is_undefined_when_the_image_surrounds_zero():
    """A contact force that can vanish (its polygon contains the origin): no angle range,
    as resultant_angle of the exact polygon says."""
    scene = small_pile()
    c, H, F = balanced(scene)
    es = ExactSet(H, F, c.mu)
    seen = {True: 0, False: 0}
    for k in range(c.n):
        L = np.zeros((2, 2 * c.n))
        for row in (0, 1):
            L[row, 2 * k], L[row, 2 * k + 1] = c.normal[k, row], c.tangent[k, row]
        ref = resultant_angle(es.polygon(L, n_dirs=24)["vertices"], 1)
        r = es.angle_range(L, 1)
        seen[bool(np.isnan(ref[0]))] += 1
        if np.isnan(ref[0]):
            assert np.isnan(r["lo"]) and np.isnan(r["hi"])
        else:
            assert abs(r["lo"] - ref[0]) <= 1e-8 and abs(r["hi"] - ref[1]) <= 1e-8
    assert seen[True] >= 2 and seen[False] >= 2
    r = es.angle_range(np.zeros((2, 2 * c.n)), 1, ref=float("nan"))      # a cut crossing no contact
    assert np.isnan(r["lo"]) and np.isnan(r["hi"])
