"""Figure 5: what governs indeterminacy -- static packings across friction, Unger et al.'s way.

Unger, Kertész & Wolf (PRL 94, 178001, 2005): discs with radii uniform in ``[R, 2R]``,
periodic sides, no gravity, compressed between two plates by a constant force on the
top plate (:mod:`ncd.figures.fig5_governing.plates`: the plate is a mobile body of the scene), a new
packing for each ``mu``; a middle slice analysed with the forces across its boundaries
fixed.  Two series (:data:`KINDS`): ``plates``, built and analysed at ``mu``; ``control``,
built frictionless and analysed at every ``mu`` (friction switched on for the sampling).

The study is two tables: *builds* (:func:`build_table`: one contact-dynamics build each)
and *analyses* (:func:`analysis_table`: a build and the ``mu`` it is analysed at).  A
build starts from a ballistic deposit with the plate resting on its top and runs
Moreau-Jean steps until the plate is slow and the one-step test from rest gives
``u_f = 0`` (rattlers, which nothing stops without gravity, do not enter that test);
its exact rest forces are the reference solution whose slice-boundary forces are held
fixed.  Each analysis (:func:`analyse`) measures the slice exactly
(:func:`ncd.figures.fig5_governing.exact.exact_measures`), samples it by Unger et al.'s random
walk and uniformly by hit-and-run (:mod:`ncd.figures.fig5_governing.unger`).
"""
import numpy as np
import xarray as xr
from scipy import stats

from ncd.core.contacts import external_load, h_matrix
from ncd.core.errors import InputError
from ncd.core.scene import make_scene
from ncd.dynamics.explore import member_rng, shard_members
from ncd.exact.exact_set import ExactSet
from ncd.exact.polytope import ForcePolytope
from ncd.figures.fig5_governing import plates
from ncd.figures.fig5_governing.exact import exact_measures
from ncd.figures.fig5_governing.unger import centrality, chains_agree, eta_u, random_walk, uniform_sample
from ncd.io.netcdf import merge_shards, provenance
from ncd.solver.settings import SolverSettings

KINDS = ("plates", "control")


def mu_values(p):
    """The friction coefficients, log-spaced from ``mu_min`` to ``mu_max``."""
    if not (0 < p["mu_min"] < p["mu_max"]):
        raise InputError(f"packings.mu_min = {p['mu_min']} and mu_max = {p['mu_max']}: need 0 < min < max")
    return np.geomspace(p["mu_min"], p["mu_max"], p["n_mu"])


def build_table(p):
    """Every build: arrays ``kind``, ``mu`` (built at), ``mu_index`` (-1: frictionless),
    ``member`` (seed member), in a fixed order: plates (mu, k), then control (k)."""
    mus = mu_values(p)
    rows = [(0, i, float(mus[i]), i * 1000 + k) for i in range(len(mus)) for k in range(p["per_mu"])]
    rows += [(1, -1, 0.0, 1_000_000 + k) for k in range(p["control"])]
    kind, idx, mu, mem = (np.array(c) for c in zip(*rows))
    return {"kind": kind.astype(np.int8), "mu_index": idx.astype(np.int64), "mu": mu.astype(float),
            "member": mem.astype(np.int64)}


def analysis_table(p):
    """Every analysis: ``build`` (row of :func:`build_table`), ``kind``, ``mu_index``, ``mu``
    (analysed at); a control build is analysed at every mu."""
    b = build_table(p)
    mus = mu_values(p)
    rows = [(j, int(b["kind"][j]), int(b["mu_index"][j]), float(b["mu"][j]))
            for j in range(len(b["mu"])) if b["kind"][j] == 0]
    rows += [(j, 1, i, float(mus[i])) for j in range(len(b["mu"])) if b["kind"][j] == 1 for i in range(len(mus))]
    build, kind, idx, mu = (np.array(c) for c in zip(*rows))
    return {"build": build.astype(np.int64), "kind": kind.astype(np.int8), "mu_index": idx.astype(np.int64),
            "mu": mu.astype(float)}


def ballistic(radius, width, rng):
    """Drop discs one by one (random x, periodic) straight down onto the floor or the discs placed."""
    n = len(radius)
    pos = np.zeros((n, 2))
    for i in range(n):
        r = radius[i]
        x = rng.uniform(0.0, width)
        y = r
        if i:
            dx = x - pos[:i, 0]
            dx -= width * np.round(dx / width)
            reach = r + radius[:i]
            hit = np.abs(dx) < reach
            if hit.any():
                y = max(y, float(np.max(pos[:i][hit, 1] + np.sqrt(reach[hit] ** 2 - dx[hit] ** 2))))
        pos[i] = (x, y * (1 + 1e-9))
    return pos


def _disc_scene(pos, radius, p, mu, overlap_tolerance):
    width = p["width_radii"] * p["radius_min"]
    return make_scene(pos, radius, p["density"], walls=[((0.0, 0.0), (0.0, 1.0))], gravity=(0.0, 0.0), mu=mu,
                      period=width, overlap_tolerance=overlap_tolerance)


def _plate_load(p, radius):
    """Plate force and mass from ``load`` (force / total disc mass, m/s^2) and ``plate_mass``
    (in total disc masses): the build's dynamics then scale like a deposit under ``load``."""
    m = p["density"] * np.pi * float(np.sum(radius ** 2))
    return p["load"] * m, p["plate_mass"] * m


def initial_cell(p, mu, member):
    """The cell of one build at its ballistic start, the plate on the highest disc."""
    rng = member_rng(member, p["root_seed"])
    R = p["radius_min"]
    radius = rng.uniform(R, 2 * R, p["n_discs"])
    pos = ballistic(radius, p["width_radii"] * R, rng)
    force, mass = _plate_load(p, radius)
    return plates.make_cell(_disc_scene(pos, radius, p, mu, 1e-2), float((pos[:, 1] + radius).max()) * (1 + 1e-9),
                            mass, force)


def build(p, mu, member, progress=None):
    """Compress the ballistic start by Moreau-Jean steps at ``mu`` until at rest:
    ``(cell, forces, contacts, info)`` with the exact rest forces of every contact."""
    cell = initial_cell(p, mu, member)
    settings = SolverSettings(**p["solver"])
    rest = SolverSettings(**p["rest_solver"])
    h, a = p["h"], p["load"]
    max_pen = 0.0
    for k in range(1, p["max_steps"] + 1):
        _, prob = plates.step(cell, h, settings, check=k == 1)     # checked once per build
        max_pen = max(max_pen, prob.max_penetration)
        if k % p["check_every"] or abs(cell.scene.vel[cell.n, 1]) > p["speed_tol"] * a * h:
            continue
        forces, umax, rp, res = plates.rest_state(cell, h, rest, check=False)
        if progress is not None:
            progress(k, p["max_steps"], f"test |u_f| {umax / (a * h):.2e} load h")
        if umax <= p["velocity_tol"] * a * h:
            return cell, forces, rp.contacts, {"steps": k, "rest_velocity": umax / (a * h),
                                               "max_penetration": max_pen / p["radius_min"]}
    raise RuntimeError(f"packing mu = {mu:.3g} member {member} is not at rest after {p['max_steps']} steps: "
                       "raise packings.max_steps")


def _var(dims, values, units, long_name):
    return (dims, values, {"units": units, "long_name": long_name})


_COORDS = {"build": "build index", "packing": "analysis index (a build at one mu)", "disc": "disc index",
           "contact": "contact index (slice)", "sample": "random-walk sample (0: the history state)",
           "chain": "hit-and-run chain", "bcontact": "contact index (whole cell)"}


def _coords(**values):
    return {k: (k, np.asarray(v), {"units": "1", "long_name": _COORDS[k]}) for k, v in values.items()}


def _no_shards(cfg):
    return {k: v for k, v in cfg.items() if k != "shards"}


def _pad(rows, width, fill=np.nan):
    out = np.full((len(rows), width) + np.shape(rows[0])[1:], fill)
    for j, r in enumerate(rows):
        out[j, :len(r)] = r
    return out


def pack_shard(cfg, shard, n_shards, progress=None):
    """Build the packings of one shard -> Dataset (dims build, disc, bcontact): centres,
    radii, plate height and force, the contacts' keys and exact rest forces, build record."""
    p = cfg["packings"]
    table = build_table(p)
    sel = shard_members(len(table["mu"]), shard, n_shards)
    n = p["n_discs"]
    x, y, r = (np.zeros((len(sel), n)) for _ in range(3))
    rec = {k: np.zeros(len(sel)) for k in ("steps", "rest_velocity", "max_penetration", "plate_y", "force")}
    keys, forces = [], []
    for j, i in enumerate(sel):
        cell, f, contacts, info = build(p, float(table["mu"][i]), int(table["member"][i]))
        s = cell.scene
        x[j], y[j], r[j] = s.pos[:n, 0], s.pos[:n, 1], s.radius[:n]
        info.update(plate_y=cell.plate_y, force=cell.force)
        keys.append(contacts.key)
        forces.append(f)
        for k in rec:
            rec[k][j] = info[k]
        if progress is not None:
            progress(j + 1, len(sel), f"{KINDS[table['kind'][i]]} mu {table['mu'][i]:.3g}: {info['steps']} steps")
    kmax = max(len(k) for k in keys)
    fpad = _pad(forces, kmax)
    return xr.Dataset(
        {"x": _var(("build", "disc"), x, "m", "disc centre x"),
         "y": _var(("build", "disc"), y, "m", "disc centre y"),
         "radius": _var(("build", "disc"), r, "m", "disc radius"),
         "contact_key": _var(("build", "bcontact"), _pad(keys, kmax, -1).astype(np.int64), "1",
                             "body-pair key of each contact at rest (-1: padding)"),
         "rest_force_n": _var(("build", "bcontact"), fpad[..., 0], "N", "normal force of the exact rest state"),
         "rest_force_t": _var(("build", "bcontact"), fpad[..., 1], "N", "tangential force of the exact rest state"),
         "build_kind": _var("build", table["kind"][sel], "1", "series: 0 plates, 1 control (built frictionless)"),
         "build_mu": _var("build", table["mu"][sel], "1", "friction coefficient of the build"),
         "member": _var("build", table["member"][sel], "1", "seed member"),
         "build_steps": _var("build", rec["steps"].astype(np.int64), "1", "Moreau-Jean steps to rest"),
         "rest_velocity": _var("build", rec["rest_velocity"], "1", "test from rest: max |u_f| / (load h)"),
         "max_penetration": _var("build", rec["max_penetration"], "1", "largest interpenetration during the build / R"),
         "plate_y": _var("build", rec["plate_y"], "m", "height of the top plate at rest"),
         "plate_force": _var("build", rec["force"], "N", "force pushing the top plate down")},
        coords=_coords(build=sel, disc=np.arange(n), bcontact=np.arange(kmax)),
        attrs=provenance(_no_shards(cfg), SolverSettings(**p["solver"])))


def cell_of(builds, j, cfg, mu):
    """The cell of build row ``j`` at rest, analysed at friction ``mu``: ``(cell, contacts, forces,
    exact)``, the rest forces matched to the contacts found again by pair key (``exact``: see
    :func:`exact_rest`)."""
    p = cfg["packings"]
    R = builds.radius[j].values
    force, mass = _plate_load(p, R)
    ds = _disc_scene(np.column_stack([builds.x[j].values, builds.y[j].values]), R, p, float(mu), 1.0)
    cell = plates.make_cell(ds, float(builds.plate_y[j]), mass, float(builds.plate_force[j]))
    contacts = plates.prepare(cell, p["h"], 1.0, vel=np.zeros_like(cell.scene.vel),
                              spin=np.zeros_like(cell.scene.spin)).contacts
    keys = builds.contact_key[j].values
    keys = keys[keys >= 0]
    if not np.array_equal(keys, contacts.key):
        raise ValueError(f"build {int(builds.build[j])}: the contacts found again differ from those stored")
    k = len(keys)
    f = np.column_stack([builds.rest_force_n[j].values[:k], builds.rest_force_t[j].values[:k]])
    f, exact = exact_rest(cell, contacts, f, float(builds.build_mu[j]))
    if mu == 0.0 or float(builds.build_mu[j]) != mu:
        contacts.mu[:] = np.where(contacts.body_b == cell.n, 0.0, float(mu))    # plate contacts stay frictionless
    return cell, contacts, f, exact


REFINE_MOVE = 1e-3      # largest move of the rest forces by their refinement (relative to the load)
REFINE_CONE = 1e-12     # largest Coulomb violation of the refined forces (relative to the load)


def exact_rest(cell, contacts, forces, build_mu):
    """``(forces, exact)``: the rest test's forces (``|H r + F|`` up to ~1e-9 of the load) made
    exact on their active Coulomb rows at the build's friction, so that a slice's loads are
    consistent to round-off.

    The refinement holds every Coulomb row met within its tolerance as an equality.  In a thin
    cone (small mu) a contact carrying a tiny force meets both its rows, which sets its force to
    zero and can contradict equilibrium: the minimum-norm correction then moves other forces out
    of their cones (seen at mu = 1e-3: by 1 % of the load, out of C by 0.3 %).  Such a refinement
    (out of C by more than :data:`REFINE_CONE`, or a move above :data:`REFINE_MOVE`; the
    ill-conditioned corrections that stay in C move the forces by 5e-5 at most) is not taken:
    the forces stay as the test from rest left them and ``exact`` is False (the slice then
    takes the loads its reference forces balance: :func:`slice_of`)."""
    mu_b = np.where(contacts.body_b == cell.n, 0.0, float(build_mu))
    es = ExactSet(h_matrix(cell.scene, contacts), external_load(cell.scene, plates.plate_load(cell)), mu_b)
    raw = np.asarray(forces, float).ravel()
    refined = es.refine(raw)
    _, cone = es.fp.violations(refined)
    exact = bool(np.abs(refined - raw).max(initial=0.0) <= REFINE_MOVE * es.scale and float(cone.max()) <= REFINE_CONE)
    return (refined if exact else raw).reshape(-1, 2), exact


def slice_of(cell, contacts, forces, p, exact=True):
    """The middle slice of ``slice_radii`` between the plates, boundary forces fixed (forces not
    ``exact``: the loads its reference forces balance, :func:`ncd.figures.fig5_governing.plates.slice_problem`)."""
    mid, half = 0.5 * cell.plate_y, 0.5 * p["slice_radii"] * p["radius_min"]
    return plates.slice_problem(cell, contacts, forces, mid - half, mid + half, p["h"], balance=not exact)


def coordination(sl, cell, contacts, forces, frictional, tol=1e-9):
    """Mean number of force-carrying contacts per slice disc, rattlers left out (slice discs
    with fewer than 2 such contacts with friction, 3 without, removed until none is left;
    contacts with discs outside the slice and with the plates count), and the discs kept."""
    nb = cell.scene.n_disc                             # discs and the plate; nb stands for the walls
    ia, ib = contacts.body_a, np.where(contacts.body_b >= 0, contacts.body_b, nb)
    carry = np.hypot(forces[:, 0], forces[:, 1]) > tol * max(np.abs(forces).max(), 1e-300)
    removable = np.zeros(nb + 1, bool)
    removable[sl.discs] = True
    keep = np.ones(nb + 1, bool)
    need = 2 if frictional else 3
    while True:
        live = carry & keep[ia] & keep[ib]
        count = np.bincount(ia[live], minlength=nb + 1) + np.bincount(ib[live], minlength=nb + 1)
        drop = removable & keep & (count < need)
        if not drop.any():
            break
        keep &= ~drop
    kept = sl.discs[keep[sl.discs]]
    return (float(count[kept].mean()) if len(kept) else np.nan), len(kept)


def measured_slice(builds, j, cfg, mu):
    """The middle slice of build ``j`` at friction ``mu`` and its exact measures:
    ``(cell, contacts, forces, exact, slice, measures)`` (:func:`cell_of`, :func:`slice_of`,
    :func:`ncd.figures.fig5_governing.exact.exact_measures` at the ``exact`` tolerances)."""
    e = cfg["exact"]
    cell, contacts, forces, exact = cell_of(builds, j, cfg, mu)
    sl = slice_of(cell, contacts, forces, cfg["packings"], exact)
    out = exact_measures(sl.H, sl.F, sl.mu, width_tol=e["width_tol"], slack_tol=e["slack_tol"],
                         feas_tol=e["feas_tol"])
    return cell, contacts, forces, exact, sl, out


def analyse(builds, j, cfg, mu, rng_walk, rng_of):
    """Every measure of build ``j`` analysed at ``mu`` -> dict."""
    e = cfg["exact"]
    cell, contacts, forces, exact, sl, out = measured_slice(builds, j, cfg, mu)
    out["rest_exact"] = float(exact)
    out["bounded_cell"] = plates_bounded(cell, contacts)
    out["z"], out["n_nonrattlers"] = coordination(sl, cell, contacts, forces, float(builds.build_mu[j]) > 0)
    out["n_slice"] = len(sl.discs)
    out["reference"] = sl.reference
    walk = random_walk(sl, cfg["walk"], rng_walk)
    out.update(walk)
    out["eta_walk"] = eta_u(walk["samples"][walk["ok"]]) if walk["ok"].sum() > 1 else np.nan
    if out["dim_AC_rank"] == 0:      # one point: the walk's spread and the LP widths are round-off
        out["eta_walk"] = out["eta_exact"] = 0.0
    uni = uniform_sample(sl, out, cfg["uniform"], rng_of, e["feas_tol"]) if out["bounded"] else None
    out["uniform"] = uni
    if uni is not None:
        out["centrality"] = centrality(sl.reference, uni["samples"], walk["samples"][walk["ok"]])
    return out


def plates_bounded(cell, contacts):
    """Whether the whole cell's ``A ∩ C`` is bounded (the mobile plate closes the box above;
    a compressive loop around the period would still be a self-stress inside ``C``)."""
    return ForcePolytope(h_matrix(cell.scene, contacts), external_load(cell.scene, plates.plate_load(cell)), contacts.mu).is_bounded()


SCALARS = {"n_contacts": "contacts kappa in the slice", "rank_H": "rank of the slice's equilibrium equations",
           "dim_A": "dim A = 2 kappa - rank H", "dim_AC_rank": "dim (A ∩ C), rank count",
           "dim_AC_lp": "dim (A ∩ C), affine rank of LP points", "n_fixed": "contacts fixed by statics",
           "eta_exact": "exact range ratio: sum of range-box diagonals / sum of box-centre forces",
           "n_lp": "linear programs solved", "scale": "largest boundary load |F|",
           "bounded": "1: the slice's A ∩ C is bounded", "bounded_cell": "1: the whole cell's A ∩ C is bounded",
           "z": "contacts per disc in the slice, rattlers left out", "n_nonrattlers": "slice discs not rattlers",
           "n_slice": "discs in the slice", "eta_walk": "eta_U over the random walk",
           "eta_uniform": "eta_U over the uniform sample (both chains)",
           "eta_uniform_gap": "|eta_U chain 1 - chain 2| / eta_U", "rhat": "largest Gelman-Rubin R-hat (2 chains)",
           "dim_uniform": "dimension of the hit-and-run space", "history_rank": "fraction of uniform samples "
           "closer to the centre than the history state", "history_distance": "|history - centre| / <|F|>",
           "walk_distance": "mean |walk sample - centre| / <|F|>", "uniform_distance": "mean |uniform sample - "
           "centre| / <|F|>", "walk_ok": "random-walk samples that are points of A ∩ C",
           "mixed": "1: the two uniform chains agree (eta_U gap <= 0.3, R-hat <= 1.2)",
           "uniform_per_chain": "points per uniform chain (longer where the first chains did not agree)",
           "rest_exact": "1: the rest forces made exact on their active Coulomb rows (0: the slice's loads "
           "are those its reference forces balance, see exact_rest)"}


def analysis_shard(builds, cfg, shard, n_shards, progress=None):
    """The analyses of one shard -> Dataset (dims packing, sample, contact, chain).

    A shard takes every ``n_shards``-th analysis (``shard_members(..., interleaved=True)``), not a
    contiguous block: an analysis at small mu costs several times one at large mu, and
    blocks of the table (ordered by mu) left one shard with most of the cost.  The merged
    file is sorted by analysis, so its content does not depend on the shards."""
    p = cfg["packings"]
    table = analysis_table(p)
    sel = shard_members(len(table["mu"]), shard, n_shards, interleaved=True)
    row_of = {int(b): j for j, b in enumerate(builds.build.values)}
    rows = []
    for i in sel:
        j = row_of[int(table["build"][i])]
        seed = int(builds.member[j]) * 100 + int(table["mu_index"][i])
        out = analyse(builds, j, cfg, float(table["mu"][i]), member_rng(seed, cfg["walk"]["root_seed"]),
                      lambda k, s=seed: member_rng(s * 10 + k, cfg["uniform"]["root_seed"]))
        rows.append(out)
        if progress is not None:
            progress(len(rows), len(sel), f"mu {table['mu'][i]:.3g}: kappa {out['n_contacts']}, "
                     f"eta walk {out['eta_walk']:.3g}")
    return _dataset(rows, table, sel, builds, cfg)


def _dataset(rows, table, sel, builds, cfg):
    n = len(rows)
    kmax = max(r["n_contacts"] for r in rows)
    m = cfg["walk"]["samples"] + 1
    walk = np.full((n, m, kmax, 2), np.nan)
    ok = np.zeros((n, m), np.int8)
    ref = np.full((n, kmax, 2), np.nan)
    umean, ustd = np.full((n, 2, kmax, 2), np.nan), np.full((n, 2, kmax, 2), np.nan)
    lo, hi = np.full((n, kmax, 2), np.nan), np.full((n, kmax, 2), np.nan)
    for j, r in enumerate(rows):
        k = r["n_contacts"]
        walk[j, :, :k], ok[j], ref[j, :k] = r["samples"], r["ok"], r["reference"]
        fin = np.isfinite(r["force_min"]) & np.isfinite(r["force_max"])
        lo[j, :k], hi[j, :k] = np.where(fin, r["force_min"], np.nan), np.where(fin, r["force_max"], np.nan)
        u = r["uniform"]
        if u is not None:
            umean[j, :, :k], ustd[j, :, :k] = u["chain_mean"], u["chain_std"]
            r.update(eta_uniform=u["eta"], eta_uniform_gap=u["gap"], rhat=u["rhat"], dim_uniform=u["dimension"],
                     mixed=float(chains_agree(u["gap"], u["rhat"])), uniform_per_chain=u["per_chain"],
                     **r["centrality"])
        r["walk_ok"] = int(r["ok"].sum())
        r.setdefault("mixed", 0.0)
    scal = {q: np.array([r.get(q, np.nan) for r in rows], float) for q in SCALARS}
    for q in ("bounded", "bounded_cell", "mixed", "rest_exact"):
        scal[q] = scal[q].astype(np.int8)
    data = {q: _var("packing", v, "N" if q == "scale" else "1", SCALARS[q]) for q, v in scal.items()}
    b = table["build"][sel]
    row_of = {int(x): i for i, x in enumerate(builds.build.values)}
    bj = np.array([row_of[int(x)] for x in b])
    data.update(
        kind=_var("packing", table["kind"][sel], "1", "series: 0 plates, 1 control (built frictionless)"),
        mu=_var("packing", table["mu"][sel], "1", "friction coefficient of the analysis"),
        mu_index=_var("packing", table["mu_index"][sel], "1", "index of mu in the grid"),
        build_index=_var("packing", b, "1", "build analysed"),
        frictional_build=_var("packing", (builds.build_mu.values[bj] > 0).astype(np.int8), "1",
                              "1: the build had friction"),
        walk_n=_var(("packing", "sample", "contact"), walk[..., 0], "N", "normal force, random-walk sample"),
        walk_t=_var(("packing", "sample", "contact"), walk[..., 1], "N", "tangential force, random-walk sample"),
        walk_point=_var(("packing", "sample"), ok, "1", "1: the sample is a point of A ∩ C (checked)"),
        history_n=_var(("packing", "contact"), ref[..., 0], "N", "normal force of the history state"),
        history_t=_var(("packing", "contact"), ref[..., 1], "N", "tangential force of the history state"),
        force_min_n=_var(("packing", "contact"), lo[..., 0], "N", "least normal force over A ∩ C"),
        force_max_n=_var(("packing", "contact"), hi[..., 0], "N", "largest normal force over A ∩ C"),
        force_min_t=_var(("packing", "contact"), lo[..., 1], "N", "least tangential force over A ∩ C"),
        force_max_t=_var(("packing", "contact"), hi[..., 1], "N", "largest tangential force over A ∩ C"),
        uniform_mean_n=_var(("packing", "chain", "contact"), umean[..., 0], "N", "chain mean of r_n"),
        uniform_mean_t=_var(("packing", "chain", "contact"), umean[..., 1], "N", "chain mean of r_t"),
        uniform_std_n=_var(("packing", "chain", "contact"), ustd[..., 0], "N", "chain standard deviation of r_n"),
        uniform_std_t=_var(("packing", "chain", "contact"), ustd[..., 1], "N", "chain standard deviation of r_t"))
    return xr.Dataset(data, coords=_coords(packing=sel, sample=np.arange(m), contact=np.arange(kmax),
                                           chain=np.arange(2)),
                      attrs=provenance(_no_shards(cfg), SolverSettings(**cfg["walk"]["solver"])))


def merge(build_paths, analysis_paths):
    """Build and analysis shards -> one Dataset over every analysis (contact padding: NaN)."""
    builds = merge_shards(build_paths, dim="build")
    ds = merge_shards(analysis_paths, dim="packing")
    return xr.merge([ds, builds], combine_attrs="override")


def builds_of(paths):
    """Every build shard as one Dataset (the input of each analysis shard)."""
    return merge_shards(paths, dim="build")


def mixed_only(ds):
    """``ds`` with the uniform sample's measures NaN where its two chains disagree (not mixed)."""
    ds = ds.copy()
    for q in ("eta_uniform", "history_distance", "uniform_distance", "walk_distance", "history_rank"):
        ds[q] = ds[q].where(ds.mixed == 1)
    return ds


def eta_table(ds, var="eta_walk", kind=0):
    """Per mu: mean, 95 % band (t-interval over packings), count of ``var`` for ``kind``."""
    sel = ds.kind.values == kind
    rows = []
    for i in np.unique(ds.mu_index.values[sel]):
        v = ds[var].values[sel & (ds.mu_index.values == i)]
        v = v[np.isfinite(v)]
        half = stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / np.sqrt(len(v)) if len(v) > 1 else np.nan
        rows.append((float(ds.mu.values[sel & (ds.mu_index.values == i)][0]), v.mean() if len(v) else np.nan,
                     half, len(v)))
    return np.array(rows).reshape(-1, 4)


__all__ = ["KINDS", "mu_values", "build_table", "analysis_table", "ballistic", "initial_cell", "build",
           "pack_shard", "cell_of", "exact_rest", "slice_of", "coordination", "analyse", "plates_bounded", "measured_slice", "analysis_shard",
           "merge", "builds_of", "mixed_only", "eta_table", "SCALARS"]
