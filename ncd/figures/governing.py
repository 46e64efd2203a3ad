"""Figure 5: what governs indeterminacy -- static packings across friction.

Packings of discs with radii uniform in ``[R, 2R]`` are built by contact dynamics at the
friction ``mu`` they are analysed at, in two geometries (:data:`KINDS`): ``plates``, the
setup of Unger, Kertész & Wolf (PRL 94, 178001, 2005) with a body force toward the bottom
plate instead of a lid (a fixed lid adds a self-stress that makes ``A ∩ C`` unbounded),
and ``box``, under gravity between side walls as in Figure 3 (:mod:`ncd.figures.equilibrium`).
A ballistic deposit starts the relaxation close to its final height; Moreau-Jean steps
then run until the equilibrium test of section 2 passes and every disc is slow.
"""
import numpy as np
import xarray as xr
from scipy import stats

from ncd.core.contacts import h_matrix, match_warm
from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.explore import member_rng, shard_members
from ncd.dynamics.stepper import equilibrium_test, solve_problem, step
from ncd.figures.governing_exact import exact_measures, unger_eta
from ncd.io.netcdf import merge_shards, provenance
from ncd.scenes.packing import external_force, rest_problem
from ncd.solver.settings import SolverSettings

KINDS = ("plates", "box")


def mu_values(p):
    """The friction coefficients, log-spaced from ``mu_min`` to ``mu_max``."""
    if not (0 < p["mu_min"] < p["mu_max"]):
        raise InputError(f"packings.mu_min = {p['mu_min']} and mu_max = {p['mu_max']}: need 0 < min < max")
    return np.geomspace(p["mu_min"], p["mu_max"], p["n_mu"])


def packing_table(p):
    """Every packing of the study: arrays ``kind``, ``mu_index``, ``mu``, ``member``
    (the seed member), in a fixed order (kind, mu, k); ``p["kinds"]`` maps a kind to
    its number of packings per mu."""
    mus = mu_values(p)
    kind, idx, mem = [], [], []
    for name, per_mu in p["kinds"].items():
        if name not in KINDS:
            raise InputError(f"packings.kinds contains {name!r}: must be one of {KINDS}")
        for i in range(len(mus)):
            for k in range(per_mu):
                kind.append(KINDS.index(name))
                idx.append(i)
                mem.append(KINDS.index(name) * 1_000_000 + i * 1000 + k)
    idx = np.array(idx, np.int64)
    return {"kind": np.array(kind, np.int8), "mu_index": idx, "mu": mus[idx], "member": np.array(mem, np.int64)}


def walls_of(kind, width):
    floor = ((0.0, 0.0), (0.0, 1.0))
    if kind == "plates":
        return [floor]
    return [floor, ((0.0, 0.0), (1.0, 0.0)), ((width, 0.0), (-1.0, 0.0))]


def ballistic(radius, width, periodic, rng):
    """Drop discs one by one (random x) straight down onto the floor or the discs placed."""
    n = len(radius)
    pos = np.zeros((n, 2))
    for i in range(n):
        r = radius[i]
        x = rng.uniform(0.0, width) if periodic else rng.uniform(r, width - r)
        y = r
        if i:
            dx = x - pos[:i, 0]
            if periodic:
                dx -= width * np.round(dx / width)
            reach = r + radius[:i]
            hit = np.abs(dx) < reach
            if hit.any():
                y = max(y, float(np.max(pos[:i][hit, 1] + np.sqrt(reach[hit] ** 2 - dx[hit] ** 2))))
        pos[i] = (x % width if periodic else x, y * (1 + 1e-9))
    return pos


def initial_scene(p, kind, mu, member):
    """The scene of one packing at its ballistic start."""
    rng = member_rng(member, p["root_seed"])
    R = p["radius_min"]
    radius = rng.uniform(R, 2 * R, p["n_discs"])
    width = p["width_radii"] * R
    pos = ballistic(radius, width, kind == "plates", rng)
    return make_scene(pos, radius, p["density"], walls=walls_of(kind, width), gravity=(0.0, -p["gravity"]),
                      mu=mu, period=width if kind == "plates" else None, overlap_tolerance=1e-2)


def build(p, kind, mu, member, progress=None):
    """Relax the ballistic start by Moreau-Jean steps at ``mu`` until at rest; ``(scene, info)``."""
    scene = initial_scene(p, kind, mu, member)
    settings = SolverSettings(**p["solver"])
    rest = SolverSettings(**p["rest_solver"])
    h, g, nm = p["h"], p["gravity"], scene.n_mobile
    max_pen = 0.0
    for k in range(1, p["max_steps"] + 1):
        rep = step(scene, h, settings=settings, init="warm")
        max_pen = max(max_pen, rep.max_penetration)
        if k % p["check_every"] == 0:
            speed = max(np.abs(scene.vel[:nm]).max(), np.abs(scene.spin[:nm] * scene.radius[:nm]).max()) / (g * h)
            if speed > p["speed_tol"]:
                continue
            eq = equilibrium_test(scene, h, rest, init="warm", velocity_tol=p["velocity_tol"])
            if progress is not None:
                progress(k, p["max_steps"], f"speed {speed:.2e} g h, test |u_f| {eq.max_velocity:.2e} g h")
            if eq.at_rest:
                return scene, {"steps": k, "speed": float(speed), "rest_velocity": eq.max_velocity,
                               "max_penetration": max_pen / p["radius_min"]}
    raise RuntimeError(f"packing {kind} mu = {mu:.3g} member {member} is not at rest after "
                       f"{p['max_steps']} steps: raise packings.max_steps")


def _var(dims, values, units, long_name):
    return (dims, values, {"units": units, "long_name": long_name})


_COORDS = {"packing": "packing index in the study", "disc": "disc index", "contact": "contact index",
           "sample": "relaxation round (0: the starting solution)"}


def _coords(**values):
    return {k: (k, np.asarray(v), {"units": "1", "long_name": _COORDS[k]}) for k, v in values.items()}


def pack_shard(cfg, shard, n_shards, progress=None):
    """Build the packings of one shard -> Dataset (dims packing, disc): centres, radii,
    build record.  Contacts are found again from the centres (:func:`scene_of`)."""
    p = cfg["packings"]
    table = packing_table(p)
    sel = shard_members(len(table["mu"]), shard, n_shards)
    n = p["n_discs"]
    x, y, r = (np.zeros((len(sel), n)) for _ in range(3))
    rec = {k: np.zeros(len(sel)) for k in ("steps", "rest_velocity", "max_penetration")}
    warm = []
    for j, i in enumerate(sel):
        kind = KINDS[table["kind"][i]]
        scene, info = build(p, kind, float(table["mu"][i]), int(table["member"][i]))
        x[j], y[j], r[j] = scene.pos[:n, 0], scene.pos[:n, 1], scene.radius[:n]
        warm.append(match_warm(rest_problem(scene, p["h"]).contacts, scene.prev_keys, scene.prev_impulse))
        for k in rec:
            rec[k][j] = info[k]
        if progress is not None:
            progress(j + 1, len(sel), f"{kind} mu {table['mu'][i]:.3g}: {info['steps']} steps")
    kmax = max(len(w) for w in warm)
    wn, wt = np.full((len(sel), kmax), np.nan), np.full((len(sel), kmax), np.nan)
    for j, w in enumerate(warm):
        wn[j, :len(w)], wt[j, :len(w)] = w[:, 0], w[:, 1]
    ds = xr.Dataset(
        {"warm_impulse_n": _var(("packing", "contact"), wn, "N s", "normal impulse of the last build step"),
         "warm_impulse_t": _var(("packing", "contact"), wt, "N s", "tangential impulse of the last build step"),
         "x": _var(("packing", "disc"), x, "m", "disc centre x"),
         "y": _var(("packing", "disc"), y, "m", "disc centre y"),
         "radius": _var(("packing", "disc"), r, "m", "disc radius"),
         "kind": _var("packing", table["kind"][sel], "1", "geometry of the packing"),
         "mu": _var("packing", table["mu"][sel], "1", "friction coefficient (built and analysed at)"),
         "mu_index": _var("packing", table["mu_index"][sel], "1", "index of mu in the grid"),
         "member": _var("packing", table["member"][sel], "1", "seed member"),
         "build_steps": _var("packing", rec["steps"].astype(np.int64), "1", "Moreau-Jean steps to rest"),
         "rest_velocity": _var("packing", rec["rest_velocity"], "1", "equilibrium test max |u_f| / (|g| h)"),
         "max_penetration": _var("packing", rec["max_penetration"], "1",
                                 "largest interpenetration during the build / R")},
        coords=_coords(packing=sel, disc=np.arange(n), contact=np.arange(kmax)),
        attrs=provenance(_no_shards(cfg), SolverSettings(**p["solver"])))
    ds["kind"].attrs.update(flag_values=np.arange(len(KINDS), dtype=np.int8), flag_meanings=" ".join(KINDS))
    return ds


def scene_of(packings, j, cfg):
    """Scene of packing row ``j`` of a packings dataset at rest, and its rest problem."""
    p = cfg["packings"]
    kind = KINDS[int(packings.kind[j])]
    width = p["width_radii"] * p["radius_min"]
    scene = make_scene(np.column_stack([packings.x[j].values, packings.y[j].values]), packings.radius[j].values,
                       p["density"], walls=walls_of(kind, width), gravity=(0.0, -p["gravity"]),
                       mu=float(packings.mu[j]), period=width if kind == "plates" else None,
                       overlap_tolerance=1.0)
    return scene, rest_problem(scene, p["h"])


def exact_shard(packings, cfg, progress=None):
    """Exact measures (:func:`ncd.figures.governing_exact.exact_measures`) of every packing of a shard
    -> Dataset (dims packing, contact; per-contact arrays NaN-padded to the largest kappa)."""
    e = cfg["exact"]
    rows = []
    for j in range(packings.sizes["packing"]):
        scene, problem = scene_of(packings, j, cfg)
        rows.append(exact_measures(h_matrix(scene, problem.contacts), external_force(scene), problem.contacts.mu,
                                   width_tol=e["width_tol"], slack_tol=e["slack_tol"]))
        if progress is not None:
            progress(j + 1, packings.sizes["packing"], f"kappa {rows[-1]['n_contacts']}, {rows[-1]['n_lp']} LPs")
    n = len(rows)
    kmax = max(r["n_contacts"] for r in rows)
    pad = {q: np.full((n, kmax), np.nan) for q in ("min_n", "max_n", "min_t", "max_t", "fixed")}
    for j, r in enumerate(rows):
        k = r["n_contacts"]
        pad["min_n"][j, :k], pad["min_t"][j, :k] = r["force_min"][:, 0], r["force_min"][:, 1]
        pad["max_n"][j, :k], pad["max_t"][j, :k] = r["force_max"][:, 0], r["force_max"][:, 1]
        pad["fixed"][j, :k] = r["fixed"]
    scal = {q: np.array([r[q] for r in rows]) for q in SCALARS}
    scal["bounded"] = scal["bounded"].astype(np.int8)
    for q in pad:                       # an infinite range (unbounded A ∩ C) is stored as NaN
        pad[q][~np.isfinite(pad[q])] = np.nan
    nm = packings.sizes["disc"]
    data = {q: _var("packing", scal[q], "1" if q != "scale" else "N", lname) for q, lname in SCALARS.items()}
    data["coordination"] = _var("packing", 2.0 * scal["n_contacts"] / nm, "1",
                                "contacts per disc, 2 kappa / N (wall contacts included)")
    data["dim_ratio"] = _var("packing", scal["dim_AC_rank"] / (2.0 * scal["n_contacts"]), "1",
                             "dim (A ∩ C) / 2 kappa")
    data["fixed_fraction"] = _var("packing", scal["n_fixed"] / scal["n_contacts"], "1",
                                  "fraction of contacts whose force is fixed by statics")
    for q, lname in (("min_n", "least normal force over A ∩ C"), ("max_n", "largest normal force over A ∩ C"),
                     ("min_t", "least tangential force over A ∩ C"),
                     ("max_t", "largest tangential force over A ∩ C")):
        data[f"force_{q}"] = _var(("packing", "contact"), pad[q], "N", lname)
    data["fixed"] = _var(("packing", "contact"), pad["fixed"], "1", "1: force fixed by statics (NaN: padding)")
    return xr.Dataset(data, coords=_coords(packing=packings.packing.values, contact=np.arange(kmax)),
                      attrs=provenance(_no_shards(cfg), None))


SCALARS = {"n_contacts": "contacts kappa", "rank_H": "rank of the equilibrium equations",
           "dim_A": "dim A = 2 kappa - rank H", "dim_AC_rank": "dim (A ∩ C), rank count",
           "dim_AC_lp": "dim (A ∩ C), affine rank of LP points", "n_fixed": "contacts fixed by statics",
           "eta_exact": "exact indeterminacy ratio (box diagonal / box-centre force)",
           "eta_normal": "exact ratio of normal-force widths to mean normal force",
           "n_lp": "linear programs solved", "scale": "largest external force |F|",
           "bounded": "1: A ∩ C bounded (no self-stress inside C)"}


def _no_shards(cfg):
    return {k: v for k, v in cfg.items() if k != "shards"}


def unger_relax(scene, problem, cfg, rng, start=None):
    """Unger et al.'s sampling: a random walk inside the solution set, ``rounds`` steps.

    Each round adds uniform noise (``noise * <|r|>``) to every force component and relaxes
    by NLGS with a random order, finished by the active-set stage so that ``u_f = 0`` holds
    to round-off.  Returns ``(forces, converged, at_rest)``; a round counts only when both
    hold, and after a failed first relaxation the rest are NaN."""
    u, p = cfg["unger"], cfg["packings"]
    settings = SolverSettings(**u["solver"])
    h, g, nm = p["h"], p["gravity"], scene.n_mobile
    n = problem.contacts.n
    forces, conv, rest = [], [], []
    s = None
    for k in range(u["rounds"] + 1):
        guess = start
        if s is not None:
            amp = u["noise"] * np.hypot(s[:, 0], s[:, 1]).mean()
            guess = s + rng.uniform(-amp, amp, (n, 2))
            guess[:, 0] = np.maximum(guess[:, 0], 0.0)
        res, vel, spin = solve_problem(scene, problem, guess, rng.permutation(n), settings)
        umax = max(np.abs(vel[:nm]).max(), np.abs(spin[:nm] * scene.radius[:nm]).max()) / (g * h)
        ok_rest = umax <= p["velocity_tol"]
        forces.append(res.impulse / h)
        conv.append(bool(res.converged))
        rest.append(bool(ok_rest))
        if res.converged and ok_rest:
            s = res.impulse.copy()
        elif s is None:     # no starting solution: the packing is recorded, unsampled (eta NaN)
            pad = u["rounds"]
            return (np.concatenate([np.array(forces), np.full((pad, n, 2), np.nan)]),
                    np.array(conv + [False] * pad), np.array(rest + [False] * pad))
    return np.array(forces), np.array(conv), np.array(rest)


def unger_shard(packings, cfg, progress=None):
    """Unger et al.'s eta of every packing of a shard -> Dataset (dims packing, sample, contact)."""
    u = cfg["unger"]
    out = []
    for j in range(packings.sizes["packing"]):
        scene, problem = scene_of(packings, j, cfg)
        rng = member_rng(int(packings.member[j]), u["root_seed"])
        k = problem.contacts.n
        start = np.column_stack([packings.warm_impulse_n.values[j, :k], packings.warm_impulse_t.values[j, :k]])
        out.append(unger_relax(scene, problem, cfg, rng, start))
        if progress is not None:
            progress(j + 1, packings.sizes["packing"])
    n, m = len(out), u["rounds"] + 1
    kmax = max(f.shape[1] for f, _, _ in out)
    fn, ft = np.full((n, m, kmax), np.nan), np.full((n, m, kmax), np.nan)
    ok = np.zeros((n, m), np.int8)
    eta = np.full(n, np.nan)
    for j, (f, c, r) in enumerate(out):
        fn[j, :, :f.shape[1]], ft[j, :, :f.shape[1]] = f[:, :, 0], f[:, :, 1]
        ok[j] = c & r
        good = f[ok[j] == 1]
        if len(good) > 1:
            eta[j] = unger_eta(good)
    return xr.Dataset(
        {"relaxed_n": _var(("packing", "sample", "contact"), fn, "N", "normal force after relaxation"),
         "relaxed_t": _var(("packing", "sample", "contact"), ft, "N", "tangential force after relaxation"),
         "relaxed_ok": _var(("packing", "sample"), ok, "1", "1: NLGS converged and u_f = 0 (a point of A ∩ C)"),
         "eta_unger": _var("packing", eta, "1", "Unger et al.'s eta: <|F_k - F_0|> / <|F_0|>")},
        coords=_coords(packing=packings.packing.values, sample=np.arange(m), contact=np.arange(kmax)),
        attrs=provenance(_no_shards(cfg), SolverSettings(**cfg["unger"]["solver"])))


def merge(pack_paths, exact_paths, unger_paths):
    """The three shard sets -> one Dataset over every packing (contact padding: NaN)."""
    parts = [merge_shards(paths, dim="packing") for paths in (pack_paths, exact_paths, unger_paths)]
    return xr.merge(parts, join="outer", combine_attrs="override")


def eta_table(ds, var="eta_exact", kind=0):
    """Per mu: mean, 95 % band (t-interval over packings), count of ``var`` for ``kind``."""
    sel = ds.kind.values == kind
    rows = []
    for i in np.unique(ds.mu_index.values[sel]):
        v = ds[var].values[sel & (ds.mu_index.values == i)]
        v = v[np.isfinite(v)]
        half = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else np.nan
        rows.append((float(ds.mu.values[sel & (ds.mu_index.values == i)][0]), v.mean() if len(v) else np.nan,
                     half, len(v)))
    return np.array(rows)


def peak_and_slope(table):
    """``(mu at the largest mean, slope of log eta against log mu over the two smallest mu)``."""
    mu, m = table[:, 0], table[:, 1]
    ok = len(mu) > 1 and bool((m[:2] > 0).all())
    slope = float(np.log(m[1] / m[0]) / np.log(mu[1] / mu[0])) if ok else np.nan
    return float(mu[np.nanargmax(m)]), slope


__all__ = ["KINDS", "mu_values", "packing_table", "ballistic", "initial_scene", "build", "pack_shard",
           "scene_of", "exact_shard", "unger_relax", "unger_shard", "merge", "eta_table", "peak_and_slope"]
