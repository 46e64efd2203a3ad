"""The claims of the end of section 5 (Moreau 2005) on the bank of the piles, as verdicts.

Each function reads ``results/fig4_bank`` and returns a :class:`ncd.shared.verdict.Verdict`
(the number measured, the verdict, the criterion over cuts and piles, the page section
holding the evidence); the figure's page prints the same objects.  Moreau's piles are
poured from a localized source: the claims are judged on the point-source piles of
``fig4_history`` (bootstrap bands over piles), the default pile of ``fig4_pile`` quoted
beside them; the rained deposits are reported on the page only.
"""
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ncd.shared.verdict import DIFFERS, NOT_COMPUTED, REPRODUCED, Verdict

MEASURES = "fig4_bank/measures.nc"
EXACT = "fig4_bank/exact"
CLAIM_HISTORY = "point"
ASYMMETRY_TOL = 1e-6     # |sigma_xy - sigma_yx| / p allowed of an equilibrium solved to 1e-10 or an LP vertex
ANCHORS = {"vertical": "surface-parallel-cuts", "reciprocity": "reciprocity", "failure": "incipient-failure"}


def _nan(stat, a, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return float(stat(a, *args, **kw))


def load(results):
    """``(measures, {pile: exact dataset})`` under ``results``, or ``(None, {})`` when absent."""
    results = Path(results)
    if not (results / MEASURES).exists():
        return None, {}
    ms = xr.load_dataset(results / MEASURES)
    exact = {p.stem: xr.load_dataset(p) for p in sorted((results / EXACT).glob("*.nc"))}
    return ms, exact


def _missing(anchor, what):
    return Verdict(f"{what} not computed in this run (no {MEASURES}).", NOT_COMPUTED, "", anchor, (MEASURES,))


def of_history(ms, name, history):
    """Values of variable ``name`` over the piles of ``history`` (pile, flank, position, depth)."""
    return ms[name].values[ms.pile_history.values == history]


def exact_summary(exact):
    """Over the exact files: cuts with a range, median and largest width of the range of the
    angle to the vertical, the share of cuts whose whole range lies within ``tol`` of the
    vertical, the largest history excursion and LP-vertex asymmetry."""
    if not exact:
        return None
    lo = np.concatenate([e.angle_min.values.ravel() for e in exact.values()])
    hi = np.concatenate([e.angle_max.values.ravel() for e in exact.values()])
    ok = np.isfinite(lo)
    width = hi[ok] - lo[ok]
    asym = np.concatenate([e.vertex_asymmetry.values.ravel() for e in exact.values()])
    out = np.concatenate([e.history_outside.values.ravel() for e in exact.values()])
    return dict(piles=len(exact), cuts=int(ok.sum()), width_median=_nan(np.median, width) if ok.any() else np.nan,
                width_max=float(width.max()) if ok.any() else np.nan, lo=lo[ok], hi=hi[ok],
                vertex_asymmetry=_nan(np.nanmax, asym) if np.isfinite(asym).any() else np.nan,
                history_outside=_nan(np.nanmax, out) if np.isfinite(out).any() else np.nan)


def vertical_numbers(ms):
    """The numbers of the first claim (point-source piles, and the default pile)."""
    h = CLAIM_HISTORY
    ang = of_history(ms, "angle_to_vertical", h)
    s = ms.sel(history=h)
    depths = ms.depth.values
    by_depth = [(float(dd), float(s.angle_by_depth[k]), float(s.angle_by_depth_lo[k]), float(s.angle_by_depth_hi[k]))
                for k, dd in enumerate(depths) if np.isfinite(s.angle_by_depth_lo[k])]
    out = dict(piles=int((ms.pile_history.values == h).sum()), cuts=int(np.isfinite(ang).sum()),
               median=float(s.angle), lo=float(s.angle_lo), hi=float(s.angle_hi),
               q25=_nan(np.nanquantile, ang, 0.25), q75=_nan(np.nanquantile, ang, 0.75), by_depth=by_depth,
               load=float(s["carried"]), load_lo=float(s["carried_lo"]), load_hi=float(s["carried_hi"]), tol=float(ms.attrs["vertical_tol_deg"]),
               level=float(ms.attrs["level"]))
    if "default" in ms.history.values:
        d = of_history(ms, "angle_to_vertical", "default")
        out.update(default=float(ms.angle.sel(history="default")), default_cuts=int(np.isfinite(d).sum()))
    return out


def claim_surface_force_vertical(results):
    """"In the latter case [cuts parallel to the free surface], the transmitted force is found vertical"."""
    ms, exact = load(results)
    anchor = ANCHORS["vertical"]
    if ms is None or CLAIM_HISTORY not in ms.history.values:
        return _missing(anchor, "Surface-parallel cuts")
    v = vertical_numbers(ms)
    tol = v["tol"]
    bands = [(lo, hi) for _, _, lo, hi in v["by_depth"]] + [(v["lo"], v["hi"])]
    ok = all(np.isfinite(lo) and -tol <= lo and hi <= tol for lo, hi in bands)
    worst = max(max(abs(lo), abs(hi)) for lo, hi in bands)
    text = (f"Across {v['cuts']} surface-parallel cuts of {v['piles']} point-source piles the resultant leans "
            f"{v['median']:+.1f}° from the vertical on median ({100 * v['level']:g} % band over piles {v['lo']:+.1f}° "
            f"to {v['hi']:+.1f}°; half of the single cuts between {v['q25']:+.1f}° and {v['q75']:+.1f}°), every "
            f"depth's band within {worst:.1f}° of the vertical; it carries {v['load']:.2f} times the weight of the "
            f"column above it.")
    if "default" in v:
        text += f" Default pile: {v['default']:+.1f}° over {v['default_cuts']} cuts."
    e = exact_summary(exact)
    if e is not None and e["cuts"]:
        forced = float(np.mean((e["lo"] >= -tol) & (e["hi"] <= tol)))
        text += (f" Over A ∩ C ({e['piles']} piles, {e['cuts']} cuts) the admissible angle spans {e['width_median']:.0f}° "
                 f"on median and every admissible state is within ±{tol:g}° of the vertical at {100 * forced:.0f} % "
                 f"of the cuts.")
    files = (MEASURES,) + tuple(f"{EXACT}/{p}.nc" for p in exact)
    return Verdict(text, REPRODUCED if ok else DIFFERS,
                   f"over cuts and piles: the {100 * v['level']:g} % bootstrap band over the point-source piles of the "
                   f"median angle between the surface-parallel cut resultant and the vertical lies within ±{tol:g}°, "
                   f"pooled and at every depth", anchor, files)


def reciprocity_numbers(ms, exact=None):
    """Asymmetry, the two sides from the stress and from the cuts' own sums, over every window of every pile."""
    ok = np.isfinite(ms.asymmetry.values)
    asym = np.abs(ms.asymmetry.values[ok])
    a, b = ms.reciprocity_vertical.values[ok], ms.reciprocity_surface.values[ok]
    da, db = ms.direct_vertical.values[ok], ms.direct_surface.values[ok]
    e = exact_summary(exact or {})
    return dict(windows=int(ok.sum()), piles=int(ms.sizes["pile"]), asym_max=float(asym.max()),
                gap_max=float(np.abs(a - b).max()), side_median=float(np.median(np.abs(a))),
                direct_gap=float(np.median(np.abs(da - db))), direct_v=float(np.median(np.abs(da - a))),
                direct_s=float(np.median(np.abs(db - b))),
                vertex_asymmetry=e["vertex_asymmetry"] if e is not None else np.nan)


def claim_reciprocity(results):
    """"These two observations are mathematically equivalent thanks to a reciprocity formula ensuing
    from the symmetry of the Cauchy stress"."""
    ms, exact = load(results)
    anchor = ANCHORS["reciprocity"]
    if ms is None:
        return _missing(anchor, "The stress windows")
    r = reciprocity_numbers(ms, exact)
    vertex_ok = not np.isfinite(r["vertex_asymmetry"]) or r["vertex_asymmetry"] <= ASYMMETRY_TOL
    ok = r["asym_max"] <= ASYMMETRY_TOL and vertex_ok
    text = (f"Over {r['windows']} windows of {r['piles']} piles the Love–Weber stress is symmetric to "
            f"{r['asym_max']:.1e} of the mean pressure p, so n_s·σe_x and e_x·σn_s agree to {r['gap_max']:.1e} p "
            f"(each side {r['side_median']:.2f} p on median)")
    if np.isfinite(r["vertex_asymmetry"]):
        text += f"; at the LP vertices of A ∩ C to {r['vertex_asymmetry']:.0e} p"
    text += (f". The cuts' own sums agree only to {r['direct_gap']:.2f} p on median: window averaging (the vertical "
             f"cut departs from σ by {r['direct_v']:.2f} p, the surface-parallel cut by {r['direct_s']:.2f} p).")
    files = (MEASURES,) + tuple(f"{EXACT}/{p}.nc" for p in exact)
    return Verdict(text, REPRODUCED if ok else DIFFERS,
                   f"window by window over all piles: the two sides of n_s·σe_x = e_x·σn_s from the Love–Weber "
                   f"stress agree within {ASYMMETRY_TOL:g} p (σ symmetric), for the history forces and at the LP "
                   f"vertices of A ∩ C", anchor, files)


def failure_numbers(ms):
    """tau / sigma_n on the surface-parallel planes against tan(flank) and tan phi (point-source piles)."""
    h = CLAIM_HISTORY
    s = ms.sel(history=h)
    ratio = of_history(ms, "mobilized", h) / of_history(ms, "tan_flank", h)
    out = dict(piles=int((ms.pile_history.values == h).sum()), windows=int(np.isfinite(ratio).sum()),
               ratio=float(s.failure), lo=float(s.failure_lo), hi=float(s.failure_hi),
               direct=float(s.direct_failure), share=float(s.friction_share), tan_phi=float(s["most_loaded"]),
               tan_flank=_nan(np.nanmedian, of_history(ms, "tan_flank", h)),
               mobilized=_nan(np.nanmedian, of_history(ms, "mobilized", h)),
               major=float(s.major), tol=float(ms.attrs["failure_tol"]), level=float(ms.attrs["level"]))
    if "default" in ms.history.values:
        out["default"] = float(ms.failure.sel(history="default"))
    return out


def claim_incipient_failure(results):
    """"... amounting to the assertion, commonly made in Civil Engineering, that the peripheral bank
    lies in a state of incipient failure"."""
    ms, _ = load(results)
    anchor = ANCHORS["failure"]
    if ms is None or CLAIM_HISTORY not in ms.history.values:
        return _missing(anchor, "The stress windows")
    f = failure_numbers(ms)
    tol = f["tol"]
    ok = np.isfinite(f["lo"]) and 1 - tol <= f["lo"] and f["hi"] <= 1 + tol
    text = (f"On planes parallel to the surface τ/σ_n = {f['ratio']:.2f} tan θ on median over {f['windows']} "
            f"windows of {f['piles']} point-source piles ({100 * f['level']:g} % band over piles {f['lo']:.2f} to "
            f"{f['hi']:.2f}; from the cuts' own resultants {f['direct']:.2f})")
    if "default" in f:
        text += f", default pile {f['default']:.2f}"
    text += (f"; that is {f['share']:.2f} of the friction tan φ = {f['tan_phi']:.2f} mobilized on the most loaded "
             f"plane of the same windows.")
    return Verdict(text, REPRODUCED if ok else DIFFERS,
                   f"over windows and piles: the {100 * f['level']:g} % bootstrap band over the point-source piles "
                   f"of the median of τ/σ_n on the surface-parallel plane over tan θ (θ the fitted flank angle, the "
                   f"angle of repose) lies within 1 ± {tol:g}", anchor, (MEASURES,))


# ---------------------------------------------------------------- the page's sentences, from the data
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
        label = "The default pile" if h == "default" else "The rained deposits"
        lines.append(f"{label}: {float(ms.angle.sel(history=h)):+.1f}° on median over {int(np.isfinite(a).sum())} "
                     f"cuts (half between {_nan(np.nanquantile, a, 0.25):+.1f}° and "
                     f"{_nan(np.nanquantile, a, 0.75):+.1f}°), carrying {float(ms['carried'].sel(history=h)):.3f} "
                     f"times the column weight"
                     + (f"; their fitted flanks slope at only {_nan(np.nanmedian, of_history(ms, 'tan_flank', h)):.2f} "
                        "(tan), so their cuts are nearly horizontal." if h == "rain" else "."))
    return " ".join(lines)


def exact_load(ms, exact):
    """Median over the exact piles' cuts of the exact range of the downward force over the column weight."""
    widths = [(e.fy_max.values - e.fy_min.values) / ms.column_weight.sel(pile=name).values
              for name, e in exact.items() if name in ms.pile.values]
    return _nan(np.nanmedian, np.concatenate([w.ravel() for w in widths])) if widths else np.nan


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
    return dict(surface=_nan(np.nanmedian, es), surface_q90=_nan(np.nanquantile, es, 0.9),
                vertical=_nan(np.nanmedian, ev), vertical_q90=_nan(np.nanquantile, ev, 0.9),
                n_surface=_nan(np.nanmedian, ms.n_crossing.values), n_vertical=_nan(np.nanmedian, ms.vertical_n_crossing.values),
                grains=_nan(np.nanmedian, ms.n_window.values))


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
    da, db = of_history(ms, "direct_vertical", h), of_history(ms, "direct_surface", h)
    ok = np.isfinite(a)
    corr = float(np.corrcoef(da[ok & np.isfinite(da)], db[ok & np.isfinite(db)])[0, 1]) if ok.sum() > 2 else np.nan
    return (f"On the point-source piles the two observations, each read from its own cut: the vertical cut's "
            f"resultant deviates from the flank slope by {_nan(np.nanmedian, dev):+.1f}° on median (half between "
            f"{_nan(np.nanquantile, dev, 0.25):+.1f}° and {_nan(np.nanquantile, dev, 0.75):+.1f}°), the "
            f"surface-parallel cut's from the vertical by {_nan(np.nanmedian, ang):+.1f}° (half between "
            f"{_nan(np.nanquantile, ang, 0.25):+.1f}° and {_nan(np.nanquantile, ang, 0.75):+.1f}°). From the window "
            f"stress, the two sides n_s·σe/p and e·σn_s/p are {_nan(np.nanmedian, np.abs(a)):.3f} and "
            f"{_nan(np.nanmedian, np.abs(b)):.3f} in magnitude on median and equal window by window (panel e, on the "
            f"diagonal); from the "
            f"cuts' own sums they scatter about it (correlation {corr:.2f}). The formula holds exactly for the "
            f"averaged stress; the single cuts obey it only up to their sampling of a few contacts.")


def failure_text(ms):
    """tau / sigma_n against tan(flank) and tan(phi) of the most loaded plane, and the principal
    directions against those of a slope at the limit (Mohr circle touching tan(theta) on the
    surface-parallel planes: the major direction leans towards the axis by 45° - theta/2)."""
    f = failure_numbers(ms)
    s = ms.sel(history=CLAIM_HISTORY)
    pos = [(float(q), float(s.major_by_position[j])) for j, q in enumerate(ms.position.values)
           if np.isfinite(s.major_by_position[j])]
    theta = float(np.degrees(np.arctan(f["tan_flank"])))
    close = f["share"] >= 0.9
    return (f"On the point-source piles τ/σ_n on the surface-parallel planes is {f['mobilized']:.3f} on median "
            f"against tan θ = {f['tan_flank']:.3f} of the fitted flanks: the ratio is {f['ratio']:.2f} "
            f"({f['lo']:.2f} to {f['hi']:.2f}). It equals tan θ exactly when the force across the plane is vertical "
            f"(a slab carrying its weight): the same statement as the first claim, read as a stress state. The most "
            f"loaded plane of the same windows mobilizes tan φ = {f['tan_phi']:.3f} on median, so the "
            f"surface-parallel plane carries {f['share']:.2f} of it: "
            + ("it is close to the most loaded plane, as in a bank at incipient failure, whose failure planes are "
               "parallel to the surface. " if close else "it is not the most loaded plane. ")
            + "The packing's macroscopic friction is not measured here (no shear test); the angle of repose θ stands "
            f"for it, as in the Civil-Engineering reading. In a slope at that limit the major principal direction "
            f"leans towards the axis by 45° − θ/2 = {45 - theta / 2:.1f}° from the vertical; measured (leaning "
            f"outward positive), medians over the piles by position |x|/L: {_fmt_list(pos)}.")


def three_d_text(ms):
    """Where the 2-D measurement speaks for Moreau's 3-D piles (conic and cylindric cuts) and where not."""
    poured = [h for h in ("default", CLAIM_HISTORY) if h in ms.history.values]
    sel = np.isin(ms.pile_history.values, poured)
    theta = _nan(np.nanmedian, ms.surface_angle.values[sel])
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
        f"these disc piles slope at {theta:.1f}° on median; the angle of repose and the contact network of discs "
        "differ from those of spheres. The numbers of this page (the spread of the angles, "
        "the share of the available friction the bank mobilizes, the principal directions) are those of 2-D disc "
        "piles; only the identities (reciprocity, the weight of a column, the symmetry at equilibrium) carry over "
        "to Moreau's conic and cylindric cuts unchanged.")


# the sentences of the paper's claims table (ncd/pages/paper_claims.yaml) these functions judge
# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {"s5-surface-parallel-vertical": (claim_surface_force_vertical,),
          "s5-reciprocity": (claim_reciprocity,),
          "s5-incipient-failure": (claim_incipient_failure,)}
