"""The disc-form problem (:func:`ncd.solver.nlgs.solve_discs`) packed for the hot loop of
:mod:`ncd.solver.kernels`, and the per-contact kernels on the packed arrays
(``U = H_c^T u``, ``u += M^-1 H_c ds``).
"""
import numpy as np

from ncd.core.jit import njit

# Data layout of the hot loop (one job: make a contact update a few cache-line
# reads): ``body`` (n_disc + 1, 4) holds ``(v_x, v_y, omega, 0)`` per disc, the
# last row a motionless dummy that stands for every wall; ``pair`` (n, 2) the
# two body rows of a contact (int32); ``coef`` (n, 13) everything else a contact update
# reads, in the order of the ``C_*`` columns below.  The Delassus block of a disc
# contact is diagonal (the normal line passes through both centres), so the sweep
# passes ``W_nt = W_tn = 0`` to the single-contact solver.
C_NX, C_NY, C_RA, C_RB, C_WNN, C_WTT, C_MU, C_BN, C_BT, C_IMA, C_IIA, C_IMB, C_IIB = range(13)
N_COEF = 13


@njit(cache=True, nogil=True)
def pack_problem(body_a, body_b, normal, arm_a, arm_b, W, mu, bias, inv_mass, inv_inertia, vel, spin):
    """Flat arrays ``(pair, coef, body)`` of the disc-form problem (layout above).

    ``coef`` stores ``1/m`` and ``r/I`` per contact side (0 for a wall), so an
    update needs no body property; the arithmetic is that of ``M^-1 H s``.  A
    ``W`` with a non-zero off-diagonal entry is refused (it is not a disc contact's).
    """
    n = body_a.shape[0]
    nd = vel.shape[0]
    body = np.zeros((nd + 1, 4))
    for i in range(nd):
        body[i, 0] = vel[i, 0]
        body[i, 1] = vel[i, 1]
        body[i, 2] = spin[i]
    pair = np.empty((n, 2), np.int32)
    coef = np.zeros((n, N_COEF))
    for c in range(n):
        a = body_a[c]
        b = body_b[c]
        pair[c, 0] = a
        pair[c, 1] = b if b >= 0 else nd
        coef[c, C_NX] = normal[c, 0]
        coef[c, C_NY] = normal[c, 1]
        coef[c, C_RA] = arm_a[c]
        coef[c, C_RB] = arm_b[c]
        if W[c, 0, 1] != 0.0 or W[c, 1, 0] != 0.0:
            raise ValueError("disc contacts have diagonal Delassus blocks: W[:, 0, 1] and W[:, 1, 0] "
                             "must be 0 (use solve_local for a general W)")
        coef[c, C_WNN] = W[c, 0, 0]
        coef[c, C_WTT] = W[c, 1, 1]
        coef[c, C_MU] = mu[c]
        coef[c, C_BN] = bias[c, 0]
        coef[c, C_BT] = bias[c, 1]
        coef[c, C_IMA] = inv_mass[a]
        coef[c, C_IIA] = inv_inertia[a] * arm_a[c]
        if b >= 0:
            coef[c, C_IMB] = inv_mass[b]
            coef[c, C_IIB] = inv_inertia[b] * arm_b[c]
    return pair, coef, body


# The kernels below take ``pair``, ``coef``, ``body`` and the impulses raveled
# (1-D): rows at constant strides, which the compiler turns into fixed offsets.
@njit(cache=True, inline="always")
def relative_velocity(pair, coef, body, c):
    """``U = H_c^T u`` of contact ``c`` (normal, tangential), bias not included.

    ``pair``, ``coef``, ``body`` are the flat (raveled) arrays: constant strides."""
    a = 4 * pair[2 * c]
    b = 4 * pair[2 * c + 1]
    k = N_COEF * c
    nx = coef[k + C_NX]
    ny = coef[k + C_NY]
    vx = body[a] - body[b]
    vy = body[a + 1] - body[b + 1]
    wt = coef[k + C_RA] * body[a + 2] + coef[k + C_RB] * body[b + 2]
    return vx * nx + vy * ny, -vx * ny + vy * nx - wt


@njit(cache=True, inline="always")
def add_impulse(pair, coef, body, c, dn, dt):
    """``u += M^-1 H_c (dn, dt)``: the impulse increment of contact ``c`` on its two bodies."""
    a = 4 * pair[2 * c]
    b = 4 * pair[2 * c + 1]
    k = N_COEF * c
    nx = coef[k + C_NX]
    ny = coef[k + C_NY]
    px = dn * nx - dt * ny
    py = dn * ny + dt * nx
    body[a] += coef[k + C_IMA] * px
    body[a + 1] += coef[k + C_IMA] * py
    body[a + 2] -= coef[k + C_IIA] * dt
    body[b] -= coef[k + C_IMB] * px
    body[b + 1] -= coef[k + C_IMB] * py
    body[b + 2] -= coef[k + C_IIB] * dt


@njit(cache=True, nogil=True)
def apply_all(pair, coef, body, imp):
    """``u += M^-1 H s`` for every contact: the initial guess on the free velocities."""
    for c in range(imp.shape[0] // 2):
        add_impulse(pair, coef, body, c, imp[2 * c], imp[2 * c + 1])
