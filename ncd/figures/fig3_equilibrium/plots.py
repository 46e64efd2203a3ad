"""The page of Figure 3 (Moreau 2005, section 4): its figure, table and sentences.

Everything the page states is computed here from the run's files (state, ensemble, exact
projections, uniform sample), so that the notebook stays a few lines per cell and the
statements are tested.  The figure is drawn for the page's width (11.5 in, fonts of at
least 9 pt, one letter per panel); only converged runs enter a cloud.
"""
import numpy as np

from ncd.exact.polygon import outside_distance
from ncd.figures.fig3_equilibrium import faces
from ncd.figures.fig3_equilibrium import measure as fe

COLORS = {"zero": "C0", "random": "C1", "warm": "C2", "uniform": "C7"}
TITLES = {"zero": "zero guess,\nrandom orders", "random": "random\nguesses", "warm": "warm start",
          "uniform": "uniform\nin A ∩ C"}


class Fig3Run:
    """The files of one run of Figure 3 and the quantities every statement reads."""

    def __init__(self, state, ens, proj, uni):
        self.state, self.ens, self.proj, self.uni = state, ens, proj, uni
        self.P = fe.polytope_of(state)
        self.shown = [int(k) for k in np.atleast_1d(proj.attrs["displayed_order"])]
        self.subsets = {m: fe.mode_subset(ens, m) for m in fe.MODES}
        self.rows = fe.cloud_measures(ens, proj, uni, self.shown)
        self._faces = None

    def converged(self, ds):
        return ds.isel(run=np.nonzero(ds.converged.values == 1)[0])

    def forces(self, ds):
        """(runs, 2 kappa) force vectors of ``ds`` (normal and tangential interleaved)."""
        return np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)

    @property
    def faces(self):
        """:func:`ncd.figures.fig3_equilibrium.faces.face_summary` over every run of each mode and the uniform sample."""
        if self._faces is None:
            groups = {m: self.forces(ds) for m, ds in self.subsets.items()}
            groups["uniform"] = self.forces(self.uni)
            self._faces = faces.face_summary(self.P, groups)
        return self._faces

    def admissibility(self):
        """(equilibrium residual, Coulomb violation, farthest distance outside an exact polygon),
        over the converged runs, relative to the largest weight."""
        conv = self.converged(self.ens)
        if not conv.sizes["run"]:
            return np.nan, np.nan, np.nan
        eq, coulomb = self.P.violations(self.forces(conv))
        out = max(outside_distance(np.column_stack([conv.force_n.values[:, k], conv.force_t.values[:, k]]),
                                   fe.polygon(self.proj, k)).max() for k in range(self.state.sizes["contact"]))
        return float(np.max(eq)), float(np.max(coulomb)), float(out / self.P.scale)


# ------------------------------------------------------------------------------- the figure
def draw_packing(ax, r):
    """(a) the packing, line widths the normal forces at rest, the displayed contacts circled."""
    from matplotlib.patches import Circle

    st = r.state
    for i in range(st.sizes["disc"]):
        ax.add_patch(Circle((st.x[i].item(), st.y[i].item()), st.radius[i].item(), fc="0.9", ec="0.4", lw=0.6))
    fmax = np.abs(st.rest_force_n.values).max()
    for k in range(st.sizes["contact"]):
        a, b = int(st.body_a[k]), int(st.body_b[k])
        pa = np.array([st.x[a].item(), st.y[a].item()])
        pb = (np.array([st.x[b].item(), st.y[b].item()]) if b >= 0 else
              np.array([st.point_x[k].item(), st.point_y[k].item()]))
        ax.plot(*np.c_[pa, pb], color="k", lw=0.3 + 2.5 * st.rest_force_n[k].item() / fmax)
    w = st.attrs["width"]
    top = float((st.y + st.radius).max()) * 1.05
    ax.plot([0, 0, w, w], [top, 0, 0, top], color="k", lw=1.5)
    slots = np.argsort(np.argsort([st.point_x[k].item() for k in r.shown]))   # left label for the left contact
    for j, k in enumerate(r.shown):                  # labels above the box, arrows to the contacts
        p = (st.point_x[k].item(), st.point_y[k].item())
        ax.plot(*p, "o", ms=10, mfc="none", mec=f"C{3 + j}", mew=2.5)
        x_label = (0.2 + 0.6 * slots[j] / max(len(r.shown) - 1, 1)) * w
        ax.annotate(f"α = {k}", p, xytext=(x_label, top + 0.12 * w), ha="center", fontsize=10,
                    color=f"C{3 + j}", weight="bold", arrowprops=dict(arrowstyle="-|>", color=f"C{3 + j}", lw=1.2))
    ax.set_aspect("equal")
    ax.set_xlim(-0.03 * w, 1.03 * w)
    ax.set_ylim(-0.03 * w, top + 0.2 * w)
    ax.axis("off")
    ax.set_title(f"(a) N = {st.sizes['disc']} discs, κ = {st.sizes['contact']}", fontsize=10, loc="left")


def draw_faces(ax, r):
    """(b) the fraction of points per dimension of the face of A ∩ C that holds them."""
    f = r.faces
    d_ac = next(iter(f.values()))["dimension"]
    width = 0.2
    for i, m in enumerate(list(fe.MODES) + ["uniform"]):
        frac = np.bincount(f[m]["dims_all"], minlength=d_ac + 1)[: d_ac + 1] / max(len(f[m]["dims_all"]), 1)
        ax.bar(np.arange(d_ac + 1) + (i - 1.5) * width, frac, width, color=COLORS[m], label=m)
    ax.set(xlabel="face dimension", ylabel="fraction of points", xticks=range(d_ac + 1))
    ax.set_title(f"(b) faces of A ∩ C (dim {d_ac})", fontsize=10, loc="left")
    ax.legend(fontsize=9, loc="upper left", ncol=2, frameon=False)


def draw_cloud(ax, r, k, j, m, ds):
    """One contact's force plane: the Coulomb sector, the exact projection, the converged points."""
    from matplotlib.ticker import MaxNLocator

    poly = 1e3 * fe.polygon(r.proj, k)                                # mN
    mu = r.state.mu[k].item()
    rn_max = poly[:, 0].max() * 1.08
    sector = np.array([[-mu * rn_max * 2, rn_max * 2], [0, 0], [mu * rn_max * 2, rn_max * 2]])
    ax.fill(*sector.T, color="0.92", zorder=0)
    ax.plot(*sector.T, color="0.5", lw=0.8)
    ax.fill(poly[:, 1], poly[:, 0], fc=f"C{3 + j}", alpha=0.18, ec=f"C{3 + j}", lw=1.2)
    if m != "uniform":
        ds = r.converged(ds)
    ft, fn = 1e3 * ds.force_t.values[:, k], 1e3 * ds.force_n.values[:, k]
    style = dict(ms=1.2 if m == "warm" else 0.7, alpha=min(0.8, 1000 / max(len(ft), 1)), color="k")
    ax.plot(ft, fn, "o", mew=0, **style)
    pad = 0.06 * rn_max
    ax.set_xlim(min(poly[:, 1].min(), 0) - pad, max(poly[:, 1].max(), 0) + pad)
    ax.set_ylim(-0.04 * rn_max, rn_max)
    ax.set_aspect("equal")
    ax.xaxis.set_major_locator(MaxNLocator(2))
    box = np.ptp(np.c_[ft, fn], axis=0).max() if len(ft) else 0.0
    if m == "zero" and 0 < box < 0.15 * rn_max:                       # a small cloud: magnify it
        ins = ax.inset_axes([0.5, 0.04, 0.47, 0.42])
        ins.fill(poly[:, 1], poly[:, 0], fc=f"C{3 + j}", alpha=0.18, ec=f"C{3 + j}", lw=1.0)
        ins.plot(ft, fn, "o", mew=0, **style)
        c = np.array([ft.mean(), fn.mean()])
        ins.set_xlim(c[0] - 0.6 * box, c[0] + 0.6 * box)
        ins.set_ylim(c[1] - 0.6 * box, c[1] + 0.6 * box)
        ins.set_xticks([])
        ins.set_yticks([])
        ins.text(0.04, 0.96, f"×{rn_max / box:.0f}", transform=ins.transAxes, va="top", fontsize=9)
        ax.indicate_inset_zoom(ins, edgecolor="0.3")


def figure(r):
    """(a) the packing, (b) the face census, then one row per displayed contact and one column
    per exploration: the exact projection of A ∩ C (shaded) in the Coulomb sector (grey)."""
    import matplotlib.pyplot as plt

    groups = list(r.subsets.items()) + [("uniform", r.uni)]
    letters = iter("cdefghijklmn")
    with plt.rc_context({"font.size": 9.5}):
        fig = plt.figure(figsize=(11.5, 3.0 * len(r.shown) + 1.2), layout="constrained")
        gs = fig.add_gridspec(len(r.shown), 5, width_ratios=[1.5, 1, 1, 1, 1])
        draw_packing(fig.add_subplot(gs[0, 0]), r)
        draw_faces(fig.add_subplot(gs[1:, 0]), r)
        for j, k in enumerate(r.shown):
            for i, (m, ds) in enumerate(groups):
                ax = fig.add_subplot(gs[j, i + 1])
                draw_cloud(ax, r, k, j, m, ds)
                head = TITLES[m] if j == 0 else f"α = {k}"
                ax.set_title(f"({next(letters)}) {head}", fontsize=9.5, loc="left")
                if i == 0:
                    ax.set_ylabel(f"α = {k}: $r_n$ (mN)")
                if j == len(r.shown) - 1:
                    ax.set_xlabel("$r_t$ (mN)")
    return fig


# ------------------------------------------------------------------------------ the sentences
def packing_text(r):
    """The packing, the polyhedron A ∩ C and its exact projections."""
    st, pa, proj = r.state, r.proj.attrs, r.proj
    kappa, N = st.sizes["contact"], st.sizes["disc"]
    nv = proj.n_vertices.values
    extra = int(pa["dimension_A"]) - int(pa["dimension_moreau"])
    why = (f"but rank $H$ = {3 * N - extra} < $3N$ (a disc whose equations are dependent, e.g. one resting on the "
           "floor only, whose horizontal-force and moment equations both say $r_t = 0$); hence " if extra > 0
           else "and ")
    tight = int(pa["dimension_AC"]) < int(pa["dimension_A"])
    gap = np.nanmax((proj.outer_area - proj.area).values) / np.nanmax(proj.area.values)
    return (f"The packing of $N$ = {N} discs was deposited in {st.attrs['deposit_steps']} steps of "
            f"$h$ = {st.attrs['h']:g} s until the warm equilibrium test gave $|u_f|$ = "
            f"{st.attrs['rest_max_velocity']:.1e} $|g| h$ (largest interpenetration "
            f"{st.attrs['max_penetration'] / st.radius.min().item():.1e} of the smallest radius). It has "
            f"$\\kappa$ = {kappa} contacts ({st.attrs['n_wall_contacts']} with walls): $2\\kappa - 3N$ = "
            f"{pa['dimension_moreau']}, {why}$\\dim A = 2\\kappa - \\operatorname{{rank}} H$ = {pa['dimension_A']}, "
            f"and $\\dim A \\cap C$ = {pa['dimension_AC']} ("
            + ("some Coulomb condition is tight at every equilibrium" if tight else
               "no Coulomb condition is tight at every equilibrium")
            + f"; {int(proj.implicit_zero.sum())} contacts carry no force at any equilibrium, "
            f"{int(proj.implicit_sliding.sum())} always slide). $A \\cap C$ is "
            f"{'bounded' if pa['bounded'] else 'unbounded'}. Its {kappa} projections on the contacts' force planes "
            f"are {int((nv == 1).sum())} points (forces fixed by statics), {int((nv == 2).sum())} segments and "
            f"{int((nv >= 3).sum())} polygons (up to {nv.max()} vertices), "
            + ("every one exact" if bool(proj.exact.all()) else
               f"{int((~proj.exact.values.astype(bool)).sum())} not exact")
            + f" (inner hull and outer half-planes agree to {gap:.0e} of the largest area; "
            f"{pa['n_lp_total']} LPs).")


def convergence_text(r):
    """Runs, converged runs, sweeps and wall time of each exploration mode."""
    parts = []
    for m, ds in r.subsets.items():
        sw, wt = ds.sweeps.values, ds.wall_time.values
        parts.append(f"{m}: {int(ds.converged.sum())} of {ds.sizes['run']} converged, {np.median(sw):.0f} sweeps "
                     f"on median ({sw.min()} to {sw.max()}), {1e3 * np.median(wt):.2f} ms per run")
    eq, coulomb, out = r.admissibility()
    return (f"NLGS runs converged to a natural-map residual $\\le$ {r.ens.attrs['solver_tol']:g}: "
            + "; ".join(parts) + f". The converged points satisfy equilibrium to {eq:.0e} and Coulomb's law to "
            f"{coulomb:.0e} of the largest weight and lie within {out:.0e} weights of their exact polygons: every "
            "point of the clouds is an admissible force state, so their spread is indeterminacy of the "
            "equilibrium forces, not unfinished iterations.")


def measures_table(r):
    """Markdown table of :func:`ncd.figures.fig3_equilibrium.measure.cloud_measures` (per contact and mode)."""
    lines = ["| contact | exploration | points | coverage | spread (N) | near the boundary |",
             "|---:|:---|---:|---:|---:|---:|"]
    for x in r.rows:
        lines.append(f"| {x['contact']} | {x['mode']} | {x['points']} | {x['coverage']:.1%} | {x['spread']:.1e} | "
                     f"{x['near_boundary']:.1%} |")
    return "\n".join(lines)


def findings_text(r):
    """What the clouds show: coverage of the exact projections by each exploration, cost, warm start."""
    cov = {m: [x["coverage"] for x in r.rows if x["mode"] == m] for m in fe.MODES}
    sub = r.subsets
    zero = ", ".join(f"{c:.1%}" for c in cov["zero"])
    warm = ", ".join(f"{x['spread']:.0e}" for x in r.rows if x["mode"] == "warm")
    verdict = ("Moreau's statement that this exploration generates \"a significant outline of the solution set\" "
               "does not hold for this packing; the exact polygons show how much it misses." if max(cov["zero"]) < 0.5
               else "This outlines a large part of the solution set, as Moreau says.")
    return (f"* **Zero guess with random orders (the paper's figure).** Its clouds cover {zero} of the exact "
            f"projections of the displayed contacts ({', '.join(str(k) for k in r.shown)}): the review orders reach "
            f"limits close to each other. {verdict}\n"
            f"* **Random initial guesses** (section 2's other exploration; normal impulses uniform in "
            f"$[0, \\max s_n^{{\\text{{rest}}}}]$, tangential ones uniform in the sector, fixed review order) cover "
            f"{', '.join(f'{c:.1%}' for c in cov['random'])} of the same polygons, at "
            f"{1e3 * np.median(sub['random'].wall_time.values):.1f} ms per run on median (zero guess: "
            f"{1e3 * np.median(sub['zero'].wall_time.values):.1f} ms).\n"
            f"* **Warm start** (the impulses of the last deposition step): {np.median(sub['warm'].sweeps.values):.0f} "
            f"sweeps on median, spread {warm} "
            "N on the displayed contacts: the \"very little indeterminacy\" of section 2.")


def faces_text(r):
    """Where the NLGS solutions lie among the faces of A ∩ C (:func:`ncd.figures.fig3_equilibrium.faces.face_text`),
    against the uniform sample, interior with probability one."""
    u = r.faces["uniform"]
    return (faces.face_text(r.faces) + f" Of the {u['runs']} points of the uniform sample, {u['interior']} are "
            "interior (face dimension " f"{u['dimension']}).")


def finding(r):
    """The figure's finding in a few sentences (the Snakemake report's caption includes it)."""
    cov = {m: [x["coverage"] for x in r.rows if x["mode"] == m] for m in ("zero", "random")}
    z = r.faces["zero"]
    return (f"On the displayed contacts the zero-guess clouds (the paper's exploration) cover "
            f"{', '.join(f'{c:.1%}' for c in cov['zero'])} of the exact projections of A ∩ C, random guesses "
            f"{', '.join(f'{c:.1%}' for c in cov['random'])}. {z['runs'] - z['interior']} of the {z['runs']} "
            f"zero-guess solutions lie on a proper face of A ∩ C (dimension {z['dimension']}), where a uniform "
            "point lies with probability zero.")
