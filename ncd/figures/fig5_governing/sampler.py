"""Hit-and-run's two kinds of direction side by side on the slices of Figure 5.

Figure 5 samples each slice's ``A ∩ C`` uniformly by hit-and-run in a rounded frame
(:mod:`ncd.figures.fig5_governing.unger`); a step along a Gaussian direction costs
O(d^2 + m d), one along a coordinate of the rounded frame O(m) (docs/governing.md).  Both
are exact samplers of the uniform law, so the comparison is of cost at equal checks: on the
same slice, with the same settings and generators, each kind's CPU time, eta_U, the two
chains' gap and R-hat, and the chain length the mixing check needed.
"""
import time

import numpy as np
import pandas as pd
import xarray as xr

from ncd.dynamics.explore import member_rng
from ncd.exact.polytope import DIRECTIONS
from ncd.figures.fig5_governing import measure
from ncd.figures.fig5_governing.unger import chains_agree, uniform_sample


def pick_slices(ds, per_mu=1):
    """Analyses of the plates series to compare on: the first ``per_mu`` at each mu whose
    ``A ∩ C`` is bounded and of positive dimension (a point has nothing to sample)."""
    ok = (ds.kind.values == 0) & (ds.bounded.values == 1) & (ds.dim_AC_rank.values > 0)
    out = []
    for i in np.unique(ds.mu_index.values[ok]):
        out += [int(j) for j in np.nonzero(ok & (ds.mu_index.values == i))[0][:per_mu]]
    return out


def compare(ds, cfg, rows, seed=0):
    """Both kinds of direction on analyses ``rows`` of ``packings.nc`` (``cfg``: the
    fig5_governing section the run used) -> Dataset over ``case`` and ``directions``."""
    e, u = cfg["exact"], cfg["uniform"]
    row_of = {int(b): j for j, b in enumerate(ds.build.values)}
    rec = {k: np.full((len(rows), len(DIRECTIONS)), np.nan) for k in ("seconds", "eta", "gap", "rhat", "per_chain")}
    mixed = np.zeros((len(rows), len(DIRECTIONS)), np.int8)
    mu, dim = np.zeros(len(rows)), np.zeros(len(rows), np.int64)
    for c, i in enumerate(rows):
        j = row_of[int(ds.build_index.values[i])]
        mu[c] = float(ds.mu.values[i])
        *_, sl, ex = measure.measured_slice(ds, j, cfg, mu[c])
        dim[c] = int(ex["dim_AC_rank"])
        for k, name in enumerate(DIRECTIONS):
            t0 = time.process_time()
            out = uniform_sample(sl, ex, dict(u, directions=name), lambda m, s=c: member_rng(s * 10 + m, seed),
                                 e["feas_tol"])
            rec["seconds"][c, k] = time.process_time() - t0
            for q in ("eta", "gap", "rhat", "per_chain"):
                rec[q][c, k] = out[q]
            mixed[c, k] = chains_agree(out["gap"], out["rhat"])
    v = lambda x, units, name: (("case", "directions"), x, {"units": units, "long_name": name})  # noqa: E731
    return xr.Dataset(
        {"cpu_seconds": v(rec["seconds"], "s", "CPU time of the two chains (pilot, burn-in and redraws included)"),
         "eta_uniform": v(rec["eta"], "1", "eta_U over both chains"),
         "gap": v(rec["gap"], "1", "|eta_U chain 1 - chain 2| / eta_U"),
         "rhat": v(rec["rhat"], "1", "largest Gelman-Rubin R-hat"),
         "per_chain": v(rec["per_chain"], "1", "points per chain the mixing check needed"),
         "mixed": v(mixed, "1", "1: the two chains agree"),
         "mu": ("case", mu, {"units": "1", "long_name": "friction coefficient of the analysis"}),
         "dimension": ("case", dim, {"units": "1", "long_name": "dim (A ∩ C), rank count"}),
         "analysis": ("case", np.asarray(rows, np.int64), {"units": "1", "long_name": "row of packings.nc"})},
        coords={"case": ("case", np.arange(len(rows)), {"units": "1", "long_name": "slice compared"}),
                "directions": ("directions", np.array(DIRECTIONS), {"units": "1", "long_name": "hit-and-run directions"})})


def frame(s):
    """Per slice: mu, dimension, and for each kind of direction its CPU seconds, eta_U, the
    chains' gap and R-hat and the points per chain the mixing check needed."""
    cols = {"μ": s.mu.values, "dim A ∩ C": s.dimension.values}
    for k, name in enumerate(s.directions.values):
        cols.update({f"{name}: CPU s": s.cpu_seconds.values[:, k], f"{name}: η_U": s.eta_uniform.values[:, k],
                     f"{name}: gap": s.gap.values[:, k], f"{name}: R-hat": s.rhat.values[:, k],
                     f"{name}: points per chain": s.per_chain.values[:, k].astype(int)})
    return pd.DataFrame(cols)


def summary(s):
    """One sentence: the median CPU ratio and how the two kinds' eta_U compare."""
    if not s.sizes.get("case"):
        return "No indeterminate slice to compare the samplers on."
    t = s.cpu_seconds.values
    ratio = np.median(t[:, 0] / t[:, 1])
    rel = np.abs(s.eta_uniform.values[:, 1] / s.eta_uniform.values[:, 0] - 1)
    return (f"On {s.sizes['case']} slices (dim(A ∩ C) {int(s.dimension.min())}–{int(s.dimension.max())}), "
            f"coordinate directions cost a median 1/{ratio:.1f} of the CPU time of random ones "
            f"({t[:, 1].sum():.0f} s against {t[:, 0].sum():.0f} s in all); their η_U differ by a median "
            f"{np.median(rel):.1%} (largest {rel.max():.1%}); chains that agree: "
            f"{int(s.mixed.values[:, 0].sum())} (random) and {int(s.mixed.values[:, 1].sum())} (coordinate) of "
            f"{s.sizes['case']}.")


__all__ = ["pick_slices", "compare", "frame", "summary"]
