"""Readability of a matplotlib figure at page width, checked on the drawn figure.

A page shows a figure at about its natural size (``width`` inches at the saving dpi
fill the page), so a font size in points is what the reader sees.  :func:`problems`
lists texts smaller than ``min_pt``, texts cut off at the figure's edge, pairs of texts
whose boxes overlap (titles, labels, tick labels, legend entries, annotations), legends
drawn over data and duplicate panel letters.
"""
import re

import numpy as np

LETTER = re.compile(r"^\(([a-z])\)")


def texts(fig):
    """Every visible, non-empty text of ``fig`` with its box in display pixels."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    # tick labels: only those of the ticks drawn (a stale label of a tick outside the view
    # keeps its old place); every other text as found
    from matplotlib.axes import Axes

    every = fig.findobj(Axes)                          # inset axes (a colorbar) included
    stale = {id(lab) for ax in every for axis in (ax.xaxis, ax.yaxis)
             for tick in axis.get_major_ticks() + axis.get_minor_ticks() for lab in (tick.label1, tick.label2)}
    drawn = []
    for ax in every:
        if not ax.get_visible():
            continue
        for axis in (ax.xaxis, ax.yaxis):
            # the ticks matplotlib draws (those inside the view), as its draw method selects them
            ticks = axis._update_ticks()
            drawn += [lab for tick in ticks for lab in (tick.label1, tick.label2) if lab.get_visible()]
    found = [t for t in fig.findobj(lambda a: hasattr(a, "get_text") and hasattr(a, "get_fontsize"))
             if id(t) not in stale] + drawn
    out = []
    for t in found:
        if not t.get_visible() or not t.get_text().strip():
            continue
        if t.axes is not None and not t.axes.get_visible():
            continue
        bb = t.get_window_extent(renderer)
        if bb.width <= 0 or bb.height <= 0 or not np.isfinite([bb.x0, bb.y0, bb.x1, bb.y1]).all():
            continue
        out.append((t, bb))
    return out


def problems(fig, min_pt=9.0, max_width_in=10.5, pad=0.5):
    """Readability problems of ``fig`` as readable lines (empty: none)."""
    found = []
    w = fig.get_size_inches()[0]
    if w > max_width_in:
        found.append(f"figure {w:.1f} in wide: its fonts shrink below their size at page width")
    items = texts(fig)
    page = fig.bbox
    for t, bb in items:
        if t.get_fontsize() < min_pt - 1e-9:
            found.append(f"{t.get_fontsize():.1f} pt: {t.get_text()[:40]!r}")
        if bb.x0 < page.x0 - 1 or bb.x1 > page.x1 + 1 or bb.y0 < page.y0 - 1 or bb.y1 > page.y1 + 1:
            found.append(f"cut off at the figure's edge: {t.get_text()[:40]!r}")
    for i, (a, ba) in enumerate(items):
        for b, bb in items[i + 1:]:
            if a.get_text() == b.get_text() and abs(ba.x0 - bb.x0) < 1 and abs(ba.y0 - bb.y0) < 1:
                continue       # the same text drawn twice (e.g. a tick label of a shared axis)
            if (min(ba.x1, bb.x1) - max(ba.x0, bb.x0) > pad and min(ba.y1, bb.y1) - max(ba.y0, bb.y0) > pad):
                found.append(f"overlap: {a.get_text()[:30]!r} and {b.get_text()[:30]!r}")
    found += legends_over_data(fig)
    titles = [ax.get_title(loc) for ax in fig.axes if ax.get_visible() for loc in ("left", "center")]
    letters = [m.group(1) for t in titles for m in [LETTER.match(t)] if m]
    dup = sorted({x for x in letters if letters.count(x) > 1})
    if dup:
        found.append(f"panel letters repeated: {dup}")
    return found


def _display_points(artist):
    """Points of a line (densified along its segments) or of a scatter, in display pixels."""
    if hasattr(artist, "get_xydata"):
        xy = artist.get_transform().transform(np.asarray(artist.get_xydata(), float))
        xy = xy[np.isfinite(xy).all(1)]
        if len(xy) < 2:
            return xy
        steps = np.linspace(0, 1, 25)[:, None, None]
        return (xy[:-1] + steps * (xy[1:] - xy[:-1])).reshape(-1, 2)
    offsets = np.asarray(artist.get_offsets(), float)
    return artist.get_offset_transform().transform(offsets) if len(offsets) else offsets


def legends_over_data(fig):
    """Legends drawn inside an axes over some of its lines or markers."""
    renderer = fig.canvas.get_renderer()
    out = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None or not ax.get_visible():
            continue
        bb = leg.get_window_extent(renderer)
        for artist in list(ax.get_lines()) + list(ax.collections):
            if not artist.get_visible() or (hasattr(artist, "get_offsets") and not hasattr(artist, "get_xydata")
                                            and len(artist.get_offsets()) == 0):
                continue
            try:
                pts = _display_points(artist)
            except (AttributeError, ValueError):
                continue
            inside = ((pts[:, 0] > bb.x0) & (pts[:, 0] < bb.x1) & (pts[:, 1] > bb.y0) & (pts[:, 1] < bb.y1))
            if inside.any():
                out.append(f"legend over data in {ax.get_title()[:30]!r}")
                break
    return out
