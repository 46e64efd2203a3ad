"""Benchmark of the ncd core (issue 2, "Performance"): not a test.

For dense packings of 10^3, 10^4 and 10^5 discs it measures

* the cost of one NLGS contact update (ns), from the time difference of two
  runs of a fixed number of sweeps on the same core problem;
* contact detection (``detect_contacts``) and the whole preparation of a step
  (``prepare_step``: middle configuration, detection, Delassus blocks, free
  velocities);
* the time per Moreau-Jean step (``ncd.step``: preparation + NLGS + update) with
  warm start and a fixed budget of sweeps per step;

and, in a fresh interpreter with a warm numba cache, the time to
``import ncd`` and to run a first step.  Results go to
``benchmarks/results/core.json``; a Markdown table is printed.

The packing is a triangular lattice of spacing ``s`` (rows alternately shifted
by ``s/2``, lattice positions jittered by ``1e-3 s``) in a box (floor and two
side walls) under gravity, with radii ``s/2 (1 + 0.005 + 0.02 u)``, ``u``
uniform in [0, 1]: every lattice neighbour pair overlaps by 0.5 % to 4.5 % of
``s/2`` (weakly polydisperse, about three contacts per disc, as in a
jammed packing).  Run from the repository root::

    python benchmarks/bench_core.py            # about 2 minutes on 1 core
    python benchmarks/bench_core.py --sizes 1000 10000
"""
import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import ncd
from ncd.contacts import detect_contacts

HERE = Path(__file__).resolve().parent
H = 1e-3


def dense_packing(n, seed=0, s=1.0):
    """About ``n`` discs on a jittered triangular lattice, neighbours slightly overlapping."""
    rng = np.random.default_rng(seed)
    ny = max(2, int(round(np.sqrt(n * np.sqrt(3) / 2))))
    nx = int(np.ceil(n / ny))
    k, j = np.divmod(np.arange(nx * ny), nx)
    x = s / 2 + j * s + (k % 2) * s / 2
    y = s / 2 + k * s * np.sqrt(3) / 2
    pos = np.column_stack([x, y]) + rng.uniform(-1e-3, 1e-3, (nx * ny, 2)) * s
    radius = s / 2 * (1.005 + 0.02 * rng.random(nx * ny))
    width = nx * s + s / 2
    walls = [((0.0, 0.0), (0.0, 1.0)), ((0.0, 0.0), (1.0, 0.0)), ((width, 0.0), (-1.0, 0.0))]
    return ncd.make_scene(pos, radius, 1.0, walls=walls, mu=0.5, overlap_tolerance=0.06)


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def fixed_sweeps(sweeps):
    """Settings that run exactly ``sweeps`` sweeps (residual evaluated once, at the end)."""
    return ncd.SolverSettings(tol=1e-300, max_sweeps=sweeps, check_every=sweeps)


def bench_size(n, step_sweeps, n_steps):
    out = {"n_target": n}
    t0 = time.perf_counter()
    scene = dense_packing(n)
    out["build_s"] = time.perf_counter() - t0
    out["n_discs"] = scene.n_mobile
    repeat = 3 if n <= 10_000 else 2
    contacts = detect_contacts(scene, alert=1e-9 * scene.radius.min())
    out["n_contacts"] = contacts.n
    out["contacts_per_disc"] = contacts.n / scene.n_mobile
    out["detect_s"] = best_of(lambda: detect_contacts(scene, alert=1e-9 * scene.radius.min()), repeat)
    out["prepare_s"] = best_of(lambda: ncd.prepare_step(scene, H), repeat)

    # NLGS sweep cost: two fixed-length runs on the same problem, the difference
    # isolates the sweeps from the set-up and the final residual evaluation
    problem = ncd.prepare_step(scene, H)
    few, many = 10, (60 if n <= 10_000 else 30)
    t_few = best_of(lambda: ncd.solve_problem(scene, problem, None, None, fixed_sweeps(few)), repeat)
    t_many = best_of(lambda: ncd.solve_problem(scene, problem, None, None, fixed_sweeps(many)), repeat)
    out["sweep_s"] = (t_many - t_few) / (many - few)
    out["ns_per_contact_update"] = 1e9 * out["sweep_s"] / problem.contacts.n
    # set-up of a solve (copies, Delassus-weighted scale, guess) plus one residual evaluation
    t_one = best_of(lambda: ncd.solve_problem(scene, problem, None, None, fixed_sweeps(1)), repeat)
    out["solve_overhead_s"] = t_one - out["sweep_s"]

    # time per step: warm start, tol 1e-4, at most step_sweeps sweeps per step
    settings = ncd.SolverSettings(tol=1e-4, max_sweeps=step_sweeps, check_every=10)
    ncd.step(scene, H, settings=settings)          # first step: fills the warm-start memory
    reports, times = [], []
    for _ in range(n_steps):
        t0 = time.perf_counter()
        reports.append(ncd.step(scene, H, settings=settings))
        times.append(time.perf_counter() - t0)
    out["step_s"] = float(np.mean(times))
    out["step_sweep_budget"] = step_sweeps
    out["step_sweeps_mean"] = float(np.mean([r.sweeps for r in reports]))
    out["step_converged_fraction"] = float(np.mean([r.converged for r in reports]))
    out["step_residual_last"] = reports[-1].residual
    out["n_steps_timed"] = n_steps
    # all-inclusive cost of a contact update inside a step (residual checks every
    # 10 sweeps and the warm-started mix of stick/slide cases included)
    n_updates = sum(r.sweeps * r.n_contacts for r in reports)
    out["step_ns_per_contact_update"] = 1e9 * (sum(times) - n_steps * out["prepare_s"]) / n_updates
    return out


FIRST_STEP = r"""
import time
t0 = time.perf_counter()
import ncd
t1 = time.perf_counter()
import numpy as np
scene = ncd.make_scene([[0.0, 0.5], [0.0, 1.5], [1.3, 0.6]], [0.5, 0.5, 0.6], walls=[((0, 0), (0, 1))])
ncd.step(scene, 1e-3)
t2 = time.perf_counter()
ncd.step(scene, 1e-3)
t3 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2)
"""


def bench_startup(repeat=3):
    """``import ncd`` and a first step in fresh interpreters (cache warmed by a first run)."""
    cmd = [sys.executable, "-c", FIRST_STEP]
    subprocess.run(cmd, check=True, capture_output=True)      # warm the numba cache
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, check=True, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        imp, first, second = map(float, proc.stdout.split())
        runs.append((imp, first, second, wall))
    imp, first, second, wall = np.min(np.array(runs), axis=0)
    return {"import_s": imp, "first_step_s": first, "second_step_s": second, "process_wall_s": wall}


def environment():
    import numba
    return {"python": platform.python_version(), "numpy": np.__version__, "numba": numba.__version__,
            "ncd": ncd.__version__, "machine": platform.machine(), "processor": platform.processor(),
            "cpu_count": os.cpu_count(), "numba_threads": numba.get_num_threads(),
            "loadavg_start": os.getloadavg()[0]}


def markdown(results):
    rows = ["| discs | contacts | contacts/disc | ns / contact update | sweep (ms) | detection (ms) "
            "| prepare_step (ms) | step (ms) | sweeps/step (budget) | ns / contact update in steps |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in results["sizes"]:
        rows.append(f"| {r['n_discs']:,} | {r['n_contacts']:,} | {r['contacts_per_disc']:.2f} "
                    f"| {r['ns_per_contact_update']:.1f} | {1e3 * r['sweep_s']:.3g} | {1e3 * r['detect_s']:.3g} "
                    f"| {1e3 * r['prepare_s']:.3g} | {1e3 * r['step_s']:.4g} "
                    f"| {r['step_sweeps_mean']:.0f} ({r['step_sweep_budget']}) "
                    f"| {r['step_ns_per_contact_update']:.1f} |")
    s = results["startup"]
    rows += ["", "| fresh interpreter, warm numba cache | seconds |", "|---|---:|",
             f"| `import ncd` | {s['import_s']:.2f} |",
             f"| first step (make_scene + step, loads cached kernels) | {s['first_step_s']:.2f} |",
             f"| second step | {s['second_step_s']:.4f} |",
             f"| whole process (python -c ...) | {s['process_wall_s']:.2f} |"]
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    parser.add_argument("--output", default=str(HERE / "results" / "core.json"))
    args = parser.parse_args()
    t_start = time.perf_counter()
    # compile / load every kernel once before timing anything
    bench_size(200, step_sweeps=20, n_steps=1)
    results = {"environment": environment(), "step_h": H, "sizes": []}
    for n in args.sizes:
        budget, n_steps = (200, 5) if n <= 10_000 else (200, 3)
        r = bench_size(n, budget, n_steps)
        print(f"N = {r['n_discs']}: {r['ns_per_contact_update']:.1f} ns/contact update, "
              f"step {1e3 * r['step_s']:.1f} ms", file=sys.stderr)
        results["sizes"].append(r)
    results["startup"] = bench_startup()
    results["total_s"] = time.perf_counter() - t_start
    results["environment"]["loadavg_end"] = os.getloadavg()[0]
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(markdown(results))
    env = results["environment"]
    print(f"\n(total {results['total_s']:.0f} s, load average {env['loadavg_start']:.1f} -> "
          f"{env['loadavg_end']:.1f} on {env['cpu_count']} cores; written to {out})")


if __name__ == "__main__":
    main()
