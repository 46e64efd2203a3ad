"""Measures of the acceleration clouds of Figure 2 (Moreau 2005, section 3).

:func:`cloud_stats` (mean, covariance, principal axes, line-likeness), :func:`solutions`
(distinct end points), :func:`verdict` (true indeterminacy or iteration error, from the
spread against the tolerance), :func:`contact_relation` (the paper's question of why the
dispersion is a line: switching contacts, sticking clusters and their rigid-motion fit),
:func:`cloud_against_census` (the cloud read through the exact solutions of
:mod:`ncd.figures.fig2_slope.census`), :func:`status_patterns` (status combinations for the census),
:func:`warm_check` (the warm runs with local exact solves against plain NLGS) and
:func:`measures_dataset` (all of it as ``measures.nc``).
"""
import itertools

import numpy as np
import xarray as xr
import yaml

from ncd.io.netcdf import provenance

STICK = 1


def cloud_stats(x, y):
    """Mean, covariance and principal axes of clouds ``(x, y)`` along the last axis.

    Per leading index: ``mean_x, mean_y, cov_xx, cov_xy, cov_yy``, ``major, minor`` (RMS
    extents along the principal axes), ``spread``, ``ratio = minor / major`` (0 a line, 1
    isotropic, nan a point) and ``angle`` of the major axis in degrees, in (-90, 90]."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    mx, my = x.mean(-1), y.mean(-1)
    dx, dy = x - mx[..., None], y - my[..., None]
    cxx, cyy, cxy = (dx * dx).mean(-1), (dy * dy).mean(-1), (dx * dy).mean(-1)
    half = 0.5 * (cxx + cyy)
    disc = np.sqrt(0.25 * (cxx - cyy) ** 2 + cxy ** 2)
    l1, l2 = half + disc, np.maximum(half - disc, 0.0)
    major, minor = np.sqrt(l1), np.sqrt(l2)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(major > 0, minor / np.where(major > 0, major, 1.0), np.nan)
    angle = np.degrees(0.5 * np.arctan2(2 * cxy, cxx - cyy))
    angle = np.where(angle <= -90.0, angle + 180.0, angle)
    return {"mean_x": mx, "mean_y": my, "cov_xx": cxx, "cov_xy": cxy, "cov_yy": cyy, "major": major,
            "minor": minor, "spread": np.sqrt(l1 + l2), "ratio": ratio, "angle": angle}


def solutions(fields, threshold):
    """Group runs whose fields ``(run, m)`` agree within ``threshold`` (max norm).

    Greedy in run order: a run joins the first solution whose representative
    (its first run) is within ``threshold``.  Returns ``(labels, representatives)``,
    labels numbered by decreasing count (0 = the most frequent solution).
    """
    fields = np.asarray(fields, float)
    reps, labels = [], np.empty(len(fields), np.int64)
    for r, f in enumerate(fields):
        for k, rep in enumerate(reps):
            if np.abs(f - fields[rep]).max() <= threshold:
                labels[r] = k
                break
        else:
            reps.append(r)
            labels[r] = len(reps) - 1
    counts = np.bincount(labels, minlength=len(reps))
    rank = np.argsort(-counts, kind="stable")
    new = np.empty_like(rank)
    new[rank] = np.arange(len(rank))
    return new[labels], np.asarray(reps)[rank]


def verdict(tol, zero_spread, warm_spread, floor, decades=2.0, ratio=10.0, plateau=0.5):
    """True indeterminacy or iteration error, from spreads against a decreasing ``tol``.

    "indeterminacy": over the last ``decades`` the zero-guess spread stays above ``floor``,
    keeps ``plateau`` of its value a decade looser and ends ``ratio`` times the warm-start
    spread; "iteration error": it shrinks tenfold; else "undecided".  Returns ``(verdict, info)``."""
    tol = np.asarray(tol, float)
    z, w = np.asarray(zero_spread, float), np.asarray(warm_spread, float)
    window = tol <= tol.min() * 10 ** decades * (1 + 1e-9)
    if np.log10(tol[window].max() / tol.min()) < decades - 1e-9:
        raise ValueError(f"the tolerances {tol} do not span {decades} decades")
    zw = z[window]
    steps = zw[1:] / np.maximum(zw[:-1], 1e-300)
    info = {"zero_min_in_window": float(zw.min()), "zero_shrink": float(zw[-1] / max(zw[0], 1e-300)),
            "zero_over_warm": float(z[-1] / max(w[-1], 1e-300)), "decade_ratio_min": float(steps.min())}
    if zw.min() >= floor and steps.min() >= plateau and z[-1] >= ratio * w[-1]:
        return "indeterminacy", info
    if zw[-1] <= 0.1 * zw[0]:
        return "iteration error", info
    return "undecided", info


def rigid_clusters(n_mobile, body_a, body_b, sticking):
    """Connected components of the mobile grains joined by sticking contacts.

    Contacts with a fixed body (ground disc, wall) are ignored: a cluster
    touching the ground is still one cluster.  Returns a label per grain.
    """
    parent = np.arange(n_mobile)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, s in zip(body_a, body_b, sticking):
        if s and 0 <= b < n_mobile:
            ra, rb = find(a), find(b)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(i) for i in range(n_mobile)])
    _, labels = np.unique(roots, return_inverse=True)
    return labels


def cluster_motion_fit(pos, delta, labels, period=0.0):
    """Least-squares rigid motion ``dV + dw x (r - r_c)`` of ``delta`` on each cluster.

    ``pos`` (n, 2) centres (cluster members unwrapped across the period
    around their first member), ``delta`` (n, 2) the difference of two
    acceleration fields.  Returns per grain the fitted vector and the size
    of its cluster.
    """
    fit = np.zeros_like(delta)
    size = np.zeros(len(pos), np.int64)
    for k in np.unique(labels):
        idx = np.nonzero(labels == k)[0]
        size[idx] = len(idx)
        p = pos[idx].copy()
        if period > 0:
            p[:, 0] -= period * np.rint((p[:, 0] - p[0, 0]) / period)
        if len(idx) == 1:
            fit[idx] = delta[idx]
            continue
        c = p.mean(0)
        rx, ry = p[:, 0] - c[0], p[:, 1] - c[1]
        # unknowns dVx, dVy, dw:  dx = dVx - dw ry,  dy = dVy + dw rx
        m = len(idx)
        A = np.zeros((2 * m, 3))
        A[:m, 0], A[:m, 2] = 1.0, -ry
        A[m:, 1], A[m:, 2] = 1.0, rx
        b = np.concatenate([delta[idx, 0], delta[idx, 1]])
        sol = np.linalg.lstsq(A, b, rcond=None)[0]
        f = A @ sol
        fit[idx, 0], fit[idx, 1] = f[:m], f[m:]
    return fit, size


def _switch_distance(n_mobile, body_a, body_b, sticking, sources):
    """Graph distance (in sticking contacts) from each grain to the nearest grain
    in ``sources``; -1 when unreachable."""
    nbr = [[] for _ in range(n_mobile)]
    for a, b, s in zip(body_a, body_b, sticking):
        if s and 0 <= b < n_mobile:
            nbr[a].append(b)
            nbr[b].append(a)
    dist = -np.ones(n_mobile, np.int64)
    frontier = list(sources)
    for i in frontier:
        dist[i] = 0
    while frontier:
        nxt = []
        for i in frontier:
            for j in nbr[i]:
                if dist[j] < 0:
                    dist[j] = dist[i] + 1
                    nxt.append(j)
        frontier = nxt
    return dist


def contact_relation(traj, ens, labels, g):
    """How the two most frequent solutions differ, contact by contact and grain by grain.

    Per grain: the acceleration difference, its rigid-motion fit on clusters joined by
    contacts sticking in both, cluster size, contact counts and sticking links to the nearest
    switching contact; per contact: ``switched``.  None with fewer than two solutions."""
    if labels.max() < 1:
        return None
    tight = ens.isel(tol=-1)
    flat = lambda v: v.values.reshape(-1, *v.shape[2:])  # noqa: E731  (init, run) -> one run axis
    ax, ay = flat(tight.accel_x), flat(tight.accel_y)
    status = flat(ens.status)
    runs = [int(np.nonzero(labels == k)[0][0]) for k in (0, 1)]
    d = np.column_stack([ax[runs[1]] - ax[runs[0]], ay[runs[1]] - ay[runs[0]]])
    s0, s1 = status[runs[0]], status[runs[1]]
    a, b = ens.body_a.values, ens.body_b.values
    nm = ens.sizes["disc"]
    stick_both = (s0 == STICK) & (s1 == STICK)
    switched = s0 != s1
    active = (s0 > 0) | (s1 > 0)
    n_stick = np.zeros(nm, np.int64)
    n_act = np.zeros(nm, np.int64)
    for arr, mask in ((n_stick, stick_both), (n_act, active)):
        np.add.at(arr, a[mask], 1)
        mb = mask & (b >= 0) & (b < nm)
        np.add.at(arr, b[mb], 1)
    labels_c = rigid_clusters(nm, a, b, stick_both)
    pos = np.column_stack([traj.pos_x.values, traj.pos_y.values])
    fit, size = cluster_motion_fit(pos, d, labels_c, float(traj.attrs["period"]))
    src = np.unique(np.concatenate([a[switched], b[switched & (b >= 0) & (b < nm)]]))
    return {"delta_x": d[:, 0], "delta_y": d[:, 1], "rigid_x": fit[:, 0], "rigid_y": fit[:, 1],
            "cluster_size": size, "n_stick_both": n_stick, "n_contacts": n_act,
            "switch_distance": _switch_distance(nm, a, b, stick_both, src), "switched": switched.astype(np.int8),
            "representative_runs": np.array(runs)}


def switching_contacts(statuses):
    """Contacts whose status differs between any two of the solutions (rows of ``statuses``)."""
    statuses = np.asarray(statuses)
    return np.nonzero((statuses != statuses[:1]).any(0))[0] if len(statuses) else np.zeros(0, np.int64)


def contact_clusters(contacts, n_mobile, idx):
    """Groups of the contacts ``idx`` joined through a shared mobile grain (list of index arrays)."""
    parent = list(range(len(idx)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner = {}
    for k, c in enumerate(idx):
        for b in (int(contacts.body_a[c]), int(contacts.body_b[c])):
            if 0 <= b < n_mobile:
                if b in owner:
                    parent[find(k)] = find(owner[b])
                else:
                    owner[b] = k
    roots = np.array([find(k) for k in range(len(idx))], np.int64)
    return [np.asarray(idx)[roots == r] for r in np.unique(roots)]


def cluster_options(statuses, cluster, max_local=16):
    """Status choices of one cluster: every combination of the statuses the solutions
    take at its contacts (when there are at most ``max_local``), else the solutions' own."""
    seen = [np.unique(statuses[:, c]) for c in cluster]
    if np.prod([len(v) for v in seen], dtype=float) <= max_local:
        return np.array(list(itertools.product(*seen)), np.int8)
    return np.unique(statuses[:, cluster], axis=0).astype(np.int8)


def status_patterns(statuses, contacts, n_mobile, max_patterns, rng):
    """Status patterns combining the changes seen between the solutions found.

    Switching contacts are grouped into clusters sharing a grain, each taking one of its
    options (:func:`cluster_options`): all combinations up to ``max_patterns``, else every
    single-cluster change plus random combinations.  Returns ``(patterns, switching, n_clusters)``."""
    statuses = np.asarray(statuses, np.int8)
    sw = switching_contacts(statuses)
    if len(sw) == 0:
        return np.zeros((0, statuses.shape[1]), np.int8), sw, 0
    clusters = contact_clusters(contacts, n_mobile, sw)
    opts = [cluster_options(statuses, cl) for cl in clusters]
    total = np.prod([len(o) for o in opts], dtype=float)
    out = []
    if total <= max_patterns:
        for pick in itertools.product(*[range(len(o)) for o in opts]):
            p = statuses[0].copy()
            for cl, o, j in zip(clusters, opts, pick):
                p[cl] = o[j]
            out.append(p)
    else:
        for base in statuses:
            for cl, o in zip(clusters, opts):
                for row in o:
                    if not np.array_equal(row, base[cl]):
                        p = base.copy()
                        p[cl] = row
                        out.append(p)
        while len(out) < max_patterns:
            p = statuses[0].copy()
            for cl, o in zip(clusters, opts):
                p[cl] = o[rng.integers(len(o))]
            out.append(p)
    known = {row.tobytes() for row in statuses}
    uniq, seen = [], set()
    for p in out[:max(max_patterns, 0)]:
        key = p.tobytes()
        if key not in known and key not in seen:
            seen.add(key)
            uniq.append(p)
    return np.array(uniq, np.int8).reshape(-1, statuses.shape[1]), sw, len(clusters)


def cloud_against_census(ens, census, grain, init="zero"):
    """The chosen grain's cloud at the tightest tolerance, read through the census.

    Each converged run is labelled with the census solution within ``basin_tol |g|`` (-1:
    none).  The cloud's principal axes differ from those of its solutions by at most the RMS
    iteration error (singular values are 1-Lipschitz), so the cloud is a set of solutions
    blurred by that error.  Returns counts and axes (m s-2)."""
    tight = ens.sel(init=init).isel(tol=-1)
    ok = tight.converged.values.astype(bool)
    g = float(census.attrs["g"])
    tol = float(yaml.safe_load(census.attrs["config_yaml"])["basin_tol"]) * g
    A = np.stack([census.accel_x.values, census.accel_y.values], -1)
    runs = np.stack([tight.accel_x.values, tight.accel_y.values], -1)[ok]
    d = np.abs(runs[:, None] - A[None]).reshape(len(runs), len(A), -1).max(-1)
    label = np.where(d.min(1) <= tol, d.argmin(1), -1)
    X = runs[:, grain]
    Y = np.where(label[:, None] >= 0, A[np.maximum(label, 0), grain], np.nan)
    E = X - Y
    lab = label >= 0
    cx = cloud_stats(X[:, 0], X[:, 1]) if len(X) else None
    cy = cloud_stats(Y[lab, 0], Y[lab, 1]) if lab.any() else None
    visited, counts = np.unique(label[lab], return_counts=True)
    return {"n_runs": int(tight.sizes["run"]), "n_converged": int(ok.sum()), "n_labelled": int(lab.sum()),
            "visited": visited, "counts": counts,
            "major": float(cx["major"]) if cx else np.nan, "minor": float(cx["minor"]) if cx else np.nan,
            "ratio": float(cx["ratio"]) if cx else np.nan, "spread": float(cx["spread"]) if cx else np.nan,
            "census_major": float(cy["major"]) if cy else np.nan, "census_minor": float(cy["minor"]) if cy else np.nan,
            "rms_offset": float(np.sqrt(np.mean(np.sum(E[lab] ** 2, 1)))) if lab.any() else np.nan,
            "max_offset": float(np.hypot(*E[lab].T).max()) if lab.any() else np.nan, "g": g,
            "n_solutions": len(A)}


def warm_check(ens, threshold):
    """The check of the warm runs made with local exact solves against plain NLGS from the
    same warm start and review order (``warm_plain_distance`` of the ensemble, the largest
    grain acceleration difference over ``|g|``): a sentence with the number of checked
    members, the largest distance at the tightest tolerance and whether it is below
    ``threshold`` (in ``|g|``, the distance that tells two solutions apart).  None when the
    ensemble's warm runs are plain NLGS (nothing to check)."""
    if "warm_plain_distance" not in ens or not int(ens.attrs.get("warm_local_exact", 0)):
        return None
    tight = float(ens.tol.min())
    dist = ens.warm_plain_distance.sel(tol=tight).values
    checked = np.isfinite(dist)
    if not checked.any():
        return "The warm runs use local exact solves; no member was also run by plain NLGS."
    worst = float(dist[checked].max())
    same = worst <= threshold
    return (f"The warm runs use local exact solves where the residual stalls; {int(checked.sum())} of them were "
            f"also run by plain NLGS from the same warm start and review order: at tolerance {tight:.0e} the two "
            f"end points differ by at most {worst:.1e} |g| in a grain's acceleration, "
            + (f"below the {threshold:.0e} |g| that tells two solutions apart: both land on the same solution."
               if same else f"above the {threshold:.0e} |g| that tells two solutions apart: they land on "
                            "different solutions."))


def measures_dataset(traj, ens, cfg):
    """Spreads per init, tolerance and grain; visible fractions; the chosen grain;
    distinct solutions at the tightest tolerance; the verdict; the contact relation."""
    an = cfg["analysis"]
    g = float(np.hypot(ens.attrs["gravity_x"], ens.attrs["gravity_y"]))
    st = cloud_stats(ens.accel_x.transpose("init", "tol", "disc", "run").values,
                     ens.accel_y.transpose("init", "tol", "disc", "run").values)
    dims = ("init", "tol", "disc")
    data = {k: (dims, v) for k, v in st.items()}
    spread = st["spread"]
    zi, wi = list(ens.init.values).index("zero"), list(ens.init.values).index("warm")
    grain = int(an["grain"]) if an["grain"] >= 0 else int(np.argmax(spread[zi, -1]))
    if grain >= ens.sizes["disc"]:
        raise ValueError(f"analysis.grain = {grain} is not a disc (there are {ens.sizes['disc']})")
    data["visible_fraction"] = (("init", "tol"), (spread > an["visible"] * g).mean(-1))
    tol = ens.tol.values
    v, info = verdict(tol, spread[zi, :, grain], spread[wi, :, grain], an["floor"] * g, an["decades"],
                      an["warm_ratio"])
    # distinct solutions at the tightest tolerance, both inits pooled
    tight = ens.isel(tol=-1)
    fields = np.concatenate([tight.accel_x.values, tight.accel_y.values], axis=-1)  # init, run, 2 disc
    ni, nr = fields.shape[:2]
    labels, reps = solutions(fields.reshape(ni * nr, -1), an["solution_threshold"] * g)
    data["solution_label"] = (("init", "run"), labels.reshape(ni, nr))
    counts = np.stack([np.bincount(labels.reshape(ni, nr)[i], minlength=len(reps)) for i in range(ni)])
    data["solution_count"] = (("init", "solution"), counts)
    flat_x = tight.accel_x.values.reshape(ni * nr, -1)
    flat_y = tight.accel_y.values.reshape(ni * nr, -1)
    data["solution_accel_x"] = (("solution", "disc"), flat_x[reps])
    data["solution_accel_y"] = (("solution", "disc"), flat_y[reps])
    # the trajectory's own solution (warm start, identity order, flow tolerance): which one?
    ref = np.concatenate([traj.reference_accel_x.values, traj.reference_accel_y.values])
    dist_ref = np.abs(fields.reshape(ni * nr, -1)[reps] - ref).max(-1)
    data["reference_distance"] = (("solution",), dist_ref)
    rel = contact_relation(traj, ens, labels, g)
    attrs = {"grain": grain, "verdict": v, "n_solutions": len(reps), "g": g,
             **{f"verdict_{k}": val for k, val in info.items()}}
    if rel is not None:
        for k in ("delta_x", "delta_y", "rigid_x", "rigid_y", "cluster_size", "n_stick_both", "n_contacts",
                  "switch_distance"):
            data[k] = (("disc",), rel[k])
        data["switched"] = (("contact",), rel["switched"])
        attrs["n_switched"] = int(rel["switched"].sum())
    ds = xr.Dataset(data, coords={"init": ens.init.values, "tol": tol, "disc": ens.disc.values,
                                  "run": ens.run.values, "solution": np.arange(len(reps)),
                                  "contact": ens.contact.values},
                    attrs=provenance(cfg["analysis"], **attrs))
    ds["angle"].attrs = {"units": "degree", "long_name": "angle of the major principal axis of the cloud from the "
                                                         "x axis, in (-90, 90]"}
    return ds
