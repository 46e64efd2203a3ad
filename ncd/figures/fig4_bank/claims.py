"""The claims of the end of section 5 (Moreau 2005) on the bank of the piles, as verdicts.

Each function reads ``results/fig4_bank`` and returns a :class:`ncd.shared.verdict.Verdict`
(the number measured, the verdict, the criterion over cuts and piles, the page section
holding the evidence); the figure's page prints the same objects.  Moreau's piles are
poured from a localized source: the claims are judged on the point-source piles of
``fig4_history`` (bootstrap bands over piles), the default pile of ``fig4_pile`` quoted
beside them; the rained heaps of the same shape and the layers are reported on the page only.
"""
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ncd.shared.verdict import CONSISTENT, DIFFERS, NOT_COMPUTED, REPRODUCED, Verdict
from ncd.shared.verdict import anchor as claim_anchor

MEASURES = "fig4_bank/measures.nc"
EXACT = "fig4_bank/exact"
TILT = "fig4_bank/tilt.nc"
CLAIM_HISTORY = "point"
ASYMMETRY_TOL = 1e-6     # |sigma_xy - sigma_yx| / p allowed of an equilibrium solved to 1e-10 or an LP vertex


def nan_stat(stat, a, *args, **kw):
    """``stat`` of ``a`` as a float, NaN (no warning) where ``a`` holds no number."""
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
    return dict(piles=len(exact), cuts=int(ok.sum()), width_median=nan_stat(np.median, width) if ok.any() else np.nan,
                width_max=float(width.max()) if ok.any() else np.nan, lo=lo[ok], hi=hi[ok],
                vertex_asymmetry=nan_stat(np.nanmax, asym) if np.isfinite(asym).any() else np.nan,
                history_outside=nan_stat(np.nanmax, out) if np.isfinite(out).any() else np.nan)


def flank_slope(ms, history=CLAIM_HISTORY):
    """θ of ``history``'s piles: the median over piles and both flanks of each pile's fitted flank
    slope (its fit by :func:`ncd.shared.pile.free_surface`, the one every page reads for that
    pile; fig4_history quotes the same median for its point-source piles)."""
    return nan_stat(np.nanmedian, ms.surface_angle.values[ms.pile_history.values == history])


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
               q25=nan_stat(np.nanquantile, ang, 0.25), q75=nan_stat(np.nanquantile, ang, 0.75), by_depth=by_depth,
               load=float(s["carried"]), load_lo=float(s["carried_lo"]), load_hi=float(s["carried_hi"]), tol=float(ms.attrs["vertical_tol_deg"]),
               level=float(ms.attrs["level"]),
               theta=flank_slope(ms, h))
    if "default" in ms.history.values:
        d = of_history(ms, "angle_to_vertical", "default")
        out.update(default=float(ms.angle.sel(history="default")), default_cuts=int(np.isfinite(d).sum()))
    return out


def claim_surface_force_vertical(results):
    """"In the latter case [cuts parallel to the free surface], the transmitted force is found vertical"."""
    ms, exact = load(results)
    anchor = claim_anchor("s5-surface-parallel-vertical")
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
                   f"pooled and at every depth (the plane's normal, the direction of a force without shear, lies the "
                   f"flank slope θ from the vertical, {v['theta']:.1f}° on median over the piles' flanks)", anchor, files)


def observation_correlation(ms, history=CLAIM_HISTORY):
    """``(r, n)``: the correlation over the windows of ``history``'s piles of the two observations
    each read from its own cut (the normal-to-surface component of the vertical cut's resultant,
    the horizontal component of the surface-parallel cut's, both per unit length over p), and
    the number of windows where both are measured."""
    a, b = of_history(ms, "direct_vertical", history).ravel(), of_history(ms, "direct_surface", history).ravel()
    ok = np.isfinite(a) & np.isfinite(b)
    if ok.sum() < 3 or np.std(a[ok]) == 0 or np.std(b[ok]) == 0:
        return np.nan, int(ok.sum())
    return float(np.corrcoef(a[ok], b[ok])[0, 1]), int(ok.sum())


def reciprocity_numbers(ms, exact=None):
    """Asymmetry, the two sides from the stress and from the cuts' own sums, over every window of every pile,
    and the correlation of the two observations from the cuts' own sums (point-source piles)."""
    ok = np.isfinite(ms.asymmetry.values)
    asym = np.abs(ms.asymmetry.values[ok])
    a, b = ms.reciprocity_vertical.values[ok], ms.reciprocity_surface.values[ok]
    da, db = ms.direct_vertical.values[ok], ms.direct_surface.values[ok]
    e = exact_summary(exact or {})
    corr, n_corr = observation_correlation(ms) if CLAIM_HISTORY in ms.pile_history.values else (np.nan, 0)
    return dict(windows=int(ok.sum()), piles=int(ms.sizes["pile"]), asym_max=float(asym.max()),
                gap_max=float(np.abs(a - b).max()), side_median=float(np.median(np.abs(a))),
                direct_gap=float(np.median(np.abs(da - db))), direct_v=float(np.median(np.abs(da - a))),
                direct_s=float(np.median(np.abs(db - b))), corr=corr, corr_windows=n_corr,
                vertex_asymmetry=e["vertex_asymmetry"] if e is not None else np.nan)


def claim_reciprocity(results):
    """"These two observations are mathematically equivalent thanks to a reciprocity formula ensuing
    from the symmetry of the Cauchy stress": the formula is the symmetry of the stress, i.e. the
    moment balance of every grain, a premise of any equilibrium (consistent, illustrated window
    by window); the two observations themselves, read from the cuts' own resultants, are
    reported with their correlation."""
    ms, exact = load(results)
    anchor = claim_anchor("s5-reciprocity")
    if ms is None:
        return _missing(anchor, "The stress windows")
    r = reciprocity_numbers(ms, exact)
    text = (f"Over {r['windows']} windows of {r['piles']} piles the Love–Weber stress is symmetric to "
            f"{r['asym_max']:.1e} of the mean pressure p, so both sides n_s·σe_x and e_x·σn_s agree window by window "
            f"to {r['gap_max']:.1e} p (each side {r['side_median']:.2f} p on median)")
    if np.isfinite(r["vertex_asymmetry"]):
        text += f"; at the LP vertices of A ∩ C to {r['vertex_asymmetry']:.0e} p"
    text += (f". Read from the cuts' own resultants, the two observations correlate at {r['corr']:.2f} over the "
             f"{r['corr_windows']} windows of the point-source piles and differ by {r['direct_gap']:.2f} p on median "
             f"(the vertical cut departs from σ by {r['direct_v']:.2f} p, the surface-parallel cut by "
             f"{r['direct_s']:.2f} p): the equivalence is one of the averaged stress, not of single cuts.")
    files = (MEASURES,) + tuple(f"{EXACT}/{p}.nc" for p in exact)
    return Verdict(text, CONSISTENT,
                   "the reciprocity formula n_s·σe = e·σn_s is the symmetry of σ, i.e. the moment balance of every "
                   "grain: it holds by construction at any equilibrium (a correct premise, not an observation), "
                   "illustrated by both sides window by window; the two cut observations are reported, not judged",
                   anchor, files)


def failure_numbers(ms):
    """tau / sigma_n on the surface-parallel planes against tan(flank) and tan phi (point-source piles)."""
    h = CLAIM_HISTORY
    s = ms.sel(history=h)
    ratio = of_history(ms, "mobilized", h) / of_history(ms, "tan_flank", h)
    out = dict(piles=int((ms.pile_history.values == h).sum()), windows=int(np.isfinite(ratio).sum()),
               ratio=float(s.failure), lo=float(s.failure_lo), hi=float(s.failure_hi),
               direct=float(s.direct_failure), share=float(s.friction_share), tan_phi=float(s["most_loaded"]),
               tan_flank=nan_stat(np.nanmedian, of_history(ms, "tan_flank", h)),
               mobilized=nan_stat(np.nanmedian, of_history(ms, "mobilized", h)),
               major=float(s.major), tol=float(ms.attrs["failure_tol"]), level=float(ms.attrs["level"]))
    if "default" in ms.history.values:
        out["default"] = float(ms.failure.sel(history="default"))
    return out


def load_tilt(results):
    """tilt.nc under ``results``, or None when absent."""
    path = Path(results) / TILT
    return xr.load_dataset(path) if path.exists() else None


def tilt_numbers(tilt, history=CLAIM_HISTORY):
    """The tilting test of ``history``'s piles: flanks, failure tilts (a flank without failure at
    ``max_deg + step_deg``), their median and band over piles, the failure angles and slopes,
    the threshold ``step_deg + hysteresis_deg``."""
    sel = tilt.pile_history.values == history
    fail = tilt.alpha_fail.values[sel]
    cens = np.where(np.isfinite(fail), fail, tilt.attrs["max_deg"] + tilt.attrs["step_deg"])
    out = dict(piles=int(sel.sum()), flanks=int(fail.size), failed=int(np.isfinite(fail).sum()),
               margin=float(tilt.margin.sel(history=history)), lo=float(tilt.margin_lo.sel(history=history)),
               hi=float(tilt.margin_hi.sel(history=history)), alpha_min=float(cens.min()), alpha_max=float(cens.max()),
               theta=float(np.median(tilt.theta.values[sel])),
               theta_fail=nan_stat(np.nanmedian, tilt.theta_fail.values[sel]),
               theta_fail_lo=nan_stat(np.nanmin, tilt.theta_fail.values[sel]),
               theta_fail_hi=nan_stat(np.nanmax, tilt.theta_fail.values[sel]),
               step=float(tilt.attrs["step_deg"]), hysteresis=float(tilt.attrs["hysteresis_deg"]),
               max_deg=float(tilt.attrs["max_deg"]), level=float(tilt.attrs["level"]))
    out["threshold"] = out["step"] + out["hysteresis"]
    # the upper end judged: the band over piles, or with one pile its larger flank
    out["upper"] = out["hi"] if np.isfinite(out["hi"]) else out["alpha_max"]
    return out


def claim_incipient_failure(results):
    """"... amounting to the assertion, commonly made in Civil Engineering, that the peripheral bank
    lies in a state of incipient failure": the bank stands at the friction angle of its grains.
    That angle is measured by tilting the piles (:mod:`ncd.figures.fig4_bank.tilt`): gravity
    turned towards a flank in steps until the flank fails; its margin ``alpha_fail`` is how far
    the bank stands below failure.  Judged on the point-source piles (both flanks, bootstrap
    band over piles of the median margin): at incipient failure the margin is within the tilt
    step plus the hysteresis between the angle of repose a pile is left at and its maximum
    angle of stability (about 2° for spheres, Jaeger, Liu & Nagel, PRL 62, 40, 1989): a poured
    bank stops at the former and fails at the latter.  The stress state is quoted beside it, not
    judged: tau / sigma_n on the surface-parallel planes against the measured tan phi (it is
    tan(theta + psi), psi the vertical-force row's angle, so only the tilt adds a number)."""
    ms, _ = load(results)
    tilt = load_tilt(results)
    anchor = claim_anchor("s5-incipient-failure")
    if tilt is None or CLAIM_HISTORY not in tilt.history.values:
        return Verdict(f"The tilting test not computed in this run (no {TILT}).", NOT_COMPUTED, "", anchor, (TILT,))
    n = tilt_numbers(tilt)
    ok = n["upper"] <= n["threshold"]
    text = (f"Tilted flank by flank, the {n['flanks']} flanks of {n['piles']} point-source piles (slope θ "
            f"{n['theta']:.1f}° on median) fail after a tilt α_fail of {n['margin']:.1f}° on median "
            + (f"({100 * n['level']:g} % band over piles {n['lo']:.1f}° to {n['hi']:.1f}°; " if np.isfinite(n['hi'])
               else "(")
            + f"single flanks {n['alpha_min']:.1f}° to {n['alpha_max']:.1f}°"
            + (f", {n['flanks'] - n['failed']} without failure up to {n['max_deg']:g}°" if n["failed"] < n["flanks"]
               else "")
            + f"): the measured friction angle φ = θ + α_fail is {n['theta_fail']:.1f}° on median "
            f"({n['theta_fail_lo']:.1f}° to {n['theta_fail_hi']:.1f}°)")
    if "default" in tilt.history.values:
        d = tilt.sel(pile=tilt.pile.values[tilt.pile_history.values == "default"][0])
        text += "; default pile " + ", ".join(
            f"{f} {float(d.alpha_fail.sel(flank=f)):.1f}°" if int(d.failed.sel(flank=f)) else f"{f} > {n['max_deg']:g}°"
            for f in d.flank.values)
    files = (TILT,)
    if ms is not None and CLAIM_HISTORY in ms.history.values and np.isfinite(n["theta_fail"]):
        f = failure_numbers(ms)
        tan_fail = float(np.tan(np.radians(n["theta_fail"])))
        text += (f". Beside it (not judged): τ/σ_n on the surface-parallel planes is {f['mobilized']:.3f} on median, "
                 f"{f['mobilized'] / tan_fail:.2f} of the measured tan φ = {tan_fail:.3f} ({f['ratio']:.2f} tan θ); the "
                 f"most loaded plane of the same windows mobilizes {f['tan_phi']:.3f}, {f['tan_phi'] / tan_fail:.2f} of "
                 f"it, and the surface-parallel plane {f['share']:.2f} of the most loaded one; the major principal "
                 f"direction lies {f['major']:+.1f}° from the vertical (a slope at failure: "
                 f"{-(45 - n['theta_fail'] / 2):+.1f}°)")
        files = (TILT, MEASURES)
    return Verdict(text, REPRODUCED if ok else DIFFERS,
                   f"over the tested flanks of the point-source piles: the upper end of the {100 * n['level']:g} % "
                   f"bootstrap band over piles of the median tilt α_fail that makes a flank fail is at most "
                   f"{n['threshold']:g}° (the tilt step {n['step']:g}° plus the hysteresis of about "
                   f"{n['hysteresis']:g}° between the angle of repose and the maximum angle of stability, Jaeger, Liu & "
                   f"Nagel 1989); failure: at least {int(tilt.attrs['grains'])} grains of the tilted side moved more "
                   f"than {float(tilt.attrs['displaced_d']):g} d", anchor, files)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {"s5-surface-parallel-vertical": (claim_surface_force_vertical,),
          "s5-reciprocity": (claim_reciprocity,),
          "s5-incipient-failure": (claim_incipient_failure,)}
