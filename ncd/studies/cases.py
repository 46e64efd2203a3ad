"""Small scenes for the studies, built deterministically from their parameters.

Length unit: the disc radius ``r`` (default 0.01 m), density 1 kg/m^2 (2-D), gravity
9.81 m/s^2.  Random jitter comes from ``numpy.random.default_rng(seed)`` only.
"""
import numpy as np

from ncd.core.scene import make_scene
from ncd.dynamics.stepper import kinetic_energy, step

G = 9.81


def box_walls(width):
    """Floor y = 0 and side walls x = 0, x = width (normals into the box)."""
    return [((0.0, 0.0), (0.0, 1.0)), ((0.0, 0.0), (1.0, 0.0)), ((width, 0.0), (-1.0, 0.0))]


def stack(mass_ratio, r=0.01):
    """A light disc on the floor carrying a disc ``mass_ratio`` times heavier, touching, at rest."""
    return make_scene([[0.0, r], [0.0, 3 * r]], r, [1.0, float(mass_ratio)],
                      walls=[((0.0, 0.0), (0.0, 1.0))], mu=0.5)


def box(n, mu=0.5, e=0.0, seed=0, r=0.01, columns=5, polydispersity=0.2, lift=0.3):
    """``n`` polydisperse discs (radii ``r (1 +- polydispersity/2)``) on a loose lattice
    ``columns`` wide, ``lift`` radii apart, released at rest above the floor of a box."""
    rng = np.random.default_rng(seed)
    rad = r * (1.0 + polydispersity * (rng.uniform(size=n) - 0.5))
    pitch = 2 * r * (1.0 + 0.5 * polydispersity) + lift * r
    width = columns * pitch
    i = np.arange(n)
    pos = np.column_stack([(i % columns + 0.5) * pitch + rng.uniform(-0.1, 0.1, n) * lift * r,
                           (i // columns + 0.5) * pitch + lift * r])
    return make_scene(pos, rad, 1.0, walls=box_walls(width), mu=mu, e_n=e)


def chain(n, speed, e=1.0, r=0.01, gap=0.5):
    """Newton's cradle without gravity: a striker at ``speed``, ``gap`` radii away from a
    row of ``n - 1`` touching discs at rest; frictionless, restitution ``e``."""
    x = np.concatenate([[0.0], 2 * r + gap * r + 2 * r * np.arange(n - 1)])
    vel = np.zeros((n, 2))
    vel[0, 0] = speed
    return make_scene(np.column_stack([x, np.zeros(n)]), r, 1.0, gravity=(0.0, 0.0), mu=0.0,
                      e_n=e, vel=vel)


def impact_wall(speed, r=0.01, distance=2.0):
    """A disc ``distance`` radii from a wall (x = 0), flying at it at ``speed``; no gravity."""
    return make_scene([[(1.0 + distance) * r, 0.0]], r, 1.0, walls=[((0.0, 0.0), (1.0, 0.0))],
                      gravity=(0.0, 0.0), mu=0.5, vel=[[-speed, 0.0]])


def impact_disc(speed, r=0.01, distance=2.0):
    """A disc flying at ``speed`` at a disc at rest ``distance`` radii away; no gravity, e = 0."""
    return make_scene([[0.0, 0.0], [(2.0 + distance) * r, 0.0]], r, 1.0, gravity=(0.0, 0.0),
                      mu=0.5, vel=[[speed, 0.0], [0.0, 0.0]])


def hexagonal(rows, columns, r=0.01, mu=0.5):
    """A dense hexagonal packing at rest in a box: ``columns`` touching discs on even rows,
    ``columns - 1`` on odd rows, every contact closed (hyperstatic)."""
    pos = []
    for j in range(rows):
        odd = j % 2
        for i in range(columns - odd):
            pos.append([r + 2 * r * i + odd * r, r + j * np.sqrt(3.0) * r])
    return make_scene(np.array(pos), r, 1.0, walls=box_walls(2 * r * columns), mu=mu)


def pile(n_base, mu=0.5, seed=0, r=0.01, polydispersity=0.2):
    """A triangular heap (``n_base`` discs at the base) on a rough floor of fixed discs,
    polydisperse, released at rest with small gaps."""
    rng = np.random.default_rng(seed)
    pitch = 2 * r * (1.0 + 0.5 * polydispersity) * 1.02
    pos = [[(i + 0.5 * j) * pitch, 1.3 * r + j * pitch * np.sqrt(3.0) / 2]
           for j in range(n_base) for i in range(n_base - j)]
    pos = np.array(pos)
    rad = r * (1.0 + polydispersity * (rng.uniform(size=len(pos)) - 0.5))
    span = n_base * pitch
    ox = np.arange(-0.5 * span, 1.5 * span, 1.6 * r)
    return make_scene(pos, rad, 1.0, obstacle_pos=np.column_stack([ox, np.zeros(len(ox)) - 0.8 * r]),
                      obstacle_radius=0.9 * r, mu=mu,
                      walls=[((0.0, 0.0), (0.0, 1.0)), ((ox[0], 0.0), (1.0, 0.0)), ((ox[-1], 0.0), (-1.0, 0.0))])


def slope(columns, layers, angle_deg=24.0, mu=0.5, seed=0, r=0.01, polydispersity=0.2):
    """A periodic chute: ``columns x layers`` polydisperse discs at rest on a rough base of
    fixed discs, gravity tilted by ``angle_deg`` (ground sloping down to the right)."""
    rng = np.random.default_rng(seed)
    pitch = 2 * r * (1.0 + 0.5 * polydispersity) * 1.02
    period = columns * pitch
    i = np.arange(columns * layers)
    pos = np.column_stack([(i % columns + 0.5 + 0.5 * ((i // columns) % 2)) * pitch,
                           1.2 * r + (i // columns) * pitch * 0.9 + 0.5 * r])
    rad = r * (1.0 + polydispersity * (rng.uniform(size=len(pos)) - 0.5))
    nb = int(round(period / (1.6 * r)))
    ox = (np.arange(nb) + 0.5) * period / nb
    a = np.radians(angle_deg)
    return make_scene(pos, rad, 1.0, obstacle_pos=np.column_stack([ox, np.full(nb, -0.4 * r)]),
                      obstacle_radius=0.9 * r, walls=[((0.0, -0.4 * r), (0.0, 1.0))],
                      gravity=(G * np.sin(a), -G * np.cos(a)), mu=mu, period=period)


def settle(scene, h, duration, settings, min_duration=0.0, ke_tol=1e-9):
    """Contact Dynamics steps until ``duration`` or, after ``min_duration``, until the
    kinetic energy per unit weight-radius falls below ``ke_tol``; returns the step count."""
    scale = scene.mobile_mass.sum() * G * scene.radius[: scene.n_mobile].mean()
    n = int(round(duration / h))
    for k in range(n):
        step(scene, h, settings=settings)
        if scene.time >= min_duration and kinetic_energy(scene) < ke_tol * scale:
            return k + 1
    return n
