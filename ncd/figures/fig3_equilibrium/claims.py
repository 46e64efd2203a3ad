"""Figure 3's rows on the index: §4 (dim A, outlines, cones, ghost images, the boundary of A ∩ C,
the exact set) and §2's review orders, equilibrium test and warm start at rest.

Clouds are the runs at rest of each exploration mode (:data:`ncd.solver.convergence.REST`);
the paper's Figure 3 is the zero-guess ensemble with random review orders.  Measures in
R^2κ (faces, depth, limits) are in :mod:`ncd.figures.fig3_equilibrium.faces`, the
positions of the equilibrium test in :mod:`ncd.figures.fig3_equilibrium.probes`.
"""
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from ncd.figures.fig3_equilibrium import faces
from ncd.figures.fig3_equilibrium import measure as fe
from ncd.shared.verdict import BEYOND, DIFFERS, REPRODUCED, judged, open_data, pct
from ncd.solver.convergence import REST

F3 = ("fig3_equilibrium/ensemble.nc", "fig3_equilibrium/projection.nc", "fig3_equilibrium/uniform.nc")
STATE = "fig3_equilibrium/state.nc"
PROBES = "fig3_equilibrium/probes.nc"     # the one-step test on positions in and out of equilibrium
WARM_FACTOR = 3        # "considerably accelerates": at least three times fewer sweeps
COVER = 0.5            # an outline: the cloud's hull covers at least half of the exact polygon
BAND = 0.1             # the vicinity of the boundary: the tenth of A ∩ C's volume nearest to it
NOISE_SIGMAS = 3       # a fraction differs from another beyond 3 binomial standard deviations
GHOST_MIN = 10         # ten dots on one edge (or at one vertex) draw a line (a point) in a cloud
LIMIT_TOLS = 1e3       # limits closer than 10^3 solver tolerances (of the largest weight) are one


def _stamp(results, *rels):
    """The modification times of ``results/<rel>``: the cache key of a measure of these files."""
    return tuple(Path(results, r).stat().st_mtime_ns if Path(results, r).exists() else -1 for r in rels)


def _rest(ds):
    """The runs at rest of ``ds`` (converged runs when it has no outcome)."""
    keep = ds.outcome.values == REST if "outcome" in ds else ds.converged.values == 1
    return ds.isel(run=np.nonzero(keep)[0])


def _forces(ds):
    """(points, 2 kappa) force vectors of ``ds`` (normal and tangential interleaved)."""
    return np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)


def warm_accelerates_rest(results):
    ens = open_data(results, F3[0])
    conv = {m: fe.mode_subset(ens, m) for m in ("zero", "warm")}
    conv = {m: ds.sweeps.values[ds.converged.values == 1] for m, ds in conv.items()}
    if not all(len(v) for v in conv.values()):
        return judged(f"converged runs: {len(conv['zero'])} from the zero guess, {len(conv['warm'])} warm-started",
                      DIFFERS, "no converged runs to compare", "s2-warm-accelerates", F3[0])
    z, w = (float(np.median(conv[m])) for m in ("zero", "warm"))
    ratio = z / max(w, 1.0)
    return judged(f"Figure 3's packing at rest (κ = {ens.sizes['contact']}, tol {float(ens.attrs['solver_tol']):g}), "
                  f"random review orders in both: median {z:.0f} sweeps from the zero guess ({len(conv['zero'])} "
                  f"converged runs), {w:.0f} from the warm guess ({len(conv['warm'])}): {ratio:.0f}× fewer",
                  REPRODUCED if ratio >= WARM_FACTOR else DIFFERS,
                  f"at rest only: the warm guess is the impulses of the deposition's last step, which nearly balance "
                  f"the packing already (the most favourable case; a computation in progress is error_vs_runtime's "
                  f"scope); median sweeps of converged runs, zero / warm ≥ {WARM_FACTOR} (\"considerably\": at least "
                  f"{WARM_FACTOR} times fewer)", "s2-warm-accelerates", F3[0])


def equilibrium_test(results):
    """§2: one step from u_i = 0 decides equilibrium.  Read from probes.nc (:mod:`.probes`,
    written by its rule): the packing (an equilibrium), a disc lifted off its supports (it can
    only fall) and the packing with its friction a tenth above and below μ*, the least
    coefficient for which A ∩ C is non-empty; on each, the one-step test from the zero and the
    warm guess against the LP."""
    pr = open_data(results, PROBES)
    mu_star, vtol = float(pr.attrs["mu_star"]), float(pr.attrs["velocity_tol"])
    rows = [(str(name), int(pr.expected.values[k]) if pr.expected.values[k] >= 0 else None,
             [(str(init), bool(pr.at_rest.values[k, j]), float(pr.max_velocity.values[k, j]),
               bool(pr.admits_equilibrium.values[k, j])) for j, init in enumerate(pr.init.values)])
            for k, name in enumerate(pr.position.values)]
    parts, agree, total = [], 0, 0
    for name, _, tests in rows:
        exact = tests[0][3]
        rest = [t for t in tests if t[1]]
        said = ("u_f = 0" if len(rest) == len(tests) else
                f"|u_f| = {max(t[2] for t in tests):.2g} |g| h" if not rest else
                "u_f = 0 from the " + " and ".join(t[0] for t in rest) + " guess only")
        parts.append(f"{name}: {said}, A ∩ C {'≠' if exact else '='} ∅")
        agree += sum(t[1] == t[3] for t in tests)
        total += len(tests)
    both = {r[1]: all(t[1] == t[3] == r[1] for t in r[2]) for r in rows if r[1] is not None}
    ok = agree == total and both.get(True, False) and both.get(False, False)
    mu_txt = (f"μ* = {mu_star:.3g}" if np.isfinite(mu_star) and mu_star > 0 else
              "the packing stands without friction" if mu_star == 0 else "the stored packing does not stand")
    return judged(f"one step from u_i = 0 (NLGS to tol, then the exact active-set finish; u_f = 0 when "
                  f"|u_f| ≤ {vtol:g} |g| h) against the LP on A ∩ C — " + "; ".join(parts)
                  + f" ({mu_txt}): the test agrees with the LP in {agree} of {total} steps",
                  REPRODUCED if ok else DIFFERS,
                  "on positions clearly in and out of equilibrium (the packing, a disc lifted off its supports, "
                  f"friction {float(pr.attrs['friction_margin']):.0%} above and below the least μ* that holds the packing), the step from "
                  "the zero and the warm guess finds u_f = 0 exactly where the LP finds A ∩ C non-empty, and both "
                  "answers occur; the margin keeps away from μ*, where the step may also have a moving solution "
                  "(Figure 1's two evolutions)", "s2-equilibrium-test", PROBES)


def _fig3_rows(results):
    proj = open_data(results, F3[1])
    ens = open_data(results, F3[0])
    uni = open_data(results, F3[2])
    shown = [int(k) for k in np.atleast_1d(proj.attrs["displayed_order"])]
    return fe.cloud_measures(ens, proj, uni, shown), proj


def fig3_outlines(results):
    rows, _ = _fig3_rows(results)
    cov = {m: [r["coverage"] for r in rows if r["mode"] == m] for m in ("zero", "random", "uniform")}
    txt = "; ".join(f"{m}: {', '.join(pct(c) for c in v)}" for m, v in cov.items() if v)
    ok = min(cov["zero"]) >= COVER
    return judged(f"area of the cloud's convex hull / area of the exact projection (displayed contacts) — {txt}",
                  REPRODUCED if ok else DIFFERS,
                  f"the paper's clouds (zero guess, random review orders, runs at rest) cover at least {COVER:.0%} of "
                  "each displayed exact projection: below half the hull shows a part of the polygon, not its outline "
                  "(the uniform sample's coverage is the reference)", "s4-outlines", *F3)


def fig3_in_cones(results):
    ens, state = open_data(results, F3[0]), open_data(results, STATE)
    ok_run = ens.converged.values.astype(bool)
    rn, rt = ens.force_n.values[ok_run], ens.force_t.values[ok_run]
    scale = float(np.abs(rn).max())
    inside = (rn >= -1e-9 * scale) & (np.abs(rt) <= state.mu.values[None, :] * rn + 1e-9 * scale)
    worst = float(np.max(np.maximum(np.abs(rt) - state.mu.values[None, :] * rn, -rn)) / scale)
    return judged(f"{inside.all(1).sum()} of {ok_run.sum()} converged runs have every contact force in its Coulomb "
                  f"sector (largest excess {max(worst, 0.0):.1e} of the largest force)",
                  REPRODUCED if inside.all() else DIFFERS,
                  "every force of every converged run in C_α within 10⁻⁹ of the force scale (\"of course\": NLGS's "
                  "local solver projects on the sector, so this checks the code)", "s4-in-cones", F3[0], STATE)


@lru_cache(maxsize=4)
def _where_in_AC(results, stamp):
    """Per group (zero, random, uniform): points, face classes and depth (faces.depth) of
    the runs at rest and of the uniform sample; ``stamp`` keys the cache to the files."""
    state = open_data(results, STATE)
    ens, uni = open_data(results, F3[0]), open_data(results, F3[2])
    P = fe.polytope_of(state)
    frame = faces.hull_frame(P)
    groups = {"zero": _forces(_rest(fe.mode_subset(ens, "zero"))),
              "random": _forces(_rest(fe.mode_subset(ens, "random"))), "uniform": _forces(uni)}
    out = {"dimension": frame[1].shape[1]}
    for name, X in groups.items():
        sizes, dims, on_ghosts, on_low = faces.shared_low_faces(P, X, 1, GHOST_MIN) if len(X) else \
            (np.zeros(0, int), np.zeros(0, int), 0, 0)
        out[name] = {"n": len(X), "depth": faces.depth(frame, P, X), "ghosts": sizes, "ghost_dims": dims,
                     "on_ghosts": on_ghosts, "on_low": on_low}
    return out


def _where(results):
    return _where_in_AC(str(results), _stamp(results, STATE, *F3))


def fig3_boundary(results):
    s = _where(results)
    z, r, u = s["zero"], s["random"], s["uniform"]
    beta = float(np.quantile(u["depth"], BAND))
    frac = {m: float(np.mean(s[m]["depth"] <= beta)) if s[m]["n"] else np.nan for m in ("zero", "random", "uniform")}
    sigma = math.sqrt(frac["uniform"] * (1 - frac["uniform"]) * (1 / max(z["n"], 1) + 1 / u["n"]))
    ok = z["n"] > 0 and frac["zero"] - frac["uniform"] > NOISE_SIGMAS * sigma
    ratio = frac["zero"] / frac["uniform"] if frac["uniform"] > 0 else np.inf
    return judged(f"in R^2κ (dim A ∩ C = {s['dimension']}), depth = smallest slack of the Coulomb rows over that row's "
                  f"width across A ∩ C (0 on the boundary, affine-invariant); within the uniform sample's shallowest "
                  f"tenth (depth ≤ {beta:.2g}): zero-guess {pct(frac['zero'])} of {z['n']} runs at rest, random-guess "
                  f"{pct(frac['random'])} of {r['n']}, uniform {pct(frac['uniform'])} of {u['n']} "
                  f"({ratio:.1f}× the uniform density near the boundary; median depth zero-guess "
                  f"{np.median(z['depth']) if z['n'] else np.nan:.2g}, uniform {np.median(u['depth']):.2g})",
                  REPRODUCED if ok else DIFFERS,
                  f"in R^2κ, the zero-guess solutions (the paper's) fall within the band of A ∩ C nearest its "
                  f"boundary that holds a tenth of a uniform sample more often than the uniform sample, beyond "
                  f"{NOISE_SIGMAS} binomial standard deviations (\"a little\" is not quantified and not judged)",
                  "s4-denser-boundary", *F3, STATE)


def fig3_ghosts(results):
    s = _where(results)
    z, r, u = s["zero"], s["random"], s["uniform"]

    def faces_txt(g):
        if not len(g["ghosts"]):
            return "none"
        kinds = ", ".join(f"{n} on {'a vertex' if d == 0 else 'an edge'}" for n, d in zip(g["ghosts"], g["ghost_dims"]))
        return f"{len(g['ghosts'])} ({kinds}; {pct(g['on_ghosts'] / g['n'])} of the runs)"

    ok = len(z["ghosts"]) > 0
    return judged(f"in R^2κ (dim A ∩ C = {s['dimension']}), edges and vertices of A ∩ C holding at least {GHOST_MIN} "
                  f"solutions: zero-guess {faces_txt(z)} of {z['n']} runs at rest ({z['on_low']} on any edge or "
                  f"vertex); random-guess {faces_txt(r)} of {r['n']}; uniform sample {u['on_low']} of {u['n']} points "
                  "on an edge or vertex", REPRODUCED if ok else DIFFERS,
                  f"a ghost image is many solutions on one edge or vertex (their projections line up on a segment or "
                  f"meet at a point inside the cloud): at least one edge or vertex of A ∩ C holds {GHOST_MIN} or more "
                  "zero-guess solutions (the paper's clouds), where an unstructured sample puts no two points",
                  "s4-ghost-images", *F3, STATE)


def fig3_dimension(results):
    proj = open_data(results, F3[1])
    a, m = int(proj.attrs["dimension_A"]), int(proj.attrs["dimension_moreau"])
    N, kappa = int(proj.attrs["n_discs"]), int(proj.attrs["n_contacts"])
    rank = 2 * kappa - a
    return judged(f"N = {N}, κ = {kappa}: 2κ − 3N = {m}, measured dim A = 2κ − rank H = {a} (rank H = {rank}"
                  f"{' < 3N' if rank < 3 * N else ''} = {3 * N})", REPRODUCED if a == m else DIFFERS,
                  "dim A = 2κ − 3N (the 3N equations independent)", "s4-dimension-A", F3[1])


def fig3_exact(results):
    proj = open_data(results, F3[1])
    return judged(f"κ = {proj.sizes['contact']} contacts, dim A ∩ C = {int(proj.attrs['dimension_AC'])}, "
                  f"bounded = {bool(proj.attrs['bounded'])}; exact LP projections of every contact "
                  f"({int(proj.attrs['n_lp_total'])} LPs)", BEYOND, "the exact set computed, not in the paper",
                  "s4-force-set", F3[1])


def _limits(ens, proj, mode):
    """Single-linkage classes of the limits of ``mode``'s runs at rest, in units of the largest
    weight, at the radius ``LIMIT_TOLS`` solver tolerances: ``(runs, sizes, nearest, radius)``."""
    radius = LIMIT_TOLS * float(ens.attrs["solver_tol"])
    X = _forces(_rest(fe.mode_subset(ens, mode))) / float(proj.attrs["force_scale"])
    _, sizes, nearest = faces.limit_clusters(X, radius)
    return len(X), sizes, nearest, radius


def fig3_review_orders(results):
    """§2: zero-guess runs with random review orders reach at most (κ − 1)! solutions, "found
    sufficient to generate a significant outline of the solution set".  The bound is a count
    of cyclic orders (it holds by construction: at κ = 2 it reads one solution of one order);
    the outline is measured: the zero-guess clouds' hull against the exact projection of
    A ∩ C at the displayed contacts."""
    rows, proj = _fig3_rows(results)
    ens = open_data(results, F3[0])
    kappa = int(proj.attrs["n_contacts"])
    n, sizes, _, _ = _limits(ens, proj, "zero")
    cover = [r["coverage"] for r in rows if r["mode"] == "zero"]
    ok = min(cover) >= COVER
    return judged(f"κ = {kappa}, (κ − 1)! = {math.factorial(kappa - 1):.3g}; {n} zero-guess runs at rest reached "
                  f"{len(sizes)} distinct solutions; their clouds cover {', '.join(pct(c) for c in cover)} of the exact "
                  "projections of the displayed contacts", REPRODUCED if ok else DIFFERS,
                  "the bound (κ − 1)! is a count of cyclic orders (consistent by construction); judged is the "
                  f"\"significant outline\": the zero-guess cloud's hull covers at least {COVER:.0%} of each displayed "
                  "exact projection", "s2-review-orders", *F3)


def limit_depends_on_order(results):
    """§2: "The limit of a run depends on this ordering": the zero-guess runs of Figure 3, each
    with its own random review order, against the distance the solver's tolerance explains."""
    ens, proj = open_data(results, F3[0]), open_data(results, F3[1])
    n, sizes, nearest, radius = _limits(ens, proj, "zero")
    ok = len(sizes) >= 2 and sizes.max() < n / 2
    warm = ""
    if np.any(ens["mode"].values == fe.MODES.index("warm")):
        nw, sw, _, _ = _limits(ens, proj, "warm")
        warm = (f"; the {nw} warm-started runs, also with random orders, reach {len(sw)} distinct "
                f"limit{'s' if len(sw) != 1 else ''}")
    med = f"{np.median(nearest):.2g}" if n > 1 else "—"
    top = int(sizes.max()) if n else 0
    return judged(f"{n} zero-guess runs at rest, each with its own random review order, reach {len(sizes)} distinct "
                  f"limits (limits within {radius:.0e} of the largest weight counted as one), the most shared by "
                  f"{top} run{'s' if top != 1 else ''}; median distance to the nearest other limit {med} of the "
                  f"largest weight{warm}", REPRODUCED if ok else DIFFERS,
                  f"the zero-guess runs reach at least two limits apart by more than {LIMIT_TOLS:g} solver "
                  "tolerances of the largest weight (three decades left for the conditioning) and no one limit is "
                  "reached by half of the runs; the data repeat no order (NLGS is deterministic: one order, one "
                  "limit, by construction)", "s2-limit-depends-on-order", F3[0], F3[1])


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s2-warm-accelerates": (warm_accelerates_rest,),
    "s2-equilibrium-test": (equilibrium_test,),
    "s4-dimension-A": (fig3_dimension,),
    "s4-outlines": (fig3_outlines,),
    "s4-in-cones": (fig3_in_cones,),
    "s4-ghost-images": (fig3_ghosts,),
    "s4-denser-boundary": (fig3_boundary,),
    "s4-force-set": (fig3_exact,),
    "s2-review-orders": (fig3_review_orders,),
    "s2-limit-depends-on-order": (limit_depends_on_order,),
}
