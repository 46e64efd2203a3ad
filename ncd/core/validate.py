"""Argument primitives shared by every layer: reals, integers, arrays, sparse matrices,
permutations, impulse guesses, and the decorators that turn non-finite results into errors.

Every public entry point checks its arguments first, so that no numba kernel is reached
with inconsistent sizes, out-of-range indices or non-finite data.  A check raises
:class:`ncd.InputError` naming the argument and the offending value, and returns the
argument in the form the kernels read.  Policy: arrays hold real numbers (no strings,
booleans, complex or ragged lists) and have exactly the stated shape (never reshaped);
scalars are real, finite and in range; a ``review_order`` is an integer permutation of
``range(n)``; an impulse guess is ``(n, 2)`` or flat ``(2 n,)``.  A solver that diverges
anyway ends in :class:`ncd.SimulationError` (:func:`finite_result`), never in silent NaN.
Each type's own checks live beside it: Scene in :mod:`ncd.core.model`, Contacts in
:mod:`ncd.core.contacts`, SolverSettings in :mod:`ncd.solver.settings`, the local form's
``W`` in :mod:`ncd.solver.nlgs`, steps in :mod:`ncd.dynamics.stepper`, ensembles in
:mod:`ncd.dynamics.explore`.
"""
import functools
import inspect
import numbers

import numpy as np
import scipy.sparse as sp

from ncd.core.errors import InputError, SimulationError
from ncd.core.jit import njit


def show(value):
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def shape_of(name, value):
    """``np.shape(value)``; a ragged nested list or a string is an InputError, not a numpy ValueError."""
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} = {show(value)} must be a number or an array of numbers, not a string")
    try:
        return np.shape(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {show(value)} is ragged or not an array of numbers") from None


def first_bad(name, arr, bad, why):
    idx = np.argwhere(bad)[0]
    where = ", ".join(str(int(i)) for i in idx)
    raise InputError(f"{name} {why}; {name}[{where}] = {arr[tuple(idx)]}")


def real(name, value, lo=-np.inf, hi=np.inf, lo_open=False, hi_open=False, allow_inf=False):
    """``value`` as a float in the interval ``lo .. hi`` (closed unless ``*_open``),
    finite unless ``allow_inf``."""
    if type(value) is float and lo <= value <= hi and (allow_inf or -np.inf < value < np.inf) \
            and not (lo_open and value == lo) and not (hi_open and value == hi):
        return value                                    # fast path: a valid Python float
    if isinstance(value, (str, bytes, bool, np.bool_)) or len(shape_of(name, value)) != 0:
        raise InputError(f"{name} = {show(value)} must be a real number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {show(value)} must be a real number") from None
    if isinstance(value, complex) or np.iscomplexobj(value):
        raise InputError(f"{name} = {show(value)} must be a real number")
    ok = (np.isfinite(v) or (allow_inf and not np.isnan(v))) and lo <= v <= hi \
        and not (lo_open and v == lo) and not (hi_open and v == hi)
    if not ok:
        span = ("(" if lo_open else "[") + f"{lo}, {hi}" + (")" if hi_open else "]")
        raise InputError(f"{name} = {value!r} is outside {span}")
    return v


def integer(name, value, lo=None, hi=None):
    """``value`` as an int (an integer type, not a float or a bool) in ``[lo, hi]``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InputError(f"{name} = {show(value)} must be an integer")
    v = int(value)
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(f"{name} = {v} is outside [{lo}, {'inf' if hi is None else hi}]")
    return v


def _shape_text(shape):
    return "(" + ", ".join("any" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def array(name, value, shape, finite=True, dtype=float):
    """``value`` as a C-contiguous array of ``dtype`` with exactly ``shape``
    (``None`` entries: any length), every entry finite unless ``finite=False``."""
    if type(value) is np.ndarray and value.dtype == dtype and value.ndim == len(shape) \
            and value.flags.c_contiguous and all(k is None or k == m for k, m in zip(shape, value.shape)) \
            and (not finite or all_finite(value.reshape(-1))):
        return value                                    # fast path: already what the kernels read
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {show(value)} is not an array of numbers") from None
    if raw.dtype.kind not in "iuf" and not (raw.size == 0 and raw.dtype.kind in "iufbO"):
        raise InputError(f"{name} must hold real numbers; got dtype {raw.dtype}: {show(value)}")
    if raw.ndim != len(shape) or any(s is not None and s != k for s, k in zip(shape, raw.shape)):
        raise InputError(f"{name} has shape {raw.shape}, expected {_shape_text(shape)}")
    arr = np.ascontiguousarray(raw, dtype=dtype)
    if finite and arr.size and not np.isfinite(arr).all():
        first_bad(name, arr, ~np.isfinite(arr), "must be finite")
    return arr


def sparse_matrix(name, M):
    """A scipy.sparse ``M`` as a CSR float matrix, its *structure* checked before anything
    reads it: indices within the shape, ``indptr`` monotone and consistent (a CSR or CSC
    with an index out of range, e.g. 1-based, segfaults a sparse product or corrupts the
    heap when converted), real and finite entries."""
    if M.dtype.kind not in "iuf":
        raise InputError(f"{name} must hold real numbers; got dtype {M.dtype}")
    fmt = M.format
    try:
        if fmt in ("csr", "csc", "bsr"):
            M.check_format(full_check=True)
        elif fmt == "coo":
            rows, cols = np.asarray(M.row), np.asarray(M.col)
            for what, idx, size in (("row", rows, M.shape[0]), ("column", cols, M.shape[1])):
                if idx.size and (idx.dtype.kind not in "iu" or idx.min() < 0 or idx.max() >= size):
                    raise ValueError(f"{what} index out of range [0, {size})")
    except (ValueError, TypeError, IndexError, OverflowError) as exc:
        raise InputError(f"{name} ({fmt}, shape {M.shape}) has an invalid structure: {exc}") from None
    out = sp.csr_matrix(M, dtype=float)
    out.sum_duplicates()
    if not np.isfinite(out.data).all():
        raise InputError(f"{name} must be finite; it holds {out.data[~np.isfinite(out.data)][0]!r}")
    return out


def matrix(name, M, shape=(None, None)):
    """A dense or scipy.sparse matrix as CSR float, finite, of ``shape`` (``None``
    entries: any); a sparse one through :func:`sparse_matrix` (its structure checked)."""
    if sp.issparse(M):
        out = sparse_matrix(name, M)
        if any(k is not None and k != m for k, m in zip(shape, out.shape)):
            raise InputError(f"{name} has shape {out.shape}, expected {_shape_text(shape)}")
        return out
    return sp.csr_matrix(array(name, M, shape))


def per_item(name, value, n, lo=-np.inf, hi=np.inf, lo_open=False):
    """A scalar broadcast to ``(n,)`` or an ``(n,)`` array, finite, in ``[lo, hi]``."""
    arr = array(name, value, () if len(shape_of(name, value)) == 0 else (n,))
    arr = np.broadcast_to(arr, (n,)).copy()
    bad = (arr < lo) | (arr > hi) | ((arr == lo) if lo_open else False)
    if np.any(bad):
        op = ">" if lo_open else ">="
        why = f"must be {op} {lo:g}" if hi == np.inf else f"must be in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
        first_bad(name, arr, bad, why)
    return arr


def permutation(name, order, n):
    """``order`` as an int64 permutation of ``range(n)`` (the identity if None)."""
    if order is None:
        return np.arange(n, dtype=np.int64)
    try:
        raw = np.asarray(order)
    except (TypeError, ValueError):
        raise InputError(f"{name} = {show(order)} is not an array of integers") from None
    if raw.ndim != 1 or len(raw) != n:
        raise InputError(f"{name} must be a permutation of range({n}); got shape {raw.shape}: {show(order)}")
    if n == 0:
        return np.zeros(0, np.int64)
    if raw.dtype.kind not in "iu":
        raise InputError(f"{name} must hold integers, a permutation of range({n}); got dtype {raw.dtype}")
    if raw.dtype.kind == "u" and raw.max() >= n:
        k = int(np.argmax(raw))
        raise InputError(f"{name}[{k}] = {raw[k]} is outside range({n})")
    arr = np.ascontiguousarray(raw, dtype=np.int64)
    bad = (arr < 0) | (arr >= n)
    if np.any(bad):
        k = int(np.argmax(bad))
        raise InputError(f"{name}[{k}] = {arr[k]} is outside range({n})")
    counts = np.bincount(arr, minlength=n)
    if counts.max() > 1:
        dup, missing = int(np.argmax(counts)), int(np.argmin(counts))
        raise InputError(f"{name} is not a permutation of range({n}): {dup} appears {counts[dup]} "
                         f"times and {missing} is missing")
    return arr


def impulse_guess(name, guess, n):
    """An initial impulse array: None (zeros), shape (n, 2) or (2 n,); finite."""
    if guess is None:
        return np.zeros((n, 2))
    shape = shape_of(name, guess)
    if shape not in ((n, 2), (2 * n,)):
        raise InputError(f"{name} has shape {shape}, expected ({n}, 2) (one impulse per contact)")
    return array(name, guess, shape).reshape(n, 2).copy()


F64 = np.dtype(np.float64)


def is_f64(a, shape):
    return type(a) is np.ndarray and a.dtype == F64 and a.shape == shape


@njit(cache=True)
def all_finite(a):
    for x in a:
        if not np.isfinite(x):
            return False
    return True


def finite_output(func):
    """Decorator of the NLGS entry points: a result (or, in disc form, ``vel`` and
    ``spin`` modified in place) that is not finite raises :class:`ncd.SimulationError`."""
    names = list(inspect.signature(func).parameters)
    slots = [(names.index(k), k) for k in ("vel", "spin") if k in names]   # looked up once, not per call

    @functools.wraps(func)
    def checked(*args, **kwargs):
        result = func(*args, **kwargs)
        arrays = [args[i] if i < len(args) else kwargs[k] for i, k in slots]
        finite_result(result, *arrays, where=func.__name__)
        return result
    return checked


def finite_result(result, *arrays, where="NLGS"):
    """Raise :class:`ncd.SimulationError` if a returned impulse or velocity is not
    finite (an NLGS that diverged), instead of handing back NaN."""
    for a in (result.impulse,) + arrays:
        if not (all_finite(a.reshape(-1)) if type(a) is np.ndarray and a.dtype == F64 else np.isfinite(a).all()):
            raise SimulationError(f"{where} diverged: non-finite impulses or velocities after "
                                  f"{result.sweeps} sweeps (residual {result.residual:.3g}); "
                                  f"is W positive semi-definite and are the data of a sane scale?")
    if result.residual != result.residual:                                      # NaN (inf is allowed)
        raise SimulationError(f"{where} diverged: NaN residual after {result.sweeps} sweeps (an overflow)")
    return result


def finite_problem(func):
    """Decorator of :func:`ncd.prepare_step`: a problem whose free velocities, Delassus
    blocks or bias overflowed (e.g. ``h * g`` beyond double precision) raises
    :class:`ncd.SimulationError` instead of being returned."""

    @functools.wraps(func)
    def checked(*args, **kwargs):
        problem = func(*args, **kwargs)
        for field in ("free_vel", "free_spin", "W", "bias", "pos_mid", "angle_mid"):
            if not all_finite(np.ascontiguousarray(getattr(problem, field)).reshape(-1)):
                raise SimulationError(f"the step's {field} overflowed double precision (h = {problem.h!r})")
        return problem
    return checked


def finite_value(func):
    """Decorator: a NaN or infinite float returned (an overflow) raises :class:`ncd.SimulationError`."""

    @functools.wraps(func)
    def checked(*args, **kwargs):
        value = func(*args, **kwargs)
        if not np.isfinite(value):
            raise SimulationError(f"{func.__name__} = {value} (overflow of the scene's values)")
        return value
    return checked
