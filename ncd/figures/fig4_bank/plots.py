"""Plots of fig4_bank: the bank of the piles, cut by segments parallel to the free surface.

Panels: (a) the right flank of the default pile with its surface-parallel cuts and the
resultants across them and across vertical cuts through their centres; (b, c) the angle
to the vertical against depth and position, medians over cuts and piles with bootstrap
bands over piles; (d) the exact ranges over A ∩ C; (e) both sides of the reciprocity
formula per window, from the stress and from the cuts' own sums; (f) the friction
mobilized on the surface-parallel planes against tan of the flank angle; (g) the major
principal direction along the flank; (h, i) the tilting test: each flank's failure angle
against its slope, and the grains displaced against the tilt.
"""
import numpy as np

from ncd.figures.fig4_bank import stress as st
from ncd.figures.fig4_bank.claims import CLAIM_HISTORY, flank_slope, tilt_numbers
from ncd.figures.fig4_bank.measure import HISTORY_LABELS

COLORS = {"default": "k", "point": "C3", "rain": "C0", "layer": "C2"}
FONT = 11


def _histories(ms):
    return [str(h) for h in ms.history.values]


def plot_flank(ax, ms, con, depth_index=1):
    """(a) The right flank of the default pile: grains, the surface-parallel cuts (one depth
    per position drawn with its window) and the resultants across them (red) and across
    the vertical cuts through their centres (blue), to one scale."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle, Polygon
    d = float(ms.attrs["mean_diameter"])
    s = ms.sel(pile="default", flank="right")
    x0 = float(np.nanmin(s.x.values)) - 0.6 * float(ms.attrs["length_d"]) * d
    keep = ((con.x.values > x0) & (con.x.values > 0))
    ax.add_collection(PatchCollection([Circle((x / d, y / d), r / d) for x, y, r in zip(
        con.x.values[keep], con.y.values[keep], con.radius.values[keep])], facecolor="0.85", edgecolor="0.6", lw=0.3))
    angle = float(ms.surface_angle.sel(pile="default", flank="right"))
    t, n = st.flank_frame(angle, 1)
    half = 0.5 * float(ms.attrs["length_d"]) * d
    F = np.hypot(s.force_x.values, s.force_y.values)
    scale = 5.0 * d / np.nanmax(F) if np.isfinite(F).any() else 1.0
    for j in range(ms.sizes["position"]):
        for k in range(ms.sizes["depth"]):
            if not s.valid.values[j, k]:
                continue
            c = np.array([float(s.x[j, k]), float(s.y[j, k])])
            ends = np.array([c - half * t, c + half * t]) / d
            ax.plot(ends[:, 0], ends[:, 1], "-", color="C1", lw=1.0)
            if k == depth_index:
                win = st.rectangle(c, t, half, 0.5 * float(s.thickness[j, k]))
                ax.add_patch(Polygon(st.rectangle_corners(win) / d, fill=False, ec="C1", lw=0.6, ls="--"))
                vh = float(s.vertical_half[j, k])
                ax.plot([c[0] / d] * 2, [(c[1] - vh) / d, (c[1] + vh) / d], "-", color="C0", lw=1.0)
                for fx, fy, col in ((s.force_x[j, k], s.force_y[j, k], "C3"),
                                    (s.vertical_fx[j, k], s.vertical_fy[j, k], "C0")):
                    ax.annotate("", xy=(c[0] / d + scale * float(fx) / d, c[1] / d + scale * float(fy) / d),
                                xytext=(c[0] / d, c[1] / d), arrowprops=dict(arrowstyle="-|>", color=col, lw=1.4))
    ax.plot([], [], "-", color="C1", label="surface-parallel cuts (depths {})".format(
        ", ".join(f"{v:g}" for v in ms.depth.values) + " d"))
    ax.plot([], [], "--", color="C1", lw=0.6, label=f"stress window at {float(ms.depth[depth_index]):g} d")
    ax.plot([], [], "-", color="C3", lw=1.4, label="resultant across the surface-parallel cut")
    ax.plot([], [], "-", color="C0", lw=1.4, label="resultant across the vertical cut")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x / d", fontsize=FONT)
    ax.set_ylabel("y / d", fontsize=FONT)
    ax.legend(fontsize=FONT - 1, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)


def _medians(ax, ms, name, dim, xlabel, ylabel, jitter=0.12):
    """Medians over cuts and piles against ``dim`` per history, with bootstrap bands over piles
    (bars) and the single cuts of the point-source piles (dots)."""
    hist = _histories(ms)
    xs = ms[dim].values
    step = np.min(np.diff(xs)) if len(xs) > 1 else 1.0
    for i, h in enumerate(hist):
        off = (i - 0.5 * (len(hist) - 1)) * jitter * step
        m = ms[f"{name}_by_{dim}"].sel(history=h).values
        lo, hi = ms[f"{name}_by_{dim}_lo"].sel(history=h).values, ms[f"{name}_by_{dim}_hi"].sel(history=h).values
        ax.vlines(xs + off, lo, hi, color=COLORS[h], lw=1.4)
        ax.plot(xs + off, m, "o", color=COLORS[h], ms=5, label=HISTORY_LABELS[h])
    if "point" in hist and name == "angle":
        v = ms.angle_to_vertical.values[ms.pile_history.values == "point"]
        axis = {"depth": 3, "position": 2}[dim]
        vv = np.moveaxis(v, axis, -1).reshape(-1, len(xs))
        for j, x in enumerate(xs):
            y = vv[:, j][np.isfinite(vv[:, j])]
            ax.plot(np.full(len(y), x + 0.3 * step), y, ".", color=COLORS["point"], ms=2, alpha=0.35)
    ax.set_xlabel(xlabel, fontsize=FONT)
    ax.set_ylabel(ylabel, fontsize=FONT)


def plot_angle(ax, ms, dim):
    """(b, c) The angle of the surface-parallel resultant to the vertical against depth or position."""
    tol = float(ms.attrs["vertical_tol_deg"])
    ax.axhspan(-tol, tol, color="0.92", lw=0)
    ax.axhline(0.0, color="0.5", lw=0.6)
    _medians(ax, ms, "angle", dim, "depth below the surface (d)" if dim == "depth" else "cut centre |x| / L",
             "angle to the vertical (deg, + outward)")
    ax.set_ylim(-30, 30)


def plot_exact(ax, exact):
    """(d) Exact range over A ∩ C of the angle to the vertical per cut (bars) and the history
    forces' angle (dots), for the piles with exact ranges."""
    x0 = 0
    ticks, labels = [], []
    for name, e in exact.items():
        h = "default" if name == "default" else name.split("_")[0]
        lo, hi, hv = (e[k].values.ravel() for k in ("angle_min", "angle_max", "history_angle"))
        ok = np.isfinite(lo)
        xs = x0 + np.arange(ok.sum())
        ax.vlines(xs, lo[ok], hi[ok], color=COLORS[h], lw=1.6, alpha=0.5)
        ax.plot(xs, hv[ok], ".", color=COLORS[h], ms=4)
        ticks.append(x0 + 0.5 * max(ok.sum() - 1, 0))
        labels.append(name.replace("_", " "))
        x0 += ok.sum() + 3
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xticks(ticks)
    ax.set_xticklabels(labels, fontsize=FONT - 1)
    ax.set_ylabel("angle to the vertical (deg)", fontsize=FONT)
    ax.set_xlabel("cuts (bars: exact range over A ∩ C; dots: history)", fontsize=FONT)


def plot_reciprocity(ax, ms):
    """(e) Both sides of the reciprocity formula per window: from the Love-Weber stress
    (coloured, on the diagonal) and from the cuts' own sums (grey)."""
    ax.plot(ms.direct_vertical.values.ravel(), ms.direct_surface.values.ravel(), ".", color="0.7", ms=3,
            label="cuts' own sums")
    for h in _histories(ms)[::-1]:
        sel = ms.pile_history.values == h
        ax.plot(ms.reciprocity_vertical.values[sel].ravel(), ms.reciprocity_surface.values[sel].ravel(), ".",
                color=COLORS[h], ms=2.5, label=f"σ, {HISTORY_LABELS[h]}")
    lim = 0.8
    ax.plot([-lim, lim], [-lim, lim], "-", color="0.4", lw=0.6)
    ax.set(xlim=(-lim, lim), ylim=(-lim, lim))
    ax.set_aspect("equal")
    ax.set_xlabel(r"$n_s\cdot\sigma e\,/\,p$ (vertical cut)", fontsize=FONT)
    ax.set_ylabel(r"$e\cdot\sigma n_s\,/\,p$ (surface-parallel cut)", fontsize=FONT)


def plot_failure(ax, ms):
    """(f) tau / sigma_n on the surface-parallel plane (window stress) against tan of the
    flank angle, per window; the diagonal is the infinite-slope identity of a vertical force."""
    for h in _histories(ms):
        sel = ms.pile_history.values == h
        ax.plot(ms.tan_flank.values[sel].ravel(), ms.mobilized.values[sel].ravel(), ".", color=COLORS[h], ms=3,
                alpha=0.6)
        ax.plot(float(np.nanmedian(ms.tan_flank.values[sel])), float(np.nanmedian(ms.mobilized.values[sel])), "D",
                color=COLORS[h], mec="w", ms=7, label=f"{HISTORY_LABELS[h]} (median)")
    ax.plot([0, 0.5], [0, 0.5], "-", color="0.4", lw=0.6)
    ax.set(xlim=(0, 0.45), ylim=(-0.1, 0.6))
    ax.set_xlabel("tan(flank angle)", fontsize=FONT)
    ax.set_ylabel(r"$\tau/\sigma_n$ on the surface-parallel plane", fontsize=FONT)


def limit_angle(ms, tilt=None):
    """``(phi, measured)``: the tilting test's median failure angle of the point-source flanks, or
    (no test) their median slope θ standing for it."""
    if tilt is not None and CLAIM_HISTORY in tilt.history.values:
        phi = tilt_numbers(tilt)["theta_fail"]
        if np.isfinite(phi):
            return phi, True
    return flank_slope(ms), False


def plot_principal(ax, ms, tilt=None):
    """(g) The major principal direction from the vertical along the flank (medians and bands), and
    that of a slope at the limit, -(45° - phi/2), phi the measured failure angle (else θ)."""
    ax.axhline(0.0, color="0.5", lw=0.6)
    if CLAIM_HISTORY in _histories(ms):
        phi, measured = limit_angle(ms, tilt)
        ax.axhline(-(45.0 - phi / 2), color=COLORS["point"], lw=0.8, ls="--")
        ax.set_title(f"dashed: a slope at the limit, {'φ' if measured else 'θ'} = {phi:.1f}°", fontsize=FONT - 1,
                     loc="right", color=COLORS["point"])
    _medians(ax, ms, "major", "position", "cut centre |x| / L", "major principal direction\nfrom the vertical "
             "(deg, + outward)")


def plot_tilt_angles(ax, tilt):
    """(h) Each tilted flank's failure angle θ + α_fail against its slope θ: on the diagonal a flank
    at incipient failure, the shaded band the claim's margin (tilt step + hysteresis)."""
    n = tilt_numbers(tilt)
    lo = float(np.nanmin(tilt.theta.values)) - 2.0
    hi = max(float(np.nanmax(tilt.theta_fail.values)) if np.isfinite(tilt.theta_fail.values).any() else lo,
             float(np.nanmax(tilt.theta.values))) + 2.0
    xs = np.array([lo, hi])
    ax.fill_between(xs, xs, xs + n["threshold"], color="0.9", lw=0)
    ax.plot(xs, xs, "-", color="0.4", lw=0.6)
    for h in [str(v) for v in tilt.history.values]:
        sel = tilt.pile_history.values == h
        for j, (f, mark) in enumerate(zip(tilt.flank.values, ("<", ">"))):
            th, tf = tilt.theta.values[sel, j], tilt.theta_fail.values[sel, j]
            ok = np.isfinite(tf)
            ax.plot(th[ok], tf[ok], mark, color=COLORS[h], ms=6, label=f"{HISTORY_LABELS[h]}, {f} flank")
            ax.plot(th[~ok], th[~ok] + n["max_deg"], "^", color=COLORS[h], ms=6, mfc="none")
    ax.set(xlim=(lo, hi), ylim=(lo, hi + n["step"]))
    ax.set_aspect("equal")
    ax.set_xlabel("flank slope θ (deg)", fontsize=FONT)
    ax.set_ylabel(r"failure angle $\theta + \alpha_\mathrm{fail}$ (deg)", fontsize=FONT)
    ax.legend(fontsize=FONT - 1, loc="upper left", bbox_to_anchor=(2.45, 1.0), frameon=False)


def plot_tilt_trajectories(ax, tilt):
    """(i) Grains of the tilted side displaced by more than the threshold against the tilt, per
    flank, up to its failure (the dotted line: the failure count)."""
    al = tilt.alpha.values
    for name, h in zip(tilt.pile.values, tilt.pile_history.values):
        for f in tilt.flank.values:
            y = tilt.displaced.sel(pile=name, flank=f).values
            ax.plot(al, np.maximum(y, 0.5), "-", color=COLORS[str(h)], lw=1.2 if h == "default" else 0.7,
                    alpha=1.0 if h == "default" else 0.6, drawstyle="steps-post")
    ax.axhline(float(tilt.attrs["grains"]), color="0.4", lw=0.6, ls=":")
    ax.set_yscale("log")
    ax.set_xlim(0, float(np.nanmax(np.where(np.isfinite(tilt.alpha_fail.values), tilt.alpha_fail.values,
                                            tilt.attrs["max_deg"]))) + 1.0)
    ax.set_xlabel(r"tilt $\alpha$ towards the flank (deg)", fontsize=FONT)
    ax.set_ylabel(f"grains moved > {float(tilt.attrs['displaced_d']):g} d", fontsize=FONT)


def figure(ms, exact, con, tilt=None):
    """The figure of the page: (a) on top, (b)-(g) below, (h, i) the tilting test when ``tilt`` is given."""
    import matplotlib.pyplot as plt
    from matplotlib.gridspec import GridSpec
    rows = 3 if tilt is None else 4
    fig = plt.figure(figsize=(13.5, 12.0 + 4.0 * (rows - 3)))
    gs = GridSpec(rows, 3, figure=fig, height_ratios=[0.8] + [1.0] * (rows - 1), hspace=0.4, wspace=0.38,
                  left=0.07, right=0.98, top=0.97, bottom=0.06 if tilt is None else 0.045)
    axa = fig.add_subplot(gs[0, :2])
    plot_flank(axa, ms, con, depth_index=min(1, ms.sizes["depth"] - 1))
    cells = [(1, 0), (1, 1), (1, 2), (2, 0), (2, 1), (2, 2)] + ([] if tilt is None else [(3, 0), (3, 1)])
    axes = [axa] + [fig.add_subplot(gs[i, j]) for i, j in cells]
    plot_angle(axes[1], ms, "depth")
    plot_angle(axes[2], ms, "position")
    plot_exact(axes[3], exact)
    plot_reciprocity(axes[4], ms)
    plot_failure(axes[5], ms)
    plot_principal(axes[6], ms, tilt)
    if tilt is not None:
        plot_tilt_angles(axes[7], tilt)
        plot_tilt_trajectories(axes[8], tilt)
    top = fig.transFigure.inverted().transform(axa.transAxes.transform((0.0, 1.0)))[1]
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(0.69, top - 0.17 * 12.0 / fig.get_figheight()),
               fontsize=FONT, frameon=False, title="medians over cuts and piles,\nbars: bootstrap band over piles",
               title_fontsize=FONT)
    h5, l5 = axes[4].get_legend_handles_labels()
    axes[4].legend(h5[::-1], l5[::-1], fontsize=FONT - 1, loc="upper left", framealpha=0.9, edgecolor="none",
                   markerscale=3)
    for ax, letter in zip(axes, "abcdefghi"):
        ax.tick_params(labelsize=FONT - 1)
        ax.text(-0.02, 1.03, f"({letter})", transform=ax.transAxes, fontsize=FONT + 1, fontweight="bold",
                ha="right", va="bottom")
    return fig


def caption(ms, depth_index=1, tilt=None):
    """The caption of :func:`figure` (the drawn window's depth and the claim's tolerance from the data)."""
    k = min(depth_index, ms.sizes["depth"] - 1)
    _, measured = limit_angle(ms, tilt)
    text = (f"**(a)** The right flank of the default pile: the surface-parallel cuts (orange) at each position and "
            f"depth, the stress window of the cuts {float(ms.depth[k]):g} d deep (dashed) with the vertical cut "
            f"through its centre (blue), and the resultants across both cuts to one scale (red: across the "
            f"surface-parallel cut; blue: across the vertical cut). **(b, c)** Angle of the surface-parallel "
            f"resultant to the vertical against depth and position: medians over cuts and piles (points), "
            f"{100 * float(ms.attrs['level']):g} % bootstrap bands over piles (bars), the single cuts of the "
            f"point-source piles (small dots); the grey band is the claim's tolerance, "
            f"±{float(ms.attrs['vertical_tol_deg']):g}°. **(d)** Exact range over A ∩ C of that angle per cut (bars) "
            f"and the history forces' angle (dots). **(e)** Both sides of the reciprocity formula per window, over "
            f"the mean pressure p: from the window's stress (coloured, on the diagonal) and from the cuts' own sums "
            f"(grey). **(f)** τ/σ_n on the surface-parallel plane against tan θ of the flank, per window (diamonds: "
            f"medians); the diagonal is a vertical force. **(g)** Major principal direction from the vertical along "
            f"the flank; dashed: a slope at the limit of friction on its surface-parallel planes, "
            + ("φ the median failure angle of the tilting test." if measured else "θ standing for the friction angle."))
    if tilt is not None:
        n = tilt_numbers(tilt)
        text += (f" **(h)** Tilting test: the failure angle θ + α_fail of each tilted flank against its slope θ "
                 f"(◁ left, ▷ right; open triangles: no failure up to {n['max_deg']:g}°); on the diagonal a flank "
                 f"at incipient failure, the grey band the claim's margin of {n['threshold']:g}°. **(i)** Grains of "
                 f"the tilted side moved more than {float(tilt.attrs['displaced_d']):g} d against the tilt, per "
                 f"flank up to its failure (dotted: {int(tilt.attrs['grains'])} grains, the failure).")
    return text
