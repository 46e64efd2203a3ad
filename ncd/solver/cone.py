"""The 2-D Coulomb cone as two nonnegative sector coordinates (Moreau 2005, section 2).

In 2-D the cone ``|r_t| <= mu r_n`` is the set of nonnegative combinations of its two
edges, so a linear program can carry Coulomb's law as column bounds instead of rows:
the exact sets (:mod:`ncd.exact.exact_set`) and the finishing stage's projections
(:mod:`ncd.solver.finish_lp`) both use these coordinates.
"""
import highspy
import numpy as np
import scipy.sparse as sp


def cone_columns(mu):
    """The Coulomb sectors as bounds: ``r = T y`` with ``y >= 0`` (``y <= upper``).

    Per contact ``y = (a, b) = (mu r_n + r_t, mu r_n - r_t)``, so that ``|r_t| <= mu r_n``
    is ``a, b >= 0`` (``r_n = (a + b) / (2 mu)``, ``r_t = (a - b) / 2``); a frictionless
    contact has ``r_n = a``, ``r_t = 0`` (``b`` fixed at 0).  The LP then has only the
    equilibrium rows, and every LP point satisfies Coulomb's law to round-off."""
    mu = np.asarray(mu, dtype=float)
    k = len(mu)
    i = np.arange(k)
    rough = mu > 0
    inv = np.where(rough, 0.5 / np.where(rough, mu, 1.0), 1.0)
    rows = np.concatenate([2 * i, 2 * i, 2 * i + 1, 2 * i + 1])
    cols = np.concatenate([2 * i, 2 * i + 1, 2 * i, 2 * i + 1])
    vals = np.concatenate([inv, np.where(rough, inv, 0.0), np.where(rough, 0.5, 0.0), np.where(rough, -0.5, 0.0)])
    T = sp.csr_matrix((vals, (rows, cols)), shape=(2 * k, 2 * k))
    T.eliminate_zeros()
    upper = np.full(2 * k, highspy.kHighsInf)
    upper[2 * i[~rough] + 1] = 0.0
    return T, upper
