"""Checks of ncd against closed-form mechanics.

Every test derives its expected numbers in its docstring and asserts them with
tolerances that a wrong sign, a missing factor or a wrong contact law would
break.  Conventions (``ncd.core.contacts``): the normal ``n`` of a contact points
from body b to the mobile disc a, ``t = (-n_y, n_x)``,
``U_n = (v_a - v_b).n``, ``U_t = (v_a - v_b).t - r_a w_a - r_b w_b``, and the
impulse ``(s_n, s_t)`` acts on a as ``s_n n + s_t t`` with torque
``-r_a s_t``.  Forces are impulses divided by ``h``.
"""
import numpy as np
import pytest

import ncd
from ncd.core.contacts import detect_contacts, h_matrix, key_order, local_velocity, pair_key
from ncd.core.detection import disc_pairs
from ncd.solver.single_contact import (
    NO_CONTACT,
    SLIDE_BACKWARD,
    SLIDE_FORWARD,
    STICK,
    solve_disc_contact,
    solve_single_contact,
)

G = 9.81
FLOOR = [((0.0, 0.0), (0.0, 1.0))]


# ----------------------------------------------------------------- helpers
def assert_coulomb(s, U, mu, atol_s, atol_u):
    """Assert the impulsional Signorini-Coulomb law at every contact.

    ``s, U`` are (n, 2) impulses and local velocities, ``mu`` (n,).  The law:
    ``s_n >= 0``, ``U_n >= 0``, ``s_n U_n = 0``, ``|s_t| <= mu s_n`` and, where
    the contact slides (``U_t != 0``), ``s_t = -sign(U_t) mu s_n``.
    """
    s, U = np.atleast_2d(s), np.atleast_2d(U)
    mu = np.broadcast_to(mu, (len(s),))
    assert np.all(s[:, 0] >= -atol_s), s[:, 0].min()
    assert np.all(U[:, 0] >= -atol_u), U[:, 0].min()
    assert np.all((s[:, 0] <= atol_s) | (np.abs(U[:, 0]) <= atol_u)), "complementarity s_n U_n = 0"
    assert np.all(np.abs(s[:, 1]) <= mu * s[:, 0] + atol_s), "impulse outside the Coulomb cone"
    sliding = np.abs(U[:, 1]) > atol_u
    err = np.abs(s[sliding, 1] + np.sign(U[sliding, 1]) * mu[sliding] * s[sliding, 0])
    assert np.all(err <= atol_s), f"sliding contact not on the cone edge opposite to U_t: {err.max()}"


def resultant(forces, contacts, mask):
    """Sum of the forces ``s_n n + s_t t`` of the masked contacts (on the mobile discs)."""
    f = forces[mask, 0:1] * contacts.normal[mask] + forces[mask, 1:2] * contacts.tangent[mask]
    return f.sum(axis=0)


def container_heap(seed, rows=5, width=6, mu=0.5):
    """About 28 polydisperse discs dropped in a U of fixed discs (rough floor and sides)."""
    rng = np.random.default_rng(seed)
    half = (width + 1) / 2 + 0.5
    fx = np.arange(-half, half + 0.01, 1.0)
    fy = np.arange(1.0, rows * 0.9 + 1.01, 1.0)
    fixed = np.vstack([np.column_stack([fx, np.zeros_like(fx)]),
                       np.column_stack([np.full_like(fy, -half), fy]),
                       np.column_stack([np.full_like(fy, half), fy])])
    pos, rad = [], []
    for k in range(rows):
        nr = width if k % 2 == 0 else width - 1
        for j in range(nr):
            pos.append([(j - (nr - 1) / 2) * 1.0, 0.95 + 0.9 * k])
            rad.append(rng.uniform(0.35, 0.45))
    return ncd.make_scene(np.array(pos), np.array(rad), rng.uniform(1.0, 2.0, len(rad)),
                          obstacle_pos=fixed, obstacle_radius=0.5, mu=mu)


H_HEAP = 2e-3


@pytest.fixture(scope="module")
def settled_heap():
    """The container heap stepped until its kinetic energy is below 1e-10 (about 1 s)."""
    scene = container_heap(seed=0)
    for _ in range(3000):
        ncd.step(scene, H_HEAP, settings=ncd.SolverSettings(tol=1e-6))
        if scene.time > 0.2 and ncd.kinetic_energy(scene) < 1e-10:
            break
    assert ncd.kinetic_energy(scene) < 1e-10, "the heap did not settle"
    return scene


# ----------------------------------------------------------------- incline
ALPHA = np.radians(25.0)
MU_ROLL = np.tan(ALPHA) / 3.0


@pytest.mark.parametrize("factor", [0.5, 0.97, 1.03, 2.0])
def test_disc_on_incline(factor):
    """A disc (m, r, I = m r^2 / 2) on a slope of angle alpha, released at rest.

    The slope is the floor ``y = 0`` with gravity tilted:
    ``g = g (sin alpha, -cos alpha)``; the contact has ``n = (0, 1)``,
    ``t = (-1, 0)`` so ``U_t = -v_x - r w``.  The normal force is
    ``N = m g cos alpha``.

    Rolling without slip (``U_t = 0``, ``w = -v_x / r``): from
    ``m a = m g sin alpha - F`` and ``I (-w') = r F`` with ``a = -r w'``,
    ``a = g sin alpha / (1 + I / (m r^2)) = 2/3 g sin alpha`` and the friction
    force ``F = m g sin alpha / 3`` (pointing up the slope, so
    ``s_t = +F h``).  It is admissible iff ``F <= mu N``, i.e.
    ``mu >= tan(alpha) / 3``.

    Below that threshold the disc slides: ``F = mu N``,
    ``a = g (sin alpha - mu cos alpha)``, ``w' = -r F / I = -2 mu g cos alpha / r``
    and ``U_t = g t (3 mu cos alpha - sin alpha) < 0``, hence ``s_t = +mu s_n``.

    The accelerations are constant, so the theta = 1/2 scheme is exact:
    ``v = a t``, ``x = a t^2 / 2``.
    """
    mu = factor * MU_ROLL
    r, rho, h, n_steps = 0.3, 2.0, 1e-3, 60
    scene = ncd.make_scene([[0.0, r]], r, rho, walls=FLOOR, mu=mu,
                           gravity=(G * np.sin(ALPHA), -G * np.cos(ALPHA)))
    m = scene.mass[0]
    for _ in range(n_steps):
        report = ncd.step(scene, h)
        assert report.n_contacts == 1 and report.converged
    t = n_steps * h
    normal_force, friction = scene.prev_impulse[0] / h
    assert normal_force == pytest.approx(m * G * np.cos(ALPHA), rel=1e-10)
    assert scene.vel[0, 1] == pytest.approx(0.0, abs=1e-12)
    if mu >= MU_ROLL:
        a = 2.0 / 3.0 * G * np.sin(ALPHA)
        assert friction == pytest.approx(m * G * np.sin(ALPHA) / 3.0, rel=1e-10)
        assert scene.spin[0] == pytest.approx(-a * t / r, rel=1e-10)
    else:
        a = G * (np.sin(ALPHA) - mu * np.cos(ALPHA))
        assert friction == pytest.approx(mu * normal_force, rel=1e-10)
        assert scene.spin[0] == pytest.approx(-2.0 * mu * G * np.cos(ALPHA) / r * t, rel=1e-10)
        # it really slips: the contact point moves backwards, U_t = g t (3 mu cos - sin) < 0
        slip = G * t * (3.0 * mu * np.cos(ALPHA) - np.sin(ALPHA))
        assert slip < 0
        assert -scene.vel[0, 0] - r * scene.spin[0] == pytest.approx(slip, rel=1e-9)
    assert scene.vel[0, 0] == pytest.approx(a * t, rel=1e-10)
    assert scene.pos[0, 0] == pytest.approx(0.5 * a * t * t, rel=1e-9)
    assert scene.pos[0, 1] == pytest.approx(r, abs=1e-12)


# ----------------------------------------------------------------- column
def test_column_at_rest():
    """A vertical column of k discs (different radii and densities) on the floor.

    Each disc is in equilibrium under its weight and the two contact forces
    along the vertical; by induction from the top, the contact below disc i
    carries the weight of discs i..k-1 and no tangential force (a tangential
    force would need a torque to balance, and there is none).  The contact
    between discs i and i+1 has a = i (lower), b = i+1, so n points down and
    its normal force is the weight of the discs above it (compression >= 0).
    """
    radius = np.array([0.5, 0.3, 0.45, 0.2, 0.35])
    density = np.array([1.0, 3.0, 0.5, 2.0, 1.5])
    y = radius + np.concatenate([[0.0], np.cumsum(2 * radius[:-1])])
    scene = ncd.make_scene(np.column_stack([np.zeros(5), y]), radius, density, walls=FLOOR, mu=0.3)
    h = 1e-3
    eq = ncd.equilibrium_test(scene, h, settings=ncd.SolverSettings(tol=1e-12, max_sweeps=100000))
    assert eq.at_rest and eq.result.converged
    weight = scene.mass[:5] * G
    above = np.cumsum(weight[::-1])[::-1]           # weight of discs i..k-1
    c = eq.contacts
    assert c.n == 5
    expected = np.empty(5)
    wall = c.body_b < 0
    assert np.count_nonzero(wall) == 1 and c.body_a[wall][0] == 0
    expected[wall] = above[0]
    pair = ~wall
    assert np.all(c.body_b[pair] == c.body_a[pair] + 1)
    expected[pair] = above[c.body_b[pair]]
    np.testing.assert_allclose(eq.forces[:, 0], expected, rtol=1e-8)
    np.testing.assert_allclose(eq.forces[:, 1], 0.0, atol=1e-10 * above[0])


# ----------------------------------------------------------------- collisions
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("angle_deg", [0.0, 35.0])
def test_binary_collision(e, angle_deg):
    """Two frictionless discs (masses m1 != m2) colliding, no gravity.

    With the normal n of the contact (from disc 1 to disc 0, taken at the middle
    configuration where the step detects it) and ``U_i = (v0 - v1).n < 0``,
    Newton's law ``U_f = -e U_i`` and momentum conservation give the normal
    impulse ``s_n = -(1 + e) m_red U_i`` (``m_red = m0 m1 / (m0 + m1)``):
    ``v0' = v0 + s_n n / m0``, ``v1' = v1 - s_n n / m1``; the tangential
    velocities and the spins are unchanged (mu = 0), and the kinetic energy
    lost is ``(1 - e^2) m_red U_i^2 / 2``.  ``angle_deg`` tilts the line of
    centres (oblique impact: the tangential relative velocity is non-zero).
    """
    phi = np.radians(angle_deg)
    d = np.array([np.cos(phi), np.sin(phi)])
    r0, r1 = 0.5, 0.3
    v0, v1 = np.array([1.0, 0.4]), np.array([-0.5, -0.3])
    scene = ncd.make_scene([[0.0, 0.0], (r0 + r1) * d], [r0, r1], [1.0, 3.0], gravity=(0.0, 0.0),
                           vel=[v0, v1], e_n=e, mu=0.0)
    h = 1e-3
    n = ncd.prepare_step(scene, h).contacts.normal[0]
    m0, m1 = scene.mass[:2]
    m_red = m0 * m1 / (m0 + m1)
    u_i = (v0 - v1) @ n
    assert u_i < 0
    ke0 = ncd.kinetic_energy(scene)
    report = ncd.step(scene, h)
    assert report.n_contacts == 1 and report.converged
    s_n = -(1.0 + e) * m_red * u_i
    np.testing.assert_allclose(scene.prev_impulse[0], [s_n, 0.0], rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(scene.vel[0], v0 + s_n * n / m0, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(scene.vel[1], v1 - s_n * n / m1, rtol=1e-10, atol=1e-14)
    assert (scene.vel[0] - scene.vel[1]) @ n == pytest.approx(-e * u_i, rel=1e-10, abs=1e-14)
    np.testing.assert_allclose(scene.spin[:2], 0.0, atol=1e-14)
    loss = ke0 - ncd.kinetic_energy(scene)
    assert loss == pytest.approx((1.0 - e * e) * 0.5 * m_red * u_i ** 2, rel=1e-10, abs=1e-14)


# ----------------------------------------------------------------- wedged disc
def test_wedged_disc_indetermination():
    """Moreau 2005, figure 1: a disc B below the line of centres of two fixed discs.

    B (radius r) touches two fixed discs (radius R) centred at ``(-+d, 0)``, its
    centre at ``(0, -y)``; the normals make an angle phi below the horizontal:
    ``n_left = (cos phi, -sin phi)``, ``n_right = (-cos phi, -sin phi)``.  The
    normals push B down, so only friction can hold it.  The free velocity
    ``u_free = h g`` gives ``U_n = h g sin phi > 0`` at both contacts, so zero
    impulses with ``u_f = h g`` (free fall) are a solution, the one NLGS finds
    from a zero guess.

    Equilibrium: with symmetric impulses ``(s_n, s_t)`` and ``(s_n, -s_t)``,
    the horizontal components cancel, the torques ``-r s_t + r s_t`` cancel,
    and the vertical balance is ``2 (s_t cos phi - s_n sin phi) = m g h``.
    Coulomb ``s_t <= mu s_n`` then requires
    ``s_n >= m g h / (2 (mu cos phi - sin phi))``: a whole half-line of
    solutions (the indetermination) when ``mu > tan phi``.  Started from one of
    them, NLGS stays there (``u_f = 0``); started from large normal impulses,
    it converges to another wedged solution.
    """
    R, r, phi, mu, g, h = 1.0, 0.5, np.radians(20.0), 0.6, G, 1e-3
    assert mu > np.tan(phi)
    L = R + r
    scene = ncd.make_scene([[0.0, -L * np.sin(phi)]], r, 1.0, mu=mu, gravity=(0.0, -g),
                           obstacle_pos=[[-L * np.cos(phi), 0.0], [L * np.cos(phi), 0.0]],
                           obstacle_radius=R)
    problem = ncd.prepare_step(scene, h, theta=1.0)
    c = problem.contacts
    assert c.n == 2 and set(c.body_b) == {1, 2}
    m = scene.mass[0]
    settings = ncd.SolverSettings(tol=1e-12, max_sweeps=100000)

    free, vel, spin = ncd.solve_problem(scene, problem, None, settings=settings)
    assert free.converged and free.residual <= settings.tol
    np.testing.assert_array_equal(free.impulse, 0.0)
    np.testing.assert_allclose(vel[0], [0.0, -g * h], rtol=1e-14)

    sn_min = m * g * h / (2.0 * (mu * np.cos(phi) - np.sin(phi)))
    sn = 1.5 * sn_min
    st = (m * g * h / 2.0 + sn * np.sin(phi)) / np.cos(phi)
    left = int(np.argmax(c.normal[:, 0]))          # left obstacle: its normal points right
    exact = np.zeros((2, 2))
    exact[left] = [sn, st]
    exact[1 - left] = [sn, -st]
    big = np.array([[100.0 * m * g * h, 0.0]] * 2)
    wedged = []
    for guess in (exact, big):
        result, vel, spin = ncd.solve_problem(scene, problem, guess, settings=settings)
        assert result.converged and result.residual <= settings.tol
        assert np.abs(vel[0]).max() <= 1e-9 * g * h and abs(spin[0]) * r <= 1e-9 * g * h
        s = result.impulse
        assert np.all(s[:, 0] > sn_min * 0.999)       # strictly wedged
        np.testing.assert_allclose(resultant(s / h, c, np.ones(2, bool)), [0.0, m * g],
                                   atol=1e-9 * m * g)
        assert np.all(np.abs(s[:, 1]) <= mu * s[:, 0])
        U = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((2, 2)))
        assert_coulomb(s, U, c.mu, 1e-12 * m * g * h, 1e-9 * g * h)
        wedged.append(s)
    # the exact equilibrium is a fixed point of NLGS; the large guess lands on
    # another member of the solution half-line
    np.testing.assert_allclose(wedged[0], exact, rtol=1e-12)
    assert wedged[1][0, 0] > 2.0 * sn


# ----------------------------------------------------------------- heap
def test_heap_ground_reaction_equals_weight(settled_heap):
    """The settled heap is an equilibrium; its support carries its weight.

    ``equilibrium_test`` solves one step from zero velocity with theta = 1:
    ``M u_f = h m g + H s``.  If ``u_f = 0`` every mobile disc balances, and
    summing over the discs the disc-disc impulses cancel pairwise (action and
    reaction), leaving: sum of the obstacle contact forces (floor and side
    discs of the U) ``= -total weight = (0, M g)``; the horizontal components
    of the side reactions cancel with those of the floor.
    """
    scene = settled_heap
    eq = ncd.equilibrium_test(scene, H_HEAP, init="warm",
                              settings=ncd.SolverSettings(tol=1e-10, max_sweeps=200000))
    assert eq.at_rest and eq.result.converged and eq.max_velocity < 1e-6
    c = eq.contacts
    obstacle = c.body_b >= scene.n_mobile
    assert np.count_nonzero(obstacle) >= 6 and c.n > scene.n_mobile
    weight = scene.mobile_mass.sum() * G
    np.testing.assert_allclose(resultant(eq.forces, c, obstacle), [0.0, weight], atol=1e-7 * weight)
    # and the same from a zero guess
    eq0 = ncd.equilibrium_test(scene, H_HEAP, init="zero",
                               settings=ncd.SolverSettings(tol=1e-10, max_sweeps=200000))
    assert eq0.at_rest
    np.testing.assert_allclose(resultant(eq0.forces, c, obstacle), [0.0, weight], atol=1e-7 * weight)


# ----------------------------------------------------------------- local form
def _law_in_local_form(W, q, mu, result, tol):
    s = result.impulse
    U = (W @ s.ravel() + q).reshape(-1, 2)
    scale_s = np.abs(s).max()
    scale_u = np.abs(q).max()
    assert_coulomb(s, U, mu, 1e3 * tol * scale_s, 1e3 * tol * scale_u)


def test_solve_local_matches_disc_form(settled_heap):
    """Local form ``U = W s + q`` with ``W = H^T M^-1 H`` vs the disc form.

    With ``q = H^T u_free`` the two forms are the same problem, and NLGS in the
    same review order computes the same Gauss-Seidel iterates: contact alpha is
    solved with ``q_alpha = U_alpha(current) - W_alpha,alpha s_alpha``, where
    ``U(current) = H^T (u_free + M^-1 H s) = W s + q``.  So impulses agree to
    rounding and the sweep counts match; the result satisfies the law.
    """
    scene = settled_heap
    rng = np.random.default_rng(7)
    c = detect_contacts(scene, alert=1e-9)
    nm = scene.n_mobile
    c.mu = rng.uniform(0.0, 1.0, c.n)
    H = h_matrix(scene, c)
    minv = np.repeat(scene.inv_mass[:nm], 3)
    minv[2::3] = scene.inv_inertia[:nm]
    W = (H.T @ H.multiply(minv[:, None])).toarray()
    vel = np.zeros_like(scene.vel)
    spin = np.zeros_like(scene.spin)
    vel[:nm] = rng.normal(size=(nm, 2)) + [0.0, -2.0]
    spin[:nm] = rng.normal(size=nm)
    u = np.column_stack([vel[:nm], spin[:nm]]).ravel()
    q = H.T @ u
    order = rng.permutation(c.n)
    settings = ncd.SolverSettings(tol=1e-10, max_sweeps=100000)
    local = ncd.solve_local(W, q, c.mu, review_order=order, settings=settings)
    disc = ncd.solve_discs(scene, c, vel, spin, review_order=order, settings=settings)
    assert local.converged and local.residual <= settings.tol
    assert disc.converged and disc.residual <= settings.tol
    assert abs(local.sweeps - disc.sweeps) <= 1
    np.testing.assert_allclose(local.impulse, disc.impulse, rtol=0, atol=1e-10 * np.abs(disc.impulse).max())
    assert np.count_nonzero(local.impulse[:, 0] > 0) > 5
    _law_in_local_form(W, q, c.mu, local, settings.tol)
    # the disc form ends with u_f = u_free + M^-1 H s
    u_f = np.column_stack([vel[:nm], spin[:nm]]).ravel()
    np.testing.assert_allclose(u_f, u + minv * (H @ disc.impulse.ravel()), atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_solve_local_random_spd(seed):
    """A random SPD ``W = B^T B + I/2 + C`` (couplings between all contacts; ``C``
    block diagonal with ``[[0, c], [c, 0]]``, ``|c| <= 0.35 < 1/2``, so the 2x2
    diagonal blocks are genuinely non-diagonal and W stays SPD), random ``q`` and
    ``mu`` per contact: NLGS converges and the result satisfies the law."""
    rng = np.random.default_rng(seed)
    n = 12
    B = rng.normal(size=(3 * n, 2 * n)) / np.sqrt(3 * n)
    W = B.T @ B + 0.5 * np.eye(2 * n)
    c = rng.uniform(0.1, 0.35, n) * np.sign(W[0::2, 1::2].diagonal())
    W[2 * np.arange(n), 2 * np.arange(n) + 1] += c
    W[2 * np.arange(n) + 1, 2 * np.arange(n)] += c
    assert np.linalg.eigvalsh(W).min() > 0.1
    q = rng.normal(size=2 * n)
    mu = rng.uniform(0.1, 1.0, n)
    assert np.abs(W[0::2, 1::2].diagonal()).min() > 0.1
    settings = ncd.SolverSettings(tol=1e-10, max_sweeps=100000)
    result = ncd.solve_local(W, q, mu, review_order=rng.permutation(n), settings=settings)
    assert result.converged and result.residual <= settings.tol
    statuses = set(result.status.tolist())
    assert NO_CONTACT in statuses and len(statuses) >= 3
    _law_in_local_form(W, q, mu, result, settings.tol)


# ----------------------------------------------------------------- single contact
W_COUPLED = np.array([[2.0, 0.6], [0.6, 1.5]])


@pytest.mark.parametrize("q, mu, expected", [
    ((0.3, -1.0), 0.5, NO_CONTACT),
    ((-1.0, 0.1), 1.0, STICK),
    ((-1.0, 5.0), 0.3, SLIDE_FORWARD),
    ((-1.0, -5.0), 0.3, SLIDE_BACKWARD),
])
def test_single_contact_cases(q, mu, expected):
    """The exact single-contact solver on a coupled block ``W`` (``W_nt = 0.6``).

    Closed forms: no contact ``r = 0`` when ``q_n >= 0``; stick
    ``r = -W^-1 q`` when inside the cone; sliding with ``U_t > 0`` means
    ``r_t = -mu r_n`` and ``U_n = 0``: ``r_n = -q_n / (W_nn - mu W_nt)``;
    sliding with ``U_t < 0``: ``r_n = -q_n / (W_nn + mu W_nt)``.
    """
    W = W_COUPLED
    rn, rt, status = solve_single_contact(W[0, 0], W[0, 1], W[1, 0], W[1, 1], q[0], q[1], mu)
    assert status == expected
    r = np.array([rn, rt])
    U = W @ r + np.asarray(q)
    if expected == NO_CONTACT:
        np.testing.assert_array_equal(r, 0.0)
    elif expected == STICK:
        np.testing.assert_allclose(r, -np.linalg.solve(W, q), rtol=1e-14)
        assert abs(U[1]) < 1e-14
    else:
        sigma = 1.0 if expected == SLIDE_FORWARD else -1.0
        assert rn == pytest.approx(-q[0] / (W[0, 0] - sigma * mu * W[0, 1]), rel=1e-14)
        assert rt == pytest.approx(-sigma * mu * rn, rel=1e-14)
        assert sigma * U[1] > 0
    assert_coulomb(r, U, mu, 1e-14, 1e-14)


def test_single_contact_random():
    """2000 random SPD coupled blocks, ``q`` and ``mu`` in [0, 3]: the solver
    never needs its fallback and always returns a solution of the law."""
    rng = np.random.default_rng(3)
    counts = np.zeros(5, int)
    for _ in range(2000):
        A = rng.normal(size=(2, 2))
        W = A @ A.T + 0.05 * np.eye(2)
        q = rng.normal(size=2)
        mu = rng.uniform(0.0, 3.0)
        rn, rt, status = solve_single_contact(W[0, 0], W[0, 1], W[1, 0], W[1, 1], q[0], q[1], mu)
        counts[status] += 1
        r = np.array([rn, rt])
        scale = 1e-10 * (1.0 + np.abs(r).max() + np.abs(q).max())
        assert_coulomb(r, W @ r + q, mu, scale, scale * (1.0 + np.abs(W).max()))
    assert counts[4] == 0 and np.all(counts[:4] > 100)


def _bits(x):
    return np.float64(x).view(np.int64)


def test_disc_contact_solver_is_the_general_one_bit_for_bit():
    """solve_disc_contact (the sweep's diagonal-block case) against solve_single_contact
    with W_nt = W_tn = 0: the same impulses bit for bit (signed zeros included) and the same
    status, over blocks, velocities and mu spanning many decades, mu = 0, and q_t = +-0.
    The comparison is of bit patterns: +0 and -0 differ there."""
    assert _bits(0.0) != _bits(-0.0)
    rng = np.random.default_rng((7, 52))
    counts = np.zeros(5, int)
    for k in range(20000):
        wnn, wtt = 10.0 ** rng.uniform(-6, 6, 2)
        qn, qt = rng.choice([-1.0, 1.0], 2) * 10.0 ** rng.uniform(-12, 3, 2)
        if k % 7 == 0:
            qt = [0.0, -0.0][k % 2]
        mu = 0.0 if k % 11 == 0 else 10.0 ** rng.uniform(-4, 1)
        a = solve_single_contact(wnn, 0.0, 0.0, wtt, qn, qt, mu)
        b = solve_disc_contact(wnn, wtt, qn, qt, mu)
        assert (_bits(a[0]), _bits(a[1]), a[2]) == (_bits(b[0]), _bits(b[1]), b[2]), (wnn, wtt, qn, qt, mu)
        counts[a[2]] += 1
    assert np.all(counts[:4] > 1000)


# ----------------------------------------------------------------- detection
def brute_force_pairs(pos, radius, n_mobile, alert, period):
    """All pairs (a < b, not both fixed) within ``alert``, by O(N^2) minimum image."""
    d = pos[:, None, :] - pos[None, :, :]
    if period > 0:
        d[..., 0] -= period * np.rint(d[..., 0] / period)
    dist = np.hypot(d[..., 0], d[..., 1])
    close = dist <= radius[:, None] + radius[None, :] + alert
    i, j = np.nonzero(np.triu(close, 1))
    keep = i < n_mobile
    return set(zip(i[keep].tolist(), j[keep].tolist()))


@pytest.mark.parametrize("period", [0.0, 30.0, 3.0])
def test_grid_detection_equals_brute_force(period):
    """The O(N) cell grid finds exactly the pairs of the O(N^2) search.

    600 polydisperse discs (radii 0.05 to 0.5, the last 60 fixed) scattered at
    random, alert 0.05.  Periodic runs also place discs slightly outside
    ``[0, period)`` as a middle configuration ``q_i + h u_i / 2`` does; the
    period 3.0 is three largest diameters, i.e. fewer than three grid columns
    once the alert is added.  Each pair is reported once, with the periodic
    shift that gives the minimum image.
    """
    rng = np.random.default_rng(11)
    n, n_mobile, alert = 600, 540, 0.05
    radius = rng.uniform(0.05, 0.5, n)
    width = period if period > 0 else 30.0
    if period == 3.0:
        radius[0] = 0.5
        n, n_mobile = 150, 140
        radius = radius[:n]
    pos = rng.uniform([0.0, 0.0], [width, 30.0 if period != 3.0 else 10.0], size=(n, 2))
    if period > 0:
        edge = rng.choice(n, n // 10, replace=False)
        pos[edge, 0] = rng.uniform(-0.3, 0.3, len(edge)) + np.where(rng.random(len(edge)) < 0.5, 0.0, period)
    a, b, shift = disc_pairs(pos, radius, n_mobile, alert, period)
    found = list(zip(a.tolist(), b.tolist()))
    assert len(found) == len(set(found)), "a pair reported twice"
    expected = brute_force_pairs(pos, radius, n_mobile, alert, period)
    assert len(expected) > n // 4
    assert set(found) == expected
    d = pos[a] - pos[b]
    d[:, 0] -= shift
    assert np.all(np.hypot(d[:, 0], d[:, 1]) <= radius[a] + radius[b] + alert + 1e-12)


def test_contact_order_is_the_merge_sort_of_the_pair_keys():
    """The counting sort of the contacts by body pair gives numpy's stable merge sort
    permutation, repeated pairs included; with 1024 walls or more (keys of one disc
    then reach the next disc's) it is the merge sort itself."""
    rng = np.random.default_rng(3)
    for trial in range(400):
        n_disc = int(rng.integers(1, 50))
        n_mobile = int(rng.integers(1, n_disc + 1))
        n_walls = int(rng.integers(0, 4)) if trial % 5 else int(rng.integers(1020, 1030))
        n = int(rng.integers(0, 150))
        a = rng.integers(0, n_mobile, n)
        b = rng.integers(-n_walls, n_disc, n)
        key = pair_key(a, b, n_disc)
        assert np.array_equal(key_order(a, key, n_disc, n_walls), np.argsort(key, kind="mergesort")), trial


def test_periodic_contact_across_the_seam_in_a_step():
    """A disc just right of x = 0 moving left meets a disc near x = period.

    With r = 0.5 the grid cells are ``period / nx = 1.0002`` wide (nx = 10).
    Disc 0 starts at ``x = 1e-6`` with ``v = -1``: its middle configuration is
    ``x = 1e-6 - h/2 = -4.99e-4``, i.e. ``period - 4.99e-4``, at distance
    ``0.999711 < 2 r`` from disc 1, which sits in grid column nx - 2.  The step
    must detect that contact and, with e_n = 0 and equal masses, end with both
    discs at the common velocity ``-1/2`` (momentum conservation).
    """
    r, period, h = 0.5, 10.002, 1e-3
    x1 = period - 1.0002 - 1e-5
    scene = ncd.make_scene([[1e-6, 0.0], [x1, 0.0]], r, gravity=(0.0, 0.0), period=period,
                           vel=[[-1.0, 0.0], [0.0, 0.0]])
    problem = ncd.prepare_step(scene, h)
    assert problem.contacts.n == 1
    assert problem.contacts.gap[0] == pytest.approx((period - 4.99e-4 - x1) - 2 * r, abs=1e-12)
    ncd.step(scene, h)
    np.testing.assert_allclose(scene.vel[:, 0], [-0.5, -0.5], rtol=1e-12)


# ----------------------------------------------------------------- warm start, review order
def test_warm_start_needs_fewer_sweeps(settled_heap):
    """Moreau 2005, section 2: starting NLGS from the previous impulses ("warm")
    converges much faster in a dense, persistent contact network than from
    zero: once the heap is at rest the warm guess is already the solution."""
    sweeps = {}
    for init in ("warm", "zero"):
        scene = settled_heap.copy()
        sweeps[init] = [ncd.step(scene, H_HEAP, init=init, settings=ncd.SolverSettings(tol=1e-4)).sweeps
                        for _ in range(15)]
    assert sum(sweeps["warm"]) * 3 < sum(sweeps["zero"]), sweeps
    assert np.median(sweeps["warm"]) * 20 < np.median(sweeps["zero"]), sweeps


def test_random_review_order(settled_heap):
    """Moreau 2005, section 2: the review order of NLGS changes the iterates
    and, the heap being hyperstatic, the limit (that is how the paper samples
    the solution set), but every converged result is a solution: Coulomb law at
    each contact, ``u_f = 0`` and the support carrying the weight."""
    scene = settled_heap
    problem = ncd.prepare_step(scene, H_HEAP, theta=1.0, vel=np.zeros_like(scene.vel),
                               spin=np.zeros_like(scene.spin))
    c = problem.contacts
    rng = np.random.default_rng(5)
    orders = [rng.permutation(c.n) for _ in range(4)]
    early = [ncd.solve_problem(scene, problem, None, o, ncd.SolverSettings(max_sweeps=3))[0].impulse
             for o in orders]
    assert min(np.abs(early[0] - e).max() for e in early[1:]) > 1e-3 * np.abs(early[0]).max()
    settings = ncd.SolverSettings(tol=1e-10, max_sweeps=200000)
    weight = scene.mobile_mass.sum() * G
    obstacle = c.body_b >= scene.n_mobile
    limits = []
    for order in orders:
        result, vel, spin = ncd.solve_problem(scene, problem, None, order, settings)
        limits.append(result.impulse)
        assert result.converged and result.residual <= settings.tol
        nm = scene.n_mobile
        assert np.abs(vel[:nm]).max() < 1e-6 * G * H_HEAP
        U = local_velocity(c.body_a, c.body_b, c.normal, c.arm_a, c.arm_b, vel, spin, np.empty((c.n, 2)))
        assert_coulomb(result.impulse, U, c.mu, 1e-8 * weight * H_HEAP, 1e-6 * G * H_HEAP)
        np.testing.assert_allclose(resultant(result.impulse / H_HEAP, c, obstacle), [0.0, weight],
                                   atol=1e-7 * weight)
    # the heap is hyperstatic: different orders reach different equilibrium forces
    spread = max(np.abs(lim - limits[0]).max() for lim in limits[1:])
    assert spread > 1e-2 * np.abs(limits[0]).max()


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_a_separating_contact_with_zero_impulse_has_zero_natural_map(mu):
    """r = 0 with U_n > 0, U_t = 0 solves the contact law: the natural map vanishes.
    (With mu = 0 the projection once returned (z_n < 0, 0) itself, so a frictionless
    separating contact read as unsolved and NLGS ran to max_sweeps.)"""
    from ncd.solver.single_contact import natural_map_sq
    assert ncd.project_cone(-1.0, 0.0, mu) == (0.0, 0.0)
    assert ncd.project_cone(2.0, 0.0, mu) == (2.0, 0.0)
    assert natural_map_sq(0.0, 0.0, 1e-8, 0.0, mu, 0.5) == 0.0
    # an approaching one does not solve it
    assert natural_map_sq(0.0, 0.0, -1e-8, 0.0, mu, 0.5) == pytest.approx((0.5e-8) ** 2)


def test_frictionless_chain_steps_converge_after_the_impact():
    """Newton's cradle with e = 1 (mu = 0): after the multi-contact impact the discs
    separate at rounding-level speeds; every step must be reported converged."""
    from ncd.studies import cases as scenes
    s = scenes.chain(5, 1.0, e=1.0)
    settings = ncd.SolverSettings(tol=1e-8, max_sweeps=2000)
    reports = [ncd.step(s, 1e-3, settings=settings) for _ in range(30)]
    assert all(r.converged for r in reports), [(r.sweeps, r.residual) for r in reports]
    assert max(r.sweeps for r in reports) < 2000


def test_the_disc_form_refuses_a_non_diagonal_delassus_block():
    """The packed sweep drops W_nt and W_tn (zero for discs); a W that has them is refused."""
    scene = ncd.make_scene([[0.0, 0.1]], radius=0.1, density=1.0, walls=[((0.0, 0.0), (0.0, 1.0))])
    problem = ncd.prepare_step(scene, 1e-3)
    W = problem.W.copy()
    W[0, 0, 1] = W[0, 1, 0] = 0.1 * W[0, 0, 0]
    with pytest.raises(ValueError, match="diagonal Delassus"):
        ncd.solve_discs(scene, problem.contacts, problem.free_vel.copy(), problem.free_spin.copy(), W=W)
    result = ncd.solve_discs(scene, problem.contacts, problem.free_vel.copy(), problem.free_spin.copy(),
                             W=problem.W)
    assert result.converged and result.impulse[0, 0] > 0
