"""Unger, Kertész & Wolf's indeterminacy, their way and on a uniform sample.

Their measure (PRL 94, 178001, 2005): ``eta_U = <dF> / <|F|>``, where for each contact
``dF`` is the standard deviation of its force vector over the sampled solutions
(``dF^2 = var F_n + var F_t``) and ``<.>`` averages over contacts (:func:`eta_u`).  Two
samples of the same set ``A ∩ C`` of a slice (:mod:`ncd.figures.fig5_governing.plates`):

* their random walk (:func:`random_walk`): every force component of the current solution
  gets uniform noise in ``[-a, a]``, ``a = noise * <F_n>``, NLGS relaxes it with random
  review order (boundary forces fixed) and the result, checked to be a point of ``A ∩ C``,
  starts the next round.  A walk stays near where it starts, so ``eta_U`` against the
  number of samples (:func:`eta_curve`) shows whether it has settled;
* a uniform sample (:func:`uniform_sample`): hit-and-run in the affine hull of ``A ∩ C``
  (:meth:`ncd.exact.polytope.ForcePolytope.uniform_samples`, implicit equalities found by
  the exact LPs, directions shaped by the LPs' vertices and rounded by a pilot chain) from
  two dispersed starts; the two chains' ``eta_U`` and the Gelman-Rubin R-hat say whether
  they mixed.  The set sampled is the whole ``A ∩ C`` in the hull of the rank count
  (``dimension`` = ``dim_AC_rank``): no direction is dropped for being thin.

:func:`centrality` measures their last finding: the history (build) state lies closer to
the centre of the set than random samples do.
"""
import numpy as np
import scipy.sparse as sp

from ncd.exact.exact_set import ExactSet
from ncd.exact.polytope import ForcePolytope
from ncd.figures.fig5_governing.plates import relax
from ncd.solver.settings import SolverSettings


def eta_u(samples):
    """``<dF> / <|F|>`` of samples (n_samples, contacts, 2): ``dF`` the per-contact standard
    deviation of the force vector over the samples, ``<|F|>`` the mean force magnitude."""
    f = np.asarray(samples, float)
    if len(f) < 2:
        return np.nan
    d = f - f[:1]                  # shifted by the first sample: identical samples give exactly 0
    dF = np.sqrt(d[..., 0].var(axis=0, ddof=1) + d[..., 1].var(axis=0, ddof=1))
    mag = np.hypot(f[..., 0], f[..., 1]).mean()
    return float(dF.mean() / mag) if mag > 0 else np.nan


def eta_curve(samples, counts):
    """``eta_U`` over the first ``n`` samples, for each ``n`` of ``counts``."""
    return np.array([eta_u(samples[:n]) for n in counts])


def random_walk(sl, w, rng):
    """Unger et al.'s random walk in ``A ∩ C`` of slice ``sl`` from its history state.

    Returns ``samples`` (w["samples"] + 1, kappa, 2; row 0 the history state) and ``ok``
    (bool per row: the relaxed forces are a point of ``A ∩ C`` within ``point_tol`` of the
    force scale, after a projection on their active rows when NLGS stopped short (a state
    with |H r + F| ~ 1e-8 lay up to 0.5 % of the force scale outside the exact ranges on a
    thin set); a failed round leaves the walk where it was)."""
    P = ForcePolytope(sl.H, sl.F, sl.mu)
    settings = SolverSettings(**w["solver"])
    k = len(sl.mu)
    cur = sl.reference.copy()
    out = np.full((w["samples"] + 1, k, 2), np.nan)
    ok = np.zeros(w["samples"] + 1, bool)
    out[0], ok[0] = cur, _is_point(P, cur, w["point_tol"])
    a = w["noise"] * float(np.mean(cur[:, 0])) if k else 0.0
    es = ExactSet(sl.H, sl.F, sl.mu) if k else None
    for s in range(1, w["samples"] + 1):
        guess = cur + rng.uniform(-a, a, (k, 2))
        r, _, _ = relax(sl, guess, rng.permutation(k), settings)
        if not _is_point(P, r, w["point_tol"]):   # NLGS stopped short of its finishing stage:
            r = es.refine(r.ravel()).reshape(k, 2)  # project on its active rows, then check again
        out[s] = r
        ok[s] = _is_point(P, r, w["point_tol"])
        if ok[s]:
            cur = r
    return {"samples": out, "ok": ok}


def _is_point(P, r, tol):
    if P.n_contacts == 0:
        return True
    eq, co = P.violations(np.asarray(r).ravel())
    return bool(eq[0] <= tol and co[0] <= tol)


MIXED_GAP, MIXED_RHAT = 0.3, 1.2   # two chains agree: eta_U within a relative 0.3 of each other, Gelman-Rubin R-hat at most 1.2


def chains_agree(gap, rhat):
    """The mixing check of two chains from dispersed starts (:data:`MIXED_GAP`, :data:`MIXED_RHAT`)."""
    return bool(gap <= MIXED_GAP and rhat <= MIXED_RHAT)


def uniform_sample(sl, exact, u, rng_of, feas_tol=1e-10):
    """Two hit-and-run chains of ``u["per_chain"]`` points from dispersed starts, uniform on
    ``A ∩ C`` of slice ``sl`` (``exact``: its :func:`exact_measures`, for the implicit
    equalities); chains that do not agree (:func:`chains_agree`) are drawn again, 4 times
    longer, up to ``u["max_per_chain"]`` points: the cost goes where the set is hard to mix
    (thin, elongated), the same generators make the result independent of the shards.
    ``u["burn"]`` (default 20): burn-in of each chain, hit-and-run steps per dim^2.
    Returns the pooled samples (2 per_chain, kappa, 2), per-chain means and standard
    deviations (2, kappa, 2), ``eta`` (pooled), ``gap`` (|eta_1 - eta_2| / eta), ``rhat``,
    the dimension and ``per_chain`` (the length used)."""
    per_chain, cap = u["per_chain"], max(u.get("max_per_chain", u["per_chain"]), u["per_chain"])
    while True:
        out = _two_chains(sl, exact, u, per_chain, rng_of, feas_tol)
        if chains_agree(out["gap"], out["rhat"]) or 4 * per_chain > cap:
            return out
        per_chain *= 4


def _two_chains(sl, exact, u, per_chain, rng_of, feas_tol):
    # sampled in r' = (r_n, r_t / mu): the Coulomb sectors become right angles, the thin
    # tangential directions of small mu as wide as the normal ones (a linear map: uniform
    # in r' is uniform in r), and the implicit rows are the same rows.  The range LPs' vertices
    # shape the first pilot's directions: their spread spans the set's widths (4-5 decades
    # on thin-sector slices), which pilots from an isotropic start did not find.  A chain
    # from a far vertex of such a set needs a burn-in ~ dim^2 (like hit-and-run's mixing
    # time in a rounded body) before its eta_U forgets the start.
    k = len(sl.mu)
    stretch = np.ones((k, 2))
    stretch[:, 1] = np.where(sl.mu > 0, sl.mu, 1.0)
    H = sl.H @ sp.diags(stretch.ravel())
    P = ForcePolytope(H, sl.F, np.where(sl.mu > 0, 1.0, 0.0), feas_tol)
    d = max(int(exact["dim_AC_rank"]), 1)
    x, info = P.uniform_samples(rng_of, 2, per_chain, thin=u.get("thin", 4) * d, rounds=u["rounds"],
                                burn=int(u.get("burn", 20) * d * d),
                                implicit=exact["implicit"], dispersed=True,
                                points=exact["lp_points"] / stretch.ravel(),
                                directions=u.get("directions", "random"))
    x = x.reshape(2, per_chain, k, 2) * stretch
    etas = [eta_u(c) for c in x]
    eta = eta_u(x.reshape(-1, k, 2))
    gap = abs(etas[0] - etas[1]) / eta if eta > 0 else 0.0
    return {"samples": x.reshape(-1, k, 2), "chain_mean": x.mean(axis=1), "chain_std": x.std(axis=1, ddof=1),
            "eta": eta, "eta_chains": etas, "gap": float(gap), "rhat": float(info["rhat"]),
            "dimension": int(info["dimension"]), "per_chain": per_chain}


def _distance(x, centre, scale):
    d = np.asarray(x) - centre
    return np.sqrt((d ** 2).sum(axis=(-1, -2)) / centre.shape[0]) / scale


def centrality(history, uniform, walk):
    """Distances to the centre of ``A ∩ C`` (the uniform sample's mean), per contact (RMS)
    over the mean force: of the history state, mean of the uniform and of the walk samples,
    and the fraction of uniform samples closer to the centre than the history state."""
    centre = uniform.mean(axis=0)
    scale = float(np.hypot(centre[:, 0], centre[:, 1]).mean()) or 1.0
    dh = float(_distance(history, centre, scale))
    du = _distance(uniform, centre, scale)
    dw = _distance(walk[1:], centre, scale) if len(walk) > 1 else np.array([np.nan])
    return {"history_distance": dh, "uniform_distance": float(du.mean()), "walk_distance": float(np.mean(dw)),
            "history_rank": float(np.mean(du < dh))}


def closed_form_segment_eta():
    """``eta_U`` of the uniform law on the segment ``r_n1 + r_n2 = 1`` (frictionless): each
    ``r_n`` uniform on [0, 1], standard deviation ``1 / sqrt(12)``, mean 1/2: ``2 / sqrt(12)``."""
    return 2.0 / np.sqrt(12.0)


__all__ = ["eta_u", "eta_curve", "random_walk", "uniform_sample", "chains_agree", "MIXED_GAP", "MIXED_RHAT", "centrality", "closed_form_segment_eta"]
