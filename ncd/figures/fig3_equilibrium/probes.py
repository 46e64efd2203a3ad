"""Positions around Figure 3's packing on which the one-step equilibrium test is checked.

Section 2 of Moreau (2005): "a single computation step is enough: starting with u_i = 0,
one checks whether u_f = 0".  The exact answer to "is this position an equilibrium?" is
whether ``A ∩ C`` is non-empty (one LP, :meth:`ncd.exact.polytope.ForcePolytope.feasible`).
:func:`probe` runs both on a scene; the scenes are the stored packing rebuilt from
``state.nc`` (:func:`rebuild`), the same packing with one disc lifted off its supports
(:func:`lifted`: it can only fall) and the packing with its friction coefficient scaled
around :func:`least_friction`, the smallest coefficient for which ``A ∩ C`` is non-empty.
:func:`probe_dataset` runs them all; the rule ``fig3_equilibrium_probes`` writes it
(``probes.nc``), so that the §2 claim reads data instead of stepping when a page renders.
"""
from dataclasses import replace

import numpy as np
import xarray as xr
import yaml

from ncd.core.contacts import external_load, h_matrix
from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.stepper import equilibrium_test
from ncd.exact.polytope import ForcePolytope, PolytopeError
from ncd.figures.fig3_equilibrium.packing import rest_problem
from ncd.solver.settings import SolverSettings

FRICTION_MARGIN = 0.1   # the friction a tenth above and below the least that holds the packing
INITS = ("zero", "warm")


def rebuild(state, pos=None, mu=None):
    """The scene of ``state`` (warm-start memory included) at positions ``pos`` (default the
    stored ones) with friction ``mu`` (default the stored one)."""
    walls = [((float(state.wall_point_x[k]), float(state.wall_point_y[k])),
              (float(state.wall_normal_x[k]), float(state.wall_normal_y[k]))) for k in state.wall.values]
    pos = np.column_stack([state.x.values, state.y.values]) if pos is None else pos
    scene = make_scene(pos, state.radius.values, state.attrs["density"], walls=walls, gravity=state.attrs["gravity"],
                       mu=state.attrs["mu"] if mu is None else mu, overlap_tolerance=1.0)
    scene.prev_keys = state.key.values.copy()
    scene.prev_impulse = np.column_stack([state.warm_impulse_n.values, state.warm_impulse_t.values])
    return scene


def lifted(state, lift=0.5):
    """``(disc, scene)``: the packing with one disc raised by ``lift`` of its radius, the
    highest disc for which this leaves it touching no other disc and overlapping no wall
    deeper than the packing does (a side wall may still touch it: it then slides down the
    wall); ``(None, None)`` if no disc qualifies."""
    h = float(state.attrs["h"])
    floor = min(float(state.gap.values.min()), 0.0) if state.sizes.get("contact", 0) else 0.0
    pos0 = np.column_stack([state.x.values, state.y.values])
    for i in np.argsort(-(state.y.values + state.radius.values), kind="stable"):
        pos = pos0.copy()
        pos[i, 1] += lift * state.radius.values[i]
        try:
            scene = rebuild(state, pos)
        except InputError:              # an overlap beyond make_scene's tolerance
            continue
        c = rest_problem(scene, h).contacts
        mine = (c.body_a == i) | (c.body_b == i)
        if not np.any(mine & ((c.body_b >= 0) | (c.gap < floor))):
            return int(i), scene
    return None, None


def admits_equilibrium(scene, contacts):
    """Whether ``A ∩ C`` of ``scene`` on ``contacts`` is non-empty (one LP)."""
    P = ForcePolytope(h_matrix(scene, contacts), external_load(scene), contacts.mu)
    try:
        P.feasible()
    except PolytopeError as err:
        if "empty" not in str(err):
            raise
        return False
    return True


def least_friction(state, rel_tol=1e-3):
    """The smallest friction coefficient (all contacts alike) for which the stored packing
    admits equilibrium forces, by bisection on the LP (feasibility grows with ``mu``):
    0 when the packing stands without friction, NaN when it does not stand at the stored
    coefficient."""
    h = float(state.attrs["h"])

    def stands(mu):
        scene = rebuild(state, mu=mu)
        return admits_equilibrium(scene, rest_problem(scene, h).contacts)

    hi = float(state.attrs["mu"])
    if not stands(hi):
        return np.nan
    if stands(0.0):
        return 0.0
    lo = 0.0
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if stands(mid) else (mid, hi)
    return hi


def probe(scene, h, settings, init, velocity_tol):
    """The one-step test on ``scene`` from the guess ``init`` and the exact answer:
    ``(u_f = 0, max |u_f| / (|g| h), A ∩ C non-empty)``."""
    eq = equilibrium_test(scene, h, settings, init=init, velocity_tol=velocity_tol)
    return bool(eq.at_rest), float(eq.max_velocity), admits_equilibrium(scene, eq.contacts)


def probe_dataset(state):
    """The one-step test against the LP on the packing of ``state``, a disc lifted off its
    supports and the friction :data:`FRICTION_MARGIN` above and below the least that holds the
    packing, each from the zero and the warm guess (NLGS then the exact active-set finish):
    variables over ``(position, init)``; ``expected`` is 1 (an equilibrium), 0 (it can only
    fall) or -1 (decided by the LP alone)."""
    cfg = yaml.safe_load(state.attrs["config_yaml"])
    settings = replace(SolverSettings(**cfg["solver"]), finish="active_set")
    vtol, h = float(cfg["packing"]["velocity_tol"]), float(state.attrs["h"])
    positions = [("the packing", rebuild(state), 1)]
    disc, scene = lifted(state)
    if disc is not None:
        positions.append((f"disc {disc} lifted by half its radius", scene, 0))
    mu_star = least_friction(state)
    if np.isfinite(mu_star) and mu_star > 0:
        for f in (1 + FRICTION_MARGIN, 1 - FRICTION_MARGIN):
            positions.append((f"μ = {f:g} μ*", rebuild(state, mu=f * mu_star), -1))
    found = np.array([[probe(sc, h, settings, init, vtol) for init in INITS] for _, sc, _ in positions], float)
    dims = ("position", "init")
    return xr.Dataset(
        {"at_rest": (dims, found[..., 0].astype(np.int8), {"units": "1", "long_name": "one step from rest gives u_f = 0"}),
         "max_velocity": (dims, found[..., 1], {"units": "1", "long_name": "largest |u_f| over |g| h"}),
         "admits_equilibrium": (dims, found[..., 2].astype(np.int8), {"units": "1", "long_name": "A ∩ C non-empty (LP)"}),
         "expected": ("position", np.array([e for *_, e in positions], np.int8),
                      {"units": "1", "long_name": "an equilibrium (1), can only fall (0), decided by the LP alone (-1)"})},
        coords={"position": ("position", [n for n, *_ in positions],
                             {"units": "1", "long_name": "position on which the one-step equilibrium test runs"}),
                "init": list(INITS)},
        attrs={"mu_star": float(mu_star), "velocity_tol": vtol, "friction_margin": FRICTION_MARGIN})
