"""Figure 4's rows on the index: §5 (the cut resultant, its cloud, cut position, ground pressure,
the dip, the geometry's sufficiency) and §6's reassuring example.
"""

import numpy as np

from ncd.figures.fig4_pile.exact import diameter
from ncd.shared.verdict import DIFFERS, NOT_COMPUTED, REPRODUCED, judged, open_data, pct
from ncd.solver.convergence import REST

F4 = ("fig4_pile/cuts.nc", "fig4_pile/ensemble.nc", "fig4_pile/exact.nc")


def _default_cut(cuts):
    kinds = [str(k) for k in cuts.kind.values]
    return kinds.index("default"), kinds


def _rest_cloud(cuts, ens, k):
    rest = ens.outcome.values == REST       # converged at rest: motion solutions are another outcome
    return np.column_stack([ens.cut_force_x.values[rest, k], ens.cut_force_y.values[rest, k]])


def fig4_parallel(results):
    cuts = open_data(results, F4[0])
    k, _ = _default_cut(cuts)
    dev = float(cuts.history_deviation.values[k])
    return judged(f"history resultant across the default cut {float(cuts.history_angle.values[k]):.1f}° below the "
              f"horizontal, {dev:+.1f}° from the free surface's slope", REPRODUCED if abs(dev) <= 10 else DIFFERS,
              "within 10° of the free surface", "s5-parallel-to-surface", F4[0])


def fig4_cloud(results):
    cuts, ens = open_data(results, F4[0]), open_data(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if len(P) < 2:
        return judged(f"{len(P)} run(s) at rest: no cloud", DIFFERS, "a cloud of distinct resultants over runs at rest",
                  "s5-cloud", F4[1])
    n = len(np.unique(np.round(P / np.abs(P).max(), 6), axis=0))
    return judged(f"{len(P)} zero-guess runs at rest give {n} distinct resultants across the default cut, spanning "
              f"{diameter(P):.3g} N", REPRODUCED if n > 1 else DIFFERS,
              "distinct resultants over the runs at rest", "s5-cloud", F4[1])


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
              "a \"may\" over cuts: some pairs of cuts one diameter apart change by more than twice the cloud",
              "s5-cut-position", F4[0], F4[1])


def fig4_contacts(results):
    cuts = open_data(results, F4[0])
    k, _ = _default_cut(cuts)
    n = int(cuts.n_loaded.values[k])
    return judged(f"{n} loaded contacts across the default cut ({int(cuts.n_crossing.values[k])} crossing)",
              REPRODUCED if 5 <= n <= 20 else DIFFERS, "same order as the paper's 10 (5 to 20)", "s5-ten-contacts",
              F4[0])


def fig4_pressure_height(results):
    cuts = open_data(results, F4[0])
    mid = 0.5 * (cuts.bin_lo.values + cuts.bin_hi.values)
    b = int(np.argmin(np.abs(mid)))
    p, w = float(cuts.history_pressure.values[b]), float(cuts.column_weight.values[b])
    loaded = cuts.column_weight.values > 0.5 * cuts.column_weight.values.max()
    dev = np.abs(cuts.history_pressure.values[loaded] / cuts.column_weight.values[loaded] - 1)
    ok = abs(p / w - 1) > 0.1
    return judged(f"under the apex the ground pressure is {p:.1f} N/m against a column weight of {w:.1f} N/m "
              f"({p / w:.0%}); over the {loaded.sum()} bins under more than half the apex column the ratio departs "
              f"from 1 by {np.median(dev):.0%} (median)", REPRODUCED if ok else DIFFERS,
              "the pressure under the apex differs from the weight of the column above it by more than 10 %",
              "s5-pressure-not-height", F4[0])


def fig4_dip(results):
    """The verdict of the fig4_pile page (:func:`ncd.figures.fig4_pile.pressure.dip_verdict`): a dip is
    called only when the history's dip depth exceeds the spread over analysis choices and
    the exact range over A ∩ C forces it."""
    ex = open_data(results, F4[2])
    a = ex.attrs
    m = [str(c) for c in ex.choice.values].index(a["dip_main_choice"])
    depth, lo, hi = (float(ex[v].values[m]) for v in ("dip_history", "dip_min", "dip_max"))
    called = bool(a["dip_called"])
    return judged(f"dip depth (flank minus centre, > 0 a dip, units of the mean ground stress W/2L) of the history forces "
              f"({a['dip_main_choice']}): {depth:+.3f}; spread over the analysis choices "
              f"{float(a['dip_binning_spread']):.3f}; exact range over A ∩ C [{lo:+.3f}, {hi:+.3f}]: a dip "
              f"{a['dip_geometry']} by the geometry", REPRODUCED if called else DIFFERS,
              "a \"may\": a dip in this pile beyond the analysis-choice spread, forced by the geometry",
              "s5-dip", F4[2])


def fig4_geometry_enough(results):
    """"Whatever is the indeterminacy" judged on the exact set: the range of the resultant's
    angle over A ∩ C at the default cut, and the cuts where every admissible state arches."""
    cuts, ens, ex = (open_data(results, f) for f in F4)
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    V = np.column_stack([ex.vertex_fx.values[k], ex.vertex_fy.values[k]])
    V = V[np.isfinite(V).all(1)]
    surf = float(cuts.surface_angle.values[k])
    lo, hi = float(ex.angle_min.values[k]), float(ex.angle_max.values[k])
    ok = abs(lo - surf) <= 10 and abs(hi - surf) <= 10
    hist = np.array([float(cuts.history_fx.values[k]), float(cuts.history_fy.values[k])])
    far = f"; the history resultant lies {np.linalg.norm(hist - P.mean(0)):.3g} N from its mean" if len(P) else ""
    exact = ex.exact.values.astype(bool)
    return judged(f"default cut: exact set of resultants {diameter(V):.3g} N across against a zero-guess cloud of "
              f"{diameter(P):.3g} N{far}; over A ∩ C the resultant's angle ranges over [{lo:.1f}°, {hi:.1f}°] below "
              f"the horizontal (free surface {surf:.1f}°); every admissible state arches at "
              f"{int(ex.all_arch.values[exact].sum())} of {exact.sum()} cuts", REPRODUCED if ok else DIFFERS,
              "\"whatever is the indeterminacy\": every admissible resultant at the default cut within 10° of the "
              "free surface", "s5-geometry-enough", *F4)


def fig4_reassuring(results):
    """"Not large enough to mask the feature": the cloud's angular width at the default cut
    against the angle between the free surface and the vertical (the direction of the
    force without arching)."""
    cuts, ens = open_data(results, F4[0]), open_data(results, F4[1])
    k, _ = _default_cut(cuts)
    P = _rest_cloud(cuts, ens, k)
    if not len(P):
        return judged("no run at rest", NOT_COMPUTED, "—", "s6-reassuring", F4[1])
    surf = float(cuts.surface_angle.values[k])
    dev = np.degrees(np.arctan2(-P[:, 1], np.abs(P[:, 0]))) - surf
    width, gap = float(dev.max() - dev.min()), 90.0 - surf
    return judged(f"the {len(P)} zero-guess runs at rest put the resultant {dev.min():+.1f}° to {dev.max():+.1f}° from "
              f"the free surface: a cloud {width:.1f}° wide, against {gap:.1f}° between the surface and the vertical "
              "(the exact set is judged in the §5 row on geometry)", REPRODUCED if width < gap / 10 else DIFFERS,
              "the NLGS cloud's angular width below a tenth of the angle between the free surface and the vertical",
              "s6-reassuring", *F4[:2])


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s5-pressure-not-height": (fig4_pressure_height,),
    "s5-dip": (fig4_dip,),
    "s5-parallel-to-surface": (fig4_parallel,),
    "s5-cloud": (fig4_cloud,),
    "s5-geometry-enough": (fig4_geometry_enough,),
    "s5-cut-position": (fig4_cut_vs_cloud,),
    "s5-ten-contacts": (fig4_contacts,),
    "s6-reassuring": (fig4_reassuring,),
}
