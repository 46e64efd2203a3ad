"""Contacts of a configuration: frames, gaps, local Delassus blocks, warm-start keys.

A contact alpha joins a mobile disc ``a = body_a`` to ``b = body_b``: another
disc (``b >= 0``, mobile or fixed) or a wall (``b = -1 - wall index``).  Its
normal ``n`` points from b to a, its tangent is ``t = (-n_y, n_x)``.  With arms
``r_a, r_b`` (the radii) the relative velocity of a with respect to b at the
contact point, in the local frame, is

    U_n = (v_a - v_b) . n,     U_t = (v_a - v_b) . t - r_a w_a - r_b w_b,

i.e. ``U = H^T u``; the impulse ``s = (s_n, s_t)`` acts on a as the force
``s_n n + s_t t`` with torque ``-r_a s_t`` (and the opposite force, torque
``-r_b s_t`` on b), i.e. ``H s``.  The local Delassus block is
``W = H^T M^-1 H`` (diagonal for discs: ``1/m`` normal, ``1/m + r^2/I``
tangential per mobile disc).
"""
from dataclasses import dataclass

import numpy as np
from numba import njit

from .detection import disc_pairs


@dataclass
class Contacts:
    """Flat arrays describing ``n`` contacts, sorted by ``key`` (body pair)."""
    body_a: np.ndarray    # (n,) mobile disc
    body_b: np.ndarray    # (n,) disc index, or -1 - wall index
    normal: np.ndarray    # (n, 2) from b to a
    point: np.ndarray     # (n, 2) middle of the gap
    gap: np.ndarray       # (n,) negative when interpenetrating
    arm_a: np.ndarray     # (n,)
    arm_b: np.ndarray     # (n,) 0 for walls
    shift_b: np.ndarray   # (n,) x offset of b's periodic image
    key: np.ndarray       # (n,) int64 body-pair key, for warm starts
    mu: np.ndarray        # (n,) friction coefficient of each contact
    e_n: np.ndarray       # (n,) normal restitution
    e_t: np.ndarray       # (n,) tangential restitution

    @property
    def n(self):
        return len(self.body_a)

    @property
    def tangent(self):
        return np.column_stack([-self.normal[:, 1], self.normal[:, 0]])

    def subset(self, mask):
        return Contacts(**{k: v[mask] for k, v in self.__dict__.items()})


def pair_key(body_a, body_b, n_disc):
    """One int64 per body pair; walls come after all discs."""
    b = np.where(body_b >= 0, body_b, n_disc - 1 - body_b)
    return body_a.astype(np.int64) * (n_disc + 1024) + b


def detect_contacts(scene, alert=0.0, pos=None):
    """Contacts of ``scene`` (at positions ``pos``, default its own) with gap <= alert.

    Disc pairs come from the O(N) grid of :mod:`ncd.detection`; disc-wall pairs
    from a direct test against each wall.  Contacts are sorted by body-pair key,
    so their order does not depend on the grid.
    """
    pos = scene.pos if pos is None else pos
    nm = scene.n_mobile
    a, b, shift = disc_pairs(pos, scene.radius, nm, alert, scene.period)
    d = pos[a] - pos[b]
    d[:, 0] -= shift
    dist = np.hypot(d[:, 0], d[:, 1])
    normal = d / np.where(dist > 0, dist, 1.0)[:, None]
    gap = dist - scene.radius[a] - scene.radius[b]
    arm_a, arm_b = scene.radius[a], scene.radius[b]
    obstacle = b >= nm
    parts = [(a, b, normal, gap, arm_a, arm_b, shift, obstacle)]
    for k in range(len(scene.wall_point)):
        wn = scene.wall_normal[k]
        wg = (pos[:nm] - scene.wall_point[k]) @ wn - scene.radius[:nm]
        (i,) = np.nonzero(wg <= alert)
        parts.append((i, np.full(len(i), -1 - k), np.tile(wn, (len(i), 1)), wg[i],
                      scene.radius[i], np.zeros(len(i)), np.zeros(len(i)), np.ones(len(i), bool)))
    a, b, normal, gap, arm_a, arm_b, shift, obstacle = (np.concatenate(x) for x in zip(*parts))
    a = a.astype(np.int64)
    b = b.astype(np.int64)
    key = pair_key(a, b, scene.n_disc)
    order = np.argsort(key, kind="stable")
    a, b, normal, gap, arm_a, arm_b, shift, obstacle, key = (
        x[order] for x in (a, b, normal.reshape(-1, 2), gap, arm_a, arm_b, shift, obstacle, key))
    point = pos[a] - (arm_a + 0.5 * gap)[:, None] * normal
    return Contacts(
        body_a=a, body_b=b, normal=normal, point=point, gap=gap, arm_a=arm_a, arm_b=arm_b,
        shift_b=shift, key=key,
        mu=np.where(obstacle, scene.mu_obstacle, scene.mu),
        e_n=np.where(obstacle, scene.e_n_obstacle, scene.e_n),
        e_t=np.where(obstacle, scene.e_t_obstacle, scene.e_t))


@njit(cache=True)
def delassus_blocks(body_a, body_b, arm_a, arm_b, inv_mass, inv_inertia):
    """Local Delassus blocks ``W_alpha = H_alpha^T M^-1 H_alpha``, shape (n, 2, 2)."""
    n = body_a.shape[0]
    W = np.zeros((n, 2, 2))
    for c in range(n):
        a = body_a[c]
        W[c, 0, 0] = inv_mass[a]
        W[c, 1, 1] = inv_mass[a] + arm_a[c] ** 2 * inv_inertia[a]
        b = body_b[c]
        if b >= 0:
            W[c, 0, 0] += inv_mass[b]
            W[c, 1, 1] += inv_mass[b] + arm_b[c] ** 2 * inv_inertia[b]
    return W


@njit(cache=True)
def local_velocity(body_a, body_b, normal, arm_a, arm_b, vel, spin, out):
    """``U = H^T u`` for every contact, written into ``out`` (n, 2)."""
    for c in range(body_a.shape[0]):
        a = body_a[c]
        b = body_b[c]
        nx = normal[c, 0]
        ny = normal[c, 1]
        vx = vel[a, 0]
        vy = vel[a, 1]
        wt = arm_a[c] * spin[a]
        if b >= 0:
            vx -= vel[b, 0]
            vy -= vel[b, 1]
            wt += arm_b[c] * spin[b]
        out[c, 0] = vx * nx + vy * ny
        out[c, 1] = -vx * ny + vy * nx - wt
    return out


def match_warm(contacts, prev_keys, prev_impulse):
    """Previous impulses of persisting contacts (matched by body pair), zero elsewhere."""
    guess = np.zeros((contacts.n, 2))
    if prev_keys is None or len(prev_keys) == 0 or contacts.n == 0:
        return guess
    idx = np.searchsorted(prev_keys, contacts.key)
    idx = np.minimum(idx, len(prev_keys) - 1)
    hit = prev_keys[idx] == contacts.key
    guess[hit] = prev_impulse[idx[hit]]
    return guess


def h_matrix(scene, contacts):
    """The sparse matrix ``H`` (3 n_mobile, 2 n): generalized force of the impulses.

    Rows ``3 i, 3 i + 1, 3 i + 2`` are the force x, y and torque on mobile disc
    ``i``; columns ``2 alpha, 2 alpha + 1`` the normal and tangential impulse of
    contact ``alpha``.  ``H^T u`` is the local velocity, ``H^T M^-1 H`` the
    Delassus matrix, ``H s + h F = 0`` the equilibrium of every mobile disc.
    """
    import scipy.sparse as sp
    c = contacts
    nm = scene.n_mobile
    t = c.tangent
    rows, cols, vals = [], [], []
    for body, sign, arm in ((c.body_a, 1.0, c.arm_a), (c.body_b, -1.0, c.arm_b)):
        mobile = (body >= 0) & (body < nm)
        idx = np.nonzero(mobile)[0]
        i = body[idx]
        for comp in range(2):
            rows += [3 * i + comp, 3 * i + comp]
            cols += [2 * idx, 2 * idx + 1]
            vals += [sign * c.normal[idx, comp], sign * t[idx, comp]]
        rows.append(3 * i + 2)
        cols.append(2 * idx + 1)
        vals.append(-arm[idx])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(3 * nm, 2 * c.n))
