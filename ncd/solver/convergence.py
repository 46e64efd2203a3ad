"""Convergence record of a run: is the iterate a solution in what the figure uses?

A small residual alone can leave grains moving, so a run is *converged* only when both
hold: its relative natural-map residual is ``<= tol`` (:mod:`ncd.solver.kernels`), and
the figure's observable has settled.  ``observe(impulse, vel, spin)`` returns a 1-D
array scaled to order one (a force over the weight, a speed over ``|g| h``); NLGS then
runs in chunks of ``check_every`` sweeps and ``observable_change`` is the largest change
over the last :data:`WINDOW` checks, over ``max(1, |observable|)``.  A converged run is
classified (:func:`classify`) as ``rest`` when its largest grain speed over ``|g| h`` is
``<= speed_tol``, ``motion`` otherwise (a partial collapse, the wedged disc falling): a
different outcome, never mixed into a cloud of rest states.  The chunks call the numba
drivers of :mod:`ncd.solver.kernels` from Python, so no Python function reaches a cached
kernel.
"""
import numpy as np

from ncd.solver.settings import CRITERIA, NLGSResult

OUTCOMES = {0: "unconverged", 1: "rest", 2: "motion"}
UNCONVERGED, REST, MOTION = 0, 1, 2
WINDOW = 4            # residual checks over which the observable must have settled
SPEED_TOL = 1e-8      # largest grain speed / (|g| h) of a state at rest


def observable_change(history):
    """Largest ``|o_j - o_last|_inf / max(1, |o_last|_inf)`` over the last WINDOW checks
    (inf until WINDOW values are known)."""
    if len(history) < WINDOW:
        return np.inf
    last = history[-1]
    scale = max(1.0, float(np.max(np.abs(last), initial=0.0)))
    return max(float(np.max(np.abs(o - last), initial=0.0)) for o in history[-WINDOW:]) / scale


def run_nlgs(iterate, data, order, status, scale, settings, observe=None):
    """Run an NLGS driver of :mod:`ncd.solver.kernels` (``iterate_discs`` or ``iterate_local``).

    Without ``observe`` the whole budget is one call.  With it, calls of
    ``check_every`` sweeps each, then ``observe()``; the run stops when the residual
    criterion holds and the observable has settled (``settings.observable_tol``).
    When the budget runs out, the iterate of smallest residual is restored
    (``settings.keep_best``).  Returns an :class:`ncd.solver.settings.NLGSResult` (impulse
    left to the caller: ``data`` holds it)."""
    imp = data[3] if len(data) == 4 else data[6]
    body = data[2] if len(data) == 4 else np.empty(0)
    keep = np.array([np.inf if settings.keep_best else -np.inf, np.inf, 0.0])
    best = (keep, np.empty_like(imp), np.empty_like(status), np.empty_like(body))
    crit = CRITERIA[settings.criterion]
    obs = np.nan
    if observe is None:
        sweeps, res, change, ok = iterate(data, order, status, scale, settings.tol, settings.max_sweeps,
                                          crit, settings.check_every, best + (0,))
    else:
        history, sweeps, ok = [], 0, False
        while sweeps < settings.max_sweeps:
            chunk = min(settings.check_every, settings.max_sweeps - sweeps)
            k, res, change, ok = iterate(data, order, status, scale, settings.tol, chunk, crit, chunk,
                                         best + (sweeps,))
            sweeps += int(k)
            history = history[-WINDOW + 1:] + [np.array(observe(), dtype=float).ravel()]
            obs = observable_change(history)
            if ok and obs <= settings.observable_tol:
                break
        ok = bool(ok and obs <= settings.observable_tol)
    best_sweep = 0
    if settings.keep_best and not ok and keep[0] < res:
        imp[:] = best[1]
        status[:] = best[2]
        body[:] = best[3]
        res, change, best_sweep = keep[0], keep[1], int(keep[2])
    return NLGSResult(None, status, int(sweeps), float(res), float(change), bool(ok),
                      observable_change=float(obs), best_sweep=best_sweep)


def max_speed(vel, spin, scene, h):
    """Largest ``|u_f|`` of the mobile grains (translation and ``r omega``) over ``|g| h``
    (over ``h`` alone without gravity)."""
    nm = scene.n_mobile
    if nm == 0:
        return 0.0
    v = np.asarray(vel)[:nm]
    w = np.asarray(spin)[:nm] * scene.radius[:nm]
    umax = max(float(np.max(np.hypot(v[:, 0], v[:, 1]))), float(np.max(np.abs(w))))
    g = float(np.linalg.norm(scene.gravity))
    return umax / ((g if g > 0 else 1.0) * h)


def classify(result, vel, spin, scene, h, speed_tol=SPEED_TOL, observable_tol=None, tol=None):
    """Outcome code (:data:`OUTCOMES`) of a run: 0 unconverged, 1 rest, 2 motion.

    Converged: ``result.converged`` (residual criterion of the run, or ``residual
    <= tol`` if ``tol`` is given) and, when the run observed something,
    ``observable_change <= observable_tol`` (default: already in ``converged``)."""
    ok = bool(result.converged) if tol is None else bool(result.residual <= tol)
    oc = getattr(result, "observable_change", np.nan)
    if observable_tol is not None and np.isfinite(oc):
        ok = ok and oc <= observable_tol
    elif observable_tol is not None and not np.isnan(oc):
        ok = False
    if not ok:
        return UNCONVERGED
    return REST if max_speed(vel, spin, scene, h) <= speed_tol else MOTION


def outcome_attrs():
    """CF attributes of an int8 ``outcome`` variable."""
    return {"units": "1", "long_name": "run outcome: converged at rest, converged in motion, or not",
            "flag_values": np.array(sorted(OUTCOMES), np.int8),
            "flag_meanings": " ".join(OUTCOMES[k] for k in sorted(OUTCOMES))}


MAX_SPEED_ATTRS = {"units": "1", "long_name": "largest grain speed / (|g| h)"}
