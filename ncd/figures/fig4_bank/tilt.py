"""A tilting test of the bank: the friction angle of the piles' own grains (Moreau 2005, end of section 5).

"The peripheral bank lies in a state of incipient failure" says that the flank stands at the
material's friction angle.  Whether it does is measured here, as on a tilting table: from the
final state of a pile (its history forces as warm start), gravity is turned by ``alpha``
towards one flank in steps of ``tilt.step_deg``, each held at least ``tilt.hold`` times
``sqrt(d/g)`` and then until the pile is back at rest, with the Moreau-Jean steps and solver
settings of the pile's construction, until the flank fails.  Turning gravity is turning the whole pile with its ground: that flank's slope becomes
``theta + alpha`` (the other flank's ``theta - alpha``), so each flank is its own test.

Failure (:func:`tilt_flank`): at least ``tilt.grains`` grains on the tilted side of the axis
have moved more than ``tilt.displaced_d`` mean diameters since the start.  Rigid grains at rest
do not move at all under a tilt the packing withstands (only the solver's tolerance lets them
creep, by far less than a diameter); a grain that moved half a diameter has left its pocket, and
one such grain alone is a single grain rolling on the surface, not a failure of the bank: ten,
a surface layer over a stretch of the flank, are.  The smallest tilt where this happens is
``alpha_fail``; ``theta_fail = theta + alpha_fail`` (``theta`` the flank's fitted slope,
:func:`ncd.figures.fig4_bank.measure.pile_geometry`, the fit every page reads) is the
maximum angle of stability of the bank, the measured friction angle phi of its grains.
"""
import time

import numpy as np
import xarray as xr
import yaml

from ncd.dynamics.stepper import step
from ncd.figures.fig4_bank.measure import FLANKS, HISTORY_LABELS, pile_geometry
from ncd.shared.pile import equilibrium_problem, final_scene
from ncd.solver.settings import SolverSettings

# the sections of the building config the tilted scene and its steps read, checked against the pile's file
SCENE_KEYS = ("grains", "mu", "mu_ground", "gravity", "h", "construction")
TILT_KEYS = ("step_deg", "max_deg", "hold", "max_hold", "check_every", "displaced_d", "grains", "hysteresis_deg")


def check_tilt(t):
    """The ``fig4_bank.tilt`` section beyond its schema: every key present, positive, ``max_deg >=
    step_deg`` and ``max_hold >= hold`` (a ValueError naming the key and its value)."""
    for k in TILT_KEYS:
        if k not in t:
            raise ValueError(f"fig4_bank.tilt: key {k!r} missing")
        if not np.isfinite(t[k]) or t[k] < 0 or (t[k] == 0 and k != "hysteresis_deg"):
            raise ValueError(f"fig4_bank.tilt.{k} = {t[k]!r} must be a positive number")
    if t["max_deg"] < t["step_deg"]:
        raise ValueError(f"fig4_bank.tilt.max_deg = {t['max_deg']!r} is below step_deg = {t['step_deg']!r}")
    if t["max_hold"] < t["hold"]:
        raise ValueError(f"fig4_bank.tilt.max_hold = {t['max_hold']!r} is below hold = {t['hold']!r}")


def config_text(cfg):
    """A config section as the YAML text a provenance attribute holds."""
    return yaml.safe_dump(cfg, sort_keys=True)


def levels(t):
    """The tilt angles (degrees): ``step_deg, 2 step_deg, ...`` up to ``max_deg``."""
    check_tilt(t)
    return t["step_deg"] * np.arange(1, int(np.floor(t["max_deg"] / t["step_deg"] + 1e-9)) + 1)


def hold_steps(t, d, g, h):
    """Steps per tilt level: ``hold`` times ``sqrt(d/g)`` (the time a grain takes to fall over
    a diameter's scale), at least one."""
    return max(1, int(np.ceil(t["hold"] * np.sqrt(d / g) / h)))


def check_pile_config(pile_cfg, ds, name):
    """The config that steps the pile must be the one that built it (its file's ``config_yaml``):
    a ValueError naming the first key that differs."""
    if "config_yaml" not in ds.attrs:
        raise ValueError(f"pile {name!r}: its file has no config_yaml attribute (not a pile file)")
    built = yaml.safe_load(ds.attrs["config_yaml"])
    for k in SCENE_KEYS:
        if k not in pile_cfg:
            raise ValueError(f"pile {name!r}: the pile config lacks key {k!r}")
        if built.get(k) != pile_cfg[k]:
            raise ValueError(f"pile {name!r}: config key {k!r} = {pile_cfg[k]!r} differs from the value that built "
                             f"it, {built.get(k)!r}")


def start_scene(pile_cfg, ds):
    """The pile's final scene at rest, warm-started from its history forces (impulses ``r h``),
    its contacts checked against the file's (:func:`ncd.shared.pile.equilibrium_problem`)."""
    scene = final_scene(pile_cfg, ds)
    equilibrium_problem(pile_cfg, scene, ds)
    scene.prev_keys = ds["key"].values.copy()
    scene.prev_impulse = pile_cfg["h"] * np.column_stack([ds["force_n"].values, ds["force_t"].values])
    return scene


def _kinetic_energy(scene):
    nm = scene.n_mobile
    m, v = scene.mass[:nm], scene.vel[:nm]
    return float(0.5 * np.sum(m * (v[:, 0] ** 2 + v[:, 1] ** 2))
                 + 0.25 * np.sum(m * scene.radius[:nm] ** 2 * scene.spin[:nm] ** 2))


def tilt_flank(scene, outer, h, settings, t, d, rest_speed, log=None, label=""):
    """Tilt ``scene`` (in place) towards the flank ``outer`` (+1 right, -1 left) level by level
    (:func:`levels`).  Each level is held at least ``hold`` and then until every grain is slower
    than ``rest_speed`` (m/s), at most ``max_hold`` (both in ``sqrt(d/g)``): the next tilt comes
    once the pile is back at rest, as on a slowly turned tilting table, so that the failing level
    is the one where motion starts and does not stop.  Every ``check_every`` steps the grains
    with ``outer x > 0`` at the start that moved more than ``displaced_d`` d since then are
    counted; the test stops at the first count of at least ``grains`` (failure).

    Returns ``dict(alpha_fail, failed, steps)`` and per level ``displaced, max_displacement,
    ke_end, ke_max, sweeps, held`` (NaN after the failing level; ``alpha_fail`` NaN without failure)."""
    al = levels(t)
    nm = scene.n_mobile
    g = float(np.linalg.norm(scene.gravity))
    pos0 = scene.pos[:nm].copy()
    side = outer * pos0[:, 0] > 0
    n_hold, n_max = hold_steps(t, d, g, h), hold_steps({"hold": t["max_hold"]}, d, g, h)
    every = int(t["check_every"])
    out = {k: np.full(len(al), np.nan) for k in ("displaced", "max_displacement", "ke_end", "ke_max", "sweeps",
                                                 "held")}
    alpha_fail, steps = np.nan, 0
    t0 = time.perf_counter()
    for i, a in enumerate(al):
        r = np.radians(a)
        scene.gravity = np.array([outer * g * np.sin(r), -g * np.cos(r)])
        ke_max, sweeps, count, disp = 0.0, 0, 0, np.zeros(nm)
        for k in range(1, n_max + 1):
            rep = step(scene, h, settings=settings, init="warm")
            sweeps += rep.sweeps
            ke_max = max(ke_max, _kinetic_energy(scene))
            if k % every and k != n_max:
                continue
            disp = np.hypot(*(scene.pos[:nm] - pos0).T)
            count = int(np.sum(disp[side] > t["displaced_d"] * d))
            if count >= t["grains"]:
                break
            if k >= n_hold and np.hypot(*scene.vel[:nm].T).max() < rest_speed:
                break
        steps += k
        out["displaced"][i], out["max_displacement"][i] = count, float(disp[side].max(initial=0.0)) / d
        out["ke_end"][i], out["ke_max"][i], out["sweeps"][i] = _kinetic_energy(scene), ke_max, sweeps / k
        out["held"][i] = k * h / np.sqrt(d / g)
        if count >= t["grains"]:
            alpha_fail = float(a)
            break
    if log is not None:
        log.info("%s %s flank: %s after %d steps, %.1f s", label, "right" if outer > 0 else "left",
                 f"fails at alpha = {alpha_fail:g} deg" if np.isfinite(alpha_fail) else
                 f"no failure up to {al[-1]:g} deg", steps, time.perf_counter() - t0)
    return dict(alpha_fail=alpha_fail, failed=bool(np.isfinite(alpha_fail)), steps=steps, **out)


def tilt_pile(t, pile_cfg, ds, cuts=None, name="", log=None):
    """Both flanks of one pile (each from the same start): the fitted flank slopes ``theta``
    (``cuts``: the default pile's cuts.nc, else the pile file's own fits) and the
    :func:`tilt_flank` of each, with the construction's step, solver settings and rest speed
    (``construction.rest_speed`` sqrt(g d), below which the construction tries its equilibrium test)."""
    check_pile_config(pile_cfg, ds, name)
    geom = pile_geometry(ds, cuts)
    settings = SolverSettings(**pile_cfg["construction"]["settings"])
    rest = pile_cfg["construction"]["rest_speed"] * np.sqrt(pile_cfg["gravity"] * geom["d"])
    res = {"theta": np.array([geom["fits"][f]["angle"] for f, _ in FLANKS]), "flanks": []}
    for _, outer in FLANKS:
        res["flanks"].append(tilt_flank(start_scene(pile_cfg, ds), outer, pile_cfg["h"], settings, t, geom["d"],
                                        rest, log, name))
    res["d"], res["n_grains"] = geom["d"], int(ds.sizes["grain"])
    return res


def censored(alpha_fail, t):
    """``alpha_fail`` with a flank that did not fail set to ``max_deg + step_deg`` (a lower bound
    of its failure tilt): medians and bands then rank it above every failed flank."""
    a = np.asarray(alpha_fail, float)
    return np.where(np.isfinite(a), a, t["max_deg"] + t["step_deg"])


def margin_band(values, analysis):
    """``(median, lo, hi)``: the median of ``values`` (piles x flanks) over piles and flanks and its
    percentile bootstrap band over piles (NaN band for one pile)."""
    v = np.asarray(values, float).reshape(len(values), -1)
    est = float(np.median(v))
    if len(v) < 2:
        return est, np.nan, np.nan
    rng = np.random.default_rng(analysis["seed"])
    idx = rng.integers(0, len(v), size=(analysis["bootstrap"], len(v)))
    boot = np.median(v[idx].reshape(len(idx), -1), axis=1)
    lo, hi = 0.5 * (1 - analysis["level"]), 0.5 * (1 + analysis["level"])
    return est, float(np.quantile(boot, lo)), float(np.quantile(boot, hi))


def tilt_dataset(cfg, piles):
    """tilt.nc from ``piles = [(name, history, source file, tilt_pile result)]``: per pile and flank
    the slope, the failure tilt and angle, the trajectory against the tilt; per history the
    median failure tilt over piles and flanks with a bootstrap band over piles (``cfg``: the
    fig4_bank section, its ``tilt`` and ``analysis``)."""
    t, a = cfg["tilt"], cfg["analysis"]
    al = levels(t)
    P, F, A, H = "pile", "flank", "alpha", "history"
    hist = np.array([p[1] for p in piles])
    histories = [h for h in HISTORY_LABELS if h in hist]
    theta = np.array([p[3]["theta"] for p in piles])
    per_flank = lambda k: np.array([[f[k] for f in p[3]["flanks"]] for p in piles])  # noqa: E731
    fail = per_flank("alpha_fail")
    data = {
        "pile_history": ((P,), hist, {"long_name": "construction history of the pile (default: fig4_pile)"}),
        "source_file": ((P,), np.array([str(p[2]) for p in piles]), {"long_name": "the pile's file, relative to the "
                        "workflow's directory"}),
        "theta": ((P, F), theta, {"units": "degree", "long_name": "fitted flank slope before the tilt"}),
        "alpha_fail": ((P, F), fail, {"units": "degree", "long_name": "smallest tilt towards the flank at which "
                                      "it fails (NaN: no failure up to max_deg)"}),
        "theta_fail": ((P, F), theta + fail, {"units": "degree", "long_name": "failure angle of the flank, "
                                              "theta + alpha_fail: the measured friction angle phi"}),
        "failed": ((P, F), np.isfinite(fail).astype(np.int8), {"units": "1", "long_name": "the flank failed "
                                                              "within max_deg"}),
        "steps": ((P, F), per_flank("steps"),
                  {"units": "1", "long_name": "Moreau-Jean steps of the test"}),
        "n_grains": ((P,), np.array([p[3]["n_grains"] for p in piles]), {"units": "1", "long_name": "grains"}),
        "displaced": ((P, F, A), per_flank("displaced"), {"units": "1", "long_name": "grains of the tilted side "
                      "displaced by more than displaced_d d since the start, at the end of the level"}),
        "max_displacement": ((P, F, A), per_flank("max_displacement"), {"units": "1", "long_name": "largest "
                             "displacement of a grain of the tilted side since the start, mean diameters"}),
        "kinetic_energy": ((P, F, A), per_flank("ke_end"), {"units": "J m-1", "long_name": "kinetic energy at the "
                           "end of the level (per unit depth)"}),
        "kinetic_energy_max": ((P, F, A), per_flank("ke_max"), {"units": "J m-1", "long_name": "largest kinetic "
                               "energy during the level"}),
        "sweeps": ((P, F, A), per_flank("sweeps"), {"units": "1", "long_name": "NLGS sweeps per step, mean over "
                   "the level"}),
        "held": ((P, F, A), per_flank("held"), {"units": "1", "long_name": "time the level was held (until back at "
                 "rest, or failure), in sqrt(d/g)"}),
    }
    band = np.full((len(histories), 3), np.nan)
    for i, h in enumerate(histories):
        band[i] = margin_band(censored(fail[hist == h], t), a)
    for j, end in enumerate(("", "_lo", "_hi")):
        what = "median over piles and flanks of alpha_fail (a flank without failure counted at max_deg + step_deg)"
        if end:
            what += f", {100 * a['level']:g} % bootstrap band over piles, {'lower' if end == '_lo' else 'upper'} end"
        data[f"margin{end}"] = ((H,), band[:, j], {"units": "degree", "long_name": what})
    ds = xr.Dataset(data, coords={P: [p[0] for p in piles], F: [f for f, _ in FLANKS], A: al, H: histories},
                    attrs={"step_deg": t["step_deg"], "max_deg": t["max_deg"], "hold": t["hold"],
                           "max_hold": t["max_hold"], "check_every": t["check_every"],
                           "displaced_d": t["displaced_d"], "grains": t["grains"],
                           "hysteresis_deg": t["hysteresis_deg"], "level": a["level"],
                           "bootstrap": a["bootstrap"], "seed": a["seed"]})
    ds[A].attrs.update(units="degree", long_name="tilt of gravity towards the flank")
    return ds
