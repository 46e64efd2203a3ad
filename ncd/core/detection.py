"""Contact detection between discs in O(N) with a cell grid (periodic along x or not).

Discs are binned by a counting sort into square cells at least one largest
diameter plus the alert distance wide; each disc is compared with the discs of
its own cell and of four neighbour cells (half stencil).  Along a periodic x the
cell indices wrap and the pair distance uses the minimum image (the period is
at least three largest diameters, checked by :func:`ncd.core.scene.make_scene`;
should an alert distance leave fewer than three columns, duplicate pairs are
removed).
"""
import numpy as np

from ncd.core.errors import InputError
from ncd.core.jit import njit
from ncd.core.model import check_scene
from ncd.core.validate import array, real


@njit(cache=True)
def _grid_pairs(pos, radius, n_mobile, alert, period, cell, out_a, out_b, out_shift):
    """Write candidate pairs ``(a, b)`` with gap <= alert; return their count.

    ``a`` is the mobile disc of the pair (the smaller index when both are
    mobile); pairs of two fixed discs are skipped.  ``out_shift`` is the x
    offset of the periodic image of ``b``.  Writes at most ``len(out_a)`` pairs
    but counts them all, so a caller can retry with a larger buffer.
    """
    n = pos.shape[0]
    cap = out_a.shape[0]
    if period > 0.0:
        x0 = 0.0
        nx = max(1, int(period / cell))
        cx_size = period / nx
    else:
        x0 = pos[:, 0].min()
        nx = int((pos[:, 0].max() - x0) / cell) + 1
        cx_size = cell
    y0 = pos[:, 1].min()
    ny = int((pos[:, 1].max() - y0) / cell) + 1
    cell_of = np.empty(n, np.int64)
    counts = np.zeros(nx * ny + 1, np.int64)
    for i in range(n):
        # floor, not int(): along a periodic x a middle configuration may lie
        # slightly left of 0 and must wrap into the last column
        cx = int(np.floor((pos[i, 0] - x0) / cx_size))
        if period > 0.0:
            cx = cx % nx
        cx = min(max(cx, 0), nx - 1)
        cy = min(int((pos[i, 1] - y0) / cell), ny - 1)
        cell_of[i] = cy * nx + cx
        counts[cell_of[i] + 1] += 1
    for c in range(nx * ny):
        counts[c + 1] += counts[c]
    start = counts.copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[start[cell_of[i]]] = i
        start[cell_of[i]] += 1
    # stencil: self, E, NW, N, NE
    sdx = (0, 1, -1, 0, 1)
    sdy = (0, 0, 1, 1, 1)
    count = 0
    for cy in range(ny):
        for cx in range(nx):
            c = cy * nx + cx
            for s in range(5):
                ncx = cx + sdx[s]
                ncy = cy + sdy[s]
                if ncy >= ny:
                    continue
                if period > 0.0:
                    ncx = ncx % nx
                elif ncx < 0 or ncx >= nx:
                    continue
                nc = ncy * nx + ncx
                for ii in range(counts[c], counts[c + 1]):
                    i = order[ii]
                    jstart = ii + 1 if s == 0 else counts[nc]
                    for jj in range(jstart, counts[nc + 1]):
                        j = order[jj]
                        if i >= n_mobile and j >= n_mobile:
                            continue
                        a, b = (i, j) if i < j else (j, i)
                        dx = pos[a, 0] - pos[b, 0]
                        shift = 0.0
                        if period > 0.0:
                            shift = period * np.rint(dx / period)
                            dx -= shift
                        dy = pos[a, 1] - pos[b, 1]
                        reach = radius[a] + radius[b] + alert
                        if dx * dx + dy * dy <= reach * reach:
                            if count < cap:
                                out_a[count] = a
                                out_b[count] = b
                                out_shift[count] = shift
                            count += 1
    return count


@njit(cache=True)
def _extent(pos, radius):
    """``x_min, x_max, y_min, y_max`` of ``pos`` and the largest radius."""
    x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
    for i in range(pos.shape[0]):
        x0, x1 = min(x0, pos[i, 0]), max(x1, pos[i, 0])
        y0, y1 = min(y0, pos[i, 1]), max(y1, pos[i, 1])
    return x0, x1, y0, y1, radius.max()


def disc_pairs(pos, radius, n_mobile, alert=0.0, period=0.0):
    """Candidate disc pairs within ``alert``: arrays ``(a, b, shift_b)``."""
    n = len(radius)
    x0, x1, y0, y1, rmax = _extent(pos, radius)
    cell = 2.0 * rmax + alert
    if period <= 0.0:
        # keep the grid about as large as the number of discs; the span from one
        # pass of _extent (np.ptp's max - min, the same bits, without its overhead)
        cell = max(cell, float(np.sqrt((x1 - x0 + cell) * (y1 - y0 + cell) / (4.0 * n + 16.0))))
    cap = 4 * n + 16
    while True:
        a = np.empty(cap, np.int64)
        b = np.empty(cap, np.int64)
        shift = np.empty(cap)
        count = _grid_pairs(pos, radius, n_mobile, float(alert), float(period), cell, a, b, shift)
        if count <= cap:
            break
        cap = count
    a, b, shift = a[:count], b[:count], shift[:count]
    if period > 0.0 and int(period / cell) < 3:
        # fewer than three columns across the period: the wrapped stencil meets
        # some cell pairs twice (and a cell with itself); keep each pair once
        keep = np.nonzero(a != b)[0]
        _, first = np.unique(a[keep] * n + b[keep], return_index=True)
        keep = keep[np.sort(first)]
        a, b, shift = a[keep], b[keep], shift[keep]
    return a, b, shift


# ------------------------------------------------------------ argument checks
MAX_GRID_CELLS = 1e7      # cells of the contact detection grid (8 bytes each)


def check_detection_args(s, alert, pos):
    """Arguments of :func:`ncd.detect_contacts`; returns ``pos`` (the scene's if None)."""
    check_scene(s)
    alert = real("alert", alert, 0.0)
    pos = array("pos", s.pos if pos is None else pos, (s.n_disc, 2))
    x0, x1, y0, y1, rmax = _extent(pos, s.radius)
    if max(-x0, x1, -y0, y1) > 1e150:
        raise InputError(f"pos must be below 1e150 in magnitude; got {max(-x0, x1, -y0, y1):.3g}")
    # the cell grid of ncd.core.detection.disc_pairs (same formulas): refuse what would not fit in memory
    n = len(pos)
    cell = 2.0 * rmax + alert
    span = (x1 - x0, y1 - y0)
    with np.errstate(over="ignore"):
        if s.period > 0:
            cells = max(1.0, s.period / cell) * (span[1] / cell + 1.0)
        else:
            cell = max(cell, float(np.sqrt((span[0] + cell) * (span[1] + cell) / (4.0 * n + 16.0))))
            cells = (span[0] / cell + 1.0) * (span[1] / cell + 1.0)
    if not cells <= MAX_GRID_CELLS:
        raise InputError(f"the contact detection grid would need {cells:.3g} cells (> {MAX_GRID_CELLS:.0g}): "
                         f"the discs span {span[0]:.3g} x {span[1]:.3g}"
                         + (f" (period {s.period:.3g})" if s.period > 0 else "")
                         + f" for a cell of {cell:.3g} (largest diameter plus alert)")
    return pos
