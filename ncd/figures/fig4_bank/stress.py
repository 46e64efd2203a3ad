"""Cuts of any direction and the granular stress tensor (Moreau 2005, section 5).

Moreau draws cuts "either vertical ... or parallel to the free surface" and reads both
through "the symmetry of the Cauchy stress, a tensor classically defined as an average
over a granular sample covering the considered cuts".  Every measure here is linear in
the contact forces ``r = (r_n, r_t)`` (a sparse matrix acting on ``r.ravel()``), so that
one matrix serves the history forces and the exact LPs over A ∩ C, as in
:mod:`ncd.shared.cuts`.

*Cut.*  A straight segment (centre ``c``, unit direction ``u``, half-length) and the unit
normal ``m`` of the side whose grains *exert* the force: the resultant is the force of
the grains with centres on the ``m`` side upon those on the other side, summed over the
grain-grain contacts whose line of centres crosses the segment.  A vertical cut of
:mod:`ncd.shared.cuts` is ``m = -outer e_x``; a cut parallel to the free surface has
``m`` the outward normal of the flank (the grains above act on the grains below).

*Stress.*  The Love-Weber average over a window ``W`` of area ``A``, compression positive,

    sigma_ij = (1/A) sum_{grains p in W} sum_{contacts c of p} f_i^{c on p} (x_p - x_c)_j,

with ``x_p - x_c`` the lever arm of the dynamics (``arm n``).  A contact with both grains
in ``W`` contributes ``f (x) l`` with ``l`` its branch vector (sum of the two arms); a
contact with the ground counts with the grain's arm only (the ground is not part of the
sample).  Its antisymmetric part is the sum of the contact torques on the grains of
``W``: zero at every equilibrium, so that ``sigma`` is symmetric to round-off for every
force state of A ∩ C.  The force per unit length exerted across a cut of normal ``m`` by
the ``m`` side is ``-sigma m`` in a uniform region.
"""
import numpy as np
import scipy.sparse as sp

from ncd.core.contacts import Contacts


# ---------------------------------------------------------------- contacts of a stored pile
def contacts_from_dataset(ds):
    """``(contacts, pos, forces)`` of a pile file (``construction.nc`` or a history pile):
    the stored contacts with the lever arms of the dynamics (the radii), the centres of the
    grains followed by the ground discs (the scene's disc order), and ``r = (r_n, r_t)``."""
    radius = np.concatenate([ds["radius"].values, ds["ground_radius"].values])
    pos = np.column_stack([np.concatenate([ds["x"].values, ds["ground_x"].values]),
                           np.concatenate([ds["y"].values, ds["ground_y"].values])])
    a, b = ds["body_a"].values.astype(np.int64), ds["body_b"].values.astype(np.int64)
    n = len(a)
    c = Contacts(body_a=a, body_b=b, normal=np.column_stack([ds["normal_x"].values, ds["normal_y"].values]),
                 point=np.column_stack([ds["point_x"].values, ds["point_y"].values]), gap=ds["gap"].values,
                 arm_a=radius[a], arm_b=np.where(b >= 0, radius[np.maximum(b, 0)], 0.0), shift_b=np.zeros(n),
                 key=ds["key"].values, mu=np.zeros(n), e_n=np.zeros(n), e_t=np.zeros(n))
    forces = np.column_stack([ds["force_n"].values, ds["force_t"].values])
    return c, pos, forces


def image_of_b(contacts, pos):
    """Centres of the ``b`` discs as seen from ``a`` (periodic images shifted by ``shift_b``);
    a wall's row is NaN."""
    b = contacts.body_b
    xb = pos[np.maximum(b, 0)].astype(float)
    xb[:, 0] += contacts.shift_b
    xb[b < 0] = np.nan
    return xb


# ---------------------------------------------------------------- cuts
def segment_weights(contacts, pos, n_mobile, centre, direction, half_length, exert_normal):
    """Per contact: +1 when grain ``a`` receives the force across the segment (its centre on
    the side opposite to ``exert_normal``, ``b`` on that side), -1 when ``b`` does, 0 when the
    line of centres does not cross the segment or ``b`` is not a grain.  A centre on the
    cut line counts on the exerting side."""
    c = np.asarray(centre, float)
    u = np.asarray(direction, float)
    m = np.asarray(exert_normal, float)
    a, b = contacts.body_a, contacts.body_b
    grain = (b >= 0) & (b < n_mobile)
    xa = pos[a]
    xb = np.where(grain[:, None], image_of_b(contacts, pos), xa)
    sa = (xa - c) @ m
    sb = (xb - c) @ m
    side_a, side_b = np.where(sa >= 0, 1, -1), np.where(sb >= 0, 1, -1)
    crossing = grain & (side_a != side_b)
    lam = np.where(crossing, sa / np.where(crossing, sa - sb, 1.0), 0.0)
    along = ((xa - c) + lam[:, None] * (xb - xa)) @ u
    inside = crossing & (np.abs(along) <= half_length)
    return np.where(inside, np.where(side_a < 0, 1, -1), 0).astype(np.int8)


def segment_matrix(contacts, pos, n_mobile, segments):
    """Sparse ``(2 k, 2 n)``: rows ``2j, 2j+1`` give ``(F_x, F_y)`` of segment ``j`` from the
    forces ``r.ravel()``; ``segments``: ``(centre, direction, half_length, exert_normal)``.
    Also returns the number of contacts crossing each segment."""
    n, t = contacts.normal, contacts.tangent
    rows, cols, vals, counts = [], [], [], []
    for j, seg in enumerate(segments):
        sign = segment_weights(contacts, pos, n_mobile, *seg)
        (idx,) = np.nonzero(sign)
        counts.append(len(idx))
        for comp in (0, 1):
            for col, e in ((0, n[:, comp]), (1, t[:, comp])):
                rows.append(np.full(len(idx), 2 * j + comp))
                cols.append(2 * idx + col)
                vals.append(sign[idx] * e[idx])
    shape = (2 * len(segments), 2 * contacts.n)
    if not segments:
        return sp.csr_matrix(shape), np.zeros(0, int)
    M = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
    return M, np.array(counts)


def vertical_segment(x_cut, outer, y_lo, y_hi):
    """The vertical cut of :mod:`ncd.shared.cuts` (force of the inner grains on the bank
    ``outer`` side) as a segment."""
    return ((x_cut, 0.5 * (y_lo + y_hi)), (0.0, 1.0), 0.5 * (y_hi - y_lo), (-float(outer), 0.0))


def flank_frame(angle_deg, outer):
    """``(t, n)``: the downhill unit tangent and the outward unit normal of a flank sloping
    at ``angle_deg`` and falling towards ``outer`` (+1: x increasing)."""
    th = np.radians(angle_deg)
    return np.array([outer * np.cos(th), -np.sin(th)]), np.array([outer * np.sin(th), np.cos(th)])


def surface_parallel_segment(surface_point, angle_deg, outer, depth, length):
    """The cut parallel to a flank at ``depth`` (along the outward normal) below the surface
    point: ``(centre, direction, half_length, exert_normal)``, the grains above acting on
    the grains below."""
    t, n = flank_frame(angle_deg, outer)
    return (np.asarray(surface_point, float) - depth * n, t, 0.5 * length, n)


def column_weight(pos, weight, segment):
    """Weight of the grains above a segment's line within the vertical strip over it:
    what the segment carries if the force across it is the weight of the material above."""
    c, u, half, m = (np.asarray(v, float) for v in segment)
    ends = c[0] + half * u[0] * np.array([-1.0, 1.0])
    sel = (pos[:, 0] >= ends.min()) & (pos[:, 0] <= ends.max()) & ((pos - c) @ m > 0)
    return float(np.sum(weight[sel]))


def angle_to_vertical(fx, fy, outer):
    """Angle (degrees) of a force from the downward vertical, positive when it leans
    outward (downhill on a flank falling towards ``outer``); NaN for a zero force."""
    fx, fy = np.asarray(fx, float), np.asarray(fy, float)
    psi = np.degrees(np.arctan2(outer * fx, -fy))
    return np.where((fx == 0.0) & (fy == 0.0), np.nan, psi)


def to_vertical_rows(rows, outer):
    """Rows ``(g'_x, g'_y)`` with ``atan2(-g'_y, g'_x)`` the angle to the vertical of the force
    ``rows @ r`` (:func:`angle_to_vertical`): the form of
    :meth:`ncd.exact.exact_set.ExactSet.angle_range` with ``outer = 1``."""
    return sp.csr_matrix(np.array([[0.0, -1.0], [-float(outer), 0.0]])) @ sp.csr_matrix(rows)


# ---------------------------------------------------------------- windows and the Love-Weber average
def rectangle(centre, direction, half_along, half_across):
    """A window: rectangle of centre, unit direction of its long axis and half-sides."""
    u = np.asarray(direction, float)
    return (np.asarray(centre, float), u, float(half_along), float(half_across))


def in_rectangle(points, window):
    c, u, ha, hc = window
    v = np.array([-u[1], u[0]])
    d = np.asarray(points, float) - c
    return (np.abs(d @ u) <= ha) & (np.abs(d @ v) <= hc)


def rectangle_corners(window):
    c, u, ha, hc = window
    v = np.array([-u[1], u[0]])
    return np.array([c + s * ha * u + q * hc * v for s, q in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def chord(window, centre, direction):
    """Half-length of the chord of the window through ``centre`` (inside it) along ``direction``."""
    c, u, ha, hc = window
    v = np.array([-u[1], u[0]])
    d = np.asarray(direction, float)
    off = np.asarray(centre, float) - c
    ends = []
    for axis, half in ((u, ha), (v, hc)):
        p, q = off @ axis, d @ axis
        if abs(q) > 1e-15:
            ends.append(min(abs((half - p) / q), abs((-half - p) / q)))
    return float(min(ends))


def stress_matrix(contacts, pos, n_mobile, windows):
    """Sparse ``(4 k, 2 n)``: rows ``4j .. 4j+3`` give ``sigma_xx, sigma_xy, sigma_yx, sigma_yy``
    (Pa m: force per unit length, compression positive) of window ``j`` from ``r.ravel()``
    (module docstring); ``sigma_ij = sum f_i arm n_j / A``.  Also returns the grain count
    per window."""
    a, b = contacts.body_a, contacts.body_b
    n, t = contacts.normal, contacts.tangent
    mobile_b = (b >= 0) & (b < n_mobile)
    rows, cols, vals, counts = [], [], [], []
    for j, w in enumerate(windows):
        c, u, ha, hc = w
        inside = in_rectangle(pos[:n_mobile], w)
        counts.append(int(inside.sum()))
        arm = np.where(inside[a], contacts.arm_a, 0.0) + np.where(
            mobile_b & inside[np.where(mobile_b, b, 0)], contacts.arm_b, 0.0)
        (idx,) = np.nonzero(arm)
        scale = arm[idx] / (4.0 * ha * hc)
        for k, (i, jj) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
            for col, e in ((0, n[:, i]), (1, t[:, i])):
                rows.append(np.full(len(idx), 4 * j + k))
                cols.append(2 * idx + col)
                vals.append(scale * e[idx] * n[idx, jj])
    shape = (4 * len(windows), 2 * contacts.n)
    if not windows:
        return sp.csr_matrix(shape), np.zeros(0, int)
    S = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
    return S, np.array(counts)


def as_tensors(values):
    """``(k, 2, 2)`` tensors from the stacked rows of :func:`stress_matrix`."""
    return np.asarray(values, float).reshape(-1, 2, 2)


# ---------------------------------------------------------------- reading a stress tensor
def asymmetry(sigma):
    """``(sigma_xy - sigma_yx) / p`` with ``p = tr(sigma) / 2`` the mean pressure (NaN if p <= 0)."""
    s = as_tensors(sigma)
    p = 0.5 * (s[:, 0, 0] + s[:, 1, 1])
    return np.where(p > 0, (s[:, 0, 1] - s[:, 1, 0]) / np.where(p > 0, p, 1.0), np.nan)


def principal(sigma):
    """Of the symmetric part: ``(s1, s2, major_from_vertical, sin_phi)``: principal stresses
    (compression positive, ``s1 >= s2``), the angle (degrees, in (-90, 90]) of the major
    principal direction from the vertical, positive towards +x, and the mobilized friction
    ``sin phi = (s1 - s2) / (s1 + s2)`` (the friction of the most loaded plane)."""
    s = as_tensors(sigma)
    sym = 0.5 * (s + np.swapaxes(s, 1, 2))
    c = 0.5 * (sym[:, 0, 0] + sym[:, 1, 1])
    r = np.hypot(0.5 * (sym[:, 0, 0] - sym[:, 1, 1]), sym[:, 0, 1])
    # the major direction makes the angle a with x: tan 2a = 2 s_xy / (s_xx - s_yy)
    a = 0.5 * np.degrees(np.arctan2(2 * sym[:, 0, 1], sym[:, 0, 0] - sym[:, 1, 1]))
    beta = (180.0 - a) % 180.0 - 90.0                 # the direction (sin beta, cos beta), up to sign
    beta = np.where(beta == -90.0, 90.0, beta)
    with np.errstate(invalid="ignore", divide="ignore"):
        sin_phi = np.where(c > 0, r / c, np.nan)
    return c + r, c - r, beta, sin_phi


def plane_stress(sigma, exert_normal, tangent):
    """``(sigma_n, tau)`` on the plane of normal ``exert_normal``: the normal compression
    ``m . sigma m`` and the shear along ``tangent`` of the force per unit length ``-sigma m``
    exerted by the ``m`` side (``tau / sigma_n``: the friction mobilized on the plane)."""
    s = as_tensors(sigma)
    m = np.asarray(exert_normal, float).reshape(-1, 2)
    t = np.asarray(tangent, float).reshape(-1, 2)
    sm = np.einsum("kij,kj->ki", s, m)
    return np.einsum("ki,ki->k", m, sm), -np.einsum("ki,ki->k", t, sm)


def reciprocity(sigma, surface_normal, outward):
    """``(n_s . sigma e, e . sigma n_s)``: the two sides of Moreau's reciprocity formula for
    the outward horizontal ``e`` (normal of a vertical cut) and the outward normal ``n_s`` of
    a cut parallel to the free surface.  The first is the component normal to the surface of
    the force per unit length across the vertical cut (zero: that force is parallel to the
    surface); the second, up to sign, the horizontal component across the surface-parallel
    cut (zero: that force is vertical).  With ``e = outer e_x`` they differ by
    ``outer (n_s)_y (sigma_yx - sigma_xy)``: equal for a symmetric stress."""
    s = as_tensors(sigma)
    n = np.asarray(surface_normal, float).reshape(-1, 2)
    e = np.asarray(outward, float).reshape(-1, 2)
    return np.einsum("ki,kij,kj->k", n, s, e), np.einsum("ki,kij,kj->k", e, s, n)
