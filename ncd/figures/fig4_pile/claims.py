"""Figure 4's rows on the index: §5 (the cut resultant, its cloud, where the cloud comes from,
cut position, ground pressure and arching, the dip, the geometry's sufficiency) and §6's
reassuring example.

The arching direction: across a vertical cut, a force with no vertical component (columns
carrying their own weight) is the direction *without* arching; the free surface's slope is
the direction the paper reports.  "Approximately parallel to the free surface" is therefore
judged within :func:`parallel_tol` of the surface: 10°, and never more than half the
surface's slope, so that the resultant is closer to the surface than to the horizontal.
"""

import numpy as np

from ncd.exact.polygon import convex_hull, outside_distance
from ncd.figures.fig4_pile.exact import diameter
from ncd.figures.fig4_pile.pressure import dip_verdict
from ncd.shared.verdict import DIFFERS, NOT_COMPUTED, REPRODUCED, judged, open_data, pct
from ncd.solver.convergence import REST, UNCONVERGED

F4 = ("fig4_pile/cuts.nc", "fig4_pile/ensemble.nc", "fig4_pile/exact.nc")
TOLERANCE = "fig4_pile/tolerance.nc"
WARM = "fig4_pile/warm.nc"
WARM_OVER_ZERO = 0.1         # "practically no indeterminacy": an order of magnitude below the zero-guess cloud
REST_SPEED = 1e-6            # g h: the equilibrium test's at-rest speed (construction.velocity_tol) if warm.nc lacks it
PARALLEL_DEG = 10.0          # "approximately parallel": within 10° of the free surface ...
CLOUD_OVER_ERROR = 10.0      # a cloud an order of magnitude wider than the tolerance's effect is not iteration error
CENTRAL = (0.1, 0.2, 0.3, 0.4, 0.5)   # central portions |x| <= f L of the arching deficit (L: half the base)
CENTRAL_THIRD = 1.0 / 3.0    # the centre against the outer parts of the base (pressure against height)
LEVEL, BOOT, SEED = 0.95, 4000, 2005


def parallel_tol(surface_deg):
    """Half-width (degrees) of "approximately parallel to the free surface": 10°, at most half
    the slope (closer to the surface than to the horizontal, the direction without arching)."""
    return min(PARALLEL_DEG, 0.5 * abs(float(surface_deg)))


def _default_cut(cuts):
    kinds = [str(k) for k in cuts.kind.values]
    return kinds.index("default"), kinds


def flank_name(cuts, k):
    """The flank cut ``k`` lies on: its slope θ is that flank's fit, the one every page quotes."""
    return "right" if int(cuts.outer.values[k]) > 0 else "left"


def _rest_cloud(cuts, ens, k):
    rest = ens.outcome.values == REST       # converged at rest: motion solutions are another outcome
    return np.column_stack([ens.cut_force_x.values[rest, k], ens.cut_force_y.values[rest, k]])


def fig4_parallel(results):
    cuts = open_data(results, F4[0])
    k, _ = _default_cut(cuts)
    dev = float(cuts.history_deviation.values[k])
    surf = float(cuts.surface_angle.values[k])
    tol = parallel_tol(surf)
    return judged(f"history resultant across the default cut {float(cuts.history_angle.values[k]):.1f}° below the "
                  f"horizontal, {dev:+.1f}° from the free surface's slope (its {flank_name(cuts, k)} flank's θ = {surf:.1f}°; "
                  f"tolerance ±{tol:.1f}°)",
                  REPRODUCED if abs(dev) <= tol else DIFFERS,
                  "the history resultant across the default cut within 10° of the free surface and closer to it "
                  "than to the horizontal (|deviation| ≤ min(10°, slope/2); the horizontal is the direction "
                  "without arching)", "s5-parallel-to-surface", F4[0])


def tolerance_effect(tol_ds, k, tol):
    """``(change, loose, tight)``: the largest move of a run's resultant across cut ``k`` when
    the NLGS tolerance goes from ``tol`` (the ensemble's; the tightest step when ``tol`` is
    not in the study or is its tightest) to the next tighter tolerance of the tolerance study."""
    t = np.asarray(tol_ds.tol.values, float)
    order = np.argsort(t)[::-1]                        # loosest first
    hit = [i for i, j in enumerate(order) if np.isclose(t[j], tol, rtol=1e-6)]
    i = hit[0] if hit and hit[0] + 1 < len(order) else len(order) - 2
    a, b = order[i], order[i + 1]
    fx, fy = tol_ds.cut_force_x.values[:, :, k], tol_ds.cut_force_y.values[:, :, k]
    move = np.hypot(fx[:, a] - fx[:, b], fy[:, a] - fy[:, b])
    return float(np.nanmax(move)), float(t[a]), float(t[b])


def fig4_cloud(results):
    """"A cloud which reflects the plurality of solutions": the cloud's diameter against the
    effect of the solver's tolerance on one run's resultant."""
    cuts, ens, tol_ds = open_data(results, F4[0]), open_data(results, F4[1]), open_data(results, TOLERANCE)
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    crit = (f"the diameter of the zero-guess cloud of the default cut (runs at rest) above {CLOUD_OVER_ERROR:g} times "
            "the largest move of a run's resultant when the NLGS tolerance is tightened by one step (tolerance "
            "study): an order of magnitude beyond iteration error, the dots are distinct solutions")
    if len(P) < 2:
        return judged(f"{len(P)} run(s) at rest: no cloud", DIFFERS, crit, "s5-cloud", F4[1])
    n = len(np.unique(np.round(P / np.abs(P).max(), 6), axis=0))
    diam = diameter(P)
    err, loose, tight = tolerance_effect(tol_ds, k, float(ens.tol.values) if "tol" in ens else np.nan)
    if not np.isfinite(err):
        return judged(f"{len(P)} runs at rest spanning {diam:.3g} N; the tolerance study moves no resultant it can "
                      "measure", NOT_COMPUTED, crit, "s5-cloud", F4[1], TOLERANCE)
    ratio = diam / err if err > 0 else np.inf
    return judged(f"{len(P)} zero-guess runs at rest give {n} distinct resultants across the default cut, spanning "
                  f"{diam:.3g} N; tightening the tolerance from {loose:g} to {tight:g} moves a run's resultant by at "
                  f"most {err:.2g} N: the cloud is {ratio:.3g} times that",
                  REPRODUCED if diam > CLOUD_OVER_ERROR * err else DIFFERS, crit, "s5-cloud", F4[1], TOLERANCE)


def fig4_cloud_vs_history(results):
    """"What the above cloud reveals is the indeterminacy ensuing in the final step from the
    decision of ignoring antecedent forces": the history state (the antecedent forces kept)
    should be one of the states the zero-guess cloud explores."""
    cuts, ens = open_data(results, F4[0]), open_data(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    crit = ("the history resultant across the default cut inside the convex hull of the zero-guess cloud (runs at "
            "rest) or within one cloud diameter of it: the state kept by the antecedent forces is then one the "
            "cloud explores, the cloud the indeterminacy of dropping them")
    if len(P) < 2:
        return judged(f"{len(P)} run(s) at rest: no cloud", NOT_COMPUTED, crit, "s5-cloud-from-ignoring-antecedent",
                      F4[1])
    hist = np.array([float(cuts.history_fx.values[k]), float(cuts.history_fy.values[k])])
    diam = diameter(P)
    out = float(outside_distance(hist[None], convex_hull(P))[0])
    mean = float(np.linalg.norm(hist - P.mean(0)))
    where = "inside the cloud's hull" if out == 0 else f"{out:.3g} N outside the cloud's hull ({out / diam:.2g} diameters)"
    return judged(f"the history resultant lies {mean:.3g} N from the mean of the {len(P)} zero-guess runs at rest "
                  f"({mean / diam:.2g} cloud diameters of {diam:.3g} N), {where}",
                  REPRODUCED if out <= diam else DIFFERS, crit, "s5-cloud-from-ignoring-antecedent", F4[0], F4[1])


def _at_rest(ds, speed_tol):
    """Converged runs whose grains stay within ``speed_tol`` g h: the equilibrium test's "at rest"."""
    return (ds.outcome.values != UNCONVERGED) & (ds.max_speed.values <= speed_tol)


def fig4_warm_construction(results):
    """"If at each time-step of this simulation, the initial guess of iterations is made of the
    antecedent contact forces, practically no indeterminacy is found": the final step (the
    equilibrium problem the zero-guess cloud explores) explored with random review orders from
    the construction's last impulses; its cloud at the default cut against the zero-guess one.

    Both clouds keep the converged runs within the equilibrium test's at-rest speed (warm.nc's
    ``rest_speed_tol``, 1e-6 g h), not the 1e-8 g h of ``outcome``: a run NLGS alone brings to the
    finishing tolerance leaves grains at 1e-9 to 1e-7 g h (the history state itself is at ~1e-7),
    which 1e-8 would split at random; a run in motion moves at ~g h.  On the default pile the
    zero-guess runs at rest are LP-projected (~1e-12 g h), so both thresholds keep the same ones."""
    cuts, ens, warm = open_data(results, F4[0]), open_data(results, F4[1]), open_data(results, WARM)
    k, _ = _default_cut(cuts)
    vmax = float(warm.attrs.get("rest_speed_tol", REST_SPEED))
    crit = (f"the final step (the problem the zero-guess cloud explores; the construction's other steps are not "
            "explored) from the construction's last impulses, random orders, the ensemble's solver settings: every "
            f"converged run at rest (|u_f| ≤ {vmax:g} g h, the equilibrium test's) and their cloud's diameter at the "
            f"default cut below {WARM_OVER_ZERO:g} times the zero-guess cloud's (runs at rest): \"practically no\" "
            "is an order of magnitude below the indeterminacy the zero guess reveals, as for §3's warm start")
    zr, wr = _at_rest(ens, vmax), _at_rest(warm, vmax)
    wconv = warm.outcome.values != UNCONVERGED
    n_w, n_conv, n_rest = warm.sizes["run"], int(wconv.sum()), int(wr.sum())
    if zr.sum() < 2:
        return judged(f"{int(zr.sum())} zero-guess run(s) at rest: no cloud to compare with", NOT_COMPUTED, crit,
                      "s5-warm-construction", F4[1], WARM)
    if n_conv == 0:
        return judged(f"none of the {n_w} warm-guess runs converged", NOT_COMPUTED, crit, "s5-warm-construction", WARM)

    def cloud(ds, rest, j):
        return np.column_stack([ds.cut_force_x.values[rest, j], ds.cut_force_y.values[rest, j]])
    Z, Wc = cloud(ens, zr, k), cloud(warm, wr, k)
    dz, dw = diameter(Z), diameter(Wc)
    ratio = dw / dz if dz > 0 else np.inf
    # every cut: the warm cloud's diameter over the zero-guess cloud's at the same cut (cuts where the latter is > 0)
    per = np.array([(diameter(cloud(warm, wr, j)), diameter(cloud(ens, zr, j))) for j in range(cuts.sizes["cut"])])
    wide = per[:, 1] > 0
    cut_text = (f"; over the {int(wide.sum())} cuts with a zero-guess cloud, the warm cloud is at most "
                f"{np.max(per[wide, 0] / per[wide, 1]):.2g} times the zero-guess one (median "
                f"{np.median(per[wide, 0] / per[wide, 1]):.2g}; largest warm diameter {per[:, 0].max():.2g} N)"
                if wide.any() and n_rest >= 2 else "")
    hist = np.array([float(cuts.history_fx.values[k]), float(cuts.history_fy.values[k])])
    far = f", {np.linalg.norm(Wc.mean(0) - hist):.2g} N from the history resultant" if n_rest else ""
    guess = (f" (the guess {float(warm.attrs['guess_offset']):.2g} away from the history forces, relative L1)"
             if "guess_offset" in warm.attrs else "")
    other = n_conv - n_rest
    ok = n_rest >= 2 and other == 0 and dw < WARM_OVER_ZERO * dz
    return judged(f"{n_rest} of {n_w} warm-guess runs at rest{guess}"
                  + (f", {other} converged in another state" if other else "")
                  + (f", {n_w - n_conv} unconverged" if n_w > n_conv else "")
                  + f": their cloud at the default cut spans {dw:.2g} N{far}, against {dz:.3g} N for the "
                  f"{int(zr.sum())} zero-guess runs at rest ({ratio:.2g} times){cut_text}",
                  REPRODUCED if ok else DIFFERS, crit, "s5-warm-construction", F4[0], F4[1], WARM)


def cut_pairs(cuts, d=None, rel=0.05):
    """Pairs (i, j) of scan cuts on the same flank whose positions differ by one mean
    diameter (within ``rel`` of it): "varying slightly the cut position"."""
    d = float(d or cuts.attrs["mean_diameter"])
    idx = np.flatnonzero(cuts.kind.values.astype(str) == "scan")
    x, o = cuts.cut_x.values, cuts.outer.values
    return [(i, j) for a, i in enumerate(idx) for j in idx[a + 1:]
            if o[i] == o[j] and abs(abs(x[i] - x[j]) - d) <= rel * d]


def fig4_cut_vs_cloud(results):
    """A "may" over cuts: the fraction of pairs of scan cuts one diameter apart whose
    history resultants differ by more than twice the default cut's cloud diameter."""
    cuts, ens = open_data(results, F4[0]), open_data(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if len(P) < 2:
        return judged(f"{len(P)} run(s) at rest: no cloud", NOT_COMPUTED, "—", "s5-cut-position", F4[1])
    diam = diameter(P)
    H = np.column_stack([cuts.history_fx.values, cuts.history_fy.values])
    pairs = cut_pairs(cuts)
    change = np.array([np.linalg.norm(H[i] - H[j]) for i, j in pairs])
    big2, big1 = float(np.mean(change > 2 * diam)), float(np.mean(change > diam))
    return judged(f"cloud diameter {diam:.3g} N over the {len(P)} runs at rest; over the {len(pairs)} pairs of scan cuts "
                  f"one diameter apart the resultant changes by more than twice that at {pct(big2)} of pairs, by more "
                  f"than it at {pct(big1)} (median change {np.median(change):.3g} N)",
                  REPRODUCED if big2 > 0 else DIFFERS,
                  "a \"may\" over cuts: some pairs of scan cuts one diameter apart change their history resultant by "
                  "more than twice the default cut's cloud diameter (\"definitely larger\")",
                  "s5-cut-position", F4[0], F4[1])


def fig4_contacts(results):
    cuts = open_data(results, F4[0])
    k, _ = _default_cut(cuts)
    n = int(cuts.n_loaded.values[k])
    return judged(f"{n} loaded contacts across the default cut ({int(cuts.n_crossing.values[k])} crossing)",
                  REPRODUCED if 5 <= n <= 20 else DIFFERS,
                  "the loaded contacts across the default cut the same as the paper's 10 within a factor 2 (5 to 20)",
                  "s5-ten-contacts", F4[0])


def _ground(cuts):
    """Bin centres, widths, history ground force per bin (N) and column weight per bin (N), and L."""
    lo, hi = cuts.bin_lo.values, cuts.bin_hi.values
    width = hi - lo
    L = 0.5 * (float(cuts.attrs["right_toe"]) - float(cuts.attrs["left_toe"]))
    return 0.5 * (lo + hi), cuts.history_pressure.values * width, cuts.column_weight.values * width, L


def fig4_pressure_height(results):
    """"The pressure distribution on ground does not relate to the height of material above":
    the ratio of ground force to column weight under the central third of the base against
    the outer parts, with a bootstrap band over the bins of each part."""
    cuts = open_data(results, F4[0])
    mid, g, w, L = _ground(cuts)
    centre = np.abs(mid) <= CENTRAL_THIRD * L
    outer = ~centre & (w > 0)
    rc, ro = g[centre].sum() / w[centre].sum(), g[outer].sum() / w[outer].sum()
    rng = np.random.default_rng(SEED)
    ic, io = np.flatnonzero(centre), np.flatnonzero(outer)
    bc, bo = rng.choice(ic, (BOOT, len(ic))), rng.choice(io, (BOOT, len(io)))
    boot = g[bc].sum(1) / w[bc].sum(1) - g[bo].sum(1) / w[bo].sum(1)
    lo, hi = np.quantile(boot, [0.5 * (1 - LEVEL), 0.5 * (1 + LEVEL)])
    ok = lo > 0 or hi < 0
    return judged(f"ground force over the weight of the column above: {rc:.2f} under the central third of the base "
                  f"({centre.sum()} bins), {ro:.2f} under the outer parts ({outer.sum()} bins); difference "
                  f"{rc - ro:+.2f}, {100 * LEVEL:g} % bootstrap band over bins [{lo:+.2f}, {hi:+.2f}]"
                  + (": the profile departs from the height beyond its bin-to-bin scatter" if ok else
                     ": within the bin-to-bin scatter of the profile about the column weight"),
                  REPRODUCED if ok else DIFFERS,
                  f"the ratio of ground force to column weight under the central third of the base differs from the "
                  f"outer parts', its {100 * LEVEL:g} % bootstrap band over bins (history forces, {BOOT} resamples) "
                  "excluding 0: a pressure that follows the height has the same ratio everywhere, up to the scatter "
                  "of bins holding a few contacts each", "s5-pressure-not-height", F4[0])


def fig4_arching_weight(results):
    """"Some central portion of the pile has part of its weight supported by arching actions
    from the surrounding bank": the ground force under |x| <= f L below the weight of the
    column above, at every f of :data:`CENTRAL`."""
    cuts, ens = open_data(results, F4[0]), open_data(results, F4[1])
    mid, g, w, L = _ground(cuts)
    grain = float(cuts.attrs["weight"]) / float(cuts.attrs["n_grains"])
    width = cuts.bin_hi.values - cuts.bin_lo.values
    rest = ens.outcome.values == REST
    ratio, deficit, runs = [], [], []
    for f in CENTRAL:
        m = np.abs(mid) <= f * L
        ratio.append(g[m].sum() / w[m].sum())
        deficit.append(w[m].sum() - g[m].sum())
        if rest.any():
            runs.append((ens.ground_pressure.values[rest][:, m] * width[m]).sum(1) / w[m].sum())
    ratio, deficit = np.array(ratio), np.array(deficit)
    ok = bool(np.all(deficit > 2 * grain))
    j = int(np.argmax(deficit))
    text = (f"history ground force over the weight of the column above, for the central portions |x| ≤ f L "
            f"(f = {', '.join(f'{f:g}' for f in CENTRAL)}; L = {1e3 * L:.0f} mm): "
            f"{', '.join(f'{r:.2f}' for r in ratio)}; the largest deficit {deficit[j]:.2f} N "
            f"({deficit[j] / grain:.0f} grain weights, f = {CENTRAL[j]:g}) is carried across the portion's sides "
            "by the bank")
    if runs:
        allr = np.concatenate(runs)
        text += f"; the zero-guess runs at rest give ratios {allr.min():.2f} to {allr.max():.2f} over the same portions"
    return judged(text, REPRODUCED if ok else DIFFERS,
                  "at every central portion |x| ≤ f L (f = 0.1 to 0.5, so the sign does not hang on one width) the "
                  "history ground force falls short of the column weight by more than two grain weights (the "
                  "bookkeeping of grains straddling the portion's edges)", "s5-arching-supports-weight", F4[0], F4[1])


def fig4_dip(results):
    """The verdict of the fig4_pile page (:func:`ncd.figures.fig4_pile.pressure.dip_verdict`),
    recomputed from the dip depths of ``exact.nc``: a dip is called only when the history's
    dip depth exceeds the spread over analysis choices and the exact range over A ∩ C
    forces it."""
    ex = open_data(results, F4[2])
    a = ex.attrs
    m = [str(c) for c in ex.choice.values].index(a["dip_main_choice"])
    hist = ex.dip_history.values
    depth, lo, hi = (float(ex[v].values[m]) for v in ("dip_history", "dip_min", "dip_max"))
    spread = float(hist.max() - hist.min())
    geometry, called = dip_verdict(depth, spread, lo, hi)
    return judged(f"dip depth (flank minus centre, > 0 a dip, units of the mean ground stress W/2L) of the history forces "
                  f"({a['dip_main_choice']}): {depth:+.3f}; spread over the {len(hist)} analysis choices "
                  f"{spread:.3f}; exact range over A ∩ C [{lo:+.3f}, {hi:+.3f}]: a dip {geometry} by the geometry",
                  REPRODUCED if called else DIFFERS,
                  "a \"may\" in this pile: the history forces' dip depth above 0 and above its spread over the "
                  "analysis choices (kernels, bins), and above 0 over all of A ∩ C (the dip is the pile's, not one "
                  "solution's)", "s5-dip", F4[2])


def _exact_at_default(results):
    """The files, the default cut and its cloud, exact angle range and largest F_y over A ∩ C."""
    cuts, ens, ex = (open_data(results, f) for f in F4)
    k, _ = _default_cut(cuts)
    return cuts, ex, k, dict(
        P=_rest_cloud(cuts, ens, k), surf=float(cuts.surface_angle.values[k]), flank=flank_name(cuts, k),
        lo=float(ex.angle_min.values[k]), hi=float(ex.angle_max.values[k]), fy_max=float(ex.fy_max.values[k]),
        arch=int(ex.all_arch.values.astype(bool).sum()), n=int(ex.sizes["cut"]))


def _cloud_angles(P, surf):
    return np.degrees(np.arctan2(-P[:, 1], np.abs(P[:, 0]))) - surf


def fig4_geometry_enough(results):
    """"Whatever is the indeterminacy" judged on the exact set: the range of the resultant's
    angle over A ∩ C at the default cut, and the cuts where every admissible state arches."""
    cuts, ex, k, e = _exact_at_default(results)
    P = e["P"]
    V = np.column_stack([ex.vertex_fx.values[k], ex.vertex_fy.values[k]])
    V = V[np.isfinite(V).all(1)]
    tol = parallel_tol(e["surf"])
    ok = abs(e["lo"] - e["surf"]) <= tol and abs(e["hi"] - e["surf"]) <= tol
    hist = np.array([float(cuts.history_fx.values[k]), float(cuts.history_fy.values[k])])
    far = f"; the history resultant lies {np.linalg.norm(hist - P.mean(0)):.3g} N from its mean" if len(P) else ""
    return judged(f"default cut: exact set of resultants {diameter(V):.3g} N across against a zero-guess cloud of "
                  f"{diameter(P):.3g} N{far}; over A ∩ C the resultant's angle ranges over [{e['lo']:.1f}°, "
                  f"{e['hi']:.1f}°] below the horizontal ({e['flank']} flank θ = {e['surf']:.1f}°, tolerance ±{tol:.1f}°); "
                  f"every admissible state arches at {e['arch']} of {e['n']} cuts", REPRODUCED if ok else DIFFERS,
                  "\"whatever is the indeterminacy\": every admissible resultant (A ∩ C) at the default cut "
                  "approximately parallel to the free surface, as in the row on the history resultant (within "
                  "min(10°, slope/2))", "s5-geometry-enough", *F4)


def fig4_reassuring(results):
    """"Not large enough to mask the feature", over the same admissible set as §5's "whatever is
    the indeterminacy": the feature (arching: the core pushing the bank downward across the
    cut) is masked when some admissible state at the default cut does not arch."""
    _, _, _, e = _exact_at_default(results)
    P = e["P"]
    cloud = ""
    if len(P):
        dev = _cloud_angles(P, e["surf"])
        cloud = (f"the {len(P)} zero-guess runs at rest span only {dev.max() - dev.min():.1f}° "
                 f"({dev.min():+.1f}° to {dev.max():+.1f}° from the free surface), but ")
    ok = e["fy_max"] < 0
    return judged(f"{cloud}over A ∩ C the default cut's resultant ranges over [{e['lo']:.1f}°, {e['hi']:.1f}°] below the "
                  f"horizontal ({e['hi'] - e['lo']:.1f}° wide; {e['flank']} flank θ = {e['surf']:.1f}°): "
                  + ("every admissible state arches there" if ok else
                     "it reaches the horizontal, the direction without arching")
                  + f"; every admissible state arches at {e['arch']} of {e['n']} cuts. The narrow cloud samples "
                  "one algorithm's solutions; the admissible range is what masks the feature or not",
                  REPRODUCED if ok else DIFFERS,
                  "over A ∩ C, the set §5's \"whatever is the indeterminacy\" ranges over (the zero-guess cloud is "
                  "one algorithm's sample of it and misses the history state): every admissible resultant at the "
                  "default cut pushes the bank downward (max F_y < 0), so no admissible state masks the arching",
                  "s6-reassuring", *F4)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s5-pressure-not-height": (fig4_pressure_height,),
    "s5-arching-supports-weight": (fig4_arching_weight,),
    "s5-dip": (fig4_dip,),
    "s5-parallel-to-surface": (fig4_parallel,),
    "s5-cloud": (fig4_cloud,),
    "s5-warm-construction": (fig4_warm_construction,),
    "s5-cloud-from-ignoring-antecedent": (fig4_cloud_vs_history,),
    "s5-geometry-enough": (fig4_geometry_enough,),
    "s5-cut-position": (fig4_cut_vs_cloud,),
    "s5-ten-contacts": (fig4_contacts,),
    "s6-reassuring": (fig4_reassuring,),
}
