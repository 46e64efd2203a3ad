"""numba's on-disk cache, keyed on the sources of the subpackages that hold kernels.

numba keys a cached function on its own file only (modification time and size): a
kernel that inlines or calls a function of another module keeps its stale machine code
when only that other module changes, so an edit of :mod:`ncd.solver.single_contact` would
not reach the NLGS sweep of :mod:`ncd.solver.kernels`.  The :func:`njit` below is numba's, with the cache
directory set, while a function is decorated, to
``<NUMBA_CACHE_DIR or ncd/__pycache__>/numba-<digest>``, the digest being that of every
source file of the kernel layers (:data:`KERNEL_LAYERS`): an edit there gives every
kernel a fresh cache, while an edit of a figure, a study or a page module keeps it.
"""
import hashlib
from functools import lru_cache
from pathlib import Path

import numba

PACKAGE = Path(__file__).resolve().parents[1]
KERNEL_LAYERS = ("core", "solver", "exact", "dynamics")   # the subpackages with @njit functions


@lru_cache(maxsize=1)
def cache_dir():
    """The cache directory of this version of the kernel sources."""
    h = hashlib.sha256()
    for layer in KERNEL_LAYERS:
        for p in sorted((PACKAGE / layer).rglob("*.py")):
            h.update(str(p.relative_to(PACKAGE)).encode())
            h.update(p.read_bytes())
    base = numba.config.CACHE_DIR or str(PACKAGE / "__pycache__")
    return str(Path(base) / f"numba-{h.hexdigest()[:16]}")


def njit(*args, **kwargs):
    """``numba.njit`` whose ``cache=True`` uses :func:`cache_dir`."""
    def decorate(func):
        saved = numba.config.CACHE_DIR
        numba.config.CACHE_DIR = cache_dir()
        try:
            return numba.njit(**kwargs)(func)
        finally:
            numba.config.CACHE_DIR = saved
    if args and callable(args[0]):
        return decorate(args[0])
    return decorate
