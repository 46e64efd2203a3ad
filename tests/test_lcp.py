"""Lemke's method on known LCPs and on the LCP form of the 2-D frictional problem."""
import itertools

import numpy as np
import pytest

import ncd
from ncd.solver.lcp import frictional_lcp, impulse_of_lcp, lcp_residual, lemke


def enumerate_lcp(M, q):
    """Every solution of a small LCP by enumeration of its 2^n complementary bases."""
    n = len(q)
    out = []
    for mask in itertools.product((0, 1), repeat=n):
        S = np.nonzero(mask)[0]                      # z basic (w = 0) on S
        z = np.zeros(n)
        if len(S):
            try:
                z[S] = np.linalg.solve(M[np.ix_(S, S)], -q[S])
            except np.linalg.LinAlgError:
                continue
        w = M @ z + q
        if z.min() >= -1e-12 and w.min() >= -1e-12:
            out.append(z)
    return out


def test_textbook_2x2():
    # w = M z + q, the example of Cottle-Pang-Stone: z = (4/3, 7/3), w = 0
    z, info = lemke(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]))
    assert info["status"] == "solution"
    np.testing.assert_allclose(z, [4 / 3, 7 / 3], rtol=0, atol=1e-14)


def test_trivial_and_ray():
    z, info = lemke(np.eye(3), np.array([1.0, 0.0, 2.0]))
    assert info["pivots"] == 0 and np.all(z == 0)
    # w = -z - 1 >= 0 has no solution with z >= 0: Lemke ends on a ray
    z, info = lemke(np.array([[-1.0]]), np.array([-1.0]))
    assert z is None and info["status"] == "secondary ray"


@pytest.mark.parametrize("seed", range(5))
def test_p_matrix_unique_solution_matches_enumeration(seed):
    rng = np.random.default_rng(seed)
    n = 7
    A = rng.standard_normal((n, n))
    M = A @ A.T + 0.5 * np.eye(n) + 0.3 * (A - A.T)   # positive definite, non-symmetric: a P-matrix
    q = rng.standard_normal(n)
    sols = enumerate_lcp(M, q)
    assert len(sols) == 1
    z, info = lemke(M, q)
    assert info["status"] == "solution" and info["residual"] <= 1e-13
    np.testing.assert_allclose(z, sols[0], atol=1e-12)


def test_degenerate_psd_matrix():
    # a singular PSD M (rank 2 of 6, copositive-plus) with a solvable q built from a
    # known complementary pair: Lemke must end on a solution (not a ray), through
    # the ties of the degenerate ratio test
    rng = np.random.default_rng(3)
    B = rng.standard_normal((6, 2))
    M = B @ B.T
    z_star = np.array([1.0, 0.0, 0.5, 0.0, 0.0, 2.0])
    w_star = np.array([0.0, 0.3, 0.0, 0.0, 1.0, 0.0])
    q = w_star - M @ z_star
    z, info = lemke(M, q)
    assert info["status"] == "solution" and info["residual"] <= 1e-12
    assert z.min() >= 0 and (M @ z + q).min() >= -1e-12


@pytest.mark.parametrize("seed", range(20))
def test_single_contact_against_the_exact_local_solver(seed):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((2, 2))
    W = A @ A.T + 0.2 * np.eye(2)
    W[0, 1] = W[1, 0] = 0.0 if seed % 2 else W[0, 1]   # disc blocks are diagonal; also full blocks
    q = rng.standard_normal(2)
    mu = float(rng.uniform(0.1, 1.0))
    M, b = frictional_lcp(W, q, [mu])
    x, info = lemke(M, b)
    assert info["status"] == "solution"
    s = impulse_of_lcp(x, [mu])[0]
    ref, status = ncd.solve_single_contact_py(W, q, mu)
    if status != 4:   # not the fallback case
        np.testing.assert_allclose(s, ref, atol=1e-12 * max(1.0, np.abs(ref).max()))


def test_frictional_lcp_two_discs_on_ground():
    """Two stacked contacts (ground and disc-disc) with W from their Delassus matrix:
    Lemke's solution satisfies the Coulomb law componentwise."""
    rng = np.random.default_rng(11)
    H = rng.standard_normal((3, 4))
    W = H.T @ H + 1e-3 * np.eye(4)
    q = np.array([-1.0, 0.3, -0.5, -0.8])
    mu = np.array([0.5, 0.3])
    M, b = frictional_lcp(W, q, mu)
    x, info = lemke(M, b)
    assert info["status"] == "solution" and lcp_residual(M, b, x) <= 1e-12
    s = impulse_of_lcp(x, mu)
    U = (W @ s.ravel() + q).reshape(-1, 2)
    assert np.all(s[:, 0] >= -1e-12) and np.all(np.abs(s[:, 1]) <= mu * s[:, 0] + 1e-12)
    assert np.all(U[:, 0] >= -1e-12) and np.all(np.abs(s[:, 0] * U[:, 0]) <= 1e-12)
    stick = np.abs(s[:, 1]) < mu * s[:, 0] - 1e-9
    assert np.all(np.abs(U[stick, 1]) <= 1e-12)
    slide = ~stick & (s[:, 0] > 1e-12)
    assert np.all(U[slide, 1] * s[slide, 1] <= 1e-12)     # sliding opposes the tangential impulse


def test_bad_input():
    with pytest.raises(ncd.InputError, match="M has shape"):
        lemke(np.eye(2), np.ones(3))
    with pytest.raises(ncd.InputError, match="W has shape"):
        frictional_lcp(np.eye(3), np.ones(4), [0.5, 0.5])
