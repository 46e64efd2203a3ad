"""Time to tolerance of one step problem: plain NLGS, NLGS + finishing stage,
Anderson-accelerated NLGS (:mod:`ncd.solver.anderson`) and both with local exact solves
where the residual stalls (:mod:`ncd.solver.local_exact`), side by side (the benchmark
``bench_tolerance``).  Measurements, not tests.
"""
import time

import numpy as np

from ncd.core.contacts import local_velocity
from ncd.dynamics.stepper import solve_problem
from ncd.solver.convergence import max_speed
from ncd.solver.finish import check_solution
from ncd.solver.lcp import lemke
from ncd.solver.settings import SolverSettings

METHODS = ("nlgs", "nlgs+finish", "anderson", "nlgs+local", "anderson+local")
FIELDS = {"seconds": ("s", "wall time to reach the tolerance (or to give up)"),
          "residual": ("1", "relative natural-map residual reached"),
          "sweeps": ("1", "NLGS sweeps"),
          "converged": ("1", "residual <= tolerance (1) or not (0)"),
          "finish_rounds": ("1", "LP solves of the finishing stage"),
          "correction": ("1", "relative L1 size of the finishing projection (0: NLGS got there)"),
          "local_solves": ("1", "local exact solves (Lemke) where the residual stalled"),
          "max_speed": ("1", "largest grain speed / (|g| h)"),
          "checked": ("1", "componentwise check of the contact law passed at 1e-9 (1) or not (0)"),
          "gap_to_nlgs": ("1", "largest |u_f - u_f of plain NLGS| / (|g| h), same order and tolerance: "
                               "0 on plain NLGS's own solution")}


def settings_of(method, tol, handoff, max_sweeps, check_every):
    """The :class:`SolverSettings` of ``method`` (one of :data:`METHODS`) run to ``tol``."""
    if method == "nlgs+finish":
        return SolverSettings(tol=max(tol, handoff), max_sweeps=max_sweeps, check_every=check_every,
                              finish="active_set", finish_tol=tol)
    return SolverSettings(tol=tol, max_sweeps=max_sweeps, check_every=check_every,
                          accel="anderson" if method.startswith("anderson") else "none",
                          local_exact=method.endswith("+local"))


def time_to_tolerance(scene, problem, tols, handoff, max_sweeps, orders=(None,), check_every=10, log=None,
                      label="", guess=None):
    """Per review order (None: identity), method and tolerance: a run from ``guess``
    (None: zero).  Plain NLGS, the accelerated run (``accel="anderson"``, default memory)
    and both with local exact solves (``local_exact=True``) run to ``tol``; the finished
    run hands over at ``max(tol, handoff)`` and finishes to ``tol`` (``finish="active_set"``).
    Returns a dict of arrays (order, method, tol)."""
    shape = (len(orders), len(METHODS), len(tols))
    out = {k: np.zeros(shape) for k in FIELDS}
    c = problem.contacts
    g = float(np.linalg.norm(scene.gravity)) or 1.0
    for accel in ("none", "anderson"):                                                              # warm-up
        solve_problem(scene, problem, settings=SolverSettings(tol=1.0, max_sweeps=3, finish="active_set", accel=accel))
        solve_problem(scene, problem, settings=SolverSettings(tol=1.0, max_sweeps=3, accel=accel, local_exact=True))
    lemke(np.eye(2), np.array([-1.0, 1.0]))                                                         # its kernel too
    plain = {}
    for i, order in enumerate(orders):
        for j, method in enumerate(METHODS):
            for k, tol in enumerate(tols):
                settings = settings_of(method, tol, handoff, max_sweeps, check_every)
                start = None if guess is None else guess.copy()
                t0 = time.perf_counter()
                r, vel, spin = solve_problem(scene, problem, start, order, settings)
                out["seconds"][i, j, k] = time.perf_counter() - t0
                U = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin,
                                   np.empty((c.n, 2))) + problem.bias
                chk = check_solution(r.impulse, U, c.mu, tol=1e-9, velocity_scale=g * problem.h)
                for key, v in (("residual", r.residual), ("sweeps", r.sweeps), ("converged", r.converged),
                               ("finish_rounds", r.finish_rounds), ("correction", r.finish_correction),
                               ("local_solves", r.local_solves),
                               ("max_speed", max_speed(vel, spin, scene, problem.h)), ("checked", chk["ok"])):
                    out[key][i, j, k] = v
                u = np.column_stack([vel, spin * scene.radius])[:scene.n_mobile]
                plain.setdefault((i, k), u)                                   # METHODS[0] is plain NLGS
                out["gap_to_nlgs"][i, j, k] = np.abs(u - plain[(i, k)]).max(initial=0.0) / (g * problem.h)
                if log is not None:
                    log.info("%s order %d, %s, tol %.0e: %.3f s, %d sweeps, residual %.2e, correction %.1e, "
                             "%d local solves", label, i, method, tol, out["seconds"][i, j, k], r.sweeps,
                             r.residual, r.finish_correction, r.local_solves)
    return out
