"""The single-contact problem of 2-D Coulomb friction, solved exactly.

One contact, its impulse ``r = (r_n, r_t)`` and relative velocity ``U = W r + q`` (``W``
the 2x2 local Delassus block, ``q`` the velocity without its own impulse), under the
impulsional Signorini-Coulomb law (Moreau 2005, section 2; Moreau 2004a):

    r_n >= 0,  U_n >= 0,  r_n U_n = 0,
    |r_t| <= mu r_n,  |r_t| < mu r_n  =>  U_t = 0,
    |r_t| = mu r_n > 0  =>  U_t = -lambda r_t  (lambda >= 0).

It is solved by enumerating its cases: no contact, stick, slide with ``U_t > 0``, slide
with ``U_t < 0``.  ``W`` may be any positive definite 2x2 block (local form), not only a
disc's diagonal one.  A disc contact's solution is unique; where a strongly coupled
block and a large ``mu`` admit several cases, the first in that order is returned.
The error measure is the natural map with De Saxce's modified velocity
``U~ = (U_n + mu |U_t|, U_t)``, ``F(r) = r - proj_K(r - rho U~)``, which vanishes
exactly at solutions (``rho = 1 / W_nn`` makes it an impulse).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ncd.core import validate
from ncd.core.errors import InputError, SimulationError
from ncd.core.jit import njit
from ncd.core.validate import array, real

NO_CONTACT, STICK, SLIDE_FORWARD, SLIDE_BACKWARD, FALLBACK = 0, 1, 2, 3, 4


@njit(cache=True, error_model="numpy")
def project_cone(zn, zt, mu):
    """Euclidean projection of ``(zn, zt)`` onto the Coulomb cone ``|r_t| <= mu r_n``."""
    at = abs(zt)
    if zn >= 0.0 and at <= mu * zn:     # zn >= 0: with mu = 0, (zn < 0, 0) is outside
        return zn, zt
    if mu * at <= -zn:
        return 0.0, 0.0
    pn = (zn + mu * at) / (1.0 + mu * mu)
    pt = mu * pn if zt > 0.0 else -mu * pn
    return pn, pt


@njit(cache=True, error_model="numpy")
def solve_single_contact(wnn, wnt, wtn, wtt, qn, qt, mu):
    """Exact solution of the single-contact Coulomb problem ``U = W r + q``.

    Returns ``(r_n, r_t, status)`` with status one of NO_CONTACT, STICK,
    SLIDE_FORWARD (``U_t > 0``), SLIDE_BACKWARD (``U_t < 0``) or FALLBACK
    (no case admissible: the stick solution projected on the cone).
    """
    if qn >= 0.0:
        return 0.0, 0.0, NO_CONTACT
    det = wnn * wtt - wnt * wtn
    rn = (-wtt * qn + wnt * qt) / det
    rt = (wtn * qn - wnn * qt) / det
    if rn >= 0.0 and abs(rt) <= mu * rn:
        return rn, rt, STICK
    # slide forward (sigma = +1: r_t = -mu r_n, U_t >= 0), then backward (sigma = -1)
    denom = wnn - mu * wnt
    if denom > 0.0:
        sn = -qn / denom
        st = -mu * sn
        if wtn * sn + wtt * st + qt >= 0.0:
            return sn, st, SLIDE_FORWARD
    denom = wnn + mu * wnt
    if denom > 0.0:
        sn = -qn / denom
        st = mu * sn
        if wtn * sn + wtt * st + qt <= 0.0:
            return sn, st, SLIDE_BACKWARD
    pn, pt = project_cone(rn, rt, mu)
    return pn, pt, FALLBACK


@njit(cache=True, error_model="numpy")
def solve_disc_contact(wnn, wtt, qn, qt, mu):
    """:func:`solve_single_contact` for a disc contact's diagonal block (``W_nt = W_tn = 0``),
    with the same result bit for bit on finite input: the products of the zero entries
    only add signed zeros to non-zero terms (``q_n < 0`` here, ``W_nn, W_tt > 0``), which
    leaves every sum and every comparison unchanged; dropping them spares the sweep's
    hot loop their multiplications."""
    if qn >= 0.0:
        return 0.0, 0.0, NO_CONTACT
    det = wnn * wtt
    rn = (-wtt * qn) / det
    rt = -(wnn * qt) / det
    if rn >= 0.0 and abs(rt) <= mu * rn:
        return rn, rt, STICK
    if wnn > 0.0:
        sn = -qn / wnn
        st = -mu * sn
        if wtt * st + qt >= 0.0:
            return sn, st, SLIDE_FORWARD
        st = mu * sn
        if wtt * st + qt <= 0.0:
            return sn, st, SLIDE_BACKWARD
    pn, pt = project_cone(rn, rt, mu)
    return pn, pt, FALLBACK


@njit(cache=True, error_model="numpy")
def natural_map_sq(rn, rt, un, ut, mu, rho):
    """Squared norm of the natural map ``r - proj_K(r - rho U~)`` for one contact."""
    zn = rn - rho * (un + mu * abs(ut))
    zt = rt - rho * ut
    pn, pt = project_cone(zn, zt, mu)
    return (rn - pn) ** 2 + (rt - pt) ** 2


def solve_single_contact_py(W: ArrayLike, q: ArrayLike, mu: float) -> tuple[np.ndarray, int]:
    """Convenience wrapper: ``W`` (2, 2), ``q`` (2,) -> (r, status)."""
    W, q, mu = check_single_contact(W, q, mu)
    W = np.asarray(W, dtype=float)
    rn, rt, status = solve_single_contact(W[0, 0], W[0, 1], W[1, 0], W[1, 1],
                                          float(q[0]), float(q[1]), float(mu))
    return np.array([rn, rt]), int(status)


def project_cone_py(zn: float, zt: float, mu: float) -> tuple[float, float]:
    """:func:`project_cone` with its arguments checked: the public ``ncd.project_cone``."""
    pn, pt = project_cone(validate.real("zn", zn), validate.real("zt", zt), validate.real("mu", mu, 0.0))
    if not (np.isfinite(pn) and np.isfinite(pt)):
        raise SimulationError(f"project_cone({zn!r}, {zt!r}, {mu!r}) overflows double precision")
    return pn, pt


def check_single_contact(W: ArrayLike, q: ArrayLike, mu: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Arguments of :func:`ncd.solve_single_contact_py`: a (2, 2) block positive
    definite as in the module docstring, ``q`` (2,), ``mu >= 0``; all finite."""
    W = array("W", W, (2, 2))
    q = array("q", q, (2,))
    if not (W[0, 0] > 0 and W[1, 1] > 0 and W[0, 0] * W[1, 1] > (0.5 * (W[0, 1] + W[1, 0])) ** 2):
        raise InputError(f"W = {W.tolist()} must be positive definite (x.Wx > 0)")
    return W, q, real("mu", mu, 0.0)
