"""InteriorSet (Clarabel's interior point, bounds from the dual) against ExactSet's simplex
vertices on the lattice pile of test_exact_set: the values it reports are attained by
admissible forces, and its certified bounds hold the exact values."""
import numpy as np
import pytest
from test_exact_set import lattice_pile, pile  # noqa: F401 (the module's fixture)
from test_pile_exact import balanced

from ncd.core.errors import InputError
from ncd.exact.exact_set import ExactSet
from ncd.exact.interior_set import BOUND_DEG, InteriorSet
from ncd.exact.polytope import PolytopeError


def test_angle_ranges_lie_within_their_bound_of_the_simplex_ranges(pile):  # noqa: F811
    """Per cut: the interior point's ends are attained (inside the exact range, forces in
    A ∩ C), the exact ends lie within the certified bound beyond them, and the bound is at
    most BOUND_DEG; three LPs per cut (min p, two Charnes-Cooper ends) once S is known."""
    H, F, mu, C, outer = pile
    es, ip = ExactSet(H, F, mu), InteriorSet(H, F, mu)
    ip.total_bound()
    widths = []
    for k in range(len(outer)):
        L = C[2 * k: 2 * k + 2]
        g = L @ es.minimize(np.zeros(es.n))[1]
        ref = np.degrees(np.arctan2(-g[1], outer[k] * g[0])) + 3.0
        a, b = es.angle_range(L, outer[k], ref=ref), ip.angle_range(L, outer[k], ref=ref)
        assert b["n_lp"] == 3 and b["bound"] <= BOUND_DEG
        assert a["lo"] - 1e-9 <= b["lo"] <= a["lo"] + b["bound"] + 1e-9
        assert a["hi"] - b["bound"] - 1e-9 <= b["hi"] <= a["hi"] + 1e-9
        eq, co = ip.fp.violations(b["points"])
        assert eq.max() <= 1e-9 and co.max() <= 1e-9
        assert abs(a["p_min"] - b["p_min"]) <= 1e-7 * es.scale
        widths.append(a["hi"] - a["lo"])
    assert min(widths) > 1.0                                        # ranges worth comparing


def test_bounds_bracket_the_simplex_minimum_and_survive_a_perturbed_dual(pile):  # noqa: F811
    """``bounds(c)``: lower <= the exact minimum <= the value attained, a gap below 1e-7 of
    the force scale, for each cut component and a random functional.  The dual bound is
    rigorous for any ``y`` (weak duality, the dual residual paid through S): a dual
    perturbed by 1e-4 still gives a lower bound."""
    H, F, mu, C, outer = pile
    es, ip = ExactSet(H, F, mu), InteriorSet(H, F, mu)
    rng = np.random.default_rng((0, 5))
    for c in list(C[:6]) + [rng.normal(size=es.n)]:
        exact = es.minimize(c)[0]
        lower, value, r = ip.bounds(c)
        assert lower <= exact + 1e-12 * es.scale <= value + 2e-12 * es.scale
        assert value - lower <= 1e-7 * es.scale
        assert abs(np.dot(c, r) - value) <= 1e-12 * es.scale
    cost = ip._Tt @ C[0] * ip.scale                  # min c . r = norm * min cost . z (r = scale T z)
    norm = np.abs(cost).max()
    _, y, _ = ip._clarabel(cost / norm, ip.A, ip.b)
    noisy = y + 1e-4 * rng.normal(size=y.shape)
    lower = ip._dual_bound(cost / norm, ip.A, ip.b, noisy, ip.total_bound()) * norm
    assert lower <= es.minimize(C[0])[0] + 1e-12 * es.scale


def test_a_reference_that_does_not_separate_goes_to_the_simplex_route(pile):  # noqa: F811
    """A reference direction 120 degrees off the image (``p < 0`` on it): the range comes
    from ExactSet's exact polygon, as ExactSet gives it."""
    H, F, mu, C, outer = pile
    es, ip = ExactSet(H, F, mu), InteriorSet(H, F, mu)
    L = C[:2]
    g = L @ es.minimize(np.zeros(es.n))[1]
    ref = np.degrees(np.arctan2(-g[1], outer[0] * g[0])) + 120.0     # the image spans ~94 degrees
    a, b = es.angle_range(L, outer[0], ref=ref), ip.angle_range(L, outer[0], ref=ref)
    assert ip._simplex is not None
    assert abs(a["lo"] - b["lo"]) <= 1e-9 and abs(a["hi"] - b["hi"]) <= 1e-9 and b["n_lp"] > 3


def test_an_empty_polytope_and_a_bad_tolerance_are_clear_errors():
    """An empty A ∩ C is a PolytopeError; a gap tolerance out of range an InputError naming
    it, before any LP."""
    scene = lattice_pile(n_base=3, mu=0.3)
    c, H, F = balanced(scene)
    with pytest.raises(PolytopeError, match="empty"):
        InteriorSet(H, 1e3 * np.abs(F) + 1.0, c.mu).minimize(np.zeros(2 * c.n))
    with pytest.raises(InputError, match="gap_tol"):
        InteriorSet(H, F, c.mu, gap_tol=0.5)
