"""Convex polygons in the plane: hulls, areas, distances, clipping, and the exact
polygon of a 2-D projection from support queries (:func:`support_polygon`).

Used by :mod:`ncd.exact.polytope` (projections of A ∩ C on a contact's force plane) and
by the figures' exact sets (:mod:`ncd.figures.fig4_pile.exact`).  Vertices are
counter-clockwise ``(n, 2)`` arrays.
"""
import numpy as np


def convex_hull(points, tol=0.0):
    """Counter-clockwise hull vertices of 2-D ``points`` (monotone chain).  Points
    within ``tol`` of each other are merged and points within ``tol`` of an edge
    line dropped; degenerate sets give 1 or 2 vertices."""
    p = np.unique(np.asarray(points, dtype=float).reshape(-1, 2), axis=0)
    if tol > 0:         # merge points closer than tol (LP vertices found twice), in sorted order
        keep = np.empty_like(p)
        m = 0
        for q in p:
            if m == 0 or np.hypot(keep[:m, 0] - q[0], keep[:m, 1] - q[1]).min() > tol:
                keep[m] = q
                m += 1
        p = keep[:m]
    if len(p) <= 2:
        return p

    def half(seq):
        out = []
        for q in seq:
            while len(out) >= 2:
                e = out[-1] - out[-2]
                cross = e[0] * (q[1] - out[-2][1]) - e[1] * (q[0] - out[-2][0])
                if cross > tol * np.hypot(*e):
                    break
                out.pop()
            out.append(q)
        return out

    lower, upper = half(p), half(p[::-1])
    hull = np.array(lower[:-1] + upper[:-1])
    return hull if len(hull) else p[:1]


def polygon_area(vertices):
    """Area of a convex polygon given counter-clockwise (shoelace); 0 below 3 vertices."""
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def hull_area(points):
    """Area of the convex hull of a 2-D point cloud (0 for fewer than 3 distinct points)."""
    return max(polygon_area(convex_hull(points)), 0.0)


def _points_and_polygon(points, vertices):
    """``(p, v)`` as (m, 2) and (k, 2) float arrays, finite, ``v`` without repeated
    consecutive vertices (a zero-length edge has no normal)."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    if not (np.isfinite(p).all() and np.isfinite(v).all()):
        raise ValueError("points and vertices must be finite")
    if len(v) == 0:
        raise ValueError("a polygon needs at least one vertex")
    keep = np.any(v != np.roll(v, -1, axis=0), axis=1)
    return p, (v[keep] if keep.any() else v[:1])


def outside_distance(points, vertices):
    """Distance by which each point lies outside a convex polygon (ccw), 0 inside.

    For a segment or a single vertex it is the distance to that set.
    """
    p, v = _points_and_polygon(points, vertices)
    if len(v) < 3:
        a, b = v[0], v[-1]
        ab = b - a
        t = np.clip(((p - a) @ ab) / max(ab @ ab, 1e-300), 0.0, 1.0) if len(v) == 2 else np.zeros(len(p))
        return np.hypot(*(p - a - t[:, None] * ab).T)
    e = np.roll(v, -1, axis=0) - v
    nrm = np.column_stack([e[:, 1], -e[:, 0]]) / np.hypot(e[:, 0], e[:, 1])[:, None]
    over = ((p[:, None, :] - v[None]) * nrm[None]).sum(-1)          # > 0 outside edge k
    if np.all(over.max(1) <= 0):
        return np.zeros(len(p))
    # outside: distance to the nearest edge segment
    t = np.clip(((p[:, None, :] - v[None]) * e[None]).sum(-1) / (e * e).sum(1), 0.0, 1.0)
    d = np.hypot(*(p[:, None, :] - v[None] - t[..., None] * e[None]).transpose(2, 0, 1)).min(1)
    return np.where(over.max(1) > 0, d, 0.0)


def boundary_distance(points, vertices):
    """Distance of points inside a convex polygon (ccw) to its boundary (negative outside)."""
    p, v = _points_and_polygon(points, vertices)
    if len(v) < 3:
        return -outside_distance(p, v)
    e = np.roll(v, -1, axis=0) - v
    nrm = np.column_stack([e[:, 1], -e[:, 0]]) / np.hypot(e[:, 0], e[:, 1])[:, None]
    inside = -((p[:, None, :] - v[None]) * nrm[None]).sum(-1).max(1)
    return np.where(inside >= 0, inside, -outside_distance(p, v))


def clip_polygon(box, normals, values):
    """Intersection of a convex polygon ``box`` with half-planes ``normals . x <= values``."""
    poly = np.asarray(box, dtype=float)
    for c, h in zip(normals, values):
        if len(poly) == 0:
            break
        s = poly @ c - h
        out = []
        for k in range(len(poly)):
            p, q, sp_, sq = poly[k], poly[(k + 1) % len(poly)], s[k], s[(k + 1) % len(poly)]
            if sp_ <= 0:
                out.append(p)
            if sp_ * sq < 0:
                out.append(p + (q - p) * sp_ / (sp_ - sq))
        poly = np.array(out).reshape(-1, 2)
    return poly


def support_polygon(query, dirs, eps, max_lp, scale):
    """Exact convex polygon from support queries: ``query(u)`` returns the point of the
    set maximizing ``u . p`` (2-D).  Support points in the directions ``dirs`` start an
    inner polygon (their hull); each edge is then tested along its outer normal: if
    nothing lies beyond it by more than ``eps`` it is a true edge, otherwise the new
    point is added, until every edge is confirmed (or ``max_lp`` queries).  Returns
    ``vertices`` (ccw), ``inner_area``, ``outer_area`` (the polygon of all supporting
    half-planes), ``n_lp`` and ``exact``; ``scale`` sizes the outer polygon's box."""
    normals, values, pts = [], [], []

    def ask(u):
        p = np.asarray(query(u), dtype=float)
        normals.append(u)
        values.append(float(u @ p))
        pts.append(p)
        return p

    for u in dirs:
        ask(u)
    confirmed = set()
    n_lp = len(dirs)
    exact = False
    while n_lp < max_lp:
        hull = convex_hull(pts, tol=eps)
        edges = [(hull[k], hull[(k + 1) % len(hull)]) for k in range(len(hull))] if len(hull) > 1 else []
        if len(hull) == 2:       # a segment: test both sides
            edges = [(hull[0], hull[1]), (hull[1], hull[0])]
        todo = [(a, b) for a, b in edges if (tuple(a), tuple(b)) not in confirmed]
        if not todo:
            exact = True
            break
        for a, b in todo:
            e = b - a
            u = np.array([e[1], -e[0]]) / np.hypot(*e)
            q = ask(u)
            n_lp += 1
            if u @ q <= u @ a + eps:
                confirmed.add((tuple(a), tuple(b)))
    hull = convex_hull(pts, tol=eps)
    if len(hull) == 1:   # every direction met the same point
        exact = exact or len(dirs) >= 3
    span = max(np.ptp(np.array(pts), axis=0).max(), scale)
    box = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * 10 * span + np.array(pts).mean(0)
    outer = clip_polygon(box, normals, np.array(values) + eps)
    return {"vertices": hull, "inner_area": polygon_area(hull), "outer_area": polygon_area(outer),
            "n_lp": n_lp, "exact": bool(exact)}
