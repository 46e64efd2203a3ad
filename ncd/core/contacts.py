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
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ncd.core.detection import check_detection_args, disc_pairs
from ncd.core.errors import InputError
from ncd.core.jit import njit
from ncd.core.model import Scene
from ncd.core.validate import array, first_bad, is_f64, shape_of, show


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
    def n(self) -> int:
        return len(self.body_a)

    @property
    def tangent(self) -> np.ndarray:
        return np.column_stack([-self.normal[:, 1], self.normal[:, 0]])

    def subset(self, mask: ArrayLike) -> Contacts:
        return Contacts(**{k: v[mask] for k, v in self.__dict__.items()})


@njit(cache=True)
def pair_key(body_a, body_b, n_disc):
    """One int64 per body pair; walls come after all discs."""
    key = np.empty(body_a.shape[0], np.int64)
    for c in range(body_a.shape[0]):
        b = body_b[c] if body_b[c] >= 0 else n_disc - 1 - body_b[c]
        key[c] = np.int64(body_a[c]) * (n_disc + 1024) + b
    return key


def detect_contacts(scene: Scene, alert: float = 0.0, pos: ArrayLike | None = None, check: bool = True) -> Contacts:
    """Contacts of ``scene`` (at positions ``pos``, default its own) with gap <= alert.

    Disc pairs come from the O(N) grid of :mod:`ncd.core.detection`; disc-wall pairs
    from a direct test against each wall.  Contacts are sorted by body-pair key,
    so their order does not depend on the grid.  ``check=False``: the caller has
    checked the arguments (:func:`ncd.step` does, once per step).
    """
    if check:
        pos = check_detection_args(scene, alert, pos)
    elif pos is None:
        pos = scene.pos
    nm = scene.n_mobile
    a, b, shift = disc_pairs(pos, scene.radius, nm, alert, scene.period)
    n_walls = len(scene.wall_point)
    wall_gap = np.empty((n_walls, nm))
    for k in range(n_walls):
        wall_gap[k] = (pos[:nm] - scene.wall_point[k]) @ scene.wall_normal[k] - scene.radius[:nm]
    laws = np.array([scene.mu, scene.e_n, scene.e_t, scene.mu_obstacle, scene.e_n_obstacle,
                     scene.e_t_obstacle], dtype=float)
    fields = _assemble(pos, scene.radius, nm, scene.n_disc, a.astype(np.int64), b.astype(np.int64), shift,
                       wall_gap, np.asarray(scene.wall_normal, dtype=float).reshape(n_walls, 2),
                       float(alert), laws)
    return Contacts(*fields)


@njit(cache=True)
def _assemble(pos, radius, nm, n_disc, a, b, shift, wall_gap, wall_normal, alert, laws):
    """The fields of :class:`Contacts` (in its order) from the disc pairs ``(a, b,
    shift)`` and the disc-wall gaps ``wall_gap`` (n_walls, nm), sorted by pair key.

    ``laws``: mu, e_n, e_t between discs, then the same with obstacles (fixed
    discs and walls).  The normal is ``d / |d|`` with ``d`` from b (or its
    periodic image) to a; the point is the middle of the gap."""
    n_pairs = a.shape[0]
    n_walls = wall_gap.shape[0]
    n = n_pairs
    for k in range(n_walls):
        for i in range(nm):
            if wall_gap[k, i] <= alert:
                n += 1
    A = np.empty(n, np.int64)
    B = np.empty(n, np.int64)
    normal = np.empty((n, 2))
    gap = np.empty(n)
    arm_a = np.empty(n)
    arm_b = np.empty(n)
    sh = np.zeros(n)
    for c in range(n_pairs):
        i, j = a[c], b[c]
        dx = pos[i, 0] - pos[j, 0] - shift[c]
        dy = pos[i, 1] - pos[j, 1]
        dist = np.hypot(dx, dy)
        den = dist if dist > 0 else 1.0
        A[c], B[c], sh[c] = i, j, shift[c]
        normal[c, 0] = dx / den
        normal[c, 1] = dy / den
        gap[c] = dist - radius[i] - radius[j]
        arm_a[c], arm_b[c] = radius[i], radius[j]
    c = n_pairs
    for k in range(n_walls):
        for i in range(nm):
            if wall_gap[k, i] <= alert:
                A[c], B[c] = i, -1 - k
                normal[c, 0], normal[c, 1] = wall_normal[k, 0], wall_normal[k, 1]
                gap[c], arm_a[c], arm_b[c] = wall_gap[k, i], radius[i], 0.0
                c += 1
    key = pair_key(A, B, n_disc)
    order = key_order(A, key, n_disc, n_walls)
    # one gathering pass in key order (the fields, then the point and the laws)
    fields = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty((n, 2)), np.empty((n, 2)), np.empty(n),
              np.empty(n), np.empty(n), np.empty(n), np.empty(n, np.int64), np.empty(n), np.empty(n), np.empty(n))
    out_a, out_b, out_normal, point, out_gap, out_arm_a, out_arm_b, out_shift, out_key, mu, e_n, e_t = fields
    for m in range(n):
        c = order[m]
        out_a[m], out_b[m], out_key[m] = A[c], B[c], key[c]
        out_normal[m, 0], out_normal[m, 1] = normal[c, 0], normal[c, 1]
        out_gap[m], out_arm_a[m], out_arm_b[m], out_shift[m] = gap[c], arm_a[c], arm_b[c], sh[c]
        w = arm_a[c] + 0.5 * gap[c]
        point[m, 0] = pos[A[c], 0] - w * normal[c, 0]
        point[m, 1] = pos[A[c], 1] - w * normal[c, 1]
        first = 3 if B[c] >= nm or B[c] < 0 else 0
        mu[m], e_n[m], e_t[m] = laws[first], laws[first + 1], laws[first + 2]
    return fields


@njit(cache=True)
def key_order(body_a, key, n_disc, n_walls):
    """``np.argsort(key, kind="mergesort")`` for the keys of :func:`pair_key`, in O(n).

    With fewer than 1024 walls a key orders the contacts by ``body_a``, then by the
    other body, so a counting sort on ``body_a`` (stable) followed by an insertion
    sort of each disc's few contacts (stable) gives the same permutation as the
    merge sort, at a fraction of its cost on every step.  More walls: the merge sort."""
    n = key.shape[0]
    if n_walls >= 1024:
        return np.argsort(key, kind="mergesort")
    start = np.zeros(n_disc + 1, np.int64)
    for c in range(n):
        start[body_a[c] + 1] += 1
    for i in range(n_disc):
        start[i + 1] += start[i]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    for c in range(n):
        order[fill[body_a[c]]] = c
        fill[body_a[c]] += 1
    for i in range(n_disc):
        for m in range(start[i] + 1, start[i + 1]):
            c = order[m]
            k = m
            while k > start[i] and key[order[k - 1]] > key[c]:
                order[k] = order[k - 1]
                k -= 1
            order[k] = c
    return order


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


def match_warm(contacts: Contacts, prev_keys: np.ndarray | None, prev_impulse: np.ndarray | None) -> np.ndarray:
    """Previous impulses of persisting contacts (matched by body pair), zero elsewhere."""
    if prev_keys is None or len(prev_keys) == 0 or contacts.n == 0:
        return np.zeros((contacts.n, 2))
    return _match_sorted(contacts.key, np.asarray(prev_keys, dtype=np.int64), prev_impulse)


@njit(cache=True)
def _match_sorted(keys, prev_keys, prev_impulse):
    """Both key lists sorted: one merge pass."""
    guess = np.zeros((keys.shape[0], 2))
    j = 0
    for c in range(keys.shape[0]):
        while j < prev_keys.shape[0] and prev_keys[j] < keys[c]:
            j += 1
        if j < prev_keys.shape[0] and prev_keys[j] == keys[c]:
            guess[c, 0] = prev_impulse[j, 0]
            guess[c, 1] = prev_impulse[j, 1]
    return guess


def external_load(scene: Scene, applied: np.ndarray | None = None) -> np.ndarray:
    """The generalized external force ``F`` of the equilibrium equations ``H r + F = 0``
    (Moreau 2005, section 4: they define the affine set A), flat (3 n_mobile,): the weight
    ``m g`` of each mobile body plus the forces ``applied`` to them, shape (n_mobile, 2)
    (the load on Unger et al.'s top plate); no external torque."""
    nm = scene.n_mobile
    F = np.zeros((nm, 3))
    F[:, :2] = scene.mass[:nm, None] * scene.gravity[None]
    if applied is not None:
        F[:, :2] += np.asarray(applied, dtype=float).reshape(nm, 2)
    return F.ravel()


def h_matrix(scene: Scene, contacts: Contacts) -> sp.csr_matrix:
    """The sparse matrix ``H`` (3 n_mobile, 2 n): generalized force of the impulses.

    Rows ``3 i, 3 i + 1, 3 i + 2`` are the force x, y and torque on mobile disc
    ``i``; columns ``2 alpha, 2 alpha + 1`` the normal and tangential impulse of
    contact ``alpha``.  ``H^T u`` is the local velocity, ``H^T M^-1 H`` the
    Delassus matrix, ``H s + h F = 0`` the equilibrium of every mobile disc.
    """
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


# ------------------------------------------------------------ argument checks
def check_contacts(s, c, name="contacts"):
    """A :class:`ncd.Contacts` of ``s``: every field of length ``n``, disc
    indices in range (``body_a`` mobile, ``body_b`` a disc or ``-1 - wall``),
    unit normals, finite arms and laws."""
    if not isinstance(c, Contacts):
        raise InputError(f"{name} must be an ncd.Contacts; got {type(c).__name__}")
    if _contacts_ok(s, c):
        return c
    for field, value in vars(c).items():
        if not isinstance(value, np.ndarray):
            raise InputError(f"{name}.{field} must be a numpy array; got {show(value)}")
    ashape = shape_of(f"{name}.body_a", c.body_a)
    n = ashape[0] if len(ashape) == 1 else -1
    if n < 0:
        raise InputError(f"{name}.body_a has shape {ashape}, expected (n,)")
    for field in ("body_a", "body_b", "key"):
        value = np.asarray(getattr(c, field))
        if value.shape != (n,) or (n and value.dtype.kind not in "iu"):
            raise InputError(f"{name}.{field} must be integers of shape ({n},); got {value.dtype} {value.shape}")
    for field, shape in (("normal", (n, 2)), ("point", (n, 2)), ("gap", (n,)), ("arm_a", (n,)),
                         ("arm_b", (n,)), ("shift_b", (n,)), ("mu", (n,)), ("e_n", (n,)), ("e_t", (n,))):
        array(f"{name}.{field}", getattr(c, field), shape)
    if n == 0:
        return c
    a, b = np.asarray(c.body_a), np.asarray(c.body_b)
    bad = (a < 0) | (a >= s.n_mobile)
    if np.any(bad):
        first_bad(f"{name}.body_a", a, bad, f"must be a mobile disc in range({s.n_mobile})")
    bad = (b < -len(s.wall_point)) | (b >= s.n_disc) | (a == b)
    if np.any(bad):
        first_bad(f"{name}.body_b", b, bad,
                   f"must be another disc in range({s.n_disc}) or -1 - wall with {len(s.wall_point)} walls")
    norm = np.hypot(c.normal[:, 0], c.normal[:, 1])
    if np.any(np.abs(norm - 1.0) > 1e-6):
        k = int(np.argmax(np.abs(norm - 1.0)))
        raise InputError(f"{name}.normal[{k}] = {c.normal[k]} is not a unit vector")
    if np.any(np.asarray(c.mu) < 0):
        first_bad(f"{name}.mu", np.asarray(c.mu), np.asarray(c.mu) < 0, "must be >= 0")
    for field in ("e_n", "e_t"):
        e = np.asarray(getattr(c, field))
        if np.any((e < 0) | (e > 1)):
            first_bad(f"{name}.{field}", e, (e < 0) | (e > 1), "must be in [0, 1]")
    return c


def _contacts_ok(s, c):
    """Fast path of :func:`check_contacts` (False: the slow path names the fault)."""
    a, b, key = c.body_a, c.body_b, c.key
    if type(a) is not np.ndarray or a.ndim != 1 or a.dtype != np.int64:
        return False
    n = a.shape[0]
    v1, v2 = (n,), (n, 2)
    if not (type(b) is np.ndarray and b.shape == v1 and b.dtype == np.int64 and type(key) is np.ndarray
            and key.shape == v1 and key.dtype.kind in "iu" and is_f64(c.normal, v2) and is_f64(c.point, v2)
            and all(is_f64(getattr(c, f), v1) for f in ("gap", "arm_a", "arm_b", "shift_b", "mu", "e_n", "e_t"))):
        return False
    if n == 0:
        return True
    return _contact_values_ok(a, b, c.normal, c.point, c.gap, c.arm_a, c.arm_b, c.shift_b, c.mu, c.e_n, c.e_t,
                              s.n_mobile, s.n_disc, len(s.wall_point))


@njit(cache=True)
def _contact_values_ok(a, b, normal, point, gap, arm_a, arm_b, shift_b, mu, e_n, e_t, nm, nd, n_walls):
    """The value checks of :func:`_contacts_ok` in one pass."""
    for c in range(a.shape[0]):
        if not (0 <= a[c] < nm and -n_walls <= b[c] < nd and a[c] != b[c]
                and abs(normal[c, 0] ** 2 + normal[c, 1] ** 2 - 1.0) <= 1e-6
                and np.isfinite(point[c, 0]) and np.isfinite(point[c, 1]) and np.isfinite(gap[c])
                and np.isfinite(arm_a[c]) and np.isfinite(arm_b[c]) and np.isfinite(shift_b[c])
                and 0.0 <= mu[c] < np.inf and 0.0 <= e_n[c] <= 1.0 and 0.0 <= e_t[c] <= 1.0):
            return False
    return True


def check_disc_blocks(W, n, name="W"):
    """Delassus blocks of disc contacts, (n, 2, 2): finite, diagonal, ``W_nn, W_tt > 0``."""
    if is_f64(W, (n, 2, 2)) and W.flags.c_contiguous and _disc_blocks_ok(W):
        return W
    W = array(name, W, (n, 2, 2))
    if n and (np.any(W[:, 0, 1] != 0) or np.any(W[:, 1, 0] != 0)):
        k = int(np.argmax((W[:, 0, 1] != 0) | (W[:, 1, 0] != 0)))
        raise InputError(f"{name}[{k}] = {W[k].tolist()}: disc contacts have diagonal Delassus blocks "
                         "(use solve_local for a general W)")
    if n and (np.any(W[:, 0, 0] <= 0) or np.any(W[:, 1, 1] <= 0)):
        k = int(np.argmax((W[:, 0, 0] <= 0) | (W[:, 1, 1] <= 0)))
        raise InputError(f"{name}[{k}] = {W[k].tolist()} is not positive definite")
    return W


@njit(cache=True)
def _disc_blocks_ok(W):
    for c in range(W.shape[0]):
        if not (W[c, 0, 1] == 0.0 and W[c, 1, 0] == 0.0 and 0.0 < W[c, 0, 0] < np.inf and 0.0 < W[c, 1, 1] < np.inf):
            return False
    return True
