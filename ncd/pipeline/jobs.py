"""What every workflow job needs around its computation: logging, threads, signals, and
recovery of a killed run.

Scripts under ``workflow/scripts`` stay thin: ``log = start(snakemake)``, read the
config section from ``snakemake.params.config``, call the figure's package, write
with :func:`ncd.io.netcdf.write_dataset`.
"""
import logging
import os
import signal
import sys
import traceback
from pathlib import Path


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
