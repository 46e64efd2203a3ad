"""CLP (COIN-OR, through ``cylp``) as the warm-started simplex of :class:`ncd.exact.exact_set.ExactSet`.

On the angle-range LPs of a 10^4-grain pile (3·10^4 equality rows, the Coulomb sectors as
column bounds), CLP's primal simplex restarted from the previous optimal basis takes
about 2.4 times fewer iterations than HiGHS's, at about the same cost per iteration
(measurements in docs/solvers.md).  ``ExactSet(..., simplex="clp")`` therefore solves its
first LP with HiGHS (interior point and crossover to a vertex) and hands that basis to CLP
for every later LP.  Bases are exchanged as arrays of :data:`LOWER`, :data:`BASIC`,
:data:`UPPER` (a nonbasic variable or row at its lower or upper bound).
"""
import numpy as np
import scipy.sparse as sp

LOWER, BASIC, UPPER = 0, 1, 2
# CLP's status codes: 0 free, 1 basic, 2 at upper, 3 at lower, 4 superbasic, 5 fixed
_TO_CLP = np.array([3, 1, 2], dtype=np.int32)


def _from_clp(status):
    s = np.asarray(status)
    return np.where(s == 1, BASIC, np.where(s == 2, UPPER, LOWER)).astype(np.int8)


class ClpModel:
    """``row_lo <= A x <= row_hi``, ``col_lo <= x <= col_hi`` in one CLP model (zero cost, silent),
    primal and dual feasibility tolerances ``tol``; infinite bounds allowed."""

    def __init__(self, A, row_lo, row_hi, col_lo, col_hi, tol):
        from cylp.cy import CyClpSimplex, CyCoinPackedMatrix  # on use: only simplex="clp" needs it
        A = sp.coo_matrix(A)
        # CLP reads the bounds by the matrix's shape: a shorter array would be read past its end
        for name, v, n in (("row_lo", row_lo, A.shape[0]), ("row_hi", row_hi, A.shape[0]),
                           ("col_lo", col_lo, A.shape[1]), ("col_hi", col_hi, A.shape[1])):
            if np.shape(v) != (n,):
                raise ValueError(f"{name} has shape {np.shape(v)}; the matrix is {A.shape}")
        self.s = s = CyClpSimplex()
        big = s.getCoinInfinity()

        def bound(v):
            return np.clip(np.asarray(v, dtype=float), -big, big)

        matrix = CyCoinPackedMatrix(True, A.row.astype(np.int32), A.col.astype(np.int32), A.data.astype(float))
        s.loadProblem(matrix, bound(col_lo), bound(col_hi), np.zeros(A.shape[1]), bound(row_lo), bound(row_hi))
        s.logLevel = 0
        s.primalTolerance = float(tol)
        s.dualTolerance = float(tol)
        self.n_col, self.n_row = A.shape[1], A.shape[0]

    def set_cost(self, c):
        self.s.setObjectiveArray(np.asarray(c, dtype=float))

    def run(self):
        """Primal simplex from the current basis; returns CLP's status ("optimal",
        "primal infeasible", ...)."""
        return str(self.s.primal())

    def solution(self):
        return np.asarray(self.s.primalVariableSolution, dtype=float)

    def basis(self):
        """``(col, row)`` statuses of the current basis."""
        col, row = self.s.getBasisStatus()
        return _from_clp(col), _from_clp(row)

    def set_basis(self, col, row):
        col, row = np.asarray(col), np.asarray(row)
        if col.shape != (self.n_col,) or row.shape != (self.n_row,):
            raise ValueError(f"basis of shape {col.shape}, {row.shape} for a model of "
                             f"{self.n_col} columns and {self.n_row} rows")
        self.s.setBasisStatus(_TO_CLP[col], _TO_CLP[row])

    def set_last_row(self, w, lo, hi):
        """Replace the model's last row by ``lo <= w . x <= hi`` (``w`` dense, length n_col)."""
        if np.shape(w) != (self.n_col,):
            raise ValueError(f"w has shape {np.shape(w)} for a model of {self.n_col} columns")
        s = self.s
        s.CLP_deleteConstraints(np.array([self.n_row - 1], dtype=np.int32))
        idx = np.nonzero(w)[0].astype(np.int32)
        s.CLP_addConstraint(len(idx), idx, np.asarray(w, dtype=float)[idx], float(lo), float(hi))
