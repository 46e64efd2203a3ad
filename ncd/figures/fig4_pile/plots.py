"""The page of Figure 4 (Moreau 2005, section 5): its figure and its sentences.

Everything the page states is computed here from the run's files (construction, cuts,
ensemble, tolerance study, exact set), so that the notebook stays a few lines per cell
and the statements are tested.  The figure is drawn for the page's width (11 in, fonts of
at least 9 pt, legends beside the data, one letter per panel); only runs converged at
rest enter a cloud (:func:`ncd.figures.fig4_pile.exact.rest_mask`).
"""
from dataclasses import dataclass

import numpy as np

from ncd.figures.fig4_pile.exact import cloud_in_polygon, diameter, polygon_of, rest_mask
from ncd.shared import cuts as cm


@dataclass
class PileRun:
    """The files of one run of Figure 4 and the quantities every statement reads."""

    con: object
    cuts: object
    ens: object
    exact: object
    cfg: dict

    def __post_init__(self):
        kind = list(self.cuts.kind.values)
        self.K, self.KM, self.KP = kind.index("default"), kind.index("minus"), kind.index("plus")
        self.d = float(self.con.attrs["mean_diameter"])
        self.W = float(self.cuts.attrs["weight"])
        self.hist = np.column_stack([self.cuts.history_fx.values, self.cuts.history_fy.values])
        self.rest = rest_mask(self.ens)
        self.change = [float(np.linalg.norm(self.hist[j] - self.hist[self.K])) for j in (self.KM, self.KP)]

    def cloud(self, k):
        """End points (F_x, F_y) of the resultant across cut ``k`` of the runs at rest."""
        e = self.ens
        return np.column_stack([e.cut_force_x.values[self.rest, k], e.cut_force_y.values[self.rest, k]])

    def scan_middle(self):
        """Scan cuts over the middle half of either flank (between 25 % and 75 % of the toe)."""
        c, a = self.cuts, self.cuts.attrs
        toe = np.where(c.outer.values < 0, abs(a["left_toe"]), a["right_toe"])
        x = np.abs(c.cut_x.values)
        return (c.kind.values == "scan") & (x > 0.25 * toe) & (x < 0.75 * toe)


def _stat(f, x):
    x = np.asarray(x, float)
    return float(f(x)) if x.size else np.nan


# ------------------------------------------------------------------------------- the figure
def draw_pile(ax, r):
    """(a) the pile, its history force chains, the cuts, the resultant and its cloud."""
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Circle

    con, cuts, d, a = r.con, r.cuts, r.d, r.cuts.attrs
    xy = np.column_stack([con.x.values, con.y.values]) / d
    ax.add_collection(PatchCollection([Circle(p, q) for p, q in zip(xy, con.radius.values / d)],
                                      fc="0.88", ec="0.6", lw=0.2))
    gxy = np.column_stack([con.ground_x.values, con.ground_y.values]) / d
    ax.add_collection(PatchCollection([Circle(p, q) for p, q in zip(gxy, con.ground_radius.values / d)],
                                      fc="0.45", ec="none"))
    allx = np.concatenate([con.x.values, con.ground_x.values])
    ally = np.concatenate([con.y.values, con.ground_y.values])
    fn = con.force_n.values
    on = fn > 0
    ia, ib = con.body_a.values, con.body_b.values
    seg = np.stack([np.column_stack([allx[ia], ally[ia]]), np.column_stack([allx[ib], ally[ib]])], axis=1)[on] / d
    ax.add_collection(LineCollection(seg, colors="0.15",
                                     linewidths=0.1 + 2.0 * np.minimum(fn[on] / np.quantile(fn[on], 0.99), 1)))
    for k, st in ((r.K, "-"), (r.KM, ":"), (r.KP, ":")):
        ax.plot([cuts.cut_x[k] / d] * 2, [cuts.y_lo[k] / d, cuts.y_hi[k] / d], st, color="tab:red", lw=2)
    scale = 0.5 * a["apex_height"] / d / np.linalg.norm(r.hist[r.K])        # d per newton
    o = np.array([float(cuts.cut_x[r.K]) / d, (a["y_ground"] + 0.5 * float(cuts.depth[r.K])) / d])
    ax.annotate("", o + scale * r.hist[r.K], o, arrowprops=dict(arrowstyle="-|>", color="tab:red", lw=2.5), zorder=5)
    P = r.cloud(r.K)
    if len(P):
        ax.plot(*(o + scale * P).T, ".", ms=2, color="tab:blue", zorder=6)
    for side in ("left", "right"):
        xs = np.linspace(0, a[f"{side}_toe"], 2)
        ax.plot(xs / d, (a["y_ground"] + a["apex_height"] * (1 - xs / a[f"{side}_toe"])) / d, "--",
                color="tab:green", lw=1)
    ax.set_xlim(con.x.values.min() / d - 4, con.x.values.max() / d + 4)
    ax.set_ylim(-1.5, a["apex_height"] / d + 3)
    ax.set_aspect("equal")
    ax.set(xlabel="x / d", ylabel="y / d")
    ax.set_title(f"(a) {r.con.sizes['grain']} grains at rest, the cuts and the resultant", fontsize=10, loc="left")


def draw_clouds(ax, r):
    """(b) the clouds of the three cuts in force space, inside their exact polygons."""
    for k, c, lab in ((r.KM, "tab:orange", "cut −1 d"), (r.K, "tab:blue", "default cut"),
                      (r.KP, "tab:purple", "cut +1 d")):
        poly = polygon_of(r.exact, k)
        if len(poly):
            ax.fill(*np.vstack([poly, poly[:1]]).T, color=c, alpha=0.12, ec=c, lw=0.8)
        Q = r.cloud(k)
        ax.plot(*Q.T, ".", ms=2, color=c, alpha=0.6)
        ax.plot(*r.hist[k], "*", ms=11, color=c, mec="k", label=lab)
    ax.set(xlabel="$F_x$ (N)", ylabel="$F_y$ (N)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("(b) cut resultants", fontsize=10, loc="left")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.13), ncol=1, frameon=False,
              title="star: history; dots: runs;\nshade: exact set", title_fontsize=9)


def draw_angles(ax, r):
    """(c) the resultant's angle against the free surface across every cut position."""
    cuts, ens = r.cuts, r.ens
    scan = cuts.kind.values == "scan"
    xc = cuts.cut_x.values / r.d
    order = np.argsort(xc[scan])
    if r.rest.any():
        dev = np.stack([cm.flank_angles(ens.cut_force_x.values[r.rest][:, k], ens.cut_force_y.values[r.rest][:, k],
                                        int(cuts.outer[k]), float(cuts.surface_angle[k]))[1]
                        for k in range(cuts.sizes["cut"])], axis=1)
        ax.fill_between(xc[scan][order], np.nanmin(dev, 0)[scan][order], np.nanmax(dev, 0)[scan][order],
                        color="tab:blue", alpha=0.3, lw=0, label="runs (range)")
    ax.plot(xc[scan][order], cuts.history_deviation.values[scan][order], "k.-", ms=3, lw=0.6, label="history")
    sel = [r.KM, r.K, r.KP]
    ax.plot(xc[sel], cuts.history_deviation.values[sel], "r*", ms=9, label="default, ±1 d")
    ax.axhline(0, color="tab:green", lw=1)
    ax.axhline(-cuts.attrs["right_angle"], color="0.5", ls=":", lw=1)
    ax.set(xlabel="cut position x / d", ylabel="resultant − surface slope (°)", ylim=(-60, 60))
    ax.set_title("(c) resultant against the surface", fontsize=10, loc="left")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.13), frameon=False,
              title="0: parallel; dotted: horizontal", title_fontsize=9)


def draw_pressure(ax, r):
    """(d) the ground pressure: binned history, runs' range, column weight, exact kernel band."""
    cuts, exact, d = r.cuts, r.exact, r.d
    xb = cuts.bin.values / d
    p_run = r.ens.ground_pressure.values[r.rest]
    if len(p_run):
        ax.fill_between(xb, p_run.min(0), p_run.max(0), step="mid", color="tab:blue", alpha=0.35, lw=0,
                        label="runs (range)")
    ax.step(xb, cuts.history_pressure.values, where="mid", color="k", lw=1.2,
            label=f"history, {r.cfg['pressure']['bin_d']:g} d bins")
    ax.step(xb, cuts.column_weight.values, where="mid", color="tab:orange", ls="--", lw=1,
            label="weight of the column above")
    x, w = exact.x_kernel.values / d, float(exact.attrs["kernel_width"]) / d
    ax.fill_between(x, exact.kernel_min.values, exact.kernel_max.values, color="tab:green", alpha=0.2, lw=0,
                    label=f"exact range over A ∩ C (kernel {w:g} d)")
    ax.plot(x, exact.kernel_history.values, "-", color="tab:green", lw=1.2, label=f"history, kernel {w:g} d")
    ax.set(xlabel="x / d", ylabel="ground pressure (N/m)")
    ax.set_title("(d) ground pressure", fontsize=10, loc="left")
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(0, -0.13), frameon=False)


def figure(r):
    """Figure 4 of the page: (a) the pile, (b) the clouds, (c) the angles, (d) the ground pressure."""
    import matplotlib.pyplot as plt

    with plt.rc_context({"font.size": 9.5}):
        fig = plt.figure(figsize=(11, 8.2), layout="constrained")
        gs = fig.add_gridspec(2, 3, height_ratios=[0.5, 1])
        draw_pile(fig.add_subplot(gs[0, :]), r)
        draw_clouds(fig.add_subplot(gs[1, 0]), r)
        draw_angles(fig.add_subplot(gs[1, 1]), r)
        draw_pressure(fig.add_subplot(gs[1, 2]), r)
    return fig


# ------------------------------------------------------------------------------ the sentences
def construction_text(r):
    """The construction: size, steps, cost, interpenetration, the equilibrium test."""
    con, d = r.con, r.d
    poured = int(np.argmax(con.n_grains.values == con.sizes["grain"]))
    nc = int((~con.converged.values.astype(bool)).sum())
    t = float(con.time[-1])
    return (f"The paper does not give its number of grains; we pour {con.sizes['grain']} in {poured + 1} steps of "
            f"{1e3 * con.attrs['h']:.2g} ms and reach rest after {con.sizes['step']} steps ({t:.2f} s, "
            f"{t / np.sqrt(d / r.cfg['gravity']):.0f} $\\sqrt{{d/g}}$), at {1e3 * float(con.wall_time.mean()):.1f} ms "
            f"per step (warm-started NLGS, {float(con.sweeps.mean()):.0f} sweeps per step on average, {nc} steps "
            f"short of the tolerance {con.attrs['solver_tol']:g} within {con.attrs['solver_max_sweeps']} sweeps). "
            f"The source is raised with the pile (a funnel {r.cfg['source']['drop_height_d']:g} d above the grains "
            f"under it): the largest interpenetration is {float(con.max_penetration.max()) / d:.3f} d during the "
            f"construction and {-float(con.gap.min()) / d:.3f} d at the end. The equilibrium test of section 2 "
            f"(one step from $u_i = 0$, warm guess) gives $|u_f| \\le$ {con.attrs['eq_max_velocity']:.1g} $g h$: "
            f"{'at rest' if con.attrs['at_rest'] else 'not at rest'}.")


def arching_text(r):
    """The free surface and the history resultants across the default, shifted and scan cuts."""
    cuts, a, K = r.cuts, r.cuts.attrs, r.K
    mid = r.scan_middle()
    dev = cuts.history_deviation.values
    std = {o: _stat(np.std, dev[mid & (cuts.outer.values == s)]) for o, s in (("left", -1), ("right", 1))}
    return (f"The pile stands {a['apex_height'] / r.d:.1f} d high with flanks at {a['left_angle']:.1f}° (left) and "
            f"{a['right_angle']:.1f}° (right) (friction {r.cfg['mu']:g}). The history resultant across the default "
            f"cut ({int(cuts.n_crossing[K])} contacts; the paper's cut crossed 10) points "
            f"{float(cuts.history_angle[K]):.0f}° below the horizontal, {dev[K]:+.0f}° from the free surface's "
            f"slope; the cuts moved by ±{r.cfg['cut']['shift_d']:g} d deviate by {dev[r.KM]:+.0f}° and "
            f"{dev[r.KP]:+.0f}°. Over the middle half of the flanks ({int(mid.sum())} scan cuts, "
            f"{_stat(np.median, cuts.n_crossing.values[mid]):.0f} contacts each on median) the deviation has a median "
            f"of {_stat(np.median, dev[mid]):+.1f}° and single cuts scatter by ±{std['left']:.0f}° (left) and "
            f"±{std['right']:.0f}° (right; standard deviations, panel c).")


def cloud_text(r):
    """The zero-guess cloud of the default cut against the change of a cut moved by one diameter."""
    ens, P = r.ens, r.cloud(r.K)
    oc = ens.outcome.values
    n = {o: int((oc == c).sum()) for c, o in ((1, "rest"), (2, "motion"), (0, "unconverged"))}
    head = (f"Of {ens.sizes['run']} zero-guess runs, {n['rest']} converged at rest, {n['motion']} on a motion "
            f"solution (grains faster than {ens.attrs['moving_tol']:g} $g h$) and {n['unconverged']} did not "
            "converge; only the rest runs enter the clouds. ")
    if not len(P):
        return head + ("This run therefore measures no cloud of equilibrium states; only the exact set of "
                       "$A \\cap C$ below describes the indeterminacy.")
    F = np.linalg.norm(P.mean(0))
    D = diameter(P)
    lo, hi = min(r.change), max(r.change)
    rel = "less than" if D < lo else ("more than" if D > hi else "between")
    return head + (
        f"The cloud of the default cut spans {D:.3f} N ({D / F:.0%} of the mean resultant), {rel} "
        + ("" if rel != "between" else "the smaller and the larger of ")
        + f"the changes of the history resultant when the cut moves by one diameter ({lo:.3f} and {hi:.3f} N)"
        + (": as the paper says." if D < lo else ": the paper's comparison does not hold at every shift.")
        + f" The history resultant lies {np.linalg.norm(r.hist[r.K] - P.mean(0)):.3f} N from the cloud's mean "
        f"and {float(np.min(np.hypot(*(P - r.hist[r.K]).T))):.3f} N from the nearest run.")


def tolerance_text(r, tol):
    """One sentence on the tolerance study (plain NLGS, no finishing stage) when it reaches rest
    too rarely to separate iteration error from indeterminacy, else the cloud against the error."""
    t = tol.tol.values
    rest = [int(rest_mask(tol.isel(tol=j)).sum()) for j in range(len(t))]
    counts = ", ".join(f"{n}/{tol.sizes['run']}" for n in rest)
    if min(rest) < 2:
        return (f"The tolerance study (the first {tol.sizes['run']} members again, plain NLGS without the "
                f"finishing stage, tolerances {', '.join(f'{x:g}' for x in t)}) brings {counts} runs to rest: too "
                "few for a cloud at every tolerance, so it cannot separate iteration error from indeterminacy on "
                "this pile; the finished ensemble, whose every run is an exact solution, does.")
    ref = tol.isel(tol=-1)
    k = r.K
    R = np.column_stack([ref.cut_force_x.values[:, k], ref.cut_force_y.values[:, k]])
    errs, clouds = [], []
    for j in range(len(t)):
        s = tol.isel(tol=j)
        ok = rest_mask(s)
        Q = np.column_stack([s.cut_force_x.values[:, k], s.cut_force_y.values[:, k]])
        both = ok & rest_mask(ref)
        errs.append(_stat(np.median, np.hypot(*(Q[both] - R[both]).T)))
        clouds.append(diameter(Q[ok]))
    return (f"Tolerance study (plain NLGS, runs at rest {counts}): from {t[0]:g} to {t[-1]:g} the median iteration "
            "error of a member goes " + " → ".join(f"{e:.2g}" for e in errs[:-1]) + " N while the cloud of the same "
            "members goes " + " → ".join(f"{c:.2g}" for c in clouds) + " N: "
            + ("the cloud does not shrink with the tolerance, it is indeterminacy." if clouds[-1] >= clouds[0]
               else "the cloud shrinks with the tolerance, part of it is iteration error."))


def pressure_text(r):
    """The binned ground pressure under the apex against the weight of the column above."""
    cuts = r.cuts
    c0 = int(np.argmin(np.abs(cuts.bin.values)))
    p, col = cuts.history_pressure.values, cuts.column_weight.values
    p_run = r.ens.ground_pressure.values[r.rest]
    runs = (f"; the rest runs give {p_run[:, c0].min():.1f} to {p_run[:, c0].max():.1f} N/m" if len(p_run) else "")
    return (f"Under the apex ({r.cfg['pressure']['bin_d']:g} d bin) the history forces press {p[c0]:.1f} N/m on the "
            f"ground against {col[c0]:.1f} N/m for the weight of the column of grains above{runs}; the largest "
            f"binned pressure is {p.max():.1f} N/m at x = {cuts.bin.values[np.argmax(p)] / r.d:+.0f} d. Fixed bins "
            "hold a few ground contacts each, so a dip in them can come from where the edges fall: the dip is "
            "judged below on a kernel average, against its spread over analysis choices and its exact range.")


def exact_text(exact, ens, cuts):
    """Markdown from exact.nc and the ensemble: polygons and coverage of the default and
    shifted cuts by the rest runs, arching over all cuts (the dip: :func:`dip_sentence`)."""
    a, W = exact.attrs, float(exact.attrs["weight"])
    mask = rest_mask(ens)
    lines = []
    for k, name in ((0, "default"), (1, "moved by -1 d"), (2, "moved by +1 d")):
        P, out, cov = cloud_in_polygon(exact, ens, k, mask)
        lines.append(f"Cut {name}: exact polygon of {int(exact.n_vertices[k])} vertices ({int(exact.n_lp[k])} LPs), "
                     f"diameter {diameter(polygon_of(exact, k)):.4f} N; the rest runs cover "
                     f"{100 * cov:.2g} % of its area and lie inside it to "
                     f"{(out.max() if len(out) else 0.0) / W:.1e} of the weight.")
    arch = exact.all_arch.values.astype(bool)
    lines.append(f"Every admissible force state arches (pushes the bank downward) across {arch.sum()} of the "
                 f"{len(arch)} cuts; the exact angle of the resultant below the horizontal spans "
                 f"{np.nanmin(exact.angle_max.values - exact.angle_min.values):.1f}° to "
                 f"{np.nanmax(exact.angle_max.values - exact.angle_min.values):.1f}° (median "
                 f"{np.nanmedian(exact.angle_max.values - exact.angle_min.values):.1f}°) across a cut (each end a "
                 f"linear-fractional program: {int(np.median(exact.angle_n_lp.values))} LPs per cut on median, "
                 f"certified to {np.nanmax(exact.angle_bound.values):.0e}°; on the three polygons the ranges agree "
                 f"with the polygons' own to {a['polygon_angle_gap']:.0e}°).")
    return "\n\n".join(lines)


def dip_sentence(exact):
    """The ground-pressure dip of ``exact.nc`` in one sentence: the dip depth (flank minus
    centre, > 0 a dip, in units of the mean ground stress W/2L as on the history page), its
    spread over the analysis choices, its exact range over A ∩ C and the verdict."""
    a = exact.attrs
    m = list(exact.choice.values).index(a["dip_main_choice"])
    return (f"Ground pressure ({a['dip_main_choice']}): the dip depth (p(−a) + p(a))/2 − p(0) with "
            f"a = {a['dip_offset'] * 1e3:.1f} mm, in units of the mean ground stress W/2L = {a['dip_unit']:.0f} N/m "
            f"(> 0 a dip, < 0 a hump), is {float(exact.dip_history[m]):+.3f} for the history forces; over the "
            f"analysis choices it spans {a['dip_binning_spread']:.3f}; over A ∩ C it ranges exactly from "
            f"{float(exact.dip_min[m]):+.3f} to {float(exact.dip_max[m]):+.3f}: a dip is **{a['dip_geometry']}** by "
            f"the geometry, and {'a dip is called' if a['dip_called'] else 'no dip is called'}.")


def finding(r):
    """The figure's finding in a few sentences (the Snakemake report's caption includes it)."""
    P = r.cloud(r.K)
    lo, hi = min(r.change), max(r.change)
    if len(P):
        D = diameter(P)
        rel = "less than" if D < lo else ("more than" if D > hi else "between")
        cloud = (f"The {len(P)} zero-guess runs at rest give a cloud of the default cut's resultant {D:.3f} N across "
                 f"({D / np.linalg.norm(P.mean(0)):.0%} of the resultant), {rel} the changes of {lo:.3f} and "
                 f"{hi:.3f} N when the cut moves by one diameter.")
    else:
        cloud = f"No zero-guess run converged at rest: no cloud; the cut moved by one diameter changes by {lo:.3f} N."
    ex = r.exact
    m = list(ex.choice.values).index(ex.attrs["dip_main_choice"])
    return (cloud + f" Every admissible force state arches across {int(ex.all_arch.sum())} of "
            f"{ex.sizes['cut']} cuts. The dip depth of the ground pressure under the apex is "
            f"{float(ex.dip_history[m]):+.3f} W/2L (> 0 a dip) for the history forces, from "
            f"{float(ex.dip_min[m]):+.3f} to {float(ex.dip_max[m]):+.3f} over A ∩ C: a dip is "
            f"{ex.attrs['dip_geometry']} by the geometry.")
