"""Where NLGS solutions lie in A ∩ C, over every run (Moreau 2005, section 4).

For each equilibrium force vector of a :class:`ncd.exact.polytope.ForcePolytope`: the
dimension of the face of A ∩ C holding it (Coulomb rows tight within ``tol``), the
contacts carrying no force and those sliding at the Coulomb limit.  :func:`face_summary`
counts them per exploration mode and :func:`face_text` words the result, so that the
notebook's sentences follow from the measurement.
"""
import numpy as np


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
