"""The two errors of the package, at the bottom so that every layer can raise them.

:class:`InputError` (a ``ValueError``) names the argument or key and the offending
value, raised before any kernel runs; :class:`SimulationError` is a state that went
non-finite or a solver that diverged, never silent NaN.
"""


class InputError(ValueError):
    """An argument, a scene or a configuration that is invalid (type, shape, range or physics)."""


class SimulationError(RuntimeError):
    """A state that went non-finite, or a solver that diverged, during stepping or solving."""
