"""Two groups of piles compared at matched shape: the test behind the history comparison.

The ground-pressure experiments that answer Moreau's section 5 (Vanel et al. 1999; Geng
et al. 2001) compare heaps of the same shape built by a localized source and by a rain.
Here a comparison of two groups of piles has two parts:

* **the shape match**: flank slope, apex height and base half-width of the two groups'
  mean piles, as relative differences of the means with bootstrap bands over piles; the
  shapes match when each difference lies within :data:`SHAPE_TOL` (5 %: a triangular
  heap 5 % higher, or 5 % steeper on the same base, carries 5 % more pressure under its
  apex, one tenth of the W/2L unit in which the dips are measured, twice the triangle's
  apex pressure 2 W/2L times 5 %);
* **the differences**, each by a two-sided permutation test of the group labels over
  piles (:data:`MEASURES`): the shape measures, the largest gap between the mean ground
  stress profiles (``|x| <= L``), the dip depth of the mean profiles and the pooled median
  arching deviation.  Two groups *differ* when some measure's p-value lies below
  ``alpha / len(MEASURES)`` (Bonferroni over the measures: one family of tests).

The test is checked on its own controls: two halves of one history's piles (different
seeds, same history) must come out not different, and a heap against the flat-topped
layer (a difference known to exist) must come out different.
"""
import warnings

import numpy as np

SHAPES = ("flank_slope", "apex_height", "base_half_width")
MEASURES = SHAPES + ("profile_gap", "dip", "arching")
SHAPE_TOL = 0.05
ALPHA = 0.05
UNITS = {"flank_slope": "degree", "apex_height": "d", "base_half_width": "d", "profile_gap": "W/2L",
         "dip": "W/2L", "arching": "degree"}


def _nanmedian(a, axis=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmedian(a, axis=axis)


def statistics(group_a, group_b, xi, dip_fn):
    """The measures of :data:`MEASURES` for group B against group A: shapes as B − A (the
    relative difference is taken by the caller), the profile gap ``max |p_A − p_B|`` over
    ``|xi| <= 1`` of the mean profiles (per kernel), the dip of A's mean profile minus B's
    (per kernel, ``dip_fn(profile)``) and the pooled median deviation of A minus B.

    ``group = dict(shape=(n, 3), profile=(n, K, X), deviation=(n, ...))``."""
    inner = np.abs(xi) <= 1.0
    pa, pb = group_a["profile"].mean(axis=0), group_b["profile"].mean(axis=0)
    return dict(shape=group_b["shape"].mean(axis=0) - group_a["shape"].mean(axis=0),
                profile_gap=np.max(np.abs(pa - pb)[..., inner], axis=-1),
                dip=dip_fn(pa) - dip_fn(pb),
                arching=_nanmedian(group_a["deviation"]) - _nanmedian(group_b["deviation"]))


def _take(group, idx):
    return {k: v[idx] for k, v in group.items()}


def compare(group_a, group_b, xi, dip_fn, rng, n_perm, n_boot, level):
    """Observed statistics, basic bootstrap bands (piles resampled within each group) and
    two-sided permutation p-values (labels shuffled over the pooled piles) of group B
    against group A.  Returns a dict of arrays: ``shape``, ``shape_rel`` (B − A over A's
    mean), their bands ``*_lo, *_hi``, ``profile_gap``, ``dip``, ``arching``, and ``p_<measure>``."""
    obs = statistics(group_a, group_b, xi, dip_fn)
    na, nb = len(group_a["shape"]), len(group_b["shape"])
    ref = group_a["shape"].mean(axis=0)
    boots = [statistics(_take(group_a, rng.integers(0, na, na)), _take(group_b, rng.integers(0, nb, nb)), xi, dip_fn)
             for _ in range(n_boot)]
    pooled = {k: np.concatenate([group_a[k], group_b[k]]) for k in group_a}
    perms = []
    for _ in range(n_perm):
        idx = rng.permutation(na + nb)
        perms.append(statistics(_take(pooled, idx[:na]), _take(pooled, idx[na:]), xi, dip_fn))
    lo, hi = 0.5 * (1 - level), 0.5 * (1 + level)
    out = {}
    for key in ("shape", "profile_gap", "dip", "arching"):
        b = np.array([s[key] for s in boots])
        out[key] = np.asarray(obs[key], float)
        out[f"{key}_lo"] = 2 * out[key] - np.nanquantile(b, hi, axis=0)
        out[f"{key}_hi"] = 2 * out[key] - np.nanquantile(b, lo, axis=0)
        perm = np.abs(np.array([s[key] for s in perms]))
        # a two-sided test of the absolute statistic; the profile gap is already >= 0
        out[f"p_{key}"] = (np.sum(perm >= np.abs(out[key]) - 1e-12, axis=0) + 1.0) / (n_perm + 1.0)
    out["shape_rel"] = out["shape"] / ref
    out["shape_rel_lo"], out["shape_rel_hi"] = out["shape_lo"] / ref, out["shape_hi"] / ref
    out["shape_reference"] = ref
    return out


def shape_matched(shape_rel, tol=SHAPE_TOL):
    """The shapes match when every relative difference of the mean piles (flank slope,
    apex height, base half-width) lies within ``tol``."""
    return bool(np.all(np.abs(np.asarray(shape_rel, float)) <= tol))


def equivalence_resolved(shape_rel_lo, shape_rel_hi, tol=SHAPE_TOL):
    """The match is resolved when the bootstrap band of every relative difference lies
    within ``± tol`` (an equivalence test at the band's level), not only its estimate."""
    return bool(np.all((np.asarray(shape_rel_lo) >= -tol) & (np.asarray(shape_rel_hi) <= tol)))


def p_values(cmp_row, kernel=0):
    """``{measure: p}`` of one comparison (:func:`compare`'s output, or the same keys read
    from a file): the shape p-values split by measure, the profile and dip at the kernel
    of index ``kernel`` (the default kernel first)."""
    at = lambda key: float(np.ravel(cmp_row[key])[kernel if np.size(cmp_row[key]) > 1 else 0])  # noqa: E731
    p = dict(zip(SHAPES, np.ravel(cmp_row["p_shape"]).tolist()))
    p.update(profile_gap=at("p_profile_gap"), dip=at("p_dip"), arching=float(np.ravel(cmp_row["p_arching"])[0]))
    return p


def differing(p, alpha=ALPHA):
    """The measures whose permutation p-value lies below ``alpha / len(p)`` (Bonferroni):
    two groups differ when this list is not empty."""
    cut = alpha / len(p)
    return [k for k, v in p.items() if v < cut]
