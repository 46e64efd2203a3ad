"""Fuzz test of the public API (issue 14, item 3): random malformed calls never
crash, hang or return NaN.

A seeded generator (``default_rng((batch, ROOT))``, no test order dependence)
builds, per entry point, ``CALLS`` calls from a valid baseline (small random
scenes: overlapping discs, mass ratios up to 1e12, periodic or walled, obstacle
discs; random SPD, indefinite or non-symmetric ``W``; empty problems) and spoils
zero to three arguments: wrong shapes and dtypes, NaN/inf, huge and tiny values,
out-of-range indices and non-permutations, corrupted scene or problem fields.

Every call must end in one of

* a result whose impulses, velocities and forces are finite and whose floats
  are not NaN (``observable_change`` excepted: NaN there means "not observed");
* :class:`ncd.InputError` or :class:`ncd.SimulationError` with a message.

The batches run in subprocesses (a few entry points each, to amortise the numba
import; two at a time), so a segfault or abort is a test failure naming the last call, not a
dead runner; each subprocess has a timeout and every solve a bounded sweep
budget (``max_sweeps <= 300``, so no hang).  The subprocesses run with
``NUMBA_BOUNDSCHECK=1`` and their own ``NUMBA_CACHE_DIR`` (a temporary
directory, so that kernels compiled without bounds checks are not loaded): an
out-of-range index inside a kernel is then an ``IndexError`` (a failure here)
instead of memory corruption.  Compiling the kernels with bounds checks costs
about a minute, paid once by the first batch; the whole test takes about two to
three minutes on two loaded cores (see the report of issue 14).
"""
import json
import os
import subprocess
import sys
import traceback
from pathlib import Path

import numpy as np
import pytest

ROOT = 14                 # root seed of the fuzz generator
CALLS = 1000              # calls per entry point
BATCHES = {
    "scene": ("make_scene", "detect_contacts", "kinetic_energy", "SolverSettings"),
    "step": ("prepare_step", "step", "equilibrium_test"),
    "solve": ("solve_problem", "solve_discs", "explore"),
    "local": ("solve_local", "solve_single_contact_py", "project_cone"),
}
TIMEOUT = 600             # seconds per batch (compilation included)


# ------------------------------------------------------------------ generators
BAD_SCALARS = [np.nan, np.inf, -np.inf, -1.0, 0.0, -0.0, 1e308, -1e308, 1e-308, 1e300, -1e-300, 1.5, 2,
               True, None, "0.5", [0.5], np.array([1.0, 2.0]), 1 + 1j, np.float32(0.3), np.int64(3), 10**30]


def bad_scalar(rng):
    return BAD_SCALARS[rng.integers(len(BAD_SCALARS))]


def spoil_array(rng, arr):
    """A malformed variant of ``arr`` (shape, dtype, values or type)."""
    try:
        arr = np.array(arr, dtype=float)
    except (TypeError, ValueError):       # already spoiled: keep it
        return arr
    k = rng.integers(16)
    if k == 0:
        return arr.T.copy() if arr.ndim == 2 else arr[:-1]
    if k == 1:
        return arr[:-1] if len(arr) else np.zeros(3)
    if k == 2:
        return np.concatenate([arr, arr[:1]]) if len(arr) else np.ones((1,) + arr.shape[1:])
    if k == 3:
        return arr.ravel()
    if k == 4:
        return arr[None]
    if k == 5:
        return np.zeros((0,) + arr.shape[1:])
    if k in (6, 7, 8) and arr.size:
        out = arr.copy()
        out.flat[rng.integers(arr.size)] = [np.nan, np.inf, -np.inf][k - 6]
        return out
    if k == 9:
        return arr * 1e300
    if k == 10:
        return arr * 1e-300
    if k == 11:
        return arr.astype(str)
    if k == 12:
        return arr.astype(bool)
    if k == 13:
        return arr.tolist() + [[1.0]] if arr.ndim == 2 else arr.tolist() + [[1.0, 2.0]]
    if k == 14:
        return None if rng.random() < 0.5 else "array"
    return np.column_stack([arr, arr]) if arr.ndim == 2 else arr.reshape(-1, 1)


def spoil_order(rng, n):
    k = rng.integers(9)
    base = rng.permutation(n)
    if k == 0:
        return [0, 1, 10**6][: max(n, 1)] if n <= 3 else np.concatenate([base[:-1], [10**6]])
    if k == 1:
        return np.zeros(n, int) if n else [0]
    if k == 2:
        return base.astype(float)
    if k == 3:
        return np.concatenate([base, [0]])
    if k == 4:
        return base[:-1]
    if k == 5:
        return -1 - base
    if k == 6:
        return base.astype(np.uint64) + np.uint64(2**63)
    if k == 7:
        return [str(i) for i in base]
    return base.reshape(1, -1)


def settings_kwargs(rng):
    return dict(tol=float(10.0 ** rng.uniform(-12, -4)), max_sweeps=int(rng.integers(1, 300)),
                check_every=int(rng.integers(1, 5)), criterion=["residual", "change"][rng.integers(2)])


def settings(rng):
    import ncd
    return ncd.SolverSettings(**settings_kwargs(rng))


def scene_kwargs(rng):
    """A random valid-looking scene: overlaps allowed, mass ratios up to 1e12."""
    n = int(rng.integers(1, 7))
    r = rng.uniform(0.2, 0.6, n)
    x = np.cumsum(2 * r) - r + rng.uniform(-0.3, 0.3, n)          # may overlap
    y = r * rng.uniform(0.9, 1.6, n)
    kw = dict(pos=np.column_stack([x, y]), radius=r if rng.random() < 0.5 else 0.4,
              density=10.0 ** rng.uniform(0, 12, n) if rng.random() < 0.5 else 1.0,
              walls=[((0.0, 0.0), (0.0, 1.0))], mu=float(rng.choice([0.0, 0.3, 1.0, 10.0])),
              e_n=float(rng.choice([0.0, 0.5, 1.0])), overlap_tolerance=3.0,
              vel=rng.normal(size=(n, 2)) if rng.random() < 0.3 else None)
    if rng.random() < 0.3:
        kw["obstacle_pos"] = np.column_stack([x[:1] + 1.0, [-0.2]])
        kw["obstacle_radius"] = 0.4
    if rng.random() < 0.2:
        kw["period"] = float(2 * r.sum() + 10.0)
    return kw


def make_scene(rng):
    import ncd
    return ncd.make_scene(**scene_kwargs(rng))


def spoil_scene(rng, s):
    """Corrupt one field of a built scene, as a user editing it by hand might."""
    field = ["pos", "vel", "spin", "angle", "radius", "inv_mass", "inv_inertia", "mass", "wall_point",
             "wall_normal", "gravity", "n_mobile", "mu", "e_n", "period", "prev_keys"][rng.integers(16)]
    if field == "n_mobile":
        s.n_mobile = [0, s.n_disc + 1, 1.5, -1][rng.integers(4)]
    elif field in ("mu", "e_n", "period"):
        setattr(s, field, bad_scalar(rng))
    elif field == "prev_keys":
        s.prev_keys, s.prev_impulse = np.arange(3), np.zeros((int(rng.integers(0, 6)), 2))
    else:
        setattr(s, field, spoil_array(rng, getattr(s, field)))
    return s


def local_problem(rng):
    n = int(rng.integers(0, 6))
    A = rng.normal(size=(2 * n, 2 * n))
    kind = rng.integers(4)
    W = A @ A.T + 0.1 * np.eye(2 * n)
    if kind == 1:
        W = A + A.T                       # indefinite
    elif kind == 2:
        W = W + 0.3 * (A - A.T)           # non-symmetric
    q = rng.normal(size=2 * n)
    return W, q, float(rng.choice([0.0, 0.5, 2.0]))


# ------------------------------------------------------------------ one call per entry point
def call(entry, rng):
    """Draw and run one call of ``entry``; returns its result."""
    import scipy.sparse as sp

    import ncd
    from ncd.explore import explore
    bad = rng.random(3) < 0.4             # which argument groups to spoil
    if entry == "make_scene":
        kw = scene_kwargs(rng)
        for _ in range(int(rng.integers(0, 3))):
            key = list(kw)[rng.integers(len(kw))] if rng.random() < 0.9 else "pos"
            v = kw[key]
            kw[key] = spoil_array(rng, v) if isinstance(v, np.ndarray) else bad_scalar(rng)
        if rng.random() < 0.05:
            kw["pos"] = np.zeros((0, 2))
        return ncd.make_scene(**kw)
    if entry == "SolverSettings":
        kw = settings_kwargs(rng)
        key = list(kw)[rng.integers(len(kw))]
        kw[key] = bad_scalar(rng) if rng.random() < 0.8 else "energy"
        return ncd.SolverSettings(**kw)
    if entry in ("project_cone", "solve_single_contact_py"):
        args = [rng.normal(), rng.normal(), abs(rng.normal())]
        if entry == "solve_single_contact_py":
            W, q, mu = local_problem(rng)
            args = [W[:2, :2] if len(W) else np.eye(2), q[:2] if len(q) else [-1.0, 0.0], mu]
            if bad[0]:
                args[0] = spoil_array(rng, args[0])
            if bad[1]:
                args[1] = spoil_array(rng, args[1])
            if bad[2]:
                args[2] = bad_scalar(rng)
            return getattr(ncd, entry)(*args)
        for i in range(3):
            if bad[i]:
                args[i] = bad_scalar(rng)
        return ncd.project_cone(*args)
    if entry == "solve_local":
        W, q, mu = local_problem(rng)
        n = len(q) // 2
        kw = dict(guess=None, review_order=None, settings=settings(rng))
        if bad[0]:
            W = spoil_array(rng, W) if rng.random() < 0.7 else W * np.nan
        if bad[1]:
            q = spoil_array(rng, q)
        if bad[2]:
            which = rng.integers(4)
            if which == 0:
                mu = bad_scalar(rng)
            elif which == 1:
                kw["guess"] = spoil_array(rng, np.zeros((n, 2)))
            elif which == 2:
                kw["review_order"] = spoil_order(rng, n)
            else:
                kw["settings"] = {"max_sweeps": 10}
        if rng.random() < 0.3 and isinstance(W, np.ndarray) and W.ndim == 2 and W.dtype.kind == "f":
            W = sp.csr_matrix(W)
        return ncd.solve_local(W, q, mu, **kw)

    s = make_scene(rng)
    if rng.random() < 0.15:
        ncd.step(s, 1e-3)                    # warm-start memory
    h = 1e-3
    if entry in ("detect_contacts", "kinetic_energy"):
        if bad[0]:
            spoil_scene(rng, s)
        if entry == "kinetic_energy":
            return ncd.kinetic_energy(s)
        alert = bad_scalar(rng) if bad[1] else 1e-9
        pos = spoil_array(rng, s.pos) if bad[2] else None
        return ncd.detect_contacts(s, alert=alert, pos=pos)
    if entry in ("prepare_step", "step", "equilibrium_test"):
        kw = {}
        if bad[0]:
            spoil_scene(rng, s)
        if bad[1]:
            key = ["h", "theta", "gap_tolerance", "speed_limit", "velocity_tol"][rng.integers(5)]
            if key == "h":
                h = bad_scalar(rng)
            elif entry == "step" or key in ("gap_tolerance", "theta", "velocity_tol"):
                if not (entry == "equilibrium_test" and key in ("theta", "speed_limit")) \
                        and not (entry == "step" and key == "velocity_tol") \
                        and not (entry == "prepare_step" and key == "velocity_tol"):
                    kw[key] = bad_scalar(rng)
        if bad[2]:
            if entry == "prepare_step":
                kw["vel" if rng.random() < 0.5 else "spin"] = spoil_array(rng, s.vel if rng.random() < 0.5 else s.spin)
            else:
                which = rng.integers(3)
                if which == 0:
                    kw["init"] = [spoil_array(rng, np.zeros((3, 2))), "hot", None, 3][rng.integers(4)]
                elif which == 1:
                    kw["review_order"] = spoil_order(rng, int(rng.integers(0, 8)))
                else:
                    kw["settings"] = "fast"
        if entry != "prepare_step":
            kw.setdefault("settings", settings(rng))
        return getattr(ncd, entry)(s, h, **kw)

    p = ncd.prepare_step(s, h)
    n = p.contacts.n
    if bad[0]:
        k = rng.integers(5)
        if k == 0:
            spoil_scene(rng, s)
        elif k == 1:
            p = ncd.prepare_step(make_scene(rng), h)          # a problem of another scene
        elif k == 2:
            field = ["W", "free_vel", "free_spin", "bias"][rng.integers(4)]
            setattr(p, field, spoil_array(rng, getattr(p, field)))
        elif k == 3 and n:
            field = ["body_a", "body_b", "normal", "arm_a", "mu", "e_n"][rng.integers(6)]
            arr = getattr(p.contacts, field).copy()
            if arr.dtype.kind == "i":
                arr[rng.integers(n)] = [10**6, -10**6, -1, s.n_disc][rng.integers(4)]
            else:
                arr.flat[rng.integers(arr.size)] = [np.nan, np.inf, -np.inf, -1.0, 1e308, 1e-308][rng.integers(6)]
            setattr(p.contacts, field, arr)
        else:
            p = "problem"
    kw = dict(settings=settings(rng))
    if bad[1]:
        kw["settings" if rng.random() < 0.2 else "review_order"] = spoil_order(rng, n)
    if entry == "explore":
        members = np.arange(int(rng.integers(0, 3)))
        kw.update(init=["zero", "warm", "random"][rng.integers(3)], review=["fixed", "random"][rng.integers(2)],
                  guess_scale=0.01, threads=int(rng.integers(1, 3)))
        kw.pop("review_order", None)
        root = 7
        if bad[2]:
            key = ["members", "root_seed", "guess_scale", "threads", "init", "review"][rng.integers(6)]
            if key == "members":
                members = spoil_order(rng, 3)
            elif key == "root_seed":
                root = bad_scalar(rng)
            else:
                kw[key] = bad_scalar(rng)
        return explore(s, p, members, root, **kw)
    if bad[2]:
        kw["guess"] = spoil_array(rng, np.zeros((n, 2)))
    if entry == "solve_problem":
        return ncd.solve_problem(s, p, **kw)
    if isinstance(p, str):
        return ncd.solve_discs(s, p, np.zeros((s.n_disc, 2)), np.zeros(s.n_disc), **kw)
    vel, spin = (v.copy() if isinstance(v, np.ndarray) else v for v in (p.free_vel, p.free_spin))
    if bad[0] and rng.random() < 0.5:
        vel = spoil_array(rng, vel)
    result = ncd.solve_discs(s, p.contacts, vel, spin, bias=p.bias, W=p.W, **kw)
    return result, vel, spin


# ------------------------------------------------------------------ judging a result
MUST_BE_FINITE = {"impulse", "vel", "spin", "forces", "pos", "free_vel", "W", "normal", "gap"}
MAY_BE_NAN = {"observable_change"}


def nan_in(value, name="result", depth=0):
    """Path of a NaN (or of a non-finite entry of a MUST_BE_FINITE field) in a result, or None."""
    if depth > 4:
        return None
    leaf = name.rsplit(".", 1)[-1].split("[")[0]
    if leaf in MAY_BE_NAN:
        return None
    if isinstance(value, np.ndarray) and value.dtype.kind == "f":
        bad = ~np.isfinite(value) if leaf in MUST_BE_FINITE else np.isnan(value)
        return name if bad.any() else None
    if isinstance(value, float):
        return name if np.isnan(value) else None
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, (tuple, list)):
        items = ((str(i), v) for i, v in enumerate(value))
    elif hasattr(value, "__dict__"):
        items = vars(value).items()
    else:
        return None
    for k, v in items:
        found = nan_in(v, f"{name}.{k}", depth + 1)
        if found:
            return found
    return None


def run_batch(entries, calls, seed, log):
    """The worker: ``calls`` calls per entry; writes each call's label to ``log``
    before running it (the last line names the call of a crash)."""
    import warnings

    import ncd
    warnings.simplefilter("ignore")
    np.seterr(all="ignore")
    tally, failures = {}, []
    with open(log, "w", buffering=1) as out:
        for e, entry in enumerate(entries):
            counts = tally.setdefault(entry, {"result": 0, "InputError": 0, "SimulationError": 0, "failure": 0})
            for i in range(calls):
                rng = np.random.default_rng((seed, e, i, ROOT))
                out.write(f"{entry} call {i} (rng key {(seed, e, i, ROOT)})\n")
                try:
                    result = call(entry, rng)
                except (ncd.InputError, ncd.SimulationError) as err:
                    kind = type(err).__name__
                    if not str(err).strip():
                        counts["failure"] += 1
                        failures.append(f"{entry} call {i}: {kind} without a message")
                    else:
                        counts[kind] += 1
                    continue
                except Exception as err:  # noqa: BLE001 -- every other exception is a finding
                    counts["failure"] += 1
                    failures.append(f"{entry} call {i}: {type(err).__name__}: {err}\n"
                                    + "".join(traceback.format_exc().splitlines(True)[-6:]))
                    continue
                where = nan_in(result)
                if where:
                    counts["failure"] += 1
                    failures.append(f"{entry} call {i}: silent NaN in {where}")
                else:
                    counts["result"] += 1
    return {"tally": tally, "failures": failures[:20], "n_failures": len(failures)}


# ------------------------------------------------------------------ the test
def run_subprocess(batch, numba_cache, log):
    """One batch in a fresh interpreter; returns ``(returncode or "timeout", stdout, stderr)``."""
    entries = BATCHES[batch]
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(numba_cache))
    cmd = [sys.executable, __file__, ",".join(entries), str(CALLS), str(list(BATCHES).index(batch)), str(log)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, env=env,
                              cwd=Path(__file__).resolve().parents[1])
    except subprocess.TimeoutExpired:
        return "timeout", "", ""
    return proc.returncode, proc.stdout, proc.stderr


@pytest.fixture(scope="module")
def numba_cache(tmp_path_factory):
    """A temporary NUMBA_CACHE_DIR for kernels compiled with bounds checks."""
    return tmp_path_factory.mktemp("numba_boundscheck")


@pytest.fixture(scope="module")
def fuzz_runs(numba_cache, tmp_path_factory):
    """All batches, two at a time (two cores), sharing one cache of kernels compiled
    with bounds checks."""
    from concurrent.futures import ThreadPoolExecutor
    logs = {b: tmp_path_factory.mktemp(f"fuzz_{b}") / "calls.log" for b in BATCHES}
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {b: pool.submit(run_subprocess, b, numba_cache, logs[b]) for b in BATCHES}
        return {b: f.result() + (logs[b],) for b, f in futures.items()}


def test_harness_turns_an_out_of_range_kernel_index_into_an_error(numba_cache):
    """The harness itself: with NUMBA_BOUNDSCHECK=1 the NLGS kernel reached with
    review order [0, 1, 10**6] (bypassing the checks) raises IndexError, where the
    unchecked build read out of bounds (segfault of issue 14)."""
    code = ("import numpy as np\nimport ncd.nlgs as m, scipy.sparse as sp\n"
            "W = sp.csr_matrix(2.0 * np.eye(6)); q = -np.ones(6); Wd = np.tile(2.0 * np.eye(2), (3, 1, 1))\n"
            "data = (W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, Wd, np.full(3, 0.5), np.zeros(6))\n"
            "try:\n    m._sweep_local(data, np.array([0, 1, 10**6]), np.zeros(3, np.int8))\n"
            "except IndexError as err:\n    print('IndexError', err)\n")
    env = dict(os.environ, NUMBA_BOUNDSCHECK="1", NUMBA_CACHE_DIR=str(numba_cache))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=TIMEOUT, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.startswith("IndexError"), proc.stdout


@pytest.mark.parametrize("batch", list(BATCHES))
def test_fuzz(batch, fuzz_runs):
    entries = BATCHES[batch]
    rc, stdout, stderr, log = fuzz_runs[batch]
    last = log.read_text().splitlines()[-1:] if log.exists() else []
    assert rc != "timeout", f"batch {batch} hung (> {TIMEOUT} s); last call: {last}"
    assert rc == 0, f"batch {batch} died with rc {rc} during {last}:\n{stderr[-3000:]}"
    report = json.loads(stdout.strip().splitlines()[-1])
    print(json.dumps(report["tally"], indent=1))
    assert report["n_failures"] == 0, "\n".join(report["failures"])
    for entry in entries:
        counts = report["tally"][entry]
        assert sum(counts.values()) == CALLS
        # the generator must exercise both sides: refused calls and valid results
        assert counts["InputError"] >= CALLS // 10, (entry, counts)
        assert counts["result"] >= (CALLS // 20 if entry != "SolverSettings" else 0), (entry, counts)


if __name__ == "__main__":
    entries, calls, seed, log = sys.argv[1].split(","), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    print(json.dumps(run_batch(entries, calls, seed, log)))
