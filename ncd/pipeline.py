"""Glue between Snakemake scripts and ncd: logging, threads, progress, settings.

Scripts under ``workflow/scripts`` stay thin: ``log = start(snakemake)``, read the
config section from ``snakemake.params.config``, call the figure module, write
with :func:`ncd.io.write_dataset`.
"""
import logging
import time

from .nlgs import SolverSettings


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
    logger.info("rule %s, threads %d (numba %d)", snakemake.rule, snakemake.threads, numba.get_num_threads())
    return logger


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
