"""Where NLGS solutions lie in A ∩ C, over every run (Moreau 2005, section 4).

For each equilibrium force vector of a :class:`ncd.exact.polytope.ForcePolytope`: the
dimension of the face of A ∩ C holding it (Coulomb rows tight within ``tol``), the
contacts carrying no force and those sliding at the Coulomb limit.  :func:`face_summary`
counts them per exploration mode and :func:`face_text` words the result, so that the
notebook's sentences follow from the measurement.  The judging functions of section 4
read three more measures: the faces shared by several points (:func:`face_classes`,
:func:`shared_low_faces`: the ghost images of edges and vertices), a scale-free distance
to the boundary of A ∩ C (:func:`depth`) and the limits that runs share
(:func:`limit_clusters`).
"""
import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ncd.exact.polytope import PolytopeError


def face_census(polytope, forces, tol=1e-9):
    """Per point: ``(face_dimension, n_no_force, n_sliding)`` (arrays)."""
    r = np.atleast_2d(np.asarray(forces, float)) / polytope.scale
    G = polytope.G.toarray()
    A = polytope.A_eq.toarray()
    active = -(r @ G.T) <= tol                          # Coulomb rows met with equality
    patterns, inverse = np.unique(active, axis=0, return_inverse=True)
    rank = np.array([np.linalg.matrix_rank(np.vstack([A, G[p]])) for p in patterns])
    dims = G.shape[1] - rank[np.ravel(inverse)]          # as ForcePolytope.active_faces, once per pattern
    rn, rt = r[:, 0::2], r[:, 1::2]
    free = rn <= tol
    slide = ~free & (np.abs(rt) >= polytope.mu[None, :] * rn - tol)
    return dims, free.sum(1), slide.sum(1)


def face_summary(polytope, modes, tol=1e-9):
    """``{mode: dict}`` over every point of each mode (``modes``: name -> forces (runs, 2 kappa)):
    runs, interior runs (face dimension = dim A ∩ C), face dimensions (min, median, max),
    runs with a contact carrying no force, sliding contacts (min, median, max)."""
    _, _, _, _, implicit = polytope.affine_hull()
    d_ac = _face_dimension(polytope, implicit)
    out = {}
    for name, forces in modes.items():
        dims, free, slide = face_census(polytope, forces, tol)
        out[name] = {"runs": len(dims), "interior": int((dims == d_ac).sum()), "dimension": d_ac,
                     "dims": (int(dims.min()), float(np.median(dims)), int(dims.max())),
                     "dims_all": dims, "with_free": int((free > 0).sum()), "max_free": int(free.max()),
                     "sliding": (int(slide.min()), float(np.median(slide)), int(slide.max()))}
    return out


def _face_dimension(polytope, implicit):
    """Dimension of A ∩ C: that of A minus the rank added by the implicit equalities."""
    G = polytope.G.toarray()
    A = polytope.A_eq.toarray()
    E = np.vstack([A, G[implicit]]) if implicit.any() else A
    return G.shape[1] - np.linalg.matrix_rank(E)


def face_text(summary, modes=("zero", "random")):
    """Sentences on where the NLGS points lie, from :func:`face_summary`."""
    parts = []
    for m in modes:
        s = summary[m]
        lo, med, hi = s["dims"]
        where = ("every one lies on a proper face of $A \\cap C$" if s["interior"] == 0 else
                 f"{s['runs'] - s['interior']} lie on a proper face of $A \\cap C$ and {s['interior']} "
                 f"{'is' if s['interior'] == 1 else 'are'} interior")
        free = ("no contact carries zero force in any of them" if s["with_free"] == 0 else
                f"{s['with_free']} have at least one contact without force (at most {s['max_free']})")
        sl = s["sliding"]
        parts.append(f"Of the {s['runs']} {m}-guess runs, {where} (face dimension {lo} to {hi}, median "
                     f"{med:g}, out of {s['dimension']}); {free}; {sl[0]} to {sl[2]} contacts (median "
                     f"{sl[1]:g}) slide at the Coulomb limit.")
    return " ".join(parts)


def face_classes(polytope, forces, tol=1e-9):
    """The face of ``A ∩ C`` holding each point, as a class shared by the points on the
    same face (the same Coulomb rows met with equality within ``tol``).  Returns
    ``(face, dims, counts)``: per point the index of its face, per face its dimension
    and the number of points on it."""
    r = np.atleast_2d(np.asarray(forces, float)) / polytope.scale
    G = polytope.G.toarray()
    A = polytope.A_eq.toarray()
    active = -(r @ G.T) <= tol
    patterns, inverse, counts = np.unique(active, axis=0, return_inverse=True, return_counts=True)
    dims = G.shape[1] - np.array([np.linalg.matrix_rank(np.vstack([A, G[p]])) for p in patterns], int)
    return np.ravel(inverse), dims, counts


def shared_low_faces(polytope, forces, max_dim=1, min_points=10, tol=1e-9):
    """Faces of dimension ``<= max_dim`` (edges and vertices for 1) holding at least
    ``min_points`` of the points: ``(sizes, dims, points on them, points on any face of
    dimension <= max_dim)``; sizes in decreasing order."""
    face, dims, counts = face_classes(polytope, forces, tol)
    low = dims <= max_dim
    ghost = low & (counts >= min_points)
    order = np.argsort(-counts[ghost], kind="stable")
    return counts[ghost][order], dims[ghost][order], int(counts[ghost].sum()), int(counts[low].sum())


def hull_frame(polytope):
    """The affine hull of ``A ∩ C`` with each Coulomb row's width: ``(x0, Z, Gz, b, width)``
    (scaled units, :meth:`ncd.exact.polytope.ForcePolytope.affine_hull`), ``width[i]`` the
    largest slack ``b_i - Gz_i y`` over ``A ∩ C`` (one LP per row), the set's extent
    across that row's hyperplane."""
    x0, Z, Gz, b, _ = polytope.affine_hull()
    d = Z.shape[1]
    width = np.empty(len(b))
    for i in range(len(b)):
        res = linprog(Gz[i], A_ub=Gz, b_ub=b, bounds=[(None, None)] * d, method="highs", options=polytope.highs)
        if res.status != 0:
            raise PolytopeError(f"width LP of Coulomb row {i} failed: {res.message}")
        width[i] = b[i] - res.fun
    return x0, Z, Gz, b, np.maximum(width, 1e-300)


def depth(frame, polytope, forces):
    """Scale-free distance of each point to the boundary of ``A ∩ C`` within its affine
    hull: the smallest slack of the Coulomb rows, each over its width (:func:`hull_frame`),
    clipped at 0.  0 on the boundary; invariant under affine maps, so that a thin
    direction of the set counts as much as a wide one; a vertex of a simplex has the
    depth 0, its centroid ``1 / (d + 1)``."""
    x0, Z, Gz, b, width = frame
    if not len(b):
        return np.zeros(len(np.atleast_2d(forces)))
    y = (np.atleast_2d(np.asarray(forces, float)) / polytope.scale - x0) @ Z
    return np.maximum(((b[None, :] - y @ Gz.T) / width[None, :]).min(1), 0.0)


def limit_clusters(points, radius):
    """Single-linkage classes of ``points`` (rows) closer than ``radius``: points reached
    by runs that share a limit.  Returns ``(label per point, size per class, distance of
    each point to its nearest other point)`` (inf for a single point)."""
    points = np.atleast_2d(np.asarray(points, float))
    n = len(points)
    if n == 0:
        return np.zeros(0, int), np.zeros(0, int), np.zeros(0)
    tree = cKDTree(points)
    pairs = tree.query_pairs(radius, output_type="ndarray")
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    nearest = tree.query(points, k=2)[0][:, 1] if n > 1 else np.full(1, np.inf)
    return labels, np.bincount(labels), nearest
