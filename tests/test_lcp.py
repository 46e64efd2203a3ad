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


def full_tableau_lemke(M, q, d, max_pivots, tol=1e-12):
    """Lemke's method on the full tableau ``[I, -M, -d | q]``, written plainly: the
    reference that the compact tableau of ``ncd.solver.lcp`` must follow pivot for pivot."""
    n = len(q)
    T = np.hstack([np.eye(n), -M, -d[:, None], q[:, None]])
    basis = list(range(n))
    row, entering = int(np.argmin(q / d)), 2 * n
    for it in range(max_pivots):
        T[row] /= T[row, entering]
        for i in range(n):
            if i != row and T[i, entering] != 0.0:
                T[i] -= T[i, entering] * T[row]
        leaving, basis[row] = basis[row], entering
        if leaving == 2 * n:
            return basis, 0, it + 1
        entering = leaving + n if leaving < n else leaving - n
        cand = [i for i in range(n) if T[i, entering] > tol]
        if not cand:
            return basis, 1, it + 1
        for c in [2 * n + 1] + list(range(n)):      # lexicographic: q, then the columns of w
            r = [T[i, c] / T[i, entering] for i in cand]
            lo = min(r)
            cand = [i for i, x in zip(cand, r) if x <= lo + tol * (1.0 + abs(lo))]
            z0 = [i for i in cand if basis[i] == 2 * n]
            if z0 or len(cand) == 1:
                break
        row = z0[-1] if z0 else cand[0]
    return basis, 2, max_pivots


@pytest.mark.parametrize("seed", range(6))
def test_compact_tableau_follows_the_full_tableau_pivot_for_pivot(seed):
    """The compact tableau stores only the nonbasic columns; its entries are computed by the
    same operations as the full tableau's, so on positive definite, indefinite and singular
    integer matrices (ties in the ratio test, some broken by the unit columns of basic w's),
    with several covering vectors, it ends with the same status, pivot count and solution."""
    from ncd.solver.lcp import LEMKE_STATUS, basis_solution
    rng = np.random.default_rng(seed)
    problems = []
    for kind in range(3):
        n = int(rng.integers(3, 25))
        A = rng.normal(size=(n, n))
        B = np.round(A[:, : n // 2])
        M = A @ A.T if kind == 0 else (A if kind == 1 else B @ B.T)
        q = rng.normal(size=n) - 0.5 if kind < 2 else np.round(2 * rng.normal(size=n))
        problems.append((M, q))
    for _ in range(8):       # q in {0, -1}: ties in q that basic columns of w break
        B = rng.integers(-1, 2, size=(8, 3)).astype(float)
        q = -rng.integers(0, 2, size=8).astype(float)
        q[0] = -1.0                 # not all q >= 0 (lemke's trivial answer)
        problems.append((B @ B.T, q))
    for M, q in problems:
        n = len(q)
        for d in (np.ones(n), 10 ** rng.uniform(-1, 1, n)):
            basis, status, pivots = full_tableau_lemke(M, q, d, 50 * n + 100)
            z, info = lemke(M, q, covering=d)
            assert info["pivots"] == pivots
            if status == 0 and info["status"] == "solution":
                np.testing.assert_array_equal(z, basis_solution(M, q, np.array(basis)))
            else:
                assert info["status"] in (LEMKE_STATUS[status], "inaccurate")
