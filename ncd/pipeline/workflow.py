"""Glue between Snakemake scripts and ncd: logging, threads, progress, settings, recovery.

Scripts under ``workflow/scripts`` stay thin: ``log = start(snakemake)``, read the
config section from ``snakemake.params.config``, call the figure module, write
with :func:`ncd.io.netcdf.write_dataset`.
"""
import logging
import os
import signal
import sys
import time
import traceback
from pathlib import Path

from ncd.solver.settings import SolverSettings


def start(snakemake):
    """Configure numba's thread count from the rule's ``threads`` and log to ``log[0]``."""
    import numba

    numba.set_num_threads(max(1, min(int(snakemake.threads), numba.config.NUMBA_NUM_THREADS)))
    logger = logging.getLogger(f"ncd.{snakemake.rule}")
    logger.setLevel(logging.INFO)
    logger.handlers.clear()
    handler = logging.FileHandler(snakemake.log[0], mode="w") if len(snakemake.log) else logging.StreamHandler()
    handler.setFormatter(logging.Formatter("%(name)s: %(message)s"))
    logger.addHandler(handler)
    logger.info("rule %s, threads %d (numba %d, OPENBLAS_NUM_THREADS=%s)", snakemake.rule, snakemake.threads,
                numba.get_num_threads(), os.environ.get("OPENBLAS_NUM_THREADS", "unset"))
    log_uncaught(logger)
    return logger


def log_uncaught(logger):
    """Write the traceback of an uncaught exception of the script to its log (it
    would otherwise reach only Snakemake's console), then exit as Python does.
    SIGTERM (Snakemake cancelling a job) becomes ``SystemExit(143)`` so that
    ``finally`` blocks run (no temporary file left) and the log says why."""
    previous = sys.excepthook

    def hook(kind, value, tb):
        logger.critical("uncaught exception, the job fails:\n%s",
                        "".join(traceback.format_exception(kind, value, tb)).rstrip())
        for handler in logger.handlers:
            handler.flush()
        previous(kind, value, tb)

    def terminate(signum, frame):
        logger.critical("terminated by signal %d", signum)
        raise SystemExit(128 + signum)

    sys.excepthook = hook
    try:
        signal.signal(signal.SIGTERM, terminate)
    except ValueError:          # not the main thread (e.g. a script run inside a thread)
        pass


def settings(cfg):
    """:class:`SolverSettings` from a config mapping (keys of the dataclass)."""
    return SolverSettings(**cfg)


class Progress:
    """Log ``label: done/total, rate, ETA`` at most every ``every`` seconds."""

    def __init__(self, logger, total, label, every=10.0):
        self.logger, self.total, self.label, self.every = logger, total, label, every
        self.t0 = self.last = time.perf_counter()
        self.last_done = -1                 # the last count logged: the end is logged once
        self.last_total = total

    def __call__(self, done, total=None, extra=""):
        total = self.total if total is None else total
        now = time.perf_counter()
        if total != self.last_total:        # a new phase with its own total
            self.last_total, self.last_done = total, -1
        if (now - self.last < self.every and done < total) or self.last_done >= total:
            return
        self.last, self.last_done = now, done
        rate = done / max(now - self.t0, 1e-9)
        eta = (total - done) / rate if rate > 0 else float("inf")
        self.logger.info("%s: %d/%d, %.1f/s, ETA %.0f s %s", self.label, done, total, rate, eta, extra)


def _snakemake_processes(workdir):
    """PIDs of the processes on this machine, other than this one and its ancestors,
    working in ``workdir`` whose command line runs Snakemake or one of its job scripts."""
    workdir = os.path.realpath(workdir)
    mine, pid = set(), os.getpid()
    while pid > 1:                      # this process and its ancestors
        mine.add(pid)
        try:
            pid = int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            break
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) in mine:
            continue
        try:
            argv = (entry / "cmdline").read_bytes().split(b"\0")
            cwd = os.readlink(entry / "cwd")
        except OSError:
            continue
        args = [a.decode(errors="replace") for a in argv if a]
        runs = any(os.path.basename(a) == "snakemake" or "/.snakemake/scripts/" in a for a in args) \
            or any(a == "-m" and b == "snakemake" for a, b in zip(args, args[1:]))
        if runs and os.path.realpath(cwd) == workdir:
            found.append(int(entry.name))
    return found


def recover_killed_run(workdir=".", logger=None):
    """After a Snakemake run was killed (SIGKILL, a lost node): remove its stale locks
    (``.snakemake/locks``) and leftover temporary files (``results/**/*.part``) when no
    Snakemake process or job of it still runs in ``workdir`` on this machine.  Returns
    the paths removed (empty when something still runs there).  Jobs that were running
    stay marked incomplete; the workflow profile (``profiles/default``:
    ``rerun-incomplete``) reruns them (outputs are written atomically, so a marked
    output is whole or absent).  Linux only (reads ``/proc``); elsewhere a no-op."""
    root = Path(workdir)
    stale = sorted((root / ".snakemake" / "locks").glob("*.lock")) + sorted((root / "results").rglob("*.part"))
    if not stale or not Path("/proc/self/cwd").exists():
        return []
    alive = _snakemake_processes(root)
    if alive:
        if logger:
            logger(f"ncd: a Snakemake process or job still runs in {root.resolve()} (pid {alive}): "
                   "its locks and temporary files are kept")
        return []
    for path in stale:
        path.unlink(missing_ok=True)
    if logger:
        logger(f"ncd: removed {len(stale)} stale lock/temporary file(s) of a killed run: "
               + ", ".join(str(p) for p in stale[:5]) + (" ..." if len(stale) > 5 else ""))
    return stale


def coalesce_reevaluations(scheduler_class=None):
    """Keep at most one pending re-evaluation timer of Snakemake's job scheduler.

    With a job rate limit (the CLI always sets one, ``100/1s``), each pass of the
    scheduler's loop that leaves jobs waiting arms a ``threading.Timer`` that wakes the
    loop one timespan later, and every other wake-up (a job finishing) starts one more
    such chain of timers.  Chains never merge: after k finished jobs the loop runs about
    k times a second, each pass re-checking every waiting job's inputs, a cost that
    grows with the run (on the default run, about a tenth of a core after 20 jobs).  A
    single pending timer wakes the loop as surely.  ``scheduler_class`` (default:
    Snakemake's ``JobScheduler``) is patched in place; returns False, and changes
    nothing, if it lacks the method this replaces (another Snakemake version)."""
    import threading

    if scheduler_class is None:
        try:
            from snakemake.scheduling.job_scheduler import JobScheduler as scheduler_class
        except ImportError:
            return False
    if not hasattr(scheduler_class, "_schedule_reevalutation") or \
            getattr(scheduler_class, "_ncd_coalesced", False):
        return False
    lock = threading.Lock()

    def schedule_reevaluation(self, delay):
        with lock:
            if getattr(self, "_ncd_reevaluation_pending", False):
                return
            self._ncd_reevaluation_pending = True

        def wake():
            with lock:
                self._ncd_reevaluation_pending = False
            self._open_jobs.release()

        threading.Timer(delay, wake).start()

    scheduler_class._schedule_reevalutation = schedule_reevaluation
    scheduler_class._ncd_coalesced = True
    return True
