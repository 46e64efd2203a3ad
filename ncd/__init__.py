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
``pipeline`` < ``scenes`` < ``figures`` < ``studies`` < ``pages``.
"""
from ncd.core.contacts import Contacts, detect_contacts
from ncd.core.errors import InputError, SimulationError
from ncd.core.model import Scene
from ncd.core.scene import make_scene
from ncd.core.version import __version__
from ncd.dynamics.stepper import (
                                  EquilibriumResult,
                                  StepProblem,
                                  StepReport,
                                  equilibrium_test,
                                  kinetic_energy,
                                  prepare_step,
                                  solve_problem,
                                  step,
)
from ncd.solver.nlgs import solve_discs, solve_local
from ncd.solver.settings import NLGSResult, SolverSettings
from ncd.solver.single_contact import project_cone_py as project_cone
from ncd.solver.single_contact import solve_single_contact_py

__all__ = [
    "Contacts", "detect_contacts", "project_cone", "solve_single_contact_py", "InputError",
    "Scene", "SimulationError", "NLGSResult", "SolverSettings", "solve_discs", "solve_local",
    "make_scene", "EquilibriumResult", "StepProblem", "StepReport", "equilibrium_test",
    "kinetic_energy", "prepare_step", "solve_problem", "step", "__version__",
]
