"""Measures on a granular pile (Moreau 2005, section 5): free surface, cut resultants, ground pressure.

Every measure is linear in the contact impulses, a sparse matrix ``C`` with
``measure = C @ s.ravel() / h``, so one matrix serves the history solution, every
member of an ensemble and the exact LPs.  The resultant across a vertical cut at
``x_cut`` is the force of the grains with centres on the inner side (towards the axis)
on those of the outer side, over the grain-grain contacts whose line of centres crosses
the cut within ``[y_lo, y_hi]`` (a centre on the cut counts as ``x >= x_cut``).  Signs
follow :mod:`ncd.core.contacts`: contact ``alpha`` pushes its mobile disc ``a`` with
``(s_n n + s_t t) / h``, ``n`` from ``b`` to ``a``, ``t = (-n_y, n_x)``.
"""
import numpy as np
import scipy.sparse as sp


def contact_force_components(contacts):
    """``(ex, ey)``: (n, 2) arrays with ``force_on_a = (ex @ s, ey @ s)`` row-wise.

    ``ex[alpha] = (n_x, t_x)``, ``ey[alpha] = (n_y, t_y)``.
    """
    n = contacts.normal
    t = contacts.tangent
    return np.column_stack([n[:, 0], t[:, 0]]), np.column_stack([n[:, 1], t[:, 1]])


def cut_weights(contacts, pos, n_mobile, x_cut, outer, y_lo=-np.inf, y_hi=np.inf):
    """Per-contact sign of the force on the outer side: +1, -1 or 0 (not crossing).

    ``outer`` is +1 when the bank lies at ``x >= x_cut`` (a right flank), -1
    when it lies at ``x < x_cut``.  Returns ``(sign, y_cross)``; ``sign`` is +1
    when ``a`` is on the outer side (the force on ``a`` is counted), -1 when
    ``b`` is (the force on ``b``, i.e. minus the force on ``a``, is counted).
    """
    if outer not in (1, -1):
        raise ValueError(f"outer = {outer!r} must be +1 (bank at x >= x_cut) or -1")
    a = contacts.body_a
    b = contacts.body_b
    grain = (b >= 0) & (b < n_mobile)
    bb = np.where(grain, b, 0)
    xa, ya = pos[a, 0], pos[a, 1]
    xb, yb = pos[bb, 0], pos[bb, 1]
    side_a = np.where(xa >= x_cut, 1, -1)
    side_b = np.where(xb >= x_cut, 1, -1)
    crossing = grain & (side_a != side_b)
    dx = np.where(crossing, xb - xa, 1.0)
    y_cross = np.where(crossing, ya + (x_cut - xa) * (yb - ya) / dx, np.nan)
    inside = crossing & (y_cross >= y_lo) & (y_cross <= y_hi)
    sign = np.where(inside, np.where(side_a == outer, 1, -1), 0)
    return sign.astype(np.int8), y_cross


def cut_matrix(contacts, pos, n_mobile, cuts):
    """Sparse ``(2 n_cut, 2 n)`` matrix: rows ``2k, 2k+1`` give ``(F_x, F_y) * h`` of cut ``k``.

    ``cuts`` is a sequence of ``(x_cut, outer, y_lo, y_hi)``.  Also returns the
    number of contacts crossing each cut segment.
    """
    ex, ey = contact_force_components(contacts)
    rows, cols, vals, counts = [], [], [], []
    for k, (x_cut, outer, y_lo, y_hi) in enumerate(cuts):
        sign, _ = cut_weights(contacts, pos, n_mobile, x_cut, outer, y_lo, y_hi)
        (idx,) = np.nonzero(sign)
        counts.append(len(idx))
        for comp, e in ((0, ex), (1, ey)):
            for j in range(2):
                rows.append(np.full(len(idx), 2 * k + comp))
                cols.append(2 * idx + j)
                vals.append(sign[idx] * e[idx, j])
    shape = (2 * len(cuts), 2 * contacts.n)
    if not rows:
        return sp.csr_matrix(shape), np.zeros(0, int)
    C = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)
    return C, np.array(counts)


def cut_resultant(contacts, impulse, pos, n_mobile, x_cut, outer, h=1.0, y_lo=-np.inf, y_hi=np.inf):
    """Resultant force ``(F_x, F_y)`` across one cut (impulses divided by ``h``) and the
    number of crossing contacts."""
    C, counts = cut_matrix(contacts, pos, n_mobile, [(x_cut, outer, y_lo, y_hi)])
    return C @ np.asarray(impulse, float).ravel() / h, int(counts[0])


def ground_matrix(contacts, n_mobile, edges):
    """Sparse ``(2 + n_bin, 2 n)``: the ground force on the grains, total and per bin.

    Rows 0, 1: the total force ``(F_x, F_y)`` exerted by the ground (fixed discs and
    walls) on the grains; row ``2 + i``: the vertical ground force on the contacts
    whose point lies in ``[edges[i], edges[i+1])``.  Everything times ``h``.
    """
    ex, ey = contact_force_components(contacts)
    ground = (contacts.body_b < 0) | (contacts.body_b >= n_mobile)
    (idx,) = np.nonzero(ground)
    b = np.searchsorted(edges, contacts.point[idx, 0], side="right") - 1
    ok = (b >= 0) & (b < len(edges) - 1)
    rows, cols, vals = [], [], []
    for j in range(2):
        rows += [np.zeros(len(idx), int), np.ones(len(idx), int), 2 + b[ok]]
        cols += [2 * idx + j, 2 * idx + j, 2 * idx[ok] + j]
        vals += [ex[idx, j], ey[idx, j], ey[idx[ok], j]]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(2 + len(edges) - 1, 2 * contacts.n))


def surface_profile(pos, radius, edges):
    """Free-surface height per bin: the highest disc top ``y + r`` among discs whose
    centre lies in the bin (NaN for an empty bin)."""
    b = np.searchsorted(edges, pos[:, 0], side="right") - 1
    top = np.full(len(edges) - 1, np.nan)
    ok = (b >= 0) & (b < len(top))
    for i, t in zip(b[ok], pos[ok, 1] + radius[ok]):
        if not t <= top[i]:
            top[i] = t
    return top


def fit_flanks(x, height, x_axis, fit_range):
    """Straight-line fits ``height = c0 + c1 x`` of the two flanks of the profile.

    Each flank is fitted on its side of the apex, on the points whose height lies within
    ``fit_range`` of the apex height; per flank (left, right): slope angle in degrees
    (positive: falling away from the apex), ``c0, c1``, toe, rms deviation, point count."""
    ok = np.isfinite(height)
    top = np.nanmax(height)
    out = {}
    for name, sign in (("left", -1), ("right", 1)):
        sel = ok & (sign * (x - x_axis) > 0) & (height >= fit_range[0] * top) & (height <= fit_range[1] * top)
        if sel.sum() < 3:
            raise ValueError(f"{name} flank: only {sel.sum()} profile points within {fit_range} of "
                             f"the apex height; the pile is too small for a fit")
        c1, c0 = np.polyfit(x[sel], height[sel], 1)
        rms = float(np.sqrt(np.mean((height[sel] - (c0 + c1 * x[sel])) ** 2)))
        out[name] = dict(angle=float(np.degrees(np.arctan(-sign * c1))), c0=float(c0), c1=float(c1),
                         toe=float(-c0 / c1), rms=rms, points=int(sel.sum()))
    return out


def flank_angles(fx, fy, outer, surface_angle):
    """Angle (degrees, below the horizontal, pointing outward) of a cut resultant, and
    its deviation from the free-surface slope (positive: steeper than the surface).
    A zero resultant (a cut that crosses no contact, near a toe) has no direction: NaN
    (``arctan2(0, 0)`` would give 0 or ±180 degrees by the signs of the zeros)."""
    fx, fy = np.asarray(fx, float), np.asarray(fy, float)
    phi = np.degrees(np.arctan2(-fy, outer * fx))
    phi = np.where((fx == 0.0) & (fy == 0.0), np.nan, phi)
    return phi, phi - surface_angle
