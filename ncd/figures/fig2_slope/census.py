"""Figure 2, exactly: a census of the solutions of the investigated step (Moreau 2005, section 3).

NLGS from the zero guess reaches a few end points, which does not say how many solutions
the step has.  The census gathers exact solutions (each polished on its contact statuses,
:func:`ncd.solver.finish.project_statuses`) from three sources: the NLGS end points of the
ensemble and of random guesses, Lemke's method (:mod:`ncd.solver.lcp`) with several
covering vectors, and an enumeration of status patterns of the switching contacts
(:func:`enumerate_statuses`, :func:`ncd.shared.slope_analysis.status_patterns`).  Per
solution: its basin (which runs end on it) and its stability under perturbation.
"""
import time
from dataclasses import replace

import numpy as np
import xarray as xr
import yaml

from ncd.dynamics.explore import explore, run_parallel
from ncd.dynamics.stepper import prepare_step, solve_problem
from ncd.io.netcdf import provenance
from ncd.shared.slope import scene_at_step
from ncd.shared.slope_analysis import status_patterns, switching_contacts
from ncd.shared.step_solutions import StepSolutions
from ncd.solver.finish import check_solution, project_statuses
from ncd.solver.lcp import frictional_lcp, impulse_of_lcp, lemke
from ncd.solver.settings import SolverSettings

METHODS = ("nlgs", "lemke", "enumeration")


class Census:
    """Distinct exact solutions, each with the methods that found it."""

    def __init__(self, step, same_tol):
        self.step, self.same = step, same_tol * step.g
        self.impulse, self.accel, self.found = [], [], []

    def add(self, s, method, polish_tol):
        """Polish ``s``; keep it if it is a solution; returns its index or -1."""
        s, res = self.step.polish(s, tol=polish_tol)
        if res > polish_tol:
            return -1
        a = self.step.accel(s)
        for k, b in enumerate(self.accel):
            if np.abs(a - b).max() <= self.same:
                self.found[k].add(method)
                return k
        self.impulse.append(s)
        self.accel.append(a)
        self.found.append({method})
        return len(self.accel) - 1

    def nearest(self, accel, tol):
        """Index of the solution within ``tol`` (max norm) of each field, -1 if none."""
        out = np.full(len(accel), -1)
        A = np.array(self.accel)
        for r, a in enumerate(accel):
            d = np.abs(A - a[None]).reshape(len(A), -1).max(1)
            if d.min() <= tol:
                out[r] = int(np.argmin(d))
        return out


def enumerate_statuses(step, census, max_patterns, ptol, rng, rounds=4, gate=1e-3):
    """Solve the step on the patterns of :func:`status_patterns`, round after round
    while new solutions appear.  Each pattern is solved on its statuses (minimum-norm
    projection from the solution nearest in status) and, when the result's residual
    is at most ``gate``, polished (statuses re-read) and added if exact.  Returns
    ``(census indices per pattern (-1: none), switching contacts of the first round,
    patterns per round, clusters per round)``."""
    found, first_sw, n_per_round, n_clusters, tried = [], None, [], [], set()
    contacts = step.problem.contacts
    for _ in range(rounds):
        n0 = len(census.impulse)
        st = np.array([step.status(s) for s in census.impulse], np.int8)
        pats, sw, ncl = status_patterns(st, contacts, step.nm, max_patterns, rng)
        first_sw = sw if first_sw is None else first_sw
        pats = [p for p in pats if p.tobytes() not in tried]
        n_per_round.append(len(pats))
        n_clusters.append(ncl)
        # the projections of a round are independent (each from a solution known at the
        # round's start): made side by side, then added to the census in pattern order
        starts = list(census.impulse)
        projected = [None] * len(pats)

        def project(k, pats=pats, st=st, sw=sw, starts=starts, projected=projected):
            base = int(np.argmin((st[:, sw] != pats[k][sw]).sum(1)))
            projected[k] = project_statuses(step.W, step.q.ravel(), step.mu, starts[base], pats[k])
        run_parallel(project, len(pats))
        for p, s in zip(pats, projected):
            tried.add(p.tobytes())
            found.append(census.add(s, "enumeration", ptol) if step.residual(s) <= gate else -1)
        if len(census.impulse) == n0:
            break
    return found, (first_sw if first_sw is not None else np.zeros(0, np.int64)), n_per_round, n_clusters


def nlgs_end_points(ens, measures):
    """Impulses of one run per distinct NLGS end point of the ensemble (tightest tolerance)."""
    labels = measures["solution_label"].values.ravel()
    imp = np.stack([ens.impulse_n.values, ens.impulse_t.values], -1).reshape(-1, ens.sizes["contact"], 2)
    return [imp[int(np.nonzero(labels == k)[0][0])] for k in range(int(labels.max()) + 1)]


def random_runs(scene, problem, s_scale, cc):
    """The census's NLGS runs from random guesses, to ``random_tol``, and the plain-NLGS check.

    With ``random_local_exact`` the runs make local exact solves where the residual stalls
    (:mod:`ncd.solver.local_exact`): plain NLGS needs several times the sweeps to 1e-8 from a
    random guess, and the census asks only which solution a run ends on.  The first
    ``random_plain_check`` members are also run by plain NLGS (same guesses and review
    orders), the check that both routes end on the same solution (:func:`_plain_check`).
    Returns ``(runs, plain)``, ``plain`` None when there is no check."""
    members = np.arange(cc["random_runs"])
    local = bool(cc["random_local_exact"])
    settings = SolverSettings(tol=cc["random_tol"], max_sweeps=cc["max_sweeps"], check_every=10, local_exact=local)
    rnd = explore(scene, problem, members, cc["root_seed"], init="random", guess_scale=s_scale, settings=settings)
    n_check = min(int(cc["random_plain_check"]), len(members)) if local else 0
    if n_check == 0:
        return rnd, None
    plain = explore(scene, problem, members[:n_check], cc["root_seed"], init="random", guess_scale=s_scale,
                    settings=replace(settings, local_exact=False))
    return rnd, plain


def end_labels(step, census, runs, basin_tol):
    """Accelerations of the end points of :func:`ncd.dynamics.explore.explore` ``runs`` and
    the census solution each ends on (-1: none within ``basin_tol``, -2: not converged)."""
    acc = np.array([step.accel(s) for s in runs["impulse"]])
    label = census.nearest(acc, basin_tol)
    label[~runs["converged"]] = -2
    return acc, label


def _plain_check(step, census, plain, acc_rnd, label_rnd, basin_tol):
    """Plain NLGS against local exact solves on the checked members: how many end on the
    same census solution (both converged), and the largest acceleration distance (/ |g|)."""
    if plain is None:
        return {"runs": 0, "same": 0, "distance": np.nan}
    k = len(plain["impulse"])
    acc, label = end_labels(step, census, plain, basin_tol)
    same = (label == label_rnd[:k]) & (label >= 0)
    return {"runs": k, "same": int(same.sum()), "distance": float(np.abs(acc - acc_rnd[:k]).max() / step.g)}


def run_census(traj, ens, measures, cfg, log=None):
    """The census of the investigated step: a dict of arrays and counts (see :func:`census_dataset`)."""
    cc = cfg["census"]
    scene = scene_at_step(traj, cfg)
    problem = prepare_step(scene, float(traj.attrs["h"]))
    step = StepSolutions(scene, problem)
    census = Census(step, cc["same_tol"])
    ptol = cc["polish_tol"]
    times = {}
    t0 = time.perf_counter()
    per_method = {m: set() for m in METHODS}
    for s in nlgs_end_points(ens, measures):
        k = census.add(s, "nlgs", ptol)
        if k >= 0:
            per_method["nlgs"].add(k)
    # random-guess NLGS runs
    s_scale = float(np.abs(np.array(census.impulse)[..., 0]).max()) if census.impulse else 1.0
    rnd, plain_check = random_runs(scene, problem, s_scale, cc)
    for s in rnd["impulse"][rnd["converged"]]:
        k = census.add(s, "nlgs", ptol)
        if k >= 0:
            per_method["nlgs"].add(k)
    times["nlgs"] = time.perf_counter() - t0
    # Lemke with several covering vectors
    t0 = time.perf_counter()
    M, b = frictional_lcp(step.W.toarray(), step.q, step.mu)
    lemke_info = []
    pivoted = [None] * cc["lemke_runs"]

    def pivot(j):      # the runs side by side (Lemke's pivots release the GIL), added in order
        d = np.ones(len(b)) if j == 0 else 10.0 ** np.random.default_rng((j, cc["root_seed"])).uniform(
            -cc["lemke_decades"], cc["lemke_decades"], len(b))
        pivoted[j] = lemke(M, b, covering=d)
    run_parallel(pivot, cc["lemke_runs"])
    for j, (x, info) in enumerate(pivoted):
        lemke_info.append(info)
        k = census.add(impulse_of_lcp(x, step.mu), "lemke", ptol) if x is not None else -1
        if k >= 0:
            per_method["lemke"].add(k)
        if log is not None:
            log.info("Lemke %d: %s after %d pivots, LCP residual %.2g -> solution %d", j, info["status"],
                     info["pivots"], info["residual"], k)
    times["lemke"] = time.perf_counter() - t0
    # status patterns combining the changes between the solutions found
    t0 = time.perf_counter()
    found, switching, n_patterns, n_clusters = enumerate_statuses(
        step, census, cc["max_patterns"], ptol, np.random.default_rng((cc["root_seed"], 1)),
        rounds=cc["enumeration_rounds"], gate=cc["pattern_gate"])
    per_method["enumeration"].update(k for k in found if k >= 0)
    times["enumeration"] = time.perf_counter() - t0
    # basins: the ensemble's runs and the random-guess runs
    tight = ens.isel(tol=-1)
    acc = np.stack([tight.accel_x.values, tight.accel_y.values], -1)          # init, run, disc, 2
    basin_tol = cc["basin_tol"] * step.g
    label_ens = np.stack([census.nearest(acc[i], basin_tol) for i in range(acc.shape[0])])
    ok_ens = tight.converged.values.astype(bool)
    acc_rnd, label_rnd = end_labels(step, census, rnd, basin_tol)
    check = _plain_check(step, census, plain_check, acc_rnd, label_rnd, basin_tol)
    # stability under perturbation
    n_sol = len(census.accel)
    returns = np.zeros(n_sol, np.int64)
    pset = SolverSettings(tol=cc["perturb_tol"], max_sweeps=cc["max_sweeps"], check_every=10)
    back = np.zeros((n_sol, cc["perturb_runs"]), bool)

    def perturb(kj):
        k, j = divmod(kj, cc["perturb_runs"])
        s = census.impulse[k]
        rng = np.random.default_rng((k, j, cc["root_seed"]))
        guess = s + cc["noise"] * np.abs(s).max() * rng.standard_normal(s.shape)
        res, vel, _ = solve_problem(scene, problem, guess, rng.permutation(len(s)), pset)
        a = (vel[:step.nm] - problem.vel_initial[:step.nm]) / step.h
        back[k, j] = bool(res.converged and np.abs(a - census.accel[k]).max() <= basin_tol)
    run_parallel(perturb, n_sol * cc["perturb_runs"])
    returns[:] = back.sum(axis=1)
    # the straight segment between the two most visited NLGS solutions
    seg_t = np.array(cc["segment_points"])
    counts = np.array([(label_ens == k).sum() for k in range(n_sol)])
    pair = np.argsort(-counts, kind="stable")[:2]
    seg = np.full(len(seg_t), np.nan)
    if n_sol >= 2:
        s0, s1 = census.impulse[pair[0]], census.impulse[pair[1]]
        seg = np.array([step.residual((1 - t) * s0 + t * s1) for t in seg_t])
    checks = [check_solution(s, step.U(s), step.mu) for s in census.impulse]
    return {"step": step, "census": census, "per_method": per_method, "label_ens": label_ens, "ok_ens": ok_ens,
            "label_rnd": label_rnd, "returns": returns, "segment_t": seg_t, "segment_residual": seg,
            "segment_pair": pair, "switching": switching_contacts([step.status(s) for s in census.impulse]),
            "switching_before": switching, "n_patterns": n_patterns, "n_clusters": n_clusters,
            "lemke_info": lemke_info, "plain_check": check,
            "checks": checks, "times": times, "random_scale": s_scale,
            "statuses": np.array([step.status(s) for s in census.impulse])}


def census_dataset(traj, ens, measures, cfg, log=None):
    """census.nc: the distinct exact solutions of the investigated step, how each was
    found, its basin among the NLGS runs, its stability and the chosen grain's acceleration."""
    out = run_census(traj, ens, measures, cfg, log)
    step, census = out["step"], out["census"]
    n = len(census.accel)
    grain = int(measures.attrs["grain"])
    A = np.array(census.accel)
    S = np.array(census.impulse)
    found = np.array([[m in f for m in METHODS] for f in census.found], np.int8).reshape(n, len(METHODS))
    inits = list(ens.init.values)
    basin = {f"n_{init}": ("solution", np.array([int(((out["label_ens"][i] == k) & out["ok_ens"][i]).sum())
                                                  for k in range(n)]),
                           {"units": "1", "long_name": f"{init} NLGS runs (tightest tolerance) ending on the solution"})
             for i, init in enumerate(inits)}
    cc = cfg["census"]
    flag = {"units": "1", "flag_values": np.array([0, 1], np.int8), "flag_meanings": "no yes"}
    ds = xr.Dataset(
        {
            "accel_x": (("solution", "disc"), A[..., 0], {"units": "m s-2", "long_name": "grain acceleration (u_f - u_i)/h, x"}),
            "accel_y": (("solution", "disc"), A[..., 1], {"units": "m s-2", "long_name": "grain acceleration (u_f - u_i)/h, y"}),
            "impulse_n": (("solution", "contact"), S[..., 0], {"units": "N s", "long_name": "normal impulse (minimum-norm representative)"}),
            "impulse_t": (("solution", "contact"), S[..., 1], {"units": "N s", "long_name": "tangential impulse (minimum-norm representative)"}),
            "status": (("solution", "contact"), out["statuses"], {"units": "1", "long_name": "contact status",
                                                                 "flag_values": np.arange(4, dtype=np.int8),
                                                                 "flag_meanings": "no_contact stick slide_forward slide_backward"}),
            "residual": ("solution", np.array([step.residual(s) for s in S]), {"units": "1", "long_name": "relative natural-map residual of the polished solution"}),
            "law_violation": ("solution", np.array([max(v for k, v in c.items() if k != "ok") for c in out["checks"]]),
                              {"units": "1", "long_name": "largest componentwise violation of the Signorini-Coulomb law (relative)"}),
            **{f"by_{m}": ("solution", found[:, j], {**flag, "long_name": f"found by {m}"}) for j, m in enumerate(METHODS)},
            **basin,
            "n_random": ("solution", np.array([int((out["label_rnd"] == k).sum()) for k in range(n)]),
                         {"units": "1", "long_name": "random-guess NLGS runs ending on the solution"}),
            "returns": ("solution", out["returns"], {"units": "1", "long_name": f"perturbed restarts (of {cc['perturb_runs']}) returning to the solution"}),
            "grain_accel_x": ("solution", A[:, grain, 0], {"units": "m s-2", "long_name": "acceleration of the chosen grain, x"}),
            "grain_accel_y": ("solution", A[:, grain, 1], {"units": "m s-2", "long_name": "acceleration of the chosen grain, y"}),
            "n_switched": ("solution", (out["statuses"] != out["statuses"][0]).sum(1) if n else np.zeros(0, int),
                           {"units": "1", "long_name": "contacts whose status differs from solution 0"}),
            "n_grains_differ": ("solution", (np.hypot(*(A - A[:1]).transpose(2, 0, 1)) > cc["grain_differ"] * step.g).sum(1) if n else np.zeros(0, int),
                                {"units": "1", "long_name": f"grains whose acceleration differs from solution 0 by more than {cc['grain_differ']} |g|"}),
            "segment_residual": ("segment_t", out["segment_residual"], {"units": "1", "long_name": "residual of (1-t) s_a + t s_b between the two most visited NLGS solutions"}),
            "switching": ("switching_contact", out["switching"], {"units": "1", "long_name": "contacts whose status differs between two of the solutions"}),
        },
        coords={"solution": np.arange(n), "disc": np.arange(step.nm), "contact": np.arange(step.problem.contacts.n),
                "segment_t": out["segment_t"], "switching_contact": np.arange(len(out["switching"]))},
        attrs=provenance(cfg["census"], grain=grain, g=step.g, n_solutions=n,
                         **{f"n_{m}": len(out["per_method"][m]) for m in METHODS},
                         n_patterns=int(sum(out["n_patterns"])),
                         patterns_per_round=np.array(out["n_patterns"], np.int64),
                         clusters_per_round=np.array(out["n_clusters"], np.int64),
                         n_switching_before=len(out["switching_before"]), segment_pair=out["segment_pair"].astype(np.int64),
                         random_guess_scale=out["random_scale"],
                         random_converged=int((out["label_rnd"] != -2).sum()),
                         random_plain_runs=out["plain_check"]["runs"], random_plain_same=out["plain_check"]["same"],
                         random_plain_distance=out["plain_check"]["distance"],
                         lemke_status="; ".join(f"{i['status']} after {i['pivots']} pivots" for i in out["lemke_info"])),
    )
    for k, (u, ln) in {"solution": ("1", "exact solution index"), "disc": ("1", "grain index"),
                       "contact": ("1", "contact index"), "segment_t": ("1", "position on the segment"),
                       "switching_contact": ("1", "switching contact index")}.items():
        ds[k].attrs.update(units=u, long_name=ln)
    if log is not None:
        log.info("census: %d distinct solutions (nlgs %d, lemke %d, enumeration %d; %d patterns), seconds %s",
                 n, *(len(out["per_method"][m]) for m in METHODS), sum(out["n_patterns"]),
                 {k: round(v, 1) for k, v in out["times"].items()})
    return ds


def cloud_text(c, grain, tol, line_ratio):
    """Markdown: what the chosen grain's cloud is, from
    :func:`ncd.shared.slope_analysis.cloud_against_census` (re-exported here)."""
    g = c["g"]
    head = (f"At {tol:.0e}, {c['n_converged']} of the {c['n_runs']} zero-guess runs converged; the cloud of "
            f"grain {grain} has RMS extents {c['major']:.2g} and {c['minor']:.2g} m/s² (minor/major "
            f"{c['ratio']:.2g}). The census places {c['n_labelled']} of these runs on "
            f"{len(c['visited'])} exact solution(s) ("
            + ", ".join(f"solution {k}: {n} runs" for k, n in zip(c["visited"], c["counts"]))
            + f"); the runs lie within {c['rms_offset']:.1e} m/s² RMS ({c['rms_offset'] / g:.1e} $g$, at most "
            f"{c['max_offset'] / g:.1e} $g$) of their solutions: that is the iteration error left at this "
            "tolerance, and it bounds how far the cloud's axes can differ from those of the solutions' points ")
    if len(c["visited"]) <= 1:
        return head + (f"(here one point). The cloud is **iteration error around one of the census's "
                       f"{c['n_solutions']} exact solution(s)**, not a line of solutions: its shape (minor/major "
                       f"{c['ratio']:.2g}) is that of the unfinished iteration.")
    shape = ("a segment" if len(c["visited"]) == 2 else
             ("a line" if c["census_minor"] < line_ratio * c["census_major"] else "not a line"))
    return head + (f"(RMS extents {c['census_major']:.2g} and {c['census_minor']:.2g} m/s²). The cloud is "
                   f"**{len(c['visited'])} of the census's {c['n_solutions']} exact solutions, {shape}**, blurred "
                   "by the iteration error.")


def _plain_text(a):
    """The random runs' route and its plain-NLGS check, for :func:`census_text`."""
    runs = int(a.get("random_plain_runs", 0))
    if runs == 0:
        return ""
    return (f", with local exact solves where NLGS stalls; {int(a['random_plain_same'])} of {runs} of them rerun by "
            f"plain NLGS end on the same solution, accelerations at most {float(a['random_plain_distance']):.0e} |g| apart")


def census_text(ds):
    """Markdown from census.nc: how many exact solutions each method found, and a table
    of the solutions (how found, basins, stability, the chosen grain's acceleration)."""
    a = ds.attrs
    n = ds.sizes["solution"]
    g = float(a["g"])
    head = (f"The census finds **{n} distinct exact solutions** of the step (relative natural-map residual "
            f"at most {float(ds.residual.max()):.0e}, largest componentwise violation of the contact law "
            f"{float(ds.law_violation.max()):.0e}): {a['n_nlgs']} among the NLGS end points (zero-guess, "
            f"warm-start and {a['random_converged']} converged random-guess runs{_plain_text(a)}), {a['n_lemke']} by Lemke's "
            f"method ({a['lemke_status']}), {a['n_enumeration']} by the enumeration of "
            f"{a['n_patterns']} status patterns (per round: "
            f"{', '.join(str(int(v)) for v in np.atleast_1d(a['patterns_per_round']))}; the switching contacts, "
            f"{ds.sizes['switching_contact']} in the end, in "
            f"{', '.join(str(int(v)) for v in np.atleast_1d(a['clusters_per_round']))} clusters). ")
    seg = ds.segment_residual.values
    pair = np.atleast_1d(a["segment_pair"])
    if n >= 2 and np.all(np.isfinite(seg)):
        verdict = ("holds no solution at these points" if seg.min() > 1e-8 else
                   "comes close to a solution at some of these points")
        head += (f"The straight segment between the two solutions most visited by the ensemble ({pair[0]} and "
                 f"{pair[1]}), sampled at t = {', '.join(f'{t:g}' for t in ds.segment_t.values)}, {verdict}: "
                 f"relative residual {seg.min():.1e} to {seg.max():.1e}.")
    inits = [v for v in ds.data_vars if v.startswith("n_") and v not in ("n_random", "n_switched", "n_grains_differ")]
    cols = ["solution", "found by"] + [f"{v[2:]} runs" for v in inits] + [
        "random runs", "returns after 1e-9 noise", "grain accel. (m/s²)", "contacts switched", "grains differ"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for k in range(n):
        by = ", ".join(m for m in METHODS if int(ds[f"by_{m}"][k]))
        lines.append("| " + " | ".join([str(k), by] + [str(int(ds[v][k])) for v in inits] + [
            str(int(ds.n_random[k])), f"{int(ds.returns[k])}/{yaml_safe(a, 'perturb_runs', '?')}",
            f"({float(ds.grain_accel_x[k]):.3f}, {float(ds.grain_accel_y[k]):.3f})", str(int(ds.n_switched[k])),
            str(int(ds.n_grains_differ[k]))]) + " |")
    tail = (f"\n\n*grains differ*: acceleration differs from solution 0 by more than "
            f"{float(yaml_safe(a, 'grain_differ', 0.01)):g} $|g|$ ($|g|$ = {g:.2f} m/s²).")
    return head + "\n\n" + "\n".join(lines) + tail


def yaml_safe(attrs, key, default):
    """A census config value from the provenance YAML of census.nc."""
    return yaml.safe_load(attrs.get("config_yaml", "{}")).get(key, default)
