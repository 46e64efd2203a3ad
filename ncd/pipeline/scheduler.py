"""A patch of Snakemake's job scheduler loop (its internals: the reason pyproject pins
Snakemake's major version)."""


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
