"""Molecular-dynamics (soft contact) baseline: Cundall-Strack discs, symplectic Euler.

Only for comparison with Contact Dynamics (Moreau 2005, section 2: MD "approximates
the impenetrability constraints ... by repulsion forces steeply dependent on the
mutual positions").  It runs on the same :class:`ncd.core.model.Scene` and the contact
frames of :mod:`ncd.core.contacts`.  With the overlap ``delta = -gap > 0``:

* normal spring-dashpot ``f_n = k_n delta - c_n U_n`` (clipped at 0 unless
  ``clip=False``), ``c_n = 2 zeta sqrt(k_n m_eff)``, ``m_eff = m_a m_b / (m_a + m_b)``
  (``m_a`` against walls and fixed discs);
* tangential spring with a Coulomb slider (Cundall & Strack 1979): ``xi += h U_t``,
  ``f_t = -k_t xi - c_t U_t``; if ``|f_t| > mu f_n``, ``f_t = +-mu f_n`` and the spring
  is reset to ``xi = -(f_t + c_t U_t) / k_t``;
* ``zeta = -ln e / sqrt(pi^2 + ln^2 e)`` from the contact's restitution ``e`` (the
  unclipped linear dashpot's), capped at 1 for e -> 0.

Symplectic Euler, ``u += h M^-1 F(q, u)``, ``q += h u``, is stable for an undamped spring
iff ``h omega < 2`` (:func:`critical_step`, with the smallest mobile mass; chains of
springs and dashpots lower the limit).  Candidate pairs come from
:func:`ncd.core.contacts.detect_contacts` with an alert distance ``skin``, rebuilt
(spring states carried by body-pair key) when a disc moved more than ``skin / 2``.
Divergence (non-finite state or a speed above ``speed_limit``) stops the run and is
reported with its step, never as inf/NaN values.
"""
from dataclasses import dataclass

import numpy as np

from ncd.core import validate
from ncd.core.contacts import check_contacts, detect_contacts
from ncd.core.errors import InputError
from ncd.core.jit import njit
from ncd.core.model import check_scene

MAX_STEPS = 10 ** 12     # n_steps of one MD.run at most (an int64 count in the kernel)


def zeta_from_restitution(e):
    """Damping ratio of the linear dashpot giving restitution ``e`` (1 for e = 0)."""
    e = np.asarray(e, dtype=float)
    le = np.log(np.maximum(e, 1e-300))
    return np.where(e <= 0.0, 1.0, np.minimum(1.0, -le / np.sqrt(np.pi ** 2 + le ** 2)))


def restitution_from_zeta(zeta):
    """``e = exp(-pi zeta / sqrt(1 - zeta^2))`` (0 for zeta >= 1)."""
    zeta = float(zeta)
    return 0.0 if zeta >= 1.0 else float(np.exp(-np.pi * zeta / np.sqrt(1.0 - zeta ** 2)))


def critical_step(scene, k_n):
    """``2 / omega`` with ``omega = sqrt(k_n / m_min)`` over the mobile discs."""
    return 2.0 / np.sqrt(k_n / scene.mobile_mass.min())


@dataclass(frozen=True)
class MDParams:
    """Contact stiffnesses and options of the soft-contact model."""
    k_n: float
    k_t_ratio: float = 0.5     # k_t = k_t_ratio * k_n
    clip: bool = True           # no attractive (negative) normal force
    skin: float = 0.2           # alert distance of the neighbour list, in largest radii

    def __post_init__(self):
        if not (np.isfinite(self.k_n) and self.k_n > 0):
            raise InputError(f"k_n = {self.k_n!r} must be > 0")
        if not (0.0 <= self.k_t_ratio < np.inf) or not (self.skin > 0):
            raise InputError(f"k_t_ratio = {self.k_t_ratio!r} must be >= 0, skin = {self.skin!r} > 0")


@dataclass
class MDReport:
    steps: int                  # steps done by this call
    diverged: bool
    diverged_step: int          # global step index of the divergence, -1 if none
    max_overlap: float          # largest overlap / smaller radius seen during the call
    rebuilds: int


@njit(cache=True)
def _md_steps(pos, vel, spin, angle, inv_mass, inv_inertia, radius, gravity, n_mobile,
              ca, cb, cshift, cmu, czeta, cmeff, wall_point, wall_normal, xi,
              kn, kt, clip, h, n_steps, ref_pos, half_skin, speed_limit):
    """Advance ``n_steps`` symplectic Euler steps; returns ``(steps, status, max_overlap)``.

    status 0: done; 1: a disc moved more than ``half_skin`` (rebuild the pair list);
    2: diverged (non-finite or faster than ``speed_limit``) at the last step counted.
    """
    n = pos.shape[0]
    fx = np.zeros(n)
    fy = np.zeros(n)
    tq = np.zeros(n)
    max_ov = 0.0
    for step in range(1, n_steps + 1):
        fx[:] = 0.0
        fy[:] = 0.0
        tq[:] = 0.0
        for c in range(ca.shape[0]):
            a = ca[c]
            b = cb[c]
            ra = radius[a]
            if b >= 0:
                rb = radius[b]
                dx = pos[a, 0] - pos[b, 0] - cshift[c]
                dy = pos[a, 1] - pos[b, 1]
                dist = np.sqrt(dx * dx + dy * dy)
                nx = dx / dist if dist > 0.0 else 1.0
                ny = dy / dist if dist > 0.0 else 0.0
                gap = dist - ra - rb
                rmin = min(ra, rb)
            else:
                w = -1 - b
                rb = 0.0
                nx = wall_normal[w, 0]
                ny = wall_normal[w, 1]
                gap = (pos[a, 0] - wall_point[w, 0]) * nx + (pos[a, 1] - wall_point[w, 1]) * ny - ra
                rmin = ra
            if gap >= 0.0:
                xi[c] = 0.0
                continue
            delta = -gap
            max_ov = max(max_ov, delta / rmin)
            vx = vel[a, 0]
            vy = vel[a, 1]
            wt = ra * spin[a]
            if b >= 0:
                vx -= vel[b, 0]
                vy -= vel[b, 1]
                wt += rb * spin[b]
            un = vx * nx + vy * ny
            ut = -vx * ny + vy * nx - wt
            root_m = np.sqrt(cmeff[c])
            cn = 2.0 * czeta[c] * np.sqrt(kn) * root_m
            fn = kn * delta - cn * un
            if clip and fn < 0.0:
                fn = 0.0
            ct = 2.0 * czeta[c] * np.sqrt(kt) * root_m
            xi[c] += h * ut
            ft = -kt * xi[c] - ct * ut
            lim = cmu[c] * fn
            if abs(ft) > lim:
                ft = lim if ft > 0.0 else -lim
                xi[c] = -(ft + ct * ut) / kt if kt > 0.0 else 0.0
            px = fn * nx - ft * ny
            py = fn * ny + ft * nx
            fx[a] += px
            fy[a] += py
            tq[a] -= ra * ft
            if b >= 0:
                fx[b] -= px
                fy[b] -= py
                tq[b] -= rb * ft
        moved = False
        bad = False
        for i in range(n_mobile):
            vel[i, 0] += h * (fx[i] * inv_mass[i] + gravity[0])
            vel[i, 1] += h * (fy[i] * inv_mass[i] + gravity[1])
            spin[i] += h * tq[i] * inv_inertia[i]
            pos[i, 0] += h * vel[i, 0]
            pos[i, 1] += h * vel[i, 1]
            angle[i] += h * spin[i]
            speed = max(abs(vel[i, 0]), abs(vel[i, 1]))
            if not (speed <= speed_limit) or not np.isfinite(spin[i]) or not np.isfinite(pos[i, 0] + pos[i, 1]):
                bad = True
            ddx = pos[i, 0] - ref_pos[i, 0]
            ddy = pos[i, 1] - ref_pos[i, 1]
            if ddx * ddx + ddy * ddy > half_skin * half_skin:
                moved = True
        if bad:
            return step, 2, max_ov
        if moved:
            return step, 1, max_ov
    return n_steps, 0, max_ov


class MD:
    """A soft-contact simulation of ``scene`` (advanced in place) with :class:`MDParams`."""

    def __init__(self, scene, params):
        self.scene = scene
        self.params = params
        self.step_count = 0
        self._keys = np.zeros(0, np.int64)
        self._xi = np.zeros(0)
        self._contacts = None

    @property
    def k_t(self):
        return self.params.k_t_ratio * self.params.k_n

    def critical_step(self):
        return critical_step(self.scene, self.params.k_n)

    def _fits(self, s):
        """The cached contacts index the scene as it is now (sizes, walls, laws)."""
        c = self._contacts
        if not (self._ref.shape == s.pos.shape and self._n_walls == len(s.wall_point) and self._n_mobile == s.n_mobile):
            return False
        try:
            check_contacts(s, c)
        except InputError:
            return False
        return True

    def _rebuild(self):
        s = self.scene
        nm = s.n_mobile
        if s.period > 0:
            s.pos[:nm, 0] %= s.period
        skin = self.params.skin * s.radius.max()
        c = detect_contacts(s, alert=skin)
        xi = np.zeros(c.n)
        if len(self._keys) and c.n:
            idx = np.minimum(np.searchsorted(self._keys, c.key), len(self._keys) - 1)
            hit = self._keys[idx] == c.key
            xi[hit] = self._xi[idx[hit]]
        self._contacts, self._keys, self._xi = c, c.key, xi
        inv_b = np.where(c.body_b >= 0, s.inv_mass[np.maximum(c.body_b, 0)], 0.0)
        self._meff = 1.0 / (s.inv_mass[c.body_a] + inv_b)
        self._zeta = zeta_from_restitution(c.e_n).astype(float)
        self._ref = s.pos.copy()
        self._n_walls, self._n_mobile = len(s.wall_point), s.n_mobile
        self._half_skin = 0.5 * skin

    def run(self, h, n_steps, speed_limit=np.inf):
        """Advance ``n_steps`` steps of length ``h``; stops early on divergence.  The scene
        is checked on every call (it may have been changed since the last one), and the
        contact list is rebuilt when it no longer fits the scene."""
        h = validate.real("h", h, 0.0, lo_open=True)
        n_steps = validate.integer("n_steps", n_steps, 0, MAX_STEPS)
        speed_limit = validate.real("speed_limit", speed_limit, 0.0, lo_open=True, allow_inf=True)
        s, p = self.scene, self.params
        check_scene(s, state=True)
        done, rebuilds, max_ov = 0, 0, 0.0
        if self._contacts is None or not self._fits(s):
            self._rebuild()
        while done < n_steps:
            c = self._contacts
            k, status, ov = _md_steps(
                s.pos, s.vel, s.spin, s.angle, s.inv_mass, s.inv_inertia, s.radius, s.gravity,
                s.n_mobile, c.body_a, c.body_b, c.shift_b, c.mu, self._zeta, self._meff,
                s.wall_point.reshape(-1, 2), s.wall_normal.reshape(-1, 2), self._xi,
                float(p.k_n), float(self.k_t), bool(p.clip), float(h), int(n_steps - done),
                self._ref, float(self._half_skin), float(speed_limit))
            done += k
            self.step_count += k
            s.time += k * h
            max_ov = max(max_ov, ov)
            if status == 2:
                return MDReport(done, True, self.step_count, max_ov, rebuilds)
            if status == 1:
                self._rebuild()
                rebuilds += 1
        return MDReport(done, False, -1, max_ov, rebuilds)

    def contact_forces(self):
        """Current contacts (overlapping pairs) and their forces ``(f_n, f_t)``, shape (n, 2)."""
        s, p = self.scene, self.params
        if self._contacts is None:
            self._rebuild()
        c = detect_contacts(s, alert=0.0)
        idx = np.minimum(np.searchsorted(self._keys, c.key), max(len(self._keys) - 1, 0))
        xi = np.where(self._keys[idx] == c.key, self._xi[idx], 0.0) if len(self._keys) else np.zeros(c.n)
        va = s.vel[c.body_a]
        vb = np.where((c.body_b >= 0)[:, None], s.vel[np.maximum(c.body_b, 0)], 0.0)
        wb = np.where(c.body_b >= 0, s.spin[np.maximum(c.body_b, 0)], 0.0)
        dv = va - vb
        t = c.tangent
        un = np.sum(dv * c.normal, axis=1)
        ut = np.sum(dv * t, axis=1) - c.arm_a * s.spin[c.body_a] - c.arm_b * wb
        inv_b = np.where(c.body_b >= 0, s.inv_mass[np.maximum(c.body_b, 0)], 0.0)
        root_m = np.sqrt(1.0 / (s.inv_mass[c.body_a] + inv_b))
        zeta = zeta_from_restitution(c.e_n)
        fn = p.k_n * (-c.gap) - 2 * zeta * np.sqrt(p.k_n) * root_m * un
        if p.clip:
            fn = np.maximum(fn, 0.0)
        ft = -self.k_t * xi - 2 * zeta * np.sqrt(self.k_t) * root_m * ut
        ft = np.clip(ft, -c.mu * fn, c.mu * fn)
        return c, np.column_stack([fn, ft])

    def elastic_energy(self):
        """``sum 1/2 k_n delta^2 + 1/2 k_t xi^2`` over overlapping pairs."""
        c, _ = self.contact_forces()
        idx = np.minimum(np.searchsorted(self._keys, c.key), max(len(self._keys) - 1, 0))
        xi = np.where(self._keys[idx] == c.key, self._xi[idx], 0.0) if len(self._keys) else np.zeros(c.n)
        return float(0.5 * self.params.k_n * np.sum(c.gap ** 2) + 0.5 * self.k_t * np.sum(xi ** 2))


def potential_energy(scene):
    """Gravitational energy ``-sum m g.x`` of the mobile discs (positions as stored)."""
    nm = scene.n_mobile
    return float(-np.sum(scene.mass[:nm] * (scene.pos[:nm] @ scene.gravity)))


def wall_reaction(scene, contacts, forces):
    """Total force exerted by walls and fixed discs on the mobile discs, shape (2,)."""
    ext = (contacts.body_b < 0) | (contacts.body_b >= scene.n_mobile)
    f = forces[ext]
    n = contacts.normal[ext]
    t = contacts.tangent[ext]
    return (f[:, :1] * n + f[:, 1:] * t).sum(axis=0)
