"""Figure 1's page: the figure and the sentences of what was measured, from
``fig1_wedged/ensemble.nc``, ``evolutions.nc`` and ``sweep.nc`` with the closed form of
:class:`ncd.figures.fig1_wedged.measure.Wedge`.

Each sentence counts the runs it speaks about and names the ones it leaves out (runs that
did not converge, runs of an unclassified outcome).
"""
import numpy as np

FALLS, WEDGED, UNCLASSIFIED = 0, 1, -1


def wedged_runs(ens):
    """Mask of the converged runs that ended wedged, and their ``(N, force_n, force_t, I_y)``
    (``N`` the mean normal force of the two contacts)."""
    wed = (ens.converged.values == 1) & (ens.outcome.values == WEDGED)
    fn, ft = ens.force_n.values[wed], ens.force_t.values[wed]
    return wed, fn.mean(axis=1), fn, ft, ens.I_y.values[wed]


def setup_sentence(wedge, h):
    """The geometry and the closed form's numbers."""
    y_bot, y_top = wedge.segment
    beta, gamma = np.degrees(wedge.beta), np.degrees(wedge.gamma)
    return (f"$B$ has radius $R$ = {wedge.radius:g} m and weight $mg$ = {wedge.weight:.4g} N; the obstacles have "
            f"radius {wedge.obstacle_radius:g} m; the contact normals make $\\beta$ = {beta:.2f}° with the "
            f"horizontal; $\\mu$ = {wedge.mu:g} ($\\gamma$ = {gamma:.2f}°); one step of $h$ = {h:g} s.  "
            f"The closed form: wedging is {'possible' if wedge.wedging_possible else 'impossible'} "
            f"($\\gamma$ {'>' if wedge.wedging_possible else '≤'} $\\beta$), $N_{{\\min}}$ = "
            f"{wedge.n_min / wedge.weight:.4f} $mg$, and $I$ ranges from $y$ = {y_bot / wedge.radius:.4f} $R$ "
            f"(a limit, $N \\to \\infty$) to {y_top / wedge.radius:.4f} $R$ (reached at $N_{{\\min}}$), a segment of "
            f"{(y_top - y_bot) / wedge.radius:.4f} $R$.")


def ensemble_sentence(ens, wedge):
    """Outcomes of the one-step runs, and how close the wedged ones are to the closed form."""
    conv = ens.converged.values == 1
    zero = ens.zero_guess.values == 1
    outcome = ens.outcome.values
    parts = []
    for label, sel in (("random guesses", ~zero), ("zero guesses", zero)):
        c = conv & sel
        parts.append(f"of the {int(sel.sum())} runs from {label}, {int((outcome[c] == FALLS).sum())} fall, "
                     f"{int((outcome[c] == WEDGED).sum())} stay wedged, {int((outcome[c] == UNCLASSIFIED).sum())} "
                     f"end in neither state and {int((sel & ~conv).sum())} did not converge")
    text = "One step from rest, solved by NLGS to a natural-map residual of " \
           f"{float(ens.attrs['solver_tol']):g}: " + "; ".join(parts) + "."
    wed, n, fn, ft, iy = wedged_runs(ens)
    if not wed.any():
        return text + " No run ended wedged: nothing to compare with the closed-form segment."
    y_bot, y_top = wedge.segment
    balance = np.abs((fn[:, :, None] * wedge.normals + ft[:, :, None] * wedge.tangents).sum(1)
                     + [0.0, -wedge.weight]).max() / wedge.weight
    return text + (
        f"  Every wedged run balances gravity to {balance:.0e} $mg$ and satisfies Coulomb's law to "
        f"|T|/(μN) ≤ {np.abs(ft / fn).max() / wedge.mu:.6f}; their normal forces range over "
        f"{n.min() / wedge.weight:.4f}–{n.max() / wedge.weight:.1f} $mg$, and their points $I$ lie within "
        f"{np.abs(iy - wedge.y_of_n(n)).max() / wedge.radius:.0e} $R$ of the closed-form curve $y_I(N)$ and span "
        f"{100 * (iy.max() - iy.min()) / (y_top - y_bot):.1f} % of the segment.  The density of dots along it "
        f"reflects the guess distribution (log-uniform normal forces), not the solution set.")


def second_contact_sentence(ens, wedge):
    """Why a random guess wedges: within a sweep the contact reviewed first is solved with the
    other's guess frozen, so the outcome follows the guess at the contact reviewed second."""
    conv, zero, outcome = ens.converged.values == 1, ens.zero_guess.values == 1, ens.outcome.values
    second = 1 - ens.first_reviewed.values
    guess = ens.guess_force_n.values[np.arange(ens.sizes["run"]), second]
    rnd = conv & ~zero
    big, small = rnd & (guess >= wedge.n_min), rnd & (guess < wedge.n_min)

    def pct(sel):
        return f"{100 * np.mean(outcome[sel] == WEDGED):.0f} %" if sel.any() else "none (no such run)"

    return (f"Within a sweep the contact reviewed first is solved with the other contact's guess frozen, so the "
            f"outcome follows the guess at the contact reviewed second: of the {int(big.sum())} converged "
            f"random-guess runs whose guessed normal force there is at least $N_{{\\min}}$, {pct(big)} stay "
            f"wedged; of the {int(small.sum())} others, {pct(small)}.")


def evolutions_sentence(evo, wedge):
    """The two evolutions from the same state, differing only by the first guess."""
    t = evo.time.values
    zero, warm = evo.sel(evolution="zero_guess"), evo.sel(evolution="wedged_warm")
    free = -0.5 * wedge.g * t[-1] ** 2
    return (f"From the zero guess at every step, $B$ ends at $y$ = {float(zero.y.values[-1]):.6g} m after "
            f"{t[-1]:g} s (free fall: {free:.6g} m).  Started from a wedged force state and warm-started, it stays "
            f"within {np.abs(warm.y.values).max():.1e} m of rest over the same time, with at most "
            f"{int(warm.sweeps.values[1:].max())} NLGS sweeps per step after the first; "
            f"{int((evo.converged.values[:, 1:] == 0).sum())} steps of either evolution did not converge.")


def sweep_sentence(swp, wedge, force_max):
    """The threshold sweep against the closed form, and what sets the apparent onset."""
    frac, gam = swp.wedged_fraction.values, swp.gamma.values
    beta = np.degrees(wedge.beta)
    below, above = gam < beta, gam > beta
    onset = np.degrees(np.arcsin(np.cos(wedge.beta) / (2 * force_max)))
    first = (f"{frac[above][0]:.2g} at the first angle above it ({gam[above][0]:.3g}°), "
             f"{np.nanmax(frac[above]):.2g} at most" if above.any() else "no angle above it was run")
    return (f"Over {swp.sizes['gamma']} friction angles ({swp.sizes['run']} random guesses each; "
            f"{int((swp.converged.values == 0).sum())} of {swp.converged.size} runs did not converge), the "
            f"wedged fraction is {np.nanmax(frac[below]) if below.any() else 0:.2g} at most below "
            f"$\\beta$ = {beta:.0f}° and {first}.  How fast it rises is set by the guesses, not by the "
            f"mechanics: near the threshold $N_{{\\min}}$ diverges, and only guesses of comparable size end wedged, "
            f"so the apparent onset is where $N_{{\\min}}$ falls below the largest guessed force "
            f"({force_max:g} $mg$), about {onset:.2g}° above $\\beta$.")


def _circle(ax, c, r, **kw):
    import matplotlib.pyplot as plt

    ax.add_patch(plt.Circle(c, r, **kw))


def _scene(ax, wedge, iy):
    """The obstacles, $B$, the Coulomb cones, the lines of action of six wedged runs and the
    closed-form segment of $I$."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Wedge as Sector

    R, P = wedge.radius, wedge.contact_points
    gamma = np.degrees(wedge.gamma)
    y_bot, y_top = wedge.segment
    for c in wedge.obstacle_pos:
        _circle(ax, c, wedge.obstacle_radius, fc="0.82", ec="0.3", lw=1)
    _circle(ax, (0, 0), R, fc="#dbe8f6", ec="C0", lw=1.5)
    for i in range(2):
        a0 = np.degrees(np.arctan2(wedge.normals[i, 1], wedge.normals[i, 0]))
        ax.add_patch(Sector(P[i], 0.45 * R, a0 - gamma, a0 + gamma, fc="C1", alpha=0.25, lw=0))
    picks = np.argsort(iy)[np.linspace(0, len(iy) - 1, 6).round().astype(int)] if len(iy) else []
    for k, j in enumerate(picks):
        for i in range(2):
            ax.plot([P[i, 0], 0], [P[i, 1], iy[j]], color=plt.cm.viridis(k / 5), lw=1)
    ax.plot([0, 0], [y_bot, y_top], color="C3", lw=4, alpha=0.35, solid_capstyle="butt")
    ax.plot(0, y_top, "o", color="C3", ms=6)
    ax.plot(0, y_bot, "o", mfc="white", mec="C3", ms=6)
    ax.plot(*P.T, "k.", ms=6)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def plot(ens, evo, swp, wedge):
    """Six panels: (a) the scene, (b) a zoom on the segment of $I$ with the wedged runs,
    (c) $I$ against the normal force, (d) the two evolutions, (e) their contact forces,
    (f) the threshold sweep.  Returns the figure."""
    import matplotlib.pyplot as plt

    plt.rcParams.update({"font.size": 9.5})
    R, mg, ro = wedge.radius, wedge.weight, wedge.obstacle_radius
    beta, gamma = np.degrees(wedge.beta), np.degrees(wedge.gamma)
    y_bot, y_top = wedge.segment
    wed, n, _, _, iy = wedged_runs(ens)
    fig = plt.figure(figsize=(10, 8.6), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[1.0, 1.0])
    ax_a, ax_b, ax_c = top.subplots(1, 3, width_ratios=[1.6, 0.7, 1.2])

    _scene(ax_a, wedge, iy)
    ax_a.text(0, -0.45 * R, "$B$", ha="center", fontsize=12)
    ax_a.annotate("", xy=(0, -0.95 * R), xytext=(0, -0.6 * R), arrowprops=dict(arrowstyle="->", color="k"))
    ax_a.text(0.06 * R, -0.85 * R, "$mg$")
    ax_a.add_patch(plt.Rectangle((-0.22 * R, 0.3 * R), 0.44 * R, 0.37 * R, fill=False, ec="k", lw=0.6, ls="--"))
    ax_a.set_xlim(wedge.obstacle_pos[0, 0] - 1.05 * ro, wedge.obstacle_pos[1, 0] + 1.05 * ro)
    ax_a.set_ylim(-1.08 * R, wedge.obstacle_pos[0, 1] + 1.05 * ro)
    ax_a.set_title(f"(a) $\\beta$ = {beta:.0f}°, $\\mu$ = {wedge.mu:g} ($\\gamma$ = {gamma:.1f}°):\n"
                   "Coulomb cones, 6 wedged runs", fontsize=10)

    _scene(ax_b, wedge, iy)
    ax_b.plot(np.zeros(len(iy)), iy, "k.", ms=3, alpha=0.25)
    ax_b.text(0.015 * R, y_top, "$N_{\\min}$", fontsize=9.5, va="bottom")
    ax_b.text(0.015 * R, y_bot, "$N\\to\\infty$", fontsize=9.5, va="top")
    ax_b.set_xlim(-0.22 * R, 0.22 * R)
    ax_b.set_ylim(0.3 * R, 0.67 * R)
    ax_b.set_title(f"(b) zoom: $I$ of\n{len(iy)} wedged runs", fontsize=10)

    hi = max(n.max() if len(n) else 10 * wedge.n_min, 10 * wedge.n_min) * 1.5
    ns = np.geomspace(wedge.n_min, hi, 300)
    ax_c.semilogx(ns / mg, wedge.y_of_n(ns) / R, color="C3", lw=2)
    ax_c.semilogx(n / mg, iy / R, "k.", ms=2.5, alpha=0.5)
    ax_c.axhline(y_top / R, color="C3", ls="--", lw=0.8)
    ax_c.axhline(y_bot / R, color="C3", ls=":", lw=0.8)
    ax_c.text(hi / mg, y_bot / R + 0.005, "$R\\sin\\beta$", ha="right", va="bottom")
    ax_c.axvline(wedge.n_min / mg, color="0.5", lw=0.8)
    ax_c.set_ylim(y_bot / R - 0.03, y_top / R + 0.02)
    ax_c.set_xlabel("normal force $N / mg$")
    ax_c.set_ylabel("height of $I$, $y_I / R$")
    ax_c.set_title("(c) $I$ against $N$: closed\nform (red), wedged runs (dots)", fontsize=10)

    ax_d, ax_e, ax_f = bottom.subplots(1, 3)
    t = evo.time.values
    labels = {"zero_guess": "zero guess", "wedged_warm": "wedged, then warm"}
    for k, name in enumerate(evo.evolution.values):
        ax_d.plot(t, evo.sel(evolution=name).y.values / R, color=f"C{k}", label=labels.get(str(name), str(name)))
    ax_d.plot(t, -0.5 * wedge.g * t ** 2 / R, "k:", lw=1, label="free fall")
    ax_d.set_yscale("symlog", linthresh=1e-3)
    ax_d.set_xlabel("time (s)")
    ax_d.set_ylabel("height of $B$'s centre, $y / R$")
    ax_d.set_title("(d) two evolutions,\nsame initial state", fontsize=10)
    ax_d.legend(fontsize=9, frameon=False, loc="center right")

    for k, name in enumerate(evo.evolution.values):
        e = evo.sel(evolution=name)
        for i, ls in enumerate(("-", "--")):
            ax_e.plot(t[1:], e.force_n.values[1:, i] / mg, color=f"C{k}", ls=ls, lw=1.8)
            ax_e.plot(t[1:], e.force_t.values[1:, i] / mg, color=f"C{k}", ls=ls, lw=0.9, alpha=0.6)
    ax_e.plot([], [], "k-", label="left contact")
    ax_e.plot([], [], "k--", label="right contact")
    ax_e.set_xlabel("time (s)")
    ax_e.set_ylabel("contact force / $mg$")
    ax_e.set_title("(e) forces of (d):\n$N$ thick, $T$ thin", fontsize=10)
    ax_e.legend(fontsize=9, frameon=False, loc="center right")

    frac, gam = swp.wedged_fraction.values, swp.gamma.values
    ax_f.axvspan(gam.min() - 1, beta, color="0.92")
    ax_f.plot(gam, frac, "o-", color="C2", ms=4)
    ax_f.axvline(beta, color="C3", lw=1.5)
    ax_f.text(beta - 1, 0.5 * max(np.nanmax(frac), 0.1), f"$\\gamma = \\beta$\n= {beta:.0f}°", ha="right", color="C3")
    ax_f.set_xlim(gam.min() - 1, gam.max() + 1)
    ax_f.set_xlabel("friction angle $\\gamma$ (degrees)")
    ax_f.set_ylabel("fraction of wedged runs")
    ax_f.set_title(f"(f) threshold sweep:\n{swp.sizes['run']} random guesses per angle", fontsize=10)
    return fig


def caption(ens, swp, wedge):
    """The Snakemake report's caption (reStructuredText): the figure's finding, from the data."""
    conv, zero, out = ens.converged.values == 1, ens.zero_guess.values == 1, ens.outcome.values
    wed, n, _, _, iy = wedged_runs(ens)
    y_bot, y_top = wedge.segment
    frac, gam = swp.wedged_fraction.values, swp.gamma.values
    beta = np.degrees(wedge.beta)
    below = np.nanmax(frac[gam < beta]) if (gam < beta).any() else 0.0
    on_segment = (f"every one with its point I within {np.abs(iy - wedge.y_of_n(n)).max() / wedge.radius:.0e} R of "
                  f"the closed-form segment, spanning {100 * (iy.max() - iy.min()) / (y_top - y_bot):.0f} % of it"
                  if wed.any() else "none to compare with the closed-form segment")
    return (f"**Figure 1 (section 1): the wedged disc.** One step from rest: {int((out[conv & zero] == FALLS).sum())} "
            f"of {int(zero.sum())} zero-guess runs let the disc fall, while {int(wed.sum())} of {int((~zero).sum())} "
            f"random-guess runs keep it wedged, {on_segment}. The largest wedged fraction below the closed-form "
            f"threshold (friction angle = {beta:.0f} degrees) is {below:.2g}. Details: ``results/html/fig1_wedged.html``.\n")
