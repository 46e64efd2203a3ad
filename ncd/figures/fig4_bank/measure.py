"""The peripheral bank of the piles of Figure 4 (Moreau 2005, end of section 5).

Moreau's 3-D piles: across cuts parallel to the free surface "the transmitted force is
found vertical", which amounts to the bank lying "in a state of incipient failure"; across
vertical cuts it is parallel to the surface; the two are "mathematically equivalent thanks
to a reciprocity formula ensuing from the symmetry of the Cauchy stress".  In 2-D every
piece is measured on the piles of ``fig4_pile`` (the default pile) and ``fig4_history``
(both histories), from their history forces: per flank, position ``|x| = q L`` and depth
below the free surface, the resultant across a segment parallel to the fitted flank
(:mod:`ncd.figures.fig4_bank.stress`), its angle to the vertical and the weight of the column above
it; the Love-Weber stress of a window covering that cut and a vertical cut through its
centre, the window's asymmetry, both sides of the reciprocity formula, the friction
mobilized on the surface-parallel plane and the principal directions.
"""
import warnings

import numpy as np
import xarray as xr

from ncd.figures.fig4_bank import stress as st
from ncd.shared import cuts as cm

FLANKS = (("left", -1), ("right", 1))
HISTORY_LABELS = {"default": "default pile (fig4_pile)", "point": "point source", "rain": "rain (same heap)",
                  "layer": "layer"}


def _nan(stat, a, *args, **kw):
    """A nan-aware statistic (cuts outside a pile are NaN), an all-NaN slice giving NaN silently."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return stat(a, *args, **kw)


# ---------------------------------------------------------------- geometry of one pile
def pile_geometry(ds, cuts=None):
    """``dict(y0, L, d, fits)`` of a pile: ground level (mean top of the ground discs), the
    half-width ``L`` of the positions ``|x| = q L`` (a history pile: the base half-width of
    its member's point-source pile, as in ``fig4_history``; the default pile: half its
    toe-to-toe width) and the flank fits, read from ``cuts.nc`` (the default pile) or the
    pile file's own attributes."""
    a = (cuts if cuts is not None else ds).attrs
    fits = {f: {q: float(a[f"{f}_{q}"]) for q in ("angle", "c0", "c1", "toe")} for f, _ in FLANKS}
    L = float(ds.attrs["point_half_width"]) if "point_half_width" in ds.attrs else \
        0.5 * (fits["right"]["toe"] - fits["left"]["toe"])
    return dict(y0=float(a["y_ground"]), L=L, d=float(a["mean_diameter"]), fits=fits)


def bank_cuts(cfg, geom, pos, radius):
    """The cuts of one pile, arrays over ``(flank, position, depth)``: the surface-parallel
    segment (centre at depth ``depth_d`` d along the flank's normal below the local free
    surface at ``|x| = q L``; the surface is the fitted flank shifted by the mean residual of
    the disc-top profile over the segment's span), its window (flank-aligned rectangle of the
    segment's length and thickness ``min(window_d d, 2 depth)``), the vertical cut through
    the centre (its chord in the window) and ``valid`` (window at least ``ground_margin_d``
    above the ground)."""
    d, y0 = geom["d"], geom["y0"]
    q = np.asarray(cfg["positions"], float)
    depths = np.asarray(cfg["depths_d"], float) * d
    half = 0.5 * cfg["length_d"] * d
    m = int(np.ceil((np.abs(pos[:, 0]).max() + d) / d))
    edges = np.arange(-m, m + 1) * d
    xs, top = 0.5 * (edges[1:] + edges[:-1]), cm.surface_profile(pos, radius, edges)
    shape = (2, len(q), len(depths))
    out = {k: np.full(shape, np.nan) for k in ("x", "y", "surface_y", "thickness", "vertical_half")}
    out["valid"] = np.zeros(shape, bool)
    segs, wins, verts = [], [], []
    for i, (name, outer) in enumerate(FLANKS):
        f = geom["fits"][name]
        t, n = st.flank_frame(f["angle"], outer)
        for j, qq in enumerate(q):
            x = outer * qq * geom["L"]
            span = np.abs(xs - x) <= half * abs(t[0])
            resid = _nan(np.nanmean, top[span] - y0 - (f["c0"] + f["c1"] * xs[span])) if span.any() else np.nan
            ys = y0 + f["c0"] + f["c1"] * x + (resid if np.isfinite(resid) else 0.0)
            for k, dep in enumerate(depths):
                seg = st.surface_parallel_segment((x, ys), f["angle"], outer, dep, 2 * half)
                thick = min(cfg["window_d"] * d, 2 * dep)
                win = st.rectangle(seg[0], t, half, 0.5 * thick)
                vhalf = st.chord(win, seg[0], (0.0, 1.0))
                vert = st.vertical_segment(seg[0][0], outer, seg[0][1] - vhalf, seg[0][1] + vhalf)
                low = st.rectangle_corners(win)[:, 1].min()
                out["valid"][i, j, k] = low >= y0 + cfg["ground_margin_d"] * d and np.isfinite(resid)
                for key, v in (("x", seg[0][0]), ("y", seg[0][1]), ("surface_y", ys), ("thickness", thick),
                               ("vertical_half", vhalf)):
                    out[key][i, j, k] = v
                segs.append(seg)
                wins.append(win)
                verts.append(vert)
    return out, segs, wins, verts


def measure_pile(cfg, ds, cuts=None):
    """The measures of one pile's history forces over its cuts (module docstring); arrays
    over ``(flank, position, depth)``, NaN where a cut is not valid."""
    geom = pile_geometry(ds, cuts)
    c, pos, r = st.contacts_from_dataset(ds)
    r = r.ravel()
    nm = ds.sizes["grain"]
    weight = float(ds.attrs["weight"])
    grain_weight = ds["mass"].values * weight / float(ds["mass"].values.sum())
    geo, segs, wins, verts = bank_cuts(cfg, geom, pos[:nm], ds["radius"].values)
    shape = geo["valid"].shape
    outer = np.broadcast_to(np.array([o for _, o in FLANKS])[:, None, None], shape).ravel()
    angle = np.broadcast_to(np.array([geom["fits"][f]["angle"] for f, _ in FLANKS])[:, None, None], shape).ravel()
    Ms, n_s = st.segment_matrix(c, pos, nm, segs)
    Mv, n_v = st.segment_matrix(c, pos, nm, verts)
    S, n_w = st.stress_matrix(c, pos, nm, wins)
    Fs, Fv = (Ms @ r).reshape(-1, 2), (Mv @ r).reshape(-1, 2)
    sig = st.as_tensors(S @ r)
    col = np.array([st.column_weight(pos[:nm], grain_weight, s) for s in segs])
    t, n = np.array([st.flank_frame(a, o) for a, o in zip(angle, outer)]).transpose(1, 0, 2)
    e = np.column_stack([outer, np.zeros_like(outer)]).astype(float)
    Ls = np.array([2 * s[2] for s in segs])
    Lv = np.array([2 * v[2] for v in verts])
    sig_n, tau = st.plane_stress(sig, n, t)
    A_side, B_side = st.reciprocity(sig, n, e)
    p = 0.5 * (sig[:, 0, 0] + sig[:, 1, 1])
    s1, s2, major, sin_phi = st.principal(sig)
    with np.errstate(invalid="ignore", divide="ignore"):
        res = dict(
            force_x=Fs[:, 0], force_y=Fs[:, 1], n_crossing=n_s.astype(float),
            angle_to_vertical=st.angle_to_vertical(Fs[:, 0], Fs[:, 1], outer),
            column_weight=col, load_ratio=-Fs[:, 1] / col,
            vertical_fx=Fv[:, 0], vertical_fy=Fv[:, 1], vertical_n_crossing=n_v.astype(float),
            vertical_deviation=cm.flank_angles(Fv[:, 0], Fv[:, 1], outer, angle)[1],
            sigma_xx=sig[:, 0, 0], sigma_xy=sig[:, 0, 1], sigma_yx=sig[:, 1, 0], sigma_yy=sig[:, 1, 1],
            n_window=n_w.astype(float), pressure=p, asymmetry=st.asymmetry(sig),
            traction_s_x=-(sig @ n[:, :, None])[:, 0, 0], traction_s_y=-(sig @ n[:, :, None])[:, 1, 0],
            direct_s_x=Fs[:, 0] / Ls, direct_s_y=Fs[:, 1] / Ls,
            traction_v_x=(sig @ e[:, :, None])[:, 0, 0], traction_v_y=(sig @ e[:, :, None])[:, 1, 0],
            direct_v_x=Fv[:, 0] / Lv, direct_v_y=Fv[:, 1] / Lv,
            reciprocity_vertical=A_side / p, reciprocity_surface=B_side / p,
            direct_vertical=np.einsum("ki,ki->k", n, Fv / Lv[:, None]) / p,
            direct_surface=-np.einsum("ki,ki->k", e, Fs / Ls[:, None]) / p,
            mobilized=tau / sig_n,
            direct_mobilized=np.einsum("ki,ki->k", t, Fs) / -np.einsum("ki,ki->k", n, Fs),
            tan_flank=np.tan(np.radians(angle)), tan_phi=np.tan(np.arcsin(np.clip(sin_phi, 0, 1))),
            major_from_vertical=outer * major, s1=s1, s2=s2)
    valid = geo["valid"].ravel() & (n_s > 0) & (n_w > 0)
    out = {k: np.where(valid, v, np.nan).reshape(shape) for k, v in res.items()}
    out.update({k: geo[k] for k in ("x", "y", "surface_y", "thickness", "vertical_half")})
    out["valid"] = valid.reshape(shape)
    out["surface_angle"] = np.array([geom["fits"][f]["angle"] for f, _ in FLANKS])
    out["L"], out["weight"], out["n_contacts"], out["d"] = geom["L"], weight, c.n, geom["d"]
    return out


# ---------------------------------------------------------------- the ensemble of piles
PER_CUT = {   # variable: (units, long_name) of the arrays of measure_pile over (pile, flank, position, depth)
    "x": ("m", "abscissa of the centre of the surface-parallel cut"),
    "y": ("m", "height of the centre of the surface-parallel cut"),
    "surface_y": ("m", "local free surface above the cut centre: the flank fit shifted by the mean residual of "
                  "the disc-top profile over the cut's span"),
    "thickness": ("m", "thickness (normal to the flank) of the Love-Weber window covering the cuts"),
    "vertical_half": ("m", "half-length of the vertical cut through the centre (its chord in the window)"),
    "force_x": ("N", "F_x of the resultant across the surface-parallel cut (grains above on grains below)"),
    "force_y": ("N", "F_y of the resultant across the surface-parallel cut (grains above on grains below)"),
    "n_crossing": ("1", "contacts crossing the surface-parallel cut"),
    "angle_to_vertical": ("degree", "angle of the surface-parallel cut resultant from the downward vertical, "
                          "positive leaning outward (downhill)"),
    "column_weight": ("N", "weight of the grains above the cut within the vertical strip over it"),
    "load_ratio": ("1", "downward component of the surface-parallel cut resultant / column_weight"),
    "vertical_fx": ("N", "F_x of the resultant across the vertical cut through the centre (inner grains on "
                    "the bank)"),
    "vertical_fy": ("N", "F_y of the resultant across the vertical cut through the centre"),
    "vertical_n_crossing": ("1", "contacts crossing the vertical cut"),
    "vertical_deviation": ("degree", "angle below the horizontal (outward) of the vertical cut resultant "
                           "minus the flank slope"),
    "sigma_xx": ("N m-1", "Love-Weber stress of the window, xx (2-D: force per unit length; compression "
                 "positive)"),
    "sigma_xy": ("N m-1", "Love-Weber stress of the window, xy: sum of f_x (arm n)_y / area"),
    "sigma_yx": ("N m-1", "Love-Weber stress of the window, yx: sum of f_y (arm n)_x / area"),
    "sigma_yy": ("N m-1", "Love-Weber stress of the window, yy"),
    "n_window": ("1", "grains with centres in the window"),
    "pressure": ("N m-1", "mean pressure p = (sigma_xx + sigma_yy) / 2 of the window"),
    "asymmetry": ("1", "(sigma_xy - sigma_yx) / p (zero when every grain of the window is in moment "
                  "equilibrium)"),
    "traction_s_x": ("N m-1", "-sigma n_s, x: the force per unit length across the surface-parallel cut "
                     "from the window's stress"),
    "traction_s_y": ("N m-1", "-sigma n_s, y"),
    "direct_s_x": ("N m-1", "resultant across the surface-parallel cut / its length, x"),
    "direct_s_y": ("N m-1", "resultant across the surface-parallel cut / its length, y"),
    "traction_v_x": ("N m-1", "sigma e: the force per unit length across the vertical cut from the "
                     "window's stress (e the outward horizontal), x"),
    "traction_v_y": ("N m-1", "sigma e, y"),
    "direct_v_x": ("N m-1", "resultant across the vertical cut / its length, x"),
    "direct_v_y": ("N m-1", "resultant across the vertical cut / its length, y"),
    "reciprocity_vertical": ("1", "n_s . sigma e / p: normal-to-surface component of the vertical cut's "
                             "force per unit length (0: parallel to the surface)"),
    "reciprocity_surface": ("1", "e . sigma n_s / p: minus the outward horizontal component of the "
                            "surface-parallel cut's force per unit length (0: vertical)"),
    "direct_vertical": ("1", "n_s . (vertical cut resultant / length) / p, from the contact forces"),
    "direct_surface": ("1", "-e . (surface-parallel cut resultant / length) / p, from the contact forces"),
    "mobilized": ("1", "tau / sigma_n on the surface-parallel plane from the window's stress (shear downhill)"),
    "direct_mobilized": ("1", "tau / sigma_n on the surface-parallel cut from its resultant"),
    "tan_flank": ("1", "tan of the fitted flank angle"),
    "tan_phi": ("1", "tan phi, sin phi = (s1 - s2) / (s1 + s2): the friction mobilized on the most loaded "
                "plane of the window"),
    "major_from_vertical": ("degree", "major principal stress direction from the vertical, positive leaning "
                            "outward"),
    "s1": ("N m-1", "major principal stress of the window (symmetric part)"),
    "s2": ("N m-1", "minor principal stress of the window (symmetric part)"),
}


def _band(values, idx, lo, hi):
    """``(median, lo, hi)`` of the median of ``values`` over piles and cuts with a percentile
    bootstrap over piles (``idx``: resampled pile indices; NaN band for one pile)."""
    v = values.reshape(values.shape[0], -1)
    est = _median(v)
    if values.shape[0] < 2:
        return est, np.nan, np.nan
    boot = _nan(np.nanmedian, v[idx].reshape(len(idx), -1), axis=1)
    return est, float(_nan(np.nanquantile, boot, lo)), float(_nan(np.nanquantile, boot, hi))


def _median(v):
    return float(_nan(np.nanmedian, v))


def bank_dataset(cfg, piles):
    """measures.nc from ``piles = [(name, history, measures of measure_pile)]``: every cut of
    every pile and, per history, medians over cuts and piles with percentile bootstrap bands
    over piles (against depth, against position, pooled)."""
    a = cfg["analysis"]
    names = [p[0] for p in piles]
    hist = np.array([p[1] for p in piles])
    m0 = piles[0][2]
    stack = {k: np.array([p[2][k] for p in piles]) for k in PER_CUT}
    stack["valid"] = np.array([p[2]["valid"] for p in piles])
    histories = [h for h in HISTORY_LABELS if h in hist]
    q = np.asarray(cfg["positions"], float)
    depths = np.asarray(cfg["depths_d"], float)
    lo, hi = 0.5 * (1 - a["level"]), 0.5 * (1 + a["level"])
    rng = np.random.default_rng(a["seed"])
    P, F, Q, D, H = "pile", "flank", "position", "depth", "history"
    data = {k: ((P, F, Q, D), stack[k], {"units": u, "long_name": ln}) for k, (u, ln) in PER_CUT.items()}
    data["valid"] = ((P, F, Q, D), stack["valid"].astype(np.int8),
                     {"units": "1", "long_name": "the cut and its window lie in the bank, above the ground margin"})
    data["pile_history"] = ((P,), hist, {"long_name": "construction history of the pile (default: fig4_pile)"})
    data["surface_angle"] = ((P, F), np.array([p[2]["surface_angle"] for p in piles]),
                             {"units": "degree", "long_name": "fitted flank angle"})
    data["half_width"] = ((P,), np.array([p[2]["L"] for p in piles]),
                          {"units": "m", "long_name": "L of the cut positions |x| = q L"})
    data["weight"] = ((P,), np.array([p[2]["weight"] for p in piles]), {"units": "N", "long_name": "pile weight"})
    ratio = stack["mobilized"] / stack["tan_flank"]
    direct_ratio = stack["direct_mobilized"] / stack["tan_flank"]
    friction_ratio = stack["mobilized"] / stack["tan_phi"]
    stats = {  # name: (values over (pile, flank, position, depth), units, long name of their median)
        "angle": (stack["angle_to_vertical"], "degree", "median over cuts and piles of the surface-parallel cut "
                  "resultant's angle to the vertical"),
        "abs_angle": (np.abs(stack["angle_to_vertical"]), "degree", "median of |angle to the vertical|"),
        "carried": (stack["load_ratio"], "1", "median of the downward force / weight of the column above"),
        "failure": (ratio, "1", "median of (tau / sigma_n on the surface-parallel plane, window stress) / "
                    "tan(flank angle)"),
        "direct_failure": (direct_ratio, "1", "median of (tau / sigma_n of the cut resultant) / tan(flank angle)"),
        "friction_share": (friction_ratio, "1", "median of (tau / sigma_n on the surface-parallel plane) / "
                           "tan phi of the most loaded plane"),
        "most_loaded": (stack["tan_phi"], "1", "median of tan phi of the most loaded plane of the windows"),
        "major": (stack["major_from_vertical"], "degree", "median major principal direction from the vertical "
                  "(positive leaning outward)"),
        "vertical_dev": (stack["vertical_deviation"], "degree", "median deviation of the vertical cut "
                               "resultant from the flank slope"),
    }
    assert not set(stats) & set(PER_CUT), "a statistic would overwrite a per-cut variable"
    coords = {P: names, F: [f for f, _ in FLANKS], Q: q, D: depths, H: histories}
    for name, (vals, units, ln) in stats.items():
        pooled = np.full((len(histories), 3), np.nan)
        by_depth = np.full((len(histories), len(depths), 3), np.nan)
        by_pos = np.full((len(histories), len(q), 3), np.nan)
        for i, h in enumerate(histories):
            v = vals[hist == h]
            idx = rng.integers(0, len(v), size=(a["bootstrap"], len(v)))
            pooled[i] = _band(v, idx, lo, hi)
            for k in range(len(depths)):
                by_depth[i, k] = _band(v[..., k], idx, lo, hi)
            for j in range(len(q)):
                by_pos[i, j] = _band(v[:, :, j], idx, lo, hi)
        for suffix, arr, dims in (("", pooled, (H,)), ("_by_depth", by_depth, (H, D)),
                                  ("_by_position", by_pos, (H, Q))):
            for j, end in enumerate(("", "_lo", "_hi")):
                what = ln + ("" if not end else f", {100 * a['level']:g} % bootstrap band over piles, "
                             f"{'lower' if end == '_lo' else 'upper'} end (NaN: one pile)")
                if suffix:
                    what += f" ({'per depth' if suffix == '_by_depth' else 'per position'})"
                data[f"{name}{suffix}{end}"] = (dims, arr[..., j], {"units": units, "long_name": what})
    ds = xr.Dataset(data, coords=coords, attrs={
        "level": a["level"], "bootstrap": a["bootstrap"], "seed": a["seed"], "mean_diameter": m0["d"], "length_d": cfg["length_d"], "window_d": cfg["window_d"],
        "ground_margin_d": cfg["ground_margin_d"], "n_cuts_per_pile": int(np.prod(m0["valid"].shape)),
        "vertical_tol_deg": cfg["vertical_tol_deg"], "failure_tol": cfg["failure_tol"]})
    ds[Q].attrs.update(units="1", long_name="cut centre |x| / L")
    ds[D].attrs.update(units="1", long_name="depth of the cut below the free surface (normal), mean diameters")
    return ds
