"""Benchmarks of the solver: measurements, not tests.

:func:`core_table` (cost of one NLGS contact update, numba against the same loop in plain
C on the same packed arrays, ``c_sweep.c``, which must give the same impulses bit for bit;
detection, step preparation, time per step, peak memory), :func:`sweeps_table` (sweeps to
a fixed tolerance against N), :func:`ensemble_table` (1 against 2 threads, bit-for-bit
equal), :func:`startup` (the start-up of one job), :func:`tolerance_table` (time to
tolerance of every solver method).
The packing is a jittered triangular lattice in a box whose neighbours overlap slightly,
about three contacts per disc, as in a jammed packing.
"""
import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
import xarray as xr

from ncd.core.contacts import detect_contacts
from ncd.core.scene import make_scene
from ncd.dynamics.explore import explore
from ncd.dynamics.stepper import initial_guess, prepare_step, solve_problem, step
from ncd.solver.kernels import sweep_discs
from ncd.solver.pack import pack_problem
from ncd.solver.settings import SolverSettings
from ncd.studies.bench.finish import settings_of

C_SOURCE = Path(__file__).with_name("c_sweep.c")
H = 1e-3


def dense_packing(n, seed=0, s=1.0):
    """About ``n`` discs on a jittered triangular lattice, neighbours slightly overlapping."""
    rng = np.random.default_rng((0, seed))
    ny = max(2, int(round(np.sqrt(n * np.sqrt(3) / 2))))
    nx = int(np.ceil(n / ny))
    k, j = np.divmod(np.arange(nx * ny), nx)
    x = s / 2 + j * s + (k % 2) * s / 2
    y = s / 2 + k * s * np.sqrt(3) / 2
    pos = np.column_stack([x, y]) + rng.uniform(-1e-3, 1e-3, (nx * ny, 2)) * s
    radius = s / 2 * (1.005 + 0.02 * rng.random(nx * ny))
    width = nx * s + s / 2
    walls = [((0.0, 0.0), (0.0, 1.0)), ((0.0, 0.0), (1.0, 0.0)), ((width, 0.0), (-1.0, 0.0))]
    return make_scene(pos, radius, 1.0, walls=walls, mu=0.5, overlap_tolerance=0.06)


# The timings of one process are its CPU seconds (user + system), not wall time: on a
# shared machine the wall time of a loop counts the other processes' turns on the cores.
# The C reference loop reads the same clock (CLOCK_PROCESS_CPUTIME_ID).
clock = time.process_time


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def _status_bytes(field):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return float(line.split()[1]) * 1024.0
    return np.nan


class PeakMemory:
    """Peak resident memory (bytes) of the process inside a ``with`` block, and its
    growth over the resident memory at entry (Linux: ``/proc/self/clear_refs``
    resets ``VmHWM``); NaN where that is not available."""

    def __enter__(self):
        try:
            Path("/proc/self/clear_refs").write_text("5")
            self.start = _status_bytes("VmRSS")
        except OSError:
            self.start = None
        return self

    def __exit__(self, *exc):
        self.peak = self.growth = np.nan
        if self.start is not None:
            self.peak = _status_bytes("VmHWM")
            self.growth = self.peak - self.start
        return False


def packed_problem(scene, problem):
    """The flat arrays of the NLGS kernel (:func:`ncd.solver.pack.pack_problem`) of a prepared step."""
    c = problem.contacts
    pair, coef, body = pack_problem(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, problem.W,
                                         c.mu, problem.bias, scene.inv_mass, scene.inv_inertia,
                                         problem.free_vel, problem.free_spin)
    return pair.ravel(), coef.ravel(), body.ravel()


def interleaved_order(n, stride=8):
    """Review order ``0, s, 2s, ..., 1, 1 + s, ...``: consecutive updates are ``s``
    contacts apart in the sorted list, so they rarely share a disc (a cheap stand-in
    for the graph colouring of Box2D's solver)."""
    return np.concatenate([np.arange(k, n, stride) for k in range(stride)])


def nlgs_sweep_cost(scene, problem, sweeps, repeat, order=None):
    """Seconds per sweep of the numba kernel (best of ``repeat`` runs of ``sweeps``
    sweeps from the zero guess; identity review order by default) and the final impulses."""
    pair, coef, body = packed_problem(scene, problem)
    n = problem.contacts.n
    order = np.arange(n) if order is None else order
    status = np.zeros(n, np.int8)
    best, imp = np.inf, None
    for _ in range(repeat):
        b, imp = body.copy(), np.zeros(2 * n)
        t0 = clock()
        for _ in range(sweeps):
            sweep_discs((pair, coef, b, imp), order, status)
        best = min(best, clock() - t0)
    return best / sweeps, imp


def c_sweep_cost(scene, problem, sweeps, workdir):
    """Seconds per sweep of ``c_sweep.c`` (gcc -O3 -ffp-contract=off) on
    the same packed arrays, and its final impulses (flat); ``(nan, None)`` without a
    C compiler."""
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        return np.nan, None
    exe = Path(workdir) / "c_sweep"
    if not exe.exists():
        subprocess.run([cc, "-O3", "-ffp-contract=off", "-o", str(exe), str(C_SOURCE), "-lm"],
                       check=True)
    pair, coef, body = packed_problem(scene, problem)
    n = problem.contacts.n
    data, result = Path(workdir) / "problem.bin", Path(workdir) / "impulses.bin"
    with open(data, "wb") as f:
        np.array([n, len(body) // 4, sweeps], np.int64).tofile(f)
        np.arange(n, dtype=np.int64).tofile(f)
        for a in (pair, coef, body, np.zeros(2 * n)):
            a.tofile(f)
    out = subprocess.run([str(exe), str(data), str(result)], check=True, capture_output=True, text=True)
    return float(out.stdout.split()[0]), np.fromfile(result, dtype=np.float64)


def core_row(n, cfg, workdir):
    """One size of :func:`core_table`."""
    with PeakMemory() as mem:
        t0 = clock()
        scene = dense_packing(n)
        build = clock() - t0
        problem = prepare_step(scene, H)
        settings = SolverSettings(tol=cfg["step_tol"], max_sweeps=cfg["step_sweeps"], check_every=10)
        step(scene, H, settings=settings)
    repeat = 3 if n <= 10_000 else 2
    gap = 1e-9 * scene.radius.min()
    sweeps = cfg["sweeps"]
    t_sweep, imp = nlgs_sweep_cost(scene, problem, sweeps, repeat)
    t_inter, _ = nlgs_sweep_cost(scene, problem, sweeps, repeat, interleaved_order(problem.contacts.n))
    t_c, imp_c = c_sweep_cost(scene, problem, sweeps, workdir)
    reports, times = [], []
    for _ in range(cfg["steps"]):
        t0 = clock()
        reports.append(step(scene, H, settings=settings))
        times.append(clock() - t0)
    nc = problem.contacts.n
    return {
        "n_discs": scene.n_mobile, "n_contacts": nc, "build_s": build,
        "sweep_s": t_sweep,
        "ns_per_update": 1e9 * t_sweep / nc, "ns_per_update_c": 1e9 * t_c / nc,
        "ns_per_update_interleaved": 1e9 * t_inter / nc,
        # the C loop performs the same floating-point operations in the same order
        "c_agrees": np.nan if imp_c is None else float(np.array_equal(imp_c, imp)),
        "detect_s": best_of(lambda: detect_contacts(scene, alert=gap), repeat),
        "prepare_s": best_of(lambda: prepare_step(scene, H), repeat),
        "step_s": float(np.mean(times)),
        "step_sweeps": float(np.mean([r.sweeps for r in reports])),
        "step_converged": float(np.mean([r.converged for r in reports])),
        "peak_memory": mem.peak, "memory_growth": mem.growth,
    }


UNITS = {"ns_per_update": ("ns", "numba NLGS sweep: CPU time per contact update"),
         "ns_per_update_c": ("ns", "the same sweep in C (gcc -O3 -ffp-contract=off): "
                                   "CPU time per contact update"),
         "ns_per_update_interleaved": ("ns", "numba NLGS sweep in the interleaved review order: CPU time per contact update"),
         "c_agrees": ("1", "1 if the C and numba sweeps give the same impulses bit for bit"),
         "build_s": ("s", "CPU time to build the packing (make_scene: positions, radii, checks)"),
         "sweep_s": ("s", "CPU time of one NLGS sweep over every contact"),
         "detect_s": ("s", "CPU time of contact detection"), "prepare_s": ("s", "CPU time of step preparation (with detection)"),
         "step_s": ("s", "CPU time of a Moreau-Jean step, warm start"), "step_sweeps": ("1", "mean NLGS sweeps per step"),
         "step_converged": ("1", "fraction of steps converged within the sweep budget"),
         "peak_memory": ("B", "peak resident memory of the process while building the packing and making one step"),
         "memory_growth": ("B", "peak resident memory above the process's resident memory before the build")}


def core_table(cfg, log=None):
    """Per size of ``cfg["sizes"]``: the quantities of :data:`UNITS` (module docstring)."""
    rows = []
    with tempfile.TemporaryDirectory() as workdir:
        core_row(200, cfg, workdir)              # compile / load every kernel first
        for n in cfg["sizes"]:
            rows.append(core_row(n, cfg, workdir))
            if log is not None:
                log.info("N = %d: %.1f ns/update (C %.1f), step %.3g s", rows[-1]["n_discs"],
                         rows[-1]["ns_per_update"], rows[-1]["ns_per_update_c"], rows[-1]["step_s"])
    ds = xr.Dataset({k: ("size", np.array([r[k] for r in rows])) for k in rows[0]},
                    coords={"size": np.asarray(cfg["sizes"])})
    for k, (units, name) in UNITS.items():
        ds[k].attrs.update(units=units, long_name=name)
    return ds


def power_law(n, t):
    """Exponent and prefactor ``(p, c)`` of the least-squares fit ``t = c n^p`` in log-log
    (NaN with fewer than two sizes or a non-positive time)."""
    n, t = np.asarray(n, float), np.asarray(t, float)
    if len(n) < 2 or np.any(t <= 0) or np.any(n <= 0):
        return float("nan"), float("nan")
    p, logc = np.polyfit(np.log(n), np.log(t), 1)
    return float(p), float(np.exp(logc))


SCALING = {"build_s": "building the packing", "prepare_s": "step preparation (detection, Delassus blocks)",
           "sweep_s": "one NLGS sweep", "step_s": "one Moreau-Jean step (warm start, NLGS to step_tol)"}


def scaling_table(core):
    """Time against N of :data:`SCALING`'s quantities of a :func:`core_table` Dataset, each
    with its fitted exponent ``p`` (``t = c N^p``): a list of ``(what, times, p)``."""
    n = core.n_discs.values
    return [(name, core[k].values, power_law(n, core[k].values)[0]) for k, name in SCALING.items()]


def sweeps_table(cfg, log=None):
    """Sweeps to reach ``cfg["tol"]`` (natural-map residual) on one step of each
    packing of ``cfg["sizes"]``: from the zero guess, and warm-started after
    ``cfg["warm_steps"]`` steps, and from the zero guess in the interleaved review
    order (:func:`interleaved_order`); runs that exhaust ``cfg["max_sweeps"]`` are flagged."""
    settings = SolverSettings(tol=cfg["tol"], max_sweeps=cfg["max_sweeps"], check_every=10)
    data = {f"{k}_{init}": [] for k in ("sweeps", "residual", "converged", "wall_time")
            for init in ("zero", "interleaved", "warm")}
    for n in cfg["sizes"]:
        scene = dense_packing(n)
        for init in ("zero", "interleaved", "warm"):
            if init == "warm":
                for _ in range(cfg["warm_steps"]):
                    step(scene, H, settings=settings)
            problem = prepare_step(scene, H)
            guess = initial_guess(scene, problem, "warm" if init == "warm" else "zero")
            order = interleaved_order(problem.contacts.n) if init == "interleaved" else None
            t0 = time.perf_counter()
            r, _, _ = solve_problem(scene, problem, guess, order, settings)
            data[f"wall_time_{init}"].append(time.perf_counter() - t0)
            data[f"sweeps_{init}"].append(r.sweeps)
            data[f"residual_{init}"].append(r.residual)
            data[f"converged_{init}"].append(int(r.converged))
        if log is not None:
            log.info("N = %d: sweeps zero %d, warm %d", n, data["sweeps_zero"][-1], data["sweeps_warm"][-1])
    ds = xr.Dataset({k: ("size", np.asarray(v)) for k, v in data.items()},
                    coords={"size": np.asarray(cfg["sizes"])})
    ds.attrs.update(tol=cfg["tol"], max_sweeps=cfg["max_sweeps"], warm_steps=cfg["warm_steps"])
    return ds


def tolerance_table(cfg, log=None):
    """Time to tolerance, plain NLGS, NLGS + finishing stage and Anderson-accelerated NLGS side by side: one step
    from rest of each dense packing, zero guess, identity review order.  Plain NLGS runs
    to each ``tolerances`` value; the finished run hands over at ``handoff`` and polishes
    to the same value (``finish="active_set"``, :mod:`ncd.solver.finish`).  -> Dataset
    (size, solver, tol): seconds, sweeps, residual, converged, finish rounds."""
    sizes, tols, methods = cfg["sizes"], cfg["tolerances"], ["nlgs", "nlgs+finish", "anderson"]
    shape = (len(sizes), len(methods), len(tols))
    out = {k: np.zeros(shape) for k in ("seconds", "residual")}
    out.update({k: np.zeros(shape, np.int64) for k in ("sweeps", "converged", "finish_rounds")})
    for i, n in enumerate(sizes):
        scene = dense_packing(n)
        problem = prepare_step(scene, H)
        solve_problem(scene, problem, settings=SolverSettings(tol=1.0, max_sweeps=1))    # warm-up
        for j, method in enumerate(methods):
            for k, tol in enumerate(tols):
                settings = settings_of(method, tol, cfg["handoff"], cfg["max_sweeps"], 10)
                t0 = time.perf_counter()
                r, _, _ = solve_problem(scene, problem, settings=settings)
                out["seconds"][i, j, k] = time.perf_counter() - t0
                out["sweeps"][i, j, k], out["residual"][i, j, k] = r.sweeps, r.residual
                out["converged"][i, j, k], out["finish_rounds"][i, j, k] = r.converged, r.finish_rounds
                if log:
                    log.info("%d discs, %s, tol %.0e: %.3f s, %d sweeps, residual %.2e", n, method, tol,
                             out["seconds"][i, j, k], r.sweeps, r.residual)
    units = {"seconds": ("s", "wall time to reach the tolerance"), "residual": ("1", "relative natural-map residual"),
             "sweeps": ("1", "NLGS sweeps"), "converged": ("1", "residual <= tolerance (1) or not (0)"),
             "finish_rounds": ("1", "rounds of the finishing stage (LP projections onto a status set)")}
    return xr.Dataset({k: (("size", "solver", "tol"), v, {"units": units[k][0], "long_name": units[k][1]})
                       for k, v in out.items()},
                      coords={"size": sizes, "solver": methods, "tol": tols})

def _digest(out):
    h = hashlib.sha256()
    for k in ("impulse", "vel", "spin", "sweeps", "residual", "change", "converged"):
        h.update(np.ascontiguousarray(out[k]).tobytes())
    return h.hexdigest()


def ensemble_table(cfg, log=None):
    """An ensemble of ``cfg["runs"]`` zero-guess NLGS runs with random review orders
    on a packing of ``cfg["n_discs"]`` discs, on 1 and 2 threads (best of
    ``cfg["repeat"]``): wall times, speed-up and whether the results are identical."""
    scene = dense_packing(cfg["n_discs"])
    problem = prepare_step(scene, H)
    settings = SolverSettings(tol=cfg["tol"], max_sweeps=cfg["max_sweeps"], check_every=10)
    explore(scene, problem, [0], 1, settings=settings, threads=1)      # warm-up
    threads = np.asarray(cfg["threads"])
    wall = np.zeros(len(threads))
    digests = []
    for i, th in enumerate(threads):
        best = np.inf
        for _ in range(cfg["repeat"]):
            t0 = time.perf_counter()
            out = explore(scene, problem, range(cfg["runs"]), cfg["root_seed"], settings=settings,
                          threads=int(th))
            best = min(best, time.perf_counter() - t0)
        wall[i] = best
        digests.append(_digest(out))
        if log is not None:
            log.info("%d threads: %.3f s, digest %s", th, best, digests[-1][:12])
    ds = xr.Dataset({"wall_time": ("threads", wall), "speedup": ("threads", wall[0] / wall),
                     "same_results": ("threads", np.array([int(d == digests[0]) for d in digests])),
                     "digest": ("threads", np.array(digests))},
                    coords={"threads": threads})
    ds.attrs.update(n_discs=scene.n_mobile, n_contacts=problem.contacts.n, runs=cfg["runs"],
                    tol=cfg["tol"], sweeps_mean=float(np.mean(out["sweeps"])),
                    converged=int(np.sum(out["converged"])), cpu_count=os.cpu_count())
    return ds


def environment():
    """Machine and library versions, as dataset attributes."""
    return {"python": platform.python_version(), "numpy": np.__version__, "numba": numba.__version__,
            "machine": platform.machine(), "cpu_count": os.cpu_count(),
            "numba_threads": numba.get_num_threads(), "loadavg_start": os.getloadavg()[0]}


STARTUP = r"""
import time
t0 = time.perf_counter()
import ncd
t1 = time.perf_counter()
scene = ncd.make_scene([[0.0, 0.5], [0.0, 1.5], [1.3, 0.6]], [0.5, 0.5, 0.6], walls=[((0, 0), (0, 1))])
ncd.step(scene, 1e-3)
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def startup(repeat=3):
    """Seconds to ``import ncd`` and to make a first step, and the whole process,
    in fresh interpreters (the numba cache warmed by a first run)."""
    cmd = [sys.executable, "-c", STARTUP]
    subprocess.run(cmd, check=True, capture_output=True)
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.split()
        runs.append((float(out[0]), float(out[1]), time.perf_counter() - t0))
    imp, first, wall = np.min(np.array(runs), axis=0)
    return {"import_s": imp, "first_step_s": first, "process_s": wall}
