"""The page of error against run time: its figure, its sentences and its tables, from
``error_vs_runtime/nlgs.nc`` (NLGS at one step) and ``integration.nc`` (CD and MD over time).

What the page reads off the data: how many sweeps a decade of tolerance costs, what the
warm start saves on each state (ratio of sweeps, both ways), how far apart the zero- and
warm-started limits are (the indeterminacy of the step), and per observable the error of
CD over its step and of MD over its step and stiffness.
"""
import numpy as np
import yaml

FLOOR = 1e-17                 # errors at exactly zero are drawn here
INIT_COLOURS = {"zero": "tab:blue", "warm": "tab:orange"}
CRITERION_STYLES = {"residual": "-", "change": ":", "finish": "-.", "anderson": (0, (5, 1, 1, 1)),
                    "anderson_local": (0, (1, 1))}
CRITERION_WORDS = {"residual": "natural-map residual", "change": "impulse change", "finish": "NLGS + finishing stage",
                   "anderson": "Anderson-accelerated", "anderson_local": "Anderson, local exact solves"}


def sweep_ratios(nl, criterion="residual"):
    """Zero-guess sweeps over warm-start sweeps, per state and tolerance (converged both)."""
    d = nl.sel(criterion=criterion)
    both = (d.converged.sel(init="zero") == 1) & (d.converged.sel(init="warm") == 1)
    return (d.sweeps.sel(init="zero") / d.sweeps.sel(init="warm")).where(both)


def nlgs_sentences(nl):
    """Markdown list: sizes, cost per decade, warm start against zero guess, the two limits."""
    lines = ["* **States**: " + "; ".join(f"`{st}` {int(nl.n_discs.sel(state=st))} discs and "
                                          f"{int(nl.n_contacts.sel(state=st))} contacts" for st in nl.state.values)
             + f"; {int(nl.converged.sum())} of {nl.converged.size} settings converged."]
    ratios = sweep_ratios(nl)
    for st in nl.state.values:
        e = nl.sel(state=st, init="zero", criterion="residual").sortby("tol", ascending=False)
        per_decade = np.diff(e.sweeps.values) / np.diff(-np.log10(e.tol.values))
        r = ratios.sel(state=st)
        lo, hi = float(r.min()), float(r.max())
        t_lo, t_hi = float(r.idxmin()), float(r.idxmax())
        lines.append(
            f"* `{st}`: from the zero guess a decade of tolerance costs {per_decade.min():.0f}–{per_decade.max():.0f} "
            f"sweeps; the warm start needs from {_times(lo)} (tolerance {t_lo:.0e}) to {_times(hi)} ({t_hi:.0e}). "
            f"The zero- and warm-started limits (tolerance {_reference_tol(nl)}) differ by "
            f"{float(nl.limits_distance_impulse.sel(state=st)):.1e} in impulses (relative) and "
            f"{float(nl.limits_distance_velocity.sel(state=st)):.1e} g h in velocities"
            + (": the same motion with other contact forces, the step's forces are indeterminate."
               if float(nl.limits_distance_impulse.sel(state=st)) > 1e-6
               and float(nl.limits_distance_velocity.sel(state=st)) < 1e-8 else "."))
    tight = float(nl.tol.min())
    r = nl.sel(tol=tight)
    for crit in [c for c in ("change", "finish", "anderson", "anderson_local") if c in nl.criterion.values]:
        words = "; ".join(f"`{st}` {int(r.sweeps.sel(state=st, init='zero', criterion=crit))} against "
                          f"{int(r.sweeps.sel(state=st, init='zero', criterion='residual'))}"
                          for st in nl.state.values)
        lines.append(f"* Stopping on *{CRITERION_WORDS[crit]}*, zero guess, tolerance {tight:.0e}: sweeps {words} "
                     f"(plain NLGS on the residual).")
    return "\n".join(lines)


def _times(r):
    if abs(r - 1) < 0.05:
        return "as many sweeps"
    return f"{r:.2g} times fewer sweeps" if r > 1 else f"{1 / r:.2g} times more sweeps"


def _reference_tol(nl):
    """The tolerance of the limits the errors are measured to (from the run's config)."""
    cfg = yaml.safe_load(nl.attrs.get("config_yaml", "{}")) or {}
    tol = cfg.get("nlgs", cfg).get("reference", {}).get("tol") if isinstance(cfg, dict) else None
    return f"{float(tol):.0e}" if tol is not None else "of the reference"


def integration_sentences(df):
    """Markdown list: per observable the error range of CD and of the MD runs that did not diverge."""
    lines = []
    inc = df[df.observable == "incline"]
    for mu in sorted(inc.mu.unique()):
        d = inc[inc.mu == mu]
        cd, md = d[d.method == "CD"], d[(d.method == "MD") & (d.diverged == 0)]
        lines.append(f"* **Incline, μ = {mu:g}**: CD's relative error is at most {cd.error.max():.1g} at every step "
                     f"(the θ-scheme integrates a constant acceleration exactly); MD's runs from "
                     f"{md.error.max():.2g} down to {md.error.min():.2g}, smaller with a smaller step and a stiffer "
                     f"spring ({int((d.method == 'MD').sum() - len(md))} MD runs diverged).")
    heap = df[(df.observable == "heap") & (df.quantity == "reaction")]
    cd, md = heap[heap.method == "CD"], heap[(heap.method == "MD") & (heap.diverged == 0)]
    lines.append(f"* **Settled heap**: |R/W − 1| is {cd.error.min():.2g}–{cd.error.max():.2g} for CD and "
                 f"{md.error.min():.2g}–{md.error.max():.2g} for MD (what remains is motion not yet damped); "
                 f"median wall time {md.wall_time.median():.2g} s (MD) against {cd.wall_time.median():.2g} s (CD).")
    phi = df[(df.observable == "heap") & (df.quantity == "packing_fraction") & (df.diverged == 0)]
    if len(phi):
        lines.append(f"* **Packing fraction of the heap**: no exact value; the runs give {phi.value.min():.3f}–"
                     f"{phi.value.max():.3f}, a spread of the deposition protocol, not of the solver (not drawn).")
    slope = df[df.observable == "slope_flow"]
    for angle in slope.angle.unique():
        s = slope[slope.angle == angle]
        check = s[s.method == "CD_reference_check"]
        cd, md = s[s.method == "CD"].sort_values("h"), s[(s.method == "MD") & (s.diverged == 0)]
        lines.append(f"* **Slope flow at {angle:g}°**: halving the reference's step moves its mean velocity by "
                     f"{float(check.error.iloc[0]):.2g} (relative), the floor of what an error means here; CD "
                     + ", ".join(f"{e:.2g} (h = {h:.0e} s)" for h, e in zip(cd.h, cd.error))
                     + f"; MD {md.error.min():.2g}–{md.error.max():.2g}.")
    return "\n".join(lines)


def nlgs_table(nl):
    """NLGS settings as formatted strings, one row per state, guess, criterion and tolerance."""
    tab = nl[["sweeps", "wall_time", "residual", "error_impulse", "error_velocity", "converged"]].to_dataframe()
    tab = tab.reset_index()
    tab["wall_time"] = (tab.wall_time * 1e3).map("{:.3g}".format)
    for k in ("residual", "error_impulse", "error_velocity"):
        tab[k] = tab[k].map("{:.1e}".format)
    tab["tol"] = tab.tol.map("{:.0e}".format)
    return tab.rename(columns={"wall_time": "wall time (ms)", "error_impulse": "|s − s*| / |s*|",
                               "error_velocity": "max |u − u*| / (g h)", "init": "guess"})


def integration_table(df):
    """Time-integration runs as formatted strings (−1: a diverged MD run)."""
    cols = ["observable", "quantity", "method", "mu", "angle", "h", "h_over_hcrit", "k_factor", "value",
            "reference", "error", "wall_time", "work", "diverged"]
    tab = df[cols].copy()
    for k, f in (("h", "{:.2g}"), ("h_over_hcrit", "{:.2g}"), ("k_factor", "{:g}"), ("value", "{:.4g}"),
                 ("reference", "{:.4g}"), ("error", "{:.2g}"), ("wall_time", "{:.2g}"), ("work", "{:.3g}")):
        tab[k] = tab[k].map(f.format)
    return tab.rename(columns={"h": "h (s)", "h_over_hcrit": "h / h_crit", "k_factor": "k / k0",
                               "wall_time": "wall time (s)"})


def _log_axes(ax):
    """Log scales on both axes, labels on the decades only (minor labels collide)."""
    from matplotlib.ticker import NullFormatter

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())


def _nlgs_panel(ax, d, title):
    for init in d.init.values:
        for crit in d.criterion.values:
            e = d.sel(init=init, criterion=crit)
            ax.plot(e.wall_time.values * 1e3, np.maximum(e.error_velocity.values, FLOOR), marker="o", ms=3,
                    ls=CRITERION_STYLES.get(crit, "-"), color=INIT_COLOURS.get(init, "k"), lw=1.2)
    _log_axes(ax)
    ax.set_xlabel("wall time (ms)")
    ax.set_title(title, fontsize=10)


def _k_colours(df):
    import matplotlib.pyplot as plt

    ks = sorted(df[df.method == "MD"].k_factor.unique())
    cmap = plt.get_cmap("viridis")
    return {k: cmap(0.85 * i / max(len(ks) - 1, 1)) for i, k in enumerate(ks)}


def _integration_panel(ax, sub, title, ylabel, colours, band=None):
    """Error against wall time: CD over h (black), MD over h for each stiffness (colours);
    runs with zero error sit on the lower edge (grey triangles)."""
    shown = sub[(sub.diverged == 0) & ~sub.method.str.startswith("CD_reference")]
    positive = shown.error[shown.error > 0]
    low = max(FLOOR, positive.min() / 10) if len(positive) else FLOOR
    cd = shown[shown.method == "CD"].sort_values("h")
    ax.plot(cd.wall_time, np.maximum(cd.error, low), "k-o", ms=4)
    md = shown[shown.method == "MD"]
    for k in sorted(md.k_factor.unique()):
        m = md[md.k_factor == k].sort_values("h")
        ax.plot(m.wall_time, np.maximum(m.error, low), "--s", ms=4, color=colours[k])
    zero = shown[shown.error <= low]
    ax.plot(zero.wall_time, np.full(len(zero), low), "v", color="0.5", ms=6)
    if band is not None:
        ax.axhspan(low / 2, band, color="r", alpha=0.08)
    ax.set_ylim(bottom=low / 2)
    _log_axes(ax)
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)


def plot(nl, df):
    """Top row: NLGS at one step (distance to the limit against wall time) on the three
    states, and the warm start's saving; lower rows: time integration, CD against MD."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    plt.rcParams.update({"font.size": 9.5})
    fig = plt.figure(figsize=(10, 11.5), layout="constrained")
    sub = fig.subfigures(2, 1, height_ratios=[1.0, 2.0])
    top = sub[0].subplots(1, 3, sharey=True)
    letters = iter("abcdefghij")
    for ax, st in zip(top, nl.state.values):
        d = nl.sel(state=st)
        _nlgs_panel(ax, d, f"({next(letters)}) NLGS, `{st}`: {int(d.n_discs)} discs, {int(d.n_contacts)} contacts"
                    .replace("`", ""))
    top[0].set_ylabel("max |u_f − u_f*| / (g h)")
    handles = [Line2D([], [], color=c, lw=2, label=f"{i} guess") for i, c in INIT_COLOURS.items()]
    handles += [Line2D([], [], color="k", ls=CRITERION_STYLES[c], label=f"stop: {CRITERION_WORDS[c]}")
                for c in nl.criterion.values if c in CRITERION_STYLES]
    sub[0].legend(handles=handles, loc="outside lower center", ncol=4, fontsize=9, frameon=False)

    axes = sub[1].subplots(2, 3)
    ax = axes[0, 0]
    ratios = sweep_ratios(nl)
    for k, st in enumerate(nl.state.values):
        ax.plot(nl.tol.values, ratios.sel(state=st).values, "o-", color=f"C{k + 2}", label=str(st))
    ax.axhline(1.0, color="k", lw=0.8)
    _log_axes(ax)
    ax.invert_xaxis()
    ax.set_xlabel("tolerance")
    ax.set_ylabel("sweeps, zero guess / warm")
    ax.set_title(f"({next(letters)}) what the warm start saves", fontsize=10)
    ax.legend(fontsize=9, frameon=False)

    colours = _k_colours(df)
    inc = df[df.observable == "incline"]
    panels = [(inc[inc.mu == mu], f"incline, μ = {mu:g}", "|x(T) − x_exact| / x_exact", None)
              for mu in sorted(inc.mu.unique())[:2]]
    heap = df[(df.observable == "heap") & (df.quantity == "reaction")]
    panels.append((heap, "settled heap: ground reaction", "|R / W − 1|", None))
    slope = df[df.observable == "slope_flow"]
    for angle in slope.angle.unique()[:2]:
        s = slope[slope.angle == angle]
        check = s[s.method == "CD_reference_check"]
        panels.append((s, f"slope flow at {angle:g}°: mean velocity", "|v − v_ref| / v_ref",
                       float(check.error.iloc[0]) if len(check) else None))
    for ax, (data, title, ylabel, band) in zip(axes.ravel()[1:], panels):
        _integration_panel(ax, data, f"({next(letters)}) {title}", ylabel, colours, band)
    for ax in axes.ravel()[1 + len(panels):]:
        ax.set_visible(False)
    handles = [Line2D([], [], color="k", marker="o", label="CD over h")]
    handles += [Line2D([], [], color=c, ls="--", marker="s", label=f"MD, k = {k:g} k0, over h") for k, c in colours.items()]
    handles += [Line2D([], [], color="0.5", ls="", marker="v", label="zero error"),
                plt.Rectangle((0, 0), 1, 1, color="r", alpha=0.08, label="reference's own uncertainty")]
    sub[1].legend(handles=handles, loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    return fig


def caption(nl, df):
    """The Snakemake report's caption (reStructuredText): the figure's finding, from the data."""
    r = sweep_ratios(nl)
    saving = "; ".join(f"{st} {float(r.sel(state=st).min()):.2g} to {float(r.sel(state=st).max()):.2g}"
                       for st in nl.state.values)
    inc = df[df.observable == "incline"]
    cd, md = inc[inc.method == "CD"], inc[(inc.method == "MD") & (inc.diverged == 0)]
    return (f"**Error against run time (section 2).** Zero-guess sweeps over warm-start sweeps, over the "
            f"tolerances: {saving}. On the incline Contact Dynamics is exact to {cd.error.max():.0e} at every step, "
            f"molecular dynamics' error falls to {md.error.min():.1e} at best over its steps and stiffnesses. Details: "
            f"``results/html/error_vs_runtime.html``.\n")
