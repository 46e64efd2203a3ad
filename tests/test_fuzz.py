"""Fuzz test of the public API: random malformed calls never
crash, hang or return NaN.

A seeded generator (:mod:`fuzz_calls`) (``default_rng((batch, ROOT))``, no test order dependence)
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
about a minute, paid once by the first batch.
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

    from fuzz_calls import call  # tests/ is on sys.path: this file runs as a script

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
    unchecked build read out of bounds (a segfault before the checks existed)."""
    code = ("import numpy as np\nimport ncd.solver.kernels as m, scipy.sparse as sp\n"
            "W = sp.csr_matrix(2.0 * np.eye(6)); q = -np.ones(6); Wd = np.tile(2.0 * np.eye(2), (3, 1, 1))\n"
            "data = (W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, Wd, np.full(3, 0.5), np.zeros(6))\n"
            "try:\n    m.sweep_local(data, np.array([0, 1, 10**6]), np.zeros(3, np.int8))\n"
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
