"""Ground pressure of Figure 4 from the ground contacts themselves (Moreau 2005, section 5).

Bins of fixed width hold a handful of contacts each, so a "dip" under the apex can come
from where the bin edges fall.  Every estimate here (Gaussian kernel average
:func:`kernel_matrix`, shifted bins :func:`bin_matrix`, dip depth :func:`dip_row`) is
instead a linear map of the contact forces, so that the same rows serve NLGS runs and
the exact LP ranges of :mod:`ncd.figures.fig4_pile.exact`.  The dip depth is the flank value
minus the central value (> 0 a dip, < 0 a hump), the sign and name of the history
piles' dip (:mod:`ncd.figures.fig4_history.analysis`).  :func:`dip_verdict` calls a dip only
when it exceeds the binning sensitivity and its exact range over A ∩ C is above zero.
"""
import numpy as np
import scipy.sparse as sp

from ncd.shared.cuts import contact_force_components


def ground_contacts(contacts, n_mobile):
    """Indices, abscissae and vertical-force rows ``ey`` of the ground contacts."""
    (idx,) = np.nonzero((contacts.body_b < 0) | (contacts.body_b >= n_mobile))
    _, ey = contact_force_components(contacts)
    return idx, contacts.point[idx, 0], ey[idx]


def _rows(weights, idx, ey, n_contacts):
    """Sparse (n_x, 2 n) matrix of ``weights[x, k] * F_y`` of ground contact ``idx[k]``."""
    w = sp.coo_matrix(weights)
    cols = np.concatenate([2 * idx[w.col], 2 * idx[w.col] + 1])
    vals = np.concatenate([w.data * ey[w.col, 0], w.data * ey[w.col, 1]])
    rows = np.concatenate([w.row, w.row])
    return sp.csr_matrix((vals, (rows, cols)), shape=(weights.shape[0], 2 * n_contacts))


def kernel_matrix(contacts, n_mobile, x, width):
    """Rows ``p(x_i)`` (N/m per unit force): Gaussian kernel of standard deviation ``width``."""
    if not width > 0:
        raise ValueError(f"kernel width = {width!r} must be > 0")
    idx, xc, ey = ground_contacts(contacts, n_mobile)
    x = np.asarray(x, float).ravel()
    z = (x[:, None] - xc[None, :]) / width
    k = np.exp(-0.5 * z * z) / (width * np.sqrt(2 * np.pi))
    k[np.abs(z) > 8] = 0.0
    return _rows(k, idx, ey, contacts.n)


def bin_matrix(contacts, n_mobile, edges):
    """Rows: the vertical ground force of the contacts in ``[edges[i], edges[i+1])`` per unit length."""
    idx, xc, ey = ground_contacts(contacts, n_mobile)
    edges = np.asarray(edges, float)
    b = np.searchsorted(edges, xc, side="right") - 1
    ok = (b >= 0) & (b < len(edges) - 1)
    w = np.zeros((len(edges) - 1, len(idx)))
    w[b[ok], np.nonzero(ok)[0]] = 1.0 / np.diff(edges)[b[ok]]
    return _rows(w, idx, ey, contacts.n)


def centred_edges(width, shift, half_span):
    """Bin edges of ``width`` covering ``|x| <= half_span``, a bin centred at ``shift``."""
    m = int(np.ceil((half_span + abs(shift)) / width)) + 1
    return shift + (np.arange(-m, m + 2) - 0.5) * width


def dip_row(P, x, offset):
    """Row of the dip depth ``(p(-a) + p(a)) / 2 - p(0)`` (> 0 a dip) from an estimate ``P``
    at abscissae ``x`` (the estimate's values are interpolated linearly; bins: their centres)."""
    x = np.asarray(x, float)
    out = sp.csr_matrix((1, P.shape[1]))
    for x0, w in ((0.0, -1.0), (-offset, 0.5), (offset, 0.5)):
        j = int(np.clip(np.searchsorted(x, x0) - 1, 0, len(x) - 2))
        t = (x0 - x[j]) / (x[j + 1] - x[j])
        out = out + w * ((1 - t) * P[j] + t * P[j + 1])
    return sp.csr_matrix(out)


def sensitivity_rows(contacts, n_mobile, d, offset, kernel_widths_d, bin_widths_d, shifts):
    """Dip-depth rows of every analysis choice: ``(labels, rows)``; kernels of the given
    widths and bins of the given widths, each shifted by every fraction in ``shifts``."""
    half = max(4 * offset, 10 * d)
    labels, rows = [], []
    x = np.arange(-half, half + 0.25 * d, 0.25 * d)
    for w in kernel_widths_d:
        labels.append(f"kernel {w:g} d")
        rows.append(dip_row(kernel_matrix(contacts, n_mobile, x, w * d), x, offset))
    for b in bin_widths_d:
        for s in shifts:
            e = centred_edges(b * d, s * b * d, half)
            labels.append(f"bins {b:g} d shifted {s:g}")
            rows.append(dip_row(bin_matrix(contacts, n_mobile, e), 0.5 * (e[1:] + e[:-1]), offset))
    return labels, sp.vstack(rows).tocsr()


def dip_verdict(history_depth, binning_spread, exact_lo, exact_hi):
    """("forced" | "allowed" | "excluded", called): the geometry's verdict from the
    exact range of the dip depth (> 0 a dip), and whether a dip is called for the history
    forces (a depth above zero, above its spread over the analysis choices, and forced)."""
    geometry = "forced" if exact_lo > 0 else ("excluded" if exact_hi <= 0 else "allowed")
    called = bool(history_depth > 0 and history_depth > binning_spread and geometry == "forced")
    return geometry, called
