"""Progress of a long computation in its job's log: done/total, rate and time left.

Here, below the science layers, so that a figure's computation can report progress
without importing the workflow glue above it.
"""
import time


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
