"""Time to tolerance of one step problem: plain NLGS, NLGS + finishing stage and
Anderson-accelerated NLGS (:mod:`ncd.anderson`) side by side (issue 13, item 2; the
benchmark ``bench_tolerance``).  Measurements, not tests."""
import time

import numpy as np

from .contacts import local_velocity
from .convergence import max_speed
from .finish import check_solution
from .nlgs import SolverSettings
from .stepper import solve_problem

METHODS = ("nlgs", "nlgs+finish", "anderson")
FIELDS = {"seconds": ("s", "wall time to reach the tolerance (or to give up)"),
          "residual": ("1", "relative natural-map residual reached"),
          "sweeps": ("1", "NLGS sweeps"),
          "converged": ("1", "residual <= tolerance (1) or not (0)"),
          "finish_rounds": ("1", "LP solves of the finishing stage"),
          "correction": ("1", "relative L1 size of the finishing projection (0: NLGS got there)"),
          "max_speed": ("1", "largest grain speed / (|g| h)"),
          "checked": ("1", "componentwise check of the contact law passed at 1e-9 (1) or not (0)")}


def time_to_tolerance(scene, problem, tols, handoff, max_sweeps, orders=(None,), check_every=10, log=None,
                      label=""):
    """Per review order (None: identity), method and tolerance: a run from the zero guess.
    Plain NLGS and the accelerated run (``accel="anderson"``, default memory) run to ``tol``;
    the finished run hands over at ``max(tol, handoff)`` and finishes to ``tol``
    (``finish="active_set"``).  Returns a dict of arrays (order, method, tol)."""
    shape = (len(orders), len(METHODS), len(tols))
    out = {k: np.zeros(shape) for k in FIELDS}
    c = problem.contacts
    g = float(np.linalg.norm(scene.gravity)) or 1.0
    for accel in ("none", "anderson"):                                                              # warm-up
        solve_problem(scene, problem, settings=SolverSettings(tol=1.0, max_sweeps=3, finish="active_set", accel=accel))
    for i, order in enumerate(orders):
        for j, method in enumerate(METHODS):
            for k, tol in enumerate(tols):
                settings = (SolverSettings(tol=tol, max_sweeps=max_sweeps, check_every=check_every,
                                           accel="anderson" if method == "anderson" else "none")
                            if method != "nlgs+finish" else
                            SolverSettings(tol=max(tol, handoff), max_sweeps=max_sweeps, check_every=check_every,
                                           finish="active_set", finish_tol=tol))
                t0 = time.perf_counter()
                r, vel, spin = solve_problem(scene, problem, None, order, settings)
                out["seconds"][i, j, k] = time.perf_counter() - t0
                U = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin,
                                   np.empty((c.n, 2))) + problem.bias
                chk = check_solution(r.impulse, U, c.mu, tol=1e-9, velocity_scale=g * problem.h)
                for key, v in (("residual", r.residual), ("sweeps", r.sweeps), ("converged", r.converged),
                               ("finish_rounds", r.finish_rounds), ("correction", r.finish_correction),
                               ("max_speed", max_speed(vel, spin, scene, problem.h)), ("checked", chk["ok"])):
                    out[key][i, j, k] = v
                if log is not None:
                    log.info("%s order %d, %s, tol %.0e: %.2f s, %d sweeps, residual %.2e, correction %.1e",
                             label, i, method, tol, out["seconds"][i, j, k], r.sweeps, r.residual,
                             r.finish_correction)
    return out
