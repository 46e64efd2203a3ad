"""The exact set A ∩ C of small piles (ncd.figures.pile_exact) and the ground-pressure maps."""
import numpy as np
import pytest

import ncd
from ncd.contacts import h_matrix
from ncd.figures import pressure as pm
from ncd.figures.pile_exact import ExactSet, resultant_angle
from ncd.polytope import ForcePolytope


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
    weight = float(scene.mass.sum() * 10.0)
    x = np.linspace(-20, 20, 4001)
    K = pm.kernel_matrix(c, scene.n_mobile, x, 1.5)
    assert abs((K @ r).sum() * (x[1] - x[0]) - weight) <= 1e-9 * weight
    e = pm.centred_edges(2.0, 0.5, 10.0)
    B = pm.bin_matrix(c, scene.n_mobile, e)
    assert abs((B @ r) @ np.diff(e) - weight) <= 1e-12 * weight
    depth = pm.dip_row(K, x, 4.0) @ r
    p = K @ r
    ref = np.interp(0.0, x, p) - 0.5 * (np.interp(-4.0, x, p) + np.interp(4.0, x, p))
    assert abs(depth[0] - ref) <= 1e-12 * weight
    assert pm.dip_verdict(-1.0, 0.5, -3.0, -0.2) == ("forced", True)
    assert pm.dip_verdict(-1.0, 1.5, -3.0, -0.2) == ("forced", False)
    assert pm.dip_verdict(-1.0, 0.1, -3.0, 0.2) == ("allowed", False)
