"""ncd: Contact Dynamics for rigid frictional discs (Moreau 2005 reproduction).

Public API::

    scene = ncd.make_scene(pos, radius, density, walls=..., gravity=..., mu=...)
    report = ncd.step(scene, h)                       # one Moreau-Jean step, in place
    eq = ncd.equilibrium_test(scene, h)               # u_f = 0 ? forces r = s/h
    problem = ncd.prepare_step(scene, h)              # the core problem of one step
    result, vel, spin = ncd.solve_problem(scene, problem, guess, review_order, settings)
    result = ncd.solve_local(W, q, mu)                # a problem in local form

The package is layered, each subpackage importing only from those below it
(checked by ``lint-imports`` and ``tests/test_layers.py``): ``core`` (scene,
contacts, validation) < ``io`` < ``solver`` < ``exact`` | ``dynamics`` <
``shared`` < ``figures`` < ``studies`` < ``pages`` < ``pipeline``.

The public names load on first use (PEP 562): a workflow job that imports one layer that
needs no kernel, say ``ncd.pages.render`` or a shard merge, does not pay for importing numba
and the stepper, once per job over a hundred jobs per run.
"""
import importlib

from ncd.core.version import __version__

# public name -> (module, attribute)
_PUBLIC = {
    "Contacts": ("ncd.core.contacts", "Contacts"),
    "detect_contacts": ("ncd.core.contacts", "detect_contacts"),
    "InputError": ("ncd.core.errors", "InputError"),
    "SimulationError": ("ncd.core.errors", "SimulationError"),
    "Scene": ("ncd.core.model", "Scene"),
    "make_scene": ("ncd.core.scene", "make_scene"),
    "EquilibriumResult": ("ncd.dynamics.stepper", "EquilibriumResult"),
    "StepProblem": ("ncd.dynamics.stepper", "StepProblem"),
    "StepReport": ("ncd.dynamics.stepper", "StepReport"),
    "equilibrium_test": ("ncd.dynamics.stepper", "equilibrium_test"),
    "kinetic_energy": ("ncd.dynamics.stepper", "kinetic_energy"),
    "prepare_step": ("ncd.dynamics.stepper", "prepare_step"),
    "solve_problem": ("ncd.dynamics.stepper", "solve_problem"),
    "step": ("ncd.dynamics.stepper", "step"),
    "solve_discs": ("ncd.solver.nlgs", "solve_discs"),
    "solve_local": ("ncd.solver.nlgs", "solve_local"),
    "NLGSResult": ("ncd.solver.settings", "NLGSResult"),
    "SolverSettings": ("ncd.solver.settings", "SolverSettings"),
    "project_cone": ("ncd.solver.single_contact", "project_cone_py"),
    "solve_single_contact_py": ("ncd.solver.single_contact", "solve_single_contact_py"),
}

__all__ = [*_PUBLIC, "__version__"]


def __getattr__(name):
    """A public name, imported from its layer on first use and kept."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'ncd' has no attribute {name!r}")
    module, attribute = _PUBLIC[name]
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
