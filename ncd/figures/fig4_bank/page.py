"""The sentences of the fig4_bank page, computed from its data (``measures.nc`` and the exact
angle ranges); the numbers they share with the verdicts come from :mod:`.claims`, so the
page and the index read the same values."""
import numpy as np

from ncd.figures.fig4_bank.claims import (
    CLAIM_HISTORY,
    exact_summary,
    failure_numbers,
    flank_slope,
    nan_stat,
    observation_correlation,
    of_history,
    reciprocity_numbers,
    tilt_numbers,
    vertical_numbers,
)


def _fmt_list(pairs, unit="°"):
    return ", ".join(f"{k:g}: {m:+.1f}{unit}" for k, m in pairs)


def cuts_text(ms):
    """Angle against depth and position, the column weight carried, the other histories."""
    v = vertical_numbers(ms)
    s = ms.sel(history=CLAIM_HISTORY)
    pos = [(float(q), float(s.angle_by_position[j])) for j, q in enumerate(ms.position.values)
           if np.isfinite(s.angle_by_position[j])]
    lines = [f"Medians over the point-source piles against depth (d): "
             f"{_fmt_list([(dd, m) for dd, m, _, _ in v['by_depth']])}; against position |x|/L: {_fmt_list(pos)}. "
             f"The downward component of the resultant is {v['load']:.3f} times the weight of the grains above "
             f"the cut in the vertical strip over it (band {v['load_lo']:.3f} to {v['load_hi']:.3f}): each column "
             f"of the bank carries its own weight, the infinite-slope balance."]
    for h in ms.history.values:
        if h == CLAIM_HISTORY:
            continue
        a = of_history(ms, "angle_to_vertical", h)
        label = {"default": "The default pile", "rain": "The rained heaps (the point source's shape)",
                 "layer": "The layers"}.get(str(h), str(h))
        lines.append(f"{label}: {float(ms.angle.sel(history=h)):+.1f}° on median over {int(np.isfinite(a).sum())} "
                     f"cuts (half between {nan_stat(np.nanquantile, a, 0.25):+.1f}° and "
                     f"{nan_stat(np.nanquantile, a, 0.75):+.1f}°), carrying {float(ms['carried'].sel(history=h)):.3f} "
                     f"times the column weight"
                     + (f"; their fitted flanks slope at only {nan_stat(np.nanmedian, of_history(ms, 'tan_flank', h)):.2f} "
                        "(tan), so their cuts are nearly horizontal." if h == "layer" else "."))
    return " ".join(lines)


def exact_load(ms, exact):
    """Median over the exact piles' cuts of the exact range of the downward force over the column weight."""
    widths = [(e.fy_max.values - e.fy_min.values) / ms.column_weight.sel(pile=name).values
              for name, e in exact.items() if name in ms.pile.values]
    return nan_stat(np.nanmedian, np.concatenate([w.ravel() for w in widths])) if widths else np.nan


def exact_text(exact, tol, ms=None):
    """The exact ranges: width, how many cuts are forced within ``tol`` of the vertical, the history inside."""
    e = exact_summary(exact)
    if e is None or not e["cuts"]:
        return "No exact range was computed in this run."
    load = exact_load(ms, exact) if ms is not None else np.nan
    forced = float(np.mean((e["lo"] >= -tol) & (e["hi"] <= tol)))
    contains = float(np.mean((e["lo"] <= 0) & (e["hi"] >= 0)))
    return (f"Over A ∩ C of {e['piles']} piles ({', '.join(exact)}), the exact range of the angle to the vertical of "
            f"the {e['cuts']} surface-parallel cuts spans {e['width_median']:.1f}° on median, at most "
            f"{e['width_max']:.1f}°. At {100 * forced:.0f} % of the cuts every admissible force state is within "
            f"±{tol:g}° of the vertical; at {100 * contains:.0f} % the range contains the vertical"
            + (f"; the downward component ranges over {100 * load:.0f} % of the column weight on median"
               if np.isfinite(load) else "") + ". The history "
            f"resultant lies inside its range (at most {e['history_outside']:.1e}° outside, the tolerance of the "
            f"history equilibrium). "
            + ("The near-vertical force is thus a property of the history forces, not imposed on each cut by the "
               "geometry of the pile." if forced < 0.5 else
               "The geometry thus forces a near-vertical force at most cuts."))


def stress_numbers(ms):
    """Traction of the window stress against the cuts' own sums per unit length (relative)."""
    ts = np.stack([ms.traction_s_x.values, ms.traction_s_y.values], -1)
    ds_ = np.stack([ms.direct_s_x.values, ms.direct_s_y.values], -1)
    tv = np.stack([ms.traction_v_x.values, ms.traction_v_y.values], -1)
    dv = np.stack([ms.direct_v_x.values, ms.direct_v_y.values], -1)
    rel = lambda a, b: np.linalg.norm(a - b, axis=-1) / np.linalg.norm(a, axis=-1)  # noqa: E731
    es, ev = rel(ts, ds_), rel(tv, dv)
    return dict(surface=nan_stat(np.nanmedian, es), surface_q90=nan_stat(np.nanquantile, es, 0.9),
                vertical=nan_stat(np.nanmedian, ev), vertical_q90=nan_stat(np.nanquantile, ev, 0.9),
                n_surface=nan_stat(np.nanmedian, ms.n_crossing.values), n_vertical=nan_stat(np.nanmedian, ms.vertical_n_crossing.values),
                grains=nan_stat(np.nanmedian, ms.n_window.values))


def stress_text(ms, exact):
    r = reciprocity_numbers(ms, exact)
    s = stress_numbers(ms)
    return (f"Asymmetry: over the {r['windows']} windows of {r['piles']} piles, |σ_xy − σ_yx| is at most "
            f"{r['asym_max']:.1e} of the mean pressure p (history forces)" + (f", and at most {r['vertex_asymmetry']:.0e} p at the LP points of A ∩ C that realise the "
                         f"extreme angles" if np.isfinite(r['vertex_asymmetry']) else "")
            + f". A window holds {s['grains']:.0f} grains on median. "
            f"Traction against the cuts: the force per unit length −σn_s of the window differs from the "
            f"surface-parallel cut's own resultant per unit length by {100 * s['surface']:.0f} % on median (90 % of "
            f"the cuts within {100 * s['surface_q90']:.0f} %; {s['n_surface']:.0f} contacts cross a cut on median), "
            f"and σe from the vertical cut's by {100 * s['vertical']:.0f} % ({100 * s['vertical_q90']:.0f} %; "
            f"{s['n_vertical']:.0f} contacts). A cut samples a few contacts; the window averages over all its grains.")


def reciprocity_text(ms):
    """The two observations, each from its own cuts, and how far their equivalence holds window by window."""
    h = CLAIM_HISTORY
    dev = of_history(ms, "vertical_deviation", h)
    ang = of_history(ms, "angle_to_vertical", h)
    a, b = of_history(ms, "reciprocity_vertical", h), of_history(ms, "reciprocity_surface", h)
    corr, _ = observation_correlation(ms, h)
    return (f"On the point-source piles the two observations, each read from its own cut: the vertical cut's "
            f"resultant deviates from the flank slope by {nan_stat(np.nanmedian, dev):+.1f}° on median (half between "
            f"{nan_stat(np.nanquantile, dev, 0.25):+.1f}° and {nan_stat(np.nanquantile, dev, 0.75):+.1f}°), the "
            f"surface-parallel cut's from the vertical by {nan_stat(np.nanmedian, ang):+.1f}° (half between "
            f"{nan_stat(np.nanquantile, ang, 0.25):+.1f}° and {nan_stat(np.nanquantile, ang, 0.75):+.1f}°). From the window "
            f"stress, the two sides n_s·σe/p and e·σn_s/p are {nan_stat(np.nanmedian, np.abs(a)):.3f} and "
            f"{nan_stat(np.nanmedian, np.abs(b)):.3f} in magnitude on median and equal window by window (panel e, on the "
            f"diagonal); from the "
            f"cuts' own sums they scatter about it (correlation {corr:.2f}). The formula holds exactly for the "
            f"averaged stress; the single cuts obey it only up to their sampling of a few contacts.")


def failure_text(ms, tilt=None):
    """tau / sigma_n against tan(flank) and tan(phi) of the most loaded plane, and the principal
    directions against those of a slope at the limit (Mohr circle touching tan(phi) on the
    surface-parallel planes: the major direction leans towards the axis by 45° - phi/2), phi the
    tilting test's failure angle when ``tilt`` is given, else the flank slope θ standing for it."""
    f = failure_numbers(ms)
    s = ms.sel(history=CLAIM_HISTORY)
    pos = [(float(q), float(s.major_by_position[j])) for j, q in enumerate(ms.position.values)
           if np.isfinite(s.major_by_position[j])]
    theta = flank_slope(ms)
    n = tilt_numbers(tilt) if tilt is not None and CLAIM_HISTORY in tilt.history.values else None
    measured = n is not None and np.isfinite(n["theta_fail"])
    phi = n["theta_fail"] if measured else theta
    close = f["share"] >= 0.9
    text = (f"On the point-source piles τ/σ_n on the surface-parallel planes is {f['mobilized']:.3f} on median; "
            f"their flanks slope at θ = {theta:.1f}° on median (tan θ = {np.tan(np.radians(theta)):.3f}), and "
            f"window by window τ/σ_n is {f['ratio']:.2f} tan θ on median ({f['lo']:.2f} to {f['hi']:.2f}). It "
            f"equals tan θ exactly when the force across the plane is vertical (a slab carrying its weight): the "
            f"same statement as the first claim, read as a stress state. The most loaded plane of the same windows "
            f"mobilizes tan φ_σ = {f['tan_phi']:.3f} on median, so the surface-parallel plane carries {f['share']:.2f} "
            f"of it: "
            + ("it is close to the most loaded plane, as in a bank at incipient failure, whose failure planes are "
               "parallel to the surface. " if close else "it is not the most loaded plane. "))
    if measured:
        tan_phi = np.tan(np.radians(phi))
        text += (f"The tilting test measures the grains' friction angle φ = {phi:.1f}° (tan φ = {tan_phi:.3f}): the "
                 f"surface-parallel planes mobilize {f['mobilized'] / tan_phi:.2f} of it and the most loaded plane "
                 f"{f['tan_phi'] / tan_phi:.2f}. ")
    else:
        text += ("The packing's macroscopic friction is not measured in this run (no tilting test); the angle of "
                 "repose θ stands for it, as in the Civil-Engineering reading. ")
    return text + (f"In a slope at that limit the major principal direction leans towards the axis by 45° − φ/2 = "
                   f"{45 - phi / 2:.1f}° from the vertical; measured (leaning outward positive), medians over the "
                   f"piles by position |x|/L: {_fmt_list(pos)}.")


def tilt_text(tilt, ms=None):
    """The tilting test: per flank the failure tilt, against the slope the pile was left at."""
    if tilt is None or CLAIM_HISTORY not in tilt.history.values:
        return "No tilting test in this run."
    n = tilt_numbers(tilt)
    t = tilt.attrs
    lines = [f"Gravity is turned towards one flank by {n['step']:g}° at a time; each tilt is held at least "
             f"{float(t['hold']):g} √(d/g) and then until every grain is back below the construction's rest speed "
             f"(at most {float(t['max_hold']):g} √(d/g)), with the construction's time step and solver settings, "
             f"warm-started from the history forces. A flank fails when {int(t['grains'])} grains of its side have "
             f"moved more than {float(t['displaced_d']):g} d since the start. The {n['flanks']} flanks of the "
             f"{n['piles']} point-source piles tilted (slope θ {n['theta']:.1f}° on median) fail after "
             f"{n['margin']:.1f}° on median, single flanks from {n['alpha_min']:.1f}° to {n['alpha_max']:.1f}°: "
             f"their failure angles θ + α_fail run from {n['theta_fail_lo']:.1f}° to {n['theta_fail_hi']:.1f}° "
             f"({n['theta_fail']:.1f}° on median)."]
    for name in tilt.pile.values[tilt.pile_history.values == "default"]:
        d = tilt.sel(pile=name)
        lines.append("The default pile: " + "; ".join(
            f"{f} flank θ = {float(d.theta.sel(flank=f)):.1f}°, "
            + (f"fails at α = {float(d.alpha_fail.sel(flank=f)):.1f}° (θ + α = {float(d.theta_fail.sel(flank=f)):.1f}°)"
               if int(d.failed.sel(flank=f)) else f"no failure up to {n['max_deg']:g}°")
            for f in d.flank.values) + ".")
    near = int(np.sum(np.where(np.isfinite(tilt.alpha_fail.values[tilt.pile_history.values == CLAIM_HISTORY]),
                               tilt.alpha_fail.values[tilt.pile_history.values == CLAIM_HISTORY], np.inf)
                      <= n["threshold"]))
    lines.append(f"{near} of the {n['flanks']} point-source flanks fail within {n['threshold']:g}° of their slope.")
    return " ".join(lines)


def three_d_text(ms):
    """Where the 2-D measurement speaks for Moreau's 3-D piles (conic and cylindric cuts) and where not."""
    theta = flank_slope(ms)
    return (
        "**Can.** The reciprocity formula is an identity of a symmetric tensor and holds in any dimension: with "
        "e_r the normal of a cylindric cut coaxial to the pile and n_s the normal of a conic cut parallel to the "
        "surface, n_s·σe_r = e_r·σn_s in 3-D as here. The symmetry itself is the moment balance of every grain, "
        "which the Love–Weber average inherits exactly at any equilibrium, in 2-D or 3-D. That a surface-parallel "
        "cut carries the weight of the column above it (a slab carrying its weight, τ/σ_n = tan θ) is the balance "
        "of an infinite slope, which a 3-D flank obeys as well far from the axis and the toe.\n\n"
        "**Cannot.** A 2-D pile of discs is a plane wedge: it has no hoop stress σ_θθ, which in an axisymmetric "
        "3-D pile enters the radial balance and changes how the weight is shared between the core and the bank; "
        "a cylindric cut near the axis encloses less material than a vertical cut through a wedge. The flanks of "
        f"the point-source disc piles slope at {theta:.1f}° on median (over piles and flanks); the angle of repose "
        "and the contact network of discs "
        "differ from those of spheres. The numbers of this page (the spread of the angles, "
        "the share of the available friction the bank mobilizes, the principal directions) are those of 2-D disc "
        "piles; only the identities (reciprocity, the weight of a column, the symmetry at equilibrium) carry over "
        "to Moreau's conic and cylindric cuts unchanged.")


# the sentences of the paper's claims table (ncd/pages/paper_claims.yaml) these functions judge
