"""ncd: Contact Dynamics for rigid frictional discs (Moreau 2005 reproduction).

Public API::

    scene = ncd.make_scene(pos, radius, density, walls=..., gravity=..., mu=...)
    report = ncd.step(scene, h)                       # one Moreau-Jean step, in place
    eq = ncd.equilibrium_test(scene, h)               # u_f = 0 ? forces r = s/h
    problem = ncd.prepare_step(scene, h)              # the core problem of one step
    result, vel, spin = ncd.solve_problem(scene, problem, guess, review_order, settings)
    result = ncd.solve_local(W, q, mu)                # a problem in local form
"""
from .contacts import Contacts, detect_contacts
from .local_solver import project_cone_py as project_cone, solve_single_contact_py
from .model import InputError, Scene, SimulationError
from .nlgs import NLGSResult, SolverSettings, solve_discs, solve_local
from .scene import make_scene
from .stepper import (EquilibriumResult, StepProblem, StepReport, equilibrium_test,
                      kinetic_energy, prepare_step, solve_problem, step)

__version__ = "0.1.0"

__all__ = [
    "Contacts", "detect_contacts", "project_cone", "solve_single_contact_py", "InputError",
    "Scene", "SimulationError", "NLGSResult", "SolverSettings", "solve_discs", "solve_local",
    "make_scene", "EquilibriumResult", "StepProblem", "StepReport", "equilibrium_test",
    "kinetic_energy", "prepare_step", "solve_problem", "step", "__version__",
]
