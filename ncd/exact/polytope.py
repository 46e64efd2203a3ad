"""The set of equilibrium contact forces, A ∩ C, handled exactly (Moreau 2005, section 4).

The contact forces ``rho`` (2 kappa components, ordered ``(r_n, r_t)`` per
contact) of a system in equilibrium satisfy ``H rho + F = 0`` (``H`` from
:func:`ncd.core.contacts.h_matrix`, ``F`` the generalized external force, one row
per equation): the affine subspace ``A`` of dimension ``2 kappa - rank H``
(``2 kappa - 3N`` when the 3N equations are independent).  Coulomb's law puts
each ``rho_alpha`` in its sector ``C_alpha: |r_t| <= mu_alpha r_n``; ``C`` is
their product.  :class:`ForcePolytope` answers, by linear programming (scipy's
HiGHS), whether ``A ∩ C`` is empty or bounded, the exact projection of
``A ∩ C`` onto the force plane of any contact (a convex polygon, by support
queries refined until inner and outer polygons coincide, :mod:`ncd.exact.polygon`), and draws points
uniformly from ``A ∩ C`` by hit-and-run (the neutral reference to which NLGS
clouds are compared).  Nothing here knows about discs: it takes ``H, F, mu``.
"""
import numpy as np
import scipy.sparse as sp
from scipy.linalg import solve_triangular
from scipy.optimize import linprog

from ncd.core import validate
from ncd.core.errors import InputError
from ncd.core.jit import njit
from ncd.exact.polygon import support_polygon


class PolytopeError(RuntimeError):
    """``A ∩ C`` is empty, or unbounded where a bounded set is needed, or an LP failed."""


@njit(cache=True, error_model="numpy")
def _chord(slack, g):
    """``(lo, hi)``: the step lengths ``t`` along a direction of row slopes ``g`` that keep
    ``slack - t g >= 0``.  Branch-free: every quotient is computed and a row that does not
    bound a side gives that side's infinity, which ``min``/``max`` leave as they were, so
    the bounds are those of the branchy loop bit for bit (the same quotients, met in the same
    order), without its mispredicted branch per row (rows of either sign alternate at
    random); a zero slope's quotient is never selected (numpy error model: no raise)."""
    lo = -np.inf
    hi = np.inf
    for i in range(slack.shape[0]):
        gi = g[i]
        q = slack[i] / gi
        hi = min(hi, q if gi > 0.0 else np.inf)
        lo = max(lo, q if gi < 0.0 else -np.inf)
    return lo, hi


@njit(cache=True)
def _hit_and_run(G, slack, y, L, thin, normals, uniforms):
    """Hit-and-run steps in ``{y : G y <= b}``, ``slack = b - G y`` kept up to date (both
    modified in place); directions ``L z`` with ``z`` the rows of ``normals``; returns
    ``y`` every ``thin`` steps."""
    m = G.shape[0]
    steps = normals.shape[0]
    out = np.empty((steps // thin, y.shape[0]))
    k = 0
    for s in range(steps):
        dirn = L @ normals[s]
        gd = G @ dirn
        lo, hi = _chord(slack, gd)
        lam = lo + (hi - lo) * uniforms[s]
        y += lam * dirn
        for i in range(m):
            slack[i] = max(slack[i] - lam * gd[i], 0.0)
        if (s + 1) % thin == 0:
            out[k] = y
            k += 1
    return out


@njit(cache=True)
def _coordinate_hit_and_run(GLt, slack, z, thin, coords, uniforms):
    """Coordinate hit-and-run in ``{z : G L z <= b}`` (the rounded frame ``y = L z``): each
    step moves one coordinate ``coords[s]`` of ``z``, so the ray test reads one column of
    ``G L`` (row ``coords[s]`` of ``GLt``) and the slack update is one axpy, O(m) a step
    instead of the O(d^2 + m d) of a random direction.  Each coordinate move is a
    reversible kernel that keeps the uniform law, and so is their random mixture
    (coordinate hit-and-run with rounding, Haraldsdottir et al., Bioinformatics 33, 1741,
    2017).  ``slack = b - G L z`` and ``z`` are modified in place; returns ``z`` every
    ``thin`` steps."""
    m = GLt.shape[1]
    steps = coords.shape[0]
    out = np.empty((steps // thin, z.shape[0]))
    k = 0
    for s in range(steps):
        j = coords[s]
        lo, hi = _chord(slack, GLt[j])
        lam = lo + (hi - lo) * uniforms[s]
        z[j] += lam
        for i in range(m):
            slack[i] = max(slack[i] - lam * GLt[j, i], 0.0)
        if (s + 1) % thin == 0:
            out[k] = z
            k += 1
    return out


DIRECTIONS = ("random", "coordinate")


class ForcePolytope:
    """``A ∩ C = {rho : H rho + F = 0, |rho_t| <= mu rho_n}`` for ``kappa`` contacts.

    Internally forces are divided by ``scale`` (the largest ``|F|``) and each
    equation by its largest coefficient, so the LP tolerances are relative.
    """

    def __init__(self, H, F, mu, feas_tol=1e-10):
        H = validate.matrix("H", H)
        F = validate.array("F", np.asarray(F).ravel() if np.ndim(F) > 1 else F, (None,))
        self.n_contacts = H.shape[1] // 2
        if H.shape != (len(F), 2 * self.n_contacts):
            raise InputError(f"H has shape {H.shape}, F length {len(F)}: expected (m, 2 kappa) and m")
        self.mu = validate.per_item("mu", mu, self.n_contacts, 0.0)
        self.H, self.F = H, F
        self.scale = float(np.abs(F).max()) if np.abs(F).max() > 0 else 1.0
        rows = np.asarray(abs(H).max(axis=1).todense()).ravel()
        D = sp.diags(1.0 / np.where(rows > 0, rows, 1.0))
        self.A_eq = (D @ H).tocsr()
        self.b_eq = -(D @ F) / self.scale
        k = self.n_contacts
        i = np.arange(k)
        # Coulomb rows: r_t - mu r_n <= 0, -r_t - mu r_n <= 0, -r_n <= 0
        r = np.concatenate([i, k + i, 2 * k + i, i, k + i])
        c = np.concatenate([2 * i + 1, 2 * i + 1, 2 * i, 2 * i, 2 * i])
        v = np.concatenate([np.ones(k), -np.ones(k), -np.ones(k), -self.mu, -self.mu])
        self.G = sp.csr_matrix((v, (r, c)), shape=(3 * k, 2 * k))
        self.n_lp = 0
        # HiGHS's tolerances (relative: forces and rows are scaled); 1e-9 when F carries
        # round-off of that order (a slice's boundary loads summed from many contacts)
        self.highs = {"primal_feasibility_tolerance": float(feas_tol), "dual_feasibility_tolerance": float(feas_tol)}

    # ------------------------------------------------------------ LP basics
    def _lp(self, c, A_ub=None, b_ub=None, extra_eq=None, n_extra=0, bounds=None):
        """Minimize ``c . x`` over the scaled set (plus optional constraints); x or None."""
        A_ub = self.G if A_ub is None else A_ub
        b_ub = np.zeros(A_ub.shape[0]) if b_ub is None else b_ub
        A_eq, b_eq = self.A_eq, self.b_eq
        if n_extra:
            A_eq = sp.hstack([A_eq, sp.csr_matrix((A_eq.shape[0], n_extra))]).tocsr()
        if extra_eq is not None:
            A_eq = sp.vstack([A_eq, extra_eq[0]]).tocsr()
            b_eq = np.concatenate([b_eq, extra_eq[1]])
        self.n_lp += 1
        res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq,
                      bounds=bounds or (None, None), method="highs", options=self.highs)
        if res.status == 2:
            return None
        if res.status != 0:
            raise PolytopeError(f"LP failed: {res.message}")
        return res.x

    def feasible(self):
        """A point of ``A ∩ C`` (forces), or :class:`PolytopeError` if it is empty."""
        x = self._lp(np.zeros(2 * self.n_contacts))
        if x is None:
            raise PolytopeError("A ∩ C is empty: no contact forces balance the external forces")
        return x * self.scale

    def is_bounded(self):
        """True iff no nonzero self-stress lies in ``C`` (the recession cone of ``A ∩ C``).

        LP: maximize ``sum r_n`` over ``{H rho = 0, rho in C, sum r_n <= 1}``; 0 iff bounded.
        """
        k = self.n_contacts
        c = np.zeros(2 * k)
        c[0::2] = -1.0
        A_ub = sp.vstack([self.G, sp.csr_matrix(-c)]).tocsr()
        b_ub = np.concatenate([np.zeros(3 * k), [1.0]])
        res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=self.A_eq, b_eq=np.zeros(len(self.b_eq)),
                      bounds=(None, None), method="highs", options=self.highs)
        self.n_lp += 1
        if res.status != 0:
            raise PolytopeError(f"boundedness LP failed: {res.message}")
        return bool(-res.fun <= 1e-9)

    def dimension(self):
        """``(2 kappa - rank H, 2 kappa - n_equations)``: the dimension of ``A`` and Moreau's count."""
        rank = np.linalg.matrix_rank(self.A_eq.toarray()) if self.A_eq.shape[0] else 0
        return 2 * self.n_contacts - rank, 2 * self.n_contacts - self.A_eq.shape[0]

    # ------------------------------------------------------------ projections
    def support(self, contact, direction):
        """The point of ``A ∩ C`` maximizing ``direction . rho_contact`` (forces, full vector)."""
        contact = validate.integer("contact", contact, 0, self.n_contacts - 1)
        c = np.zeros(2 * self.n_contacts)
        c[2 * contact: 2 * contact + 2] = -validate.array("direction", direction, (2,))
        x = self._lp(c)
        if x is None:
            raise PolytopeError("A ∩ C is empty")
        return x * self.scale

    def project(self, contact, n_init=8, tol=1e-9, max_lp=400):
        """Exact projection of ``A ∩ C`` onto the plane ``(r_n, r_t)`` of ``contact``.

        Support points in ``n_init`` directions start an inner polygon (their
        hull); each of its edges is then tested by a support query along its
        outer normal: if nothing lies beyond (within ``tol * scale``) the edge is
        a true edge, otherwise the new support point is added.  When every edge
        is confirmed, the inner polygon equals the outer one (the intersection
        of all supporting half-planes).  Returns a dict: ``vertices`` (ccw, in
        force units), ``inner_area``, ``outer_area``, ``n_lp``, ``exact``.
        Requires a bounded ``A ∩ C``.
        """
        contact = validate.integer("contact", contact, 0, self.n_contacts - 1)
        n_init = validate.integer("n_init", n_init, 3, 10 ** 6)
        dirs = [np.array([np.cos(a), np.sin(a)]) for a in 2 * np.pi * np.arange(n_init) / n_init]
        return support_polygon(lambda u: self.support(contact, u)[2 * contact: 2 * contact + 2],
                               dirs, tol * self.scale, max_lp, self.scale)

    # ------------------------------------------------------------ uniform sampling
    def affine_hull(self, tol=1e-9, implicit=None):
        """Point, orthonormal basis and reduced inequalities of the affine hull of ``A ∩ C``.

        Coulomb rows that no point of ``A ∩ C`` satisfies strictly (implicit
        equalities, e.g. a contact forced to slide or to carry no force) are
        moved to the equalities.  ``implicit`` (bool per row of ``G``), when known
        (e.g. from :func:`ncd.figures.fig5_governing.exact.implicit_rows`), starts the search,
        which then needs one LP when it is complete.  Returns ``(x0, Z, Gz, b, implicit)``
        in scaled units.
        """
        G = self.G.toarray()
        m, n = G.shape
        implicit = np.zeros(m, bool) if implicit is None else np.array(implicit, bool).reshape(m)
        # one LP: maximize the smallest slack t (capped at 1) of rows not yet known to be tight
        while True:
            rows = ~implicit
            c = np.zeros(n + 1)
            c[-1] = -1.0
            A_ub = np.hstack([G, np.where(rows, 1.0, 0.0)[:, None]])
            eq = (sp.csr_matrix(np.hstack([G[implicit], np.zeros((implicit.sum(), 1))])),
                  np.zeros(implicit.sum())) if implicit.any() else None
            x = self._lp(c, A_ub=sp.csr_matrix(A_ub), b_ub=np.zeros(m), extra_eq=eq, n_extra=1,
                         bounds=[(None, None)] * n + [(None, 1.0)])
            if x is None:
                raise PolytopeError("A ∩ C is empty")
            if x[-1] > tol:
                break
            # some rows are tight everywhere: find them one by one
            for i in np.nonzero(rows)[0]:
                eq_i = (sp.csr_matrix(G[implicit]), np.zeros(implicit.sum())) if implicit.any() else None
                x_i = self._lp(G[i], A_ub=self.G, extra_eq=eq_i)
                if x_i is None or -(G[i] @ x_i) <= tol:
                    implicit[i] = True
        x0 = x[:n]
        E = np.vstack([self.A_eq.toarray(), G[implicit]])
        _, s, vt = np.linalg.svd(E)
        rank = int(np.sum(s > 1e-10 * s[0]))
        Z = vt[rank:].T
        Gz = G[~implicit] @ Z
        b = -(G[~implicit] @ x0)
        keep = np.hypot.reduce(Gz, axis=1) > 1e-12 if Gz.size else np.zeros(0, bool)
        return x0, Z, Gz[keep], b[keep], implicit

    def uniform_samples(self, rng_of, n_chains, per_chain, thin=None, burn=None, rounds=2, implicit=None,
                        dispersed=False, points=None, directions="random"):
        """Points drawn uniformly from ``A ∩ C`` (forces, shape (n_chains * per_chain, 2 kappa)).

        Hit-and-run in the affine hull of ``A ∩ C`` from its Chebyshev centre,
        with directions shaped by the covariance of ``rounds`` pilot chains
        (any symmetric direction law keeps the uniform law stationary); pilots start
        at the centre, after a burn-in of 50 d steps.  ``burn``: hit-and-run steps
        discarded at the start of every chain (default 50 d).
        ``dispersed``: chain ``k`` starts instead 95 % of the way from the centre to the
        vertex maximizing a random direction (drawn from ``rng_of(k)``), so that chains
        that agree have forgotten different starts (a mixing check).  ``implicit``: known
        implicit equalities (:meth:`affine_hull`).
        ``points``: known points of ``A ∩ C`` (forces, rows, e.g. the vertices found by
        range LPs) whose covariance, plus the inscribed ball, shapes the first pilot's
        directions: an isotropic first pilot crawls along a set whose widths span
        several decades and leaves a covariance no better than its start.
        ``directions``: ``"random"`` (Gaussian directions shaped by the rounding) or
        ``"coordinate"`` (coordinate hit-and-run in the rounded frame,
        :func:`_coordinate_hit_and_run`: the same steps at O(m) each instead of O(d^2 + m d)).
        ``rng_of(k)`` is the generator of chain ``k``; pilots use ``n_chains + r``.
        Returns ``(samples, info)``; ``info`` has the dimension, the implicit
        equalities and the largest Gelman-Rubin R-hat over coordinates.
        """
        n_chains = validate.integer("n_chains", n_chains, 1, 10 ** 6)
        per_chain = validate.integer("per_chain", per_chain, 1, 10 ** 9)
        thin = None if thin is None else validate.integer("thin", thin, 1, 10 ** 9)
        burn = None if burn is None else validate.integer("burn", burn, 0, 10 ** 9)
        rounds = validate.integer("rounds", rounds, 0, 100)
        if points is not None:
            points = validate.array("points", points, (None, 2 * self.n_contacts))
        if directions not in DIRECTIONS:
            raise InputError(f"directions = {directions!r}: expected one of {DIRECTIONS}")
        if not callable(rng_of):
            raise InputError(f"rng_of must be a callable k -> numpy Generator; got {rng_of!r}")
        if not self.is_bounded():
            raise PolytopeError("A ∩ C is unbounded: there is no uniform law on it")
        x0, Z, Gz, b, implicit = self.affine_hull(implicit=implicit)
        d = Z.shape[1]
        if d == 0:
            pts = np.tile(x0 * self.scale, (n_chains * per_chain, 1))
            return pts, {"dimension": 0, "implicit": implicit, "rhat": 1.0}
        norms = np.hypot.reduce(Gz, axis=1)
        c = np.zeros(d + 1)
        c[-1] = -1.0
        res = linprog(c, A_ub=np.hstack([Gz, norms[:, None]]), b_ub=b, bounds=[(None, None)] * (d + 1),
                      method="highs", options=self.highs)
        if res.status != 0 or res.x[-1] <= 0:
            raise PolytopeError("A ∩ C has an empty relative interior")
        y0 = res.x[:d]
        thin = thin or 4 * d
        burn = burn or 50 * d
        L = np.eye(d) * res.x[-1]
        if points is not None and len(points) > 1:
            V = (points / self.scale - x0) @ Z
            L = np.linalg.cholesky(np.atleast_2d(np.cov(V.T)) + res.x[-1] ** 2 * np.eye(d))

        def start(rng):
            if not dispersed:
                return y0.copy()
            v = linprog(-rng.standard_normal(d), A_ub=Gz, b_ub=b, bounds=[(None, None)] * d, method="highs",
                        options=self.highs)
            return y0 + 0.95 * (v.x - y0) if v.status == 0 else y0.copy()

        def chain(rng, n_keep, L, y, n_burn):
            blocks = [max(n_burn // thin, 1)] + [min(1000, n_keep - k) for k in range(0, n_keep, 1000)]
            keep = []
            if directions == "coordinate":
                GLt = np.ascontiguousarray((Gz @ L).T)
                z = solve_triangular(L, y, lower=True)
                for n in blocks:                              # the first block is burn-in
                    slack = b - GLt.T @ z                     # fresh slack: no drift
                    keep.append(_coordinate_hit_and_run(GLt, slack, z, thin, rng.integers(0, d, n * thin),
                                                        rng.uniform(size=n * thin)) @ L.T)
                return np.concatenate(keep[1:])
            for n in blocks:                                  # the first block is burn-in
                slack = b - Gz @ y                            # fresh slack: no drift
                keep.append(_hit_and_run(Gz, slack, y, L, thin, rng.standard_normal((n * thin, d)),
                                         rng.uniform(size=n * thin)))
            return np.concatenate(keep[1:])

        for r in range(rounds):             # pilots start at the centre: the short burn-in is enough
            pilot = chain(rng_of(n_chains + r), max(20 * d, 200), L, y0.copy(), 50 * d)
            cov = np.cov(pilot.T).reshape(d, d) + 1e-12 * np.eye(d) * np.trace(np.atleast_2d(np.cov(pilot.T)))
            L = np.linalg.cholesky(cov)
        chains = []
        for k in range(n_chains):
            rng = rng_of(k)
            chains.append(chain(rng, per_chain, L, start(rng), burn))
        chains = np.array(chains)
        x = x0 + chains @ Z.T                                   # (chains, per_chain, 2 kappa)
        rhat = _rhat(x) if n_chains > 1 and per_chain > 1 else np.nan
        return x.reshape(-1, 2 * self.n_contacts) * self.scale, {
            "dimension": d, "implicit": implicit, "rhat": rhat}

    # ------------------------------------------------------------ checks of points
    def violations(self, rho):
        """Per point: largest equilibrium residual ``|H rho + F|`` (relative to ``scale``
        and each equation's coefficients) and largest Coulomb violation (relative to ``scale``)."""
        x = np.atleast_2d(rho) / self.scale
        eq = np.abs(self.A_eq @ x.T - self.b_eq[:, None]).max(0)
        co = np.maximum((self.G @ x.T).max(0), 0.0)
        return eq, co

    def active_faces(self, rho, tol=1e-7):
        """Per point: the number of Coulomb rows active within ``tol`` (relative) and the
        dimension of the face of ``A ∩ C`` they define (``d`` for an interior point)."""
        x = np.atleast_2d(rho) / self.scale
        Gd = self.G.toarray()
        Aeq = self.A_eq.toarray()
        rank_eq = np.linalg.matrix_rank(Aeq)
        slack = -(Gd @ x.T)                                    # >= 0 inside
        n_active = (slack <= tol).sum(0)
        dims = np.empty(x.shape[0], int)
        for k in range(x.shape[0]):
            act = Gd[slack[:, k] <= tol]
            dims[k] = Gd.shape[1] - (np.linalg.matrix_rank(np.vstack([Aeq, act])) if len(act) else rank_eq)
        return n_active, dims


def _rhat(x):
    """Largest Gelman-Rubin potential scale reduction over coordinates; x (chains, n, dim)."""
    m, n, _ = x.shape
    W = x.var(axis=1, ddof=1).mean(0)
    B = n * x.mean(1).var(axis=0, ddof=1)
    ok = W > 1e-12 * max(W.max(), 1e-300)      # a variance at round-off level is no coordinate to mix
    var = (n - 1) / n * W[ok] + B[ok] / n
    return float(np.sqrt(var / W[ok]).max()) if ok.any() else 1.0
