"""Exploring the solutions of one step: ensembles of NLGS runs (Moreau 2005, section 2).

Each member of an ensemble is one NLGS run on the same core problem, started
from an initial guess (zero, warm, or drawn at random from a stated range) with
a review order (fixed, or a random permutation).  Its randomness comes only
from ``numpy.random.default_rng((member, root_seed))``, so a member gives the
same result whatever shard or process runs it.

The members of an ensemble run in parallel on ``threads`` threads (default:
numba's thread count, which :func:`ncd.pipeline.jobs.start` sets from the rule's
``threads``): the NLGS kernels release the GIL, every member runs serially on
its own copies of the velocities and impulses, so the results are identical
bit for bit whatever the thread count.
"""
import time
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from ncd.core import validate
from ncd.core.errors import InputError
from ncd.core.validate import integer, real, show
from ncd.dynamics.stepper import check_step_problem, initial_guess, solve_problem
from ncd.solver.convergence import SPEED_TOL, classify, max_speed
from ncd.solver.settings import SolverSettings, check_settings_arg

INIT_MODES = ("zero", "warm", "random")


def member_rng(member, root_seed):
    """The generator of one ensemble member."""
    return np.random.default_rng((int(member), int(root_seed)))


def random_guess(rng, mu, scale):
    """Impulses drawn uniformly in the Coulomb cone truncated at ``s_n <= scale``:
    ``s_n ~ U[0, scale]``, ``s_t ~ U[-mu s_n, mu s_n]`` (per contact ``mu``)."""
    sn = rng.uniform(0.0, 1.0, size=len(mu)) * scale
    st = rng.uniform(-1.0, 1.0, size=len(mu)) * mu * sn
    return np.column_stack([sn, st])


def shard_members(n_members, shard, n_shards, interleaved=False):
    """Members of shard ``shard`` (0-based) among ``n_shards``: a contiguous block, or with
    ``interleaved`` every ``n_shards``-th member from ``shard`` (for a table whose cost
    varies along it, so that each shard takes its share of every part)."""
    n_members = validate.integer("n_members", n_members, 0)
    n_shards = validate.integer("n_shards", n_shards, 1)
    shard = validate.integer("shard", shard, 0)
    if not (0 <= shard < n_shards):
        raise ValueError(f"shard {shard} is outside 0..{n_shards - 1}")
    if interleaved:
        return np.arange(shard, n_members, n_shards)
    bounds = np.linspace(0, n_members, n_shards + 1).round().astype(int)
    return np.arange(bounds[shard], bounds[shard + 1])


def run_parallel(task, n, threads=None, progress=None):
    """Call ``task(k)`` for ``k`` in ``range(n)`` on ``threads`` threads (default:
    ``numba.get_num_threads()``); ``progress(done, n)`` after each, in order.

    ``task`` must write its own outputs (disjoint per ``k``) and spend its time in
    GIL-free numba kernels; an exception in a task is raised here."""
    threads = numba.get_num_threads() if threads is None else int(threads)
    if threads < 1:
        raise ValueError(f"threads = {threads} must be >= 1")
    if threads == 1 or n <= 1:
        results = map(task, range(n))
        pool = None
    else:
        pool = ThreadPoolExecutor(max_workers=min(threads, n))
        results = pool.map(task, range(n))
    try:
        for done, _ in enumerate(results, 1):
            if progress is not None:
                progress(done, n)
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def explore(scene, problem, members, root_seed, init="zero", review="random", guess_scale=None,
            settings=SolverSettings(), progress=None, threads=None, observe=None, speed_tol=SPEED_TOL):
    """Run one NLGS per member on ``problem``; returns a dict of arrays stacked over members.

    ``init``: "zero", "warm" (the scene's previous impulses) or "random"
    (:func:`random_guess` with ``guess_scale``); ``review``: "fixed" or "random".
    ``progress(done, total)`` is called now and then; ``threads``: see :func:`run_parallel`.
    ``observe``: the figure's observable (:func:`ncd.dynamics.stepper.solve_problem`).  Each run is
    classified (:func:`ncd.solver.convergence.classify`): ``outcome`` 0 unconverged, 1 rest,
    2 motion (``max_speed`` above ``speed_tol``), with ``max_speed`` (largest grain
    speed over ``|g| h``).
    """
    members = check_explore_args(scene, problem, members, root_seed, init, review, guess_scale,
                                  settings, progress, threads)
    speed_tol = validate.real("speed_tol", speed_tol, 0.0, lo_open=True)
    if observe is not None and not callable(observe):
        raise InputError(f"observe = {observe!r} must be None or a callable (impulse, vel, spin) -> array")
    members = np.asarray(members, dtype=np.int64)
    n = problem.contacts.n
    nm = scene.n_mobile
    out = {
        "impulse": np.zeros((len(members), n, 2)),
        "vel": np.zeros((len(members), nm, 2)),
        "spin": np.zeros((len(members), nm)),
        "sweeps": np.zeros(len(members), np.int64),
        "residual": np.zeros(len(members)),
        "change": np.zeros(len(members)),
        "converged": np.zeros(len(members), bool),
        "outcome": np.zeros(len(members), np.int8),
        "max_speed": np.zeros(len(members)),
        "observable_change": np.zeros(len(members)),
        "finish_rounds": np.zeros(len(members), np.int64),
        "finish_correction": np.zeros(len(members)),
        "wall_time": np.zeros(len(members)),
    }
    warm = initial_guess(scene, problem, "warm") if init == "warm" else None

    def run(k):
        rng = member_rng(members[k], root_seed)
        order = rng.permutation(n) if review == "random" else None
        guess = warm if init == "warm" else (
            random_guess(rng, problem.contacts.mu, guess_scale) if init == "random" else None)
        t0 = time.perf_counter()
        result, vel, spin = solve_problem(scene, problem, guess, order, settings, observe)
        out["wall_time"][k] = time.perf_counter() - t0
        out["impulse"][k] = result.impulse
        out["vel"][k] = vel[:nm]
        out["spin"][k] = spin[:nm]
        out["sweeps"][k] = result.sweeps
        out["residual"][k] = result.residual
        out["change"][k] = result.change
        out["converged"][k] = result.converged
        out["outcome"][k] = classify(result, vel, spin, scene, problem.h, speed_tol)
        out["max_speed"][k] = max_speed(vel, spin, scene, problem.h)
        out["observable_change"][k] = result.observable_change
        out["finish_rounds"][k] = result.finish_rounds
        out["finish_correction"][k] = result.finish_correction

    run_parallel(run, len(members), threads, progress)
    return out


# ------------------------------------------------------------ argument checks
def check_explore_args(s, problem, members, root_seed, init, review, guess_scale, settings, progress, threads):
    """Arguments of :func:`ncd.dynamics.explore.explore`; returns ``members`` as int64."""
    check_step_problem(s, problem, full=True)
    members = np.asarray(members) if not isinstance(members, (str, bytes)) else np.asarray(None)
    if members.ndim != 1 or (members.size and members.dtype.kind not in "iu"):
        raise InputError(f"members must be a 1-D array of integers; got {members.dtype} {members.shape}")
    if members.size and members.dtype.kind == "u" and members.max() > np.iinfo(np.int64).max:
        raise InputError(f"members must be below 2**63; got {members.max()}")
    if members.size and members.min() < 0:
        raise InputError(f"members must be >= 0 (they seed default_rng); got {members.min()}")
    integer("root_seed", root_seed, 0)
    if not isinstance(init, str) or init not in INIT_MODES:
        raise InputError(f"init = {init!r} must be one of {INIT_MODES}")
    if not isinstance(review, str) or review not in ("fixed", "random"):
        raise InputError(f"review = {review!r} must be 'fixed' or 'random'")
    if init == "random" and guess_scale is None:
        raise InputError("init = 'random' needs guess_scale > 0, got None")
    if guess_scale is not None:
        real("guess_scale", guess_scale, 0.0, lo_open=True)
    check_settings_arg(settings)
    if progress is not None and not callable(progress):
        raise InputError(f"progress = {show(progress)} must be callable or None")
    if threads is not None:
        integer("threads", threads, 1)
    return members.astype(np.int64)
