"""Solver settings and the result of one NLGS run: the types every solver shares.

A :class:`SolverSettings` is checked once, when it is built (``__post_init__``), so
that every entry point can trust an instance of the exact type (:func:`check_settings_arg`)
and the kernels receive plain floats and ints.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ncd.core.errors import InputError
from ncd.core.validate import integer, real, show

CRITERIA = {"residual": 0, "change": 1}      # stopping criterion -> the kernels' code
FINISHES = ("none", "active_set")            # finishing stage after NLGS (ncd.solver.finish)
ACCELS = ("none", "anderson")                # the iteration: plain NLGS or Anderson-accelerated
MAX_SWEEPS = 10 ** 9      # sweep budget at most (the kernels count sweeps in int64)
MAX_ACCEL_MEMORY = 100    # stored differences of Anderson acceleration at most


@dataclass(frozen=True)
class SolverSettings:
    """NLGS settings: tolerance on the chosen criterion, sweep budget, variants.

    ``finish``: "none" or "active_set" (:mod:`ncd.solver.finish`: the iterate projected on
    the solutions with the contact statuses NLGS has settled, to ``finish_tol``).
    ``finish_presolve``: HiGHS's presolve before the finishing stage's LPs (``False``: off;
    on thin-cone slices of Figure 5 its reduced LP stalls the interior point, and the dual
    simplex that follows from scratch stops at the iteration cap: docs/solvers.md).
    ``observable_tol``: largest relative change of an observed quantity over the last
    residual checks for a converged run (:mod:`ncd.solver.convergence`).
    ``keep_best``: at ``max_sweeps`` return the iterate of smallest residual seen
    (``False``: the last sweep's, as LMGC90 and Siconos do; time stepping that goes on
    from the best iterate can gain energy).
    ``accel``: "none" or "anderson" (:mod:`ncd.solver.anderson`, ``accel_memory`` stored
    differences, 0 being plain NLGS; disc form only).
    ``local_exact``: exact solves of the drifting contacts' region where the residual
    stalls (:mod:`ncd.solver.local_exact`; disc form only).  Trade-offs: docs/solvers.md.
    """
    tol: float = 1e-8
    max_sweeps: int = 20000
    criterion: str = "residual"   # "residual" (natural map) or "change"
    check_every: int = 1          # sweeps between residual evaluations
    finish: str = "none"          # "none" or "active_set"
    finish_tol: float = 1e-10
    finish_presolve: bool = True
    observable_tol: float = 1e-6
    keep_best: bool = True
    accel: str = "none"           # "none" or "anderson"
    accel_memory: int = 20
    local_exact: bool = False

    def __post_init__(self) -> None:
        check_solver_settings(self)    # InputError naming the field

    def as_attrs(self) -> dict[str, float | int | str]:
        return {f"solver_{k}": int(v) if isinstance(v, bool) else v for k, v in asdict(self).items()}


@dataclass
class NLGSResult:
    """Impulses ``(n, 2)`` (normal, tangential), final status per contact and diagnostics."""
    impulse: np.ndarray
    status: np.ndarray
    sweeps: int
    residual: float
    change: float
    converged: bool
    finish_rounds: int = 0                  # LP projections of the finishing stage (0: none)
    finish_correction: float = 0.0          # relative L1 size of the accepted projection (0: none)
    observable_change: float = float("nan")  # relative change of the observable (nan: not observed)
    best_sweep: int = 0                     # sweep of the returned iterate (keep_best), 0: the last
    local_solves: int = 0                   # local exact solves (ncd.solver.local_exact; 0: none)

    @property
    def impulse_n(self) -> np.ndarray:
        return self.impulse[:, 0]

    @property
    def impulse_t(self) -> np.ndarray:
        return self.impulse[:, 1]


def check_solver_settings(settings: SolverSettings, name: str = "settings") -> SolverSettings:
    """Field checks of :class:`SolverSettings` (run by its ``__post_init__``). Values are
    stored back as plain float / int (frozen dataclass: ``object.__setattr__``), so that
    later checks, kernels and netCDF attributes see one type whatever the caller passed."""
    if not isinstance(settings, SolverSettings):
        raise InputError(f"{name} must be an ncd.SolverSettings; got {show(settings)}")
    object.__setattr__(settings, "tol", real(f"{name}.tol", settings.tol, 0.0, lo_open=True))
    object.__setattr__(settings, "max_sweeps", integer(f"{name}.max_sweeps", settings.max_sweeps, 1, MAX_SWEEPS))
    object.__setattr__(settings, "check_every", integer(f"{name}.check_every", settings.check_every, 1, MAX_SWEEPS))
    if not isinstance(settings.criterion, str) or settings.criterion not in CRITERIA:
        raise InputError(f"{name}.criterion = {settings.criterion!r} must be one of {sorted(CRITERIA)}")
    if not isinstance(settings.finish, str) or settings.finish not in FINISHES:
        raise InputError(f"{name}.finish = {settings.finish!r} must be one of {FINISHES}")
    for field in ("finish_tol", "observable_tol"):
        object.__setattr__(settings, field, real(f"{name}.{field}", getattr(settings, field), 0.0, lo_open=True))
    for field in ("keep_best", "local_exact", "finish_presolve"):
        if not isinstance(getattr(settings, field), (bool, np.bool_)):
            raise InputError(f"{name}.{field} = {getattr(settings, field)!r} must be True or False")
    if not isinstance(settings.accel, str) or settings.accel not in ACCELS:
        raise InputError(f"{name}.accel = {settings.accel!r} must be one of {ACCELS}")
    object.__setattr__(settings, "accel_memory",
                       integer(f"{name}.accel_memory", settings.accel_memory, 0, MAX_ACCEL_MEMORY))
    return settings


def check_settings_arg(settings: SolverSettings, name: str = "settings") -> SolverSettings:
    """A :class:`SolverSettings` argument. An instance of the exact type was checked when
    it was built (and is frozen); a subclass's instance is checked again."""
    if type(settings) is not SolverSettings:
        if not isinstance(settings, SolverSettings):
            raise InputError(f"{name} must be an ncd.SolverSettings; got {show(settings)}")
        check_solver_settings(settings, name)
    return settings
