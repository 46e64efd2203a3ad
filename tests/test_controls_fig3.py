"""Controls of Figure 3's judging functions: data where each sentence holds (reproduced) and
where it is false (differs), written to ``tmp_path/fig3_equilibrium/<file>.nc`` in the
layout the functions read.

The files that need a real packing (state, exact projections, uniform sample) come from the
figure's own producing code on a packing of ten discs (:func:`mini`, a few seconds); the
clouds are then replaced by points placed where the sentence is true or false: on the
boundary of A ∩ C or shrunk into its interior, many on one vertex or each on its own face,
spread over the set or gathered at one limit.
"""
import copy
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from ncd.core.contacts import external_load, h_matrix
from ncd.core.scene import make_scene
from ncd.exact.polytope import ForcePolytope
from ncd.figures.fig3_equilibrium import claims as cl
from ncd.figures.fig3_equilibrium import faces, probes
from ncd.figures.fig3_equilibrium import measure as fe
from ncd.figures.fig3_equilibrium.packing import rest_problem
from ncd.shared.verdict import BEYOND, DIFFERS, REPRODUCED

ROOT = Path(__file__).resolve().parent.parent
D = "fig3_equilibrium"


def config():
    """The figure's configuration, shrunk to ten discs in a box of seven diameters (the full width)."""
    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config.yaml").read_text())["fig3_equilibrium"])
    cfg["packing"].update(n_discs=10, width=0.07, seed=1)
    cfg["modes"] = {"zero": {"runs": 40, "review": "random"},
                    "random": {"runs": 20, "review": "fixed", "guess_factor": 1.0},
                    "warm": {"runs": 5, "review": "random"}}
    cfg["uniform"] = {"chains": 4, "per_chain": 500, "thin": 0, "burn": 0, "rounds": 2, "root_seed": 2006}
    return cfg


@pytest.fixture(scope="module")
def mini():
    """A small Figure 3 made by the figure's code: state, ensemble, projection, uniform."""
    cfg = config()
    scene, info = fe.deposit(cfg)
    state = fe.state_dataset(scene, info, cfg)
    ens = xr.concat([fe.run_ensemble(state, cfg, m, 0, 1) for m in fe.MODES], "run", data_vars="minimal",
                    coords="minimal", compat="override", join="outer", combine_attrs="override")
    return {"state": state, "ensemble": ens, "projection": fe.projection_dataset(state, cfg),
            "uniform": fe.uniform_dataset(state, cfg), "P": fe.polytope_of(state)}


def write(root, **datasets):
    """``root/fig3_equilibrium/<name>.nc`` for each dataset; returns ``root``."""
    (root / D).mkdir(parents=True, exist_ok=True)
    for name, ds in datasets.items():
        ds.to_netcdf(root / D / f"{name}.nc")
    return root


def ensemble_of(modes, solver_tol=1e-8, sweeps=None):
    """An ensemble.nc of given force vectors per mode (``{mode: (runs, 2 kappa)}``), every run
    converged and at rest; ``sweeps``: ``{mode: sweeps per run}``."""
    forces = np.concatenate([np.asarray(modes[m], float) for m in fe.MODES])
    mode = np.concatenate([np.full(len(modes[m]), k, np.int8) for k, m in enumerate(fe.MODES)])
    n = len(forces)
    sw = np.concatenate([np.broadcast_to(np.asarray((sweeps or {}).get(m, 100), np.int64), (len(modes[m]),))
                         for m in fe.MODES])
    ds = xr.Dataset({"force_n": (("run", "contact"), forces[:, 0::2]), "force_t": (("run", "contact"), forces[:, 1::2]),
                     "sweeps": ("run", sw), "residual": ("run", np.full(n, 1e-11)),
                     "converged": ("run", np.ones(n, np.int8)), "outcome": ("run", np.ones(n, np.int8)),
                     "max_speed": ("run", np.zeros(n)), "mode": ("run", mode)},
                    coords={"run": np.arange(n), "contact": np.arange(forces.shape[1] // 2)},
                    attrs={"solver_tol": solver_tol})
    ds["mode"].attrs.update(flag_values=np.arange(3, dtype=np.int8), flag_meanings=" ".join(fe.MODES))
    return ds


def points(ds):
    return np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)


def to_boundary(P, X, c):
    """Each point of ``X`` pushed from the centre ``c`` along its ray to the boundary of A ∩ C."""
    G = P.G.toarray()
    slack = -(G @ c) / P.scale
    out = []
    for x in X:
        gd = G @ (x - c) / P.scale
        t = np.min(slack[gd > 1e-15] / gd[gd > 1e-15])
        out.append(c + t * (x - c))
    return np.array(out)


def with_clouds(tmp_path, mini, zero, random=None, warm=None):
    """The mini run's state, projection and uniform sample with the given clouds."""
    u = points(mini["uniform"])
    modes = {"zero": zero, "random": u[:20] if random is None else random, "warm": u[:3] if warm is None else warm}
    return write(tmp_path, state=mini["state"], projection=mini["projection"], uniform=mini["uniform"],
                 ensemble=ensemble_of(modes))


# ------------------------------------------------------------------ s2-warm-accelerates (at rest)
def test_warm_start_at_rest_controls(tmp_path):
    X = np.ones((10, 4))
    fast = ensemble_of({"zero": X, "random": X[:2], "warm": X[:5]}, sweeps={"zero": 900, "warm": 40})
    v = cl.warm_accelerates_rest(write(tmp_path / "a", ensemble=fast))
    assert v.verdict == REPRODUCED and "900 sweeps from the zero guess" in v.value and "22×" in v.value
    assert "at rest only" in v.criterion
    same = ensemble_of({"zero": X, "random": X[:2], "warm": X[:5]}, sweeps={"zero": 900, "warm": 900})
    assert cl.warm_accelerates_rest(write(tmp_path / "b", ensemble=same)).verdict == DIFFERS
    twice = ensemble_of({"zero": X, "random": X[:2], "warm": X[:5]}, sweeps={"zero": 900, "warm": 450})
    assert cl.warm_accelerates_rest(write(tmp_path / "c", ensemble=twice)).verdict == DIFFERS


# ------------------------------------------------------------------ s2-equilibrium-test
def test_equilibrium_test_agrees_with_the_lp_on_a_packing(tmp_path, mini):
    v = cl.equilibrium_test(write(tmp_path, probes=probes.probe_dataset(mini["state"])))
    assert v.verdict == REPRODUCED, v.value
    assert "the packing: u_f = 0, A ∩ C ≠ ∅" in v.value and "lifted by half its radius" in v.value
    assert "μ = 0.9 μ*" in v.value and "A ∩ C = ∅" in v.value and "8 of 8 steps" in v.value


def roof_state(beta_deg=20.0, mu=0.75, radius=0.01):
    """Figure 1's wedged disc with two walls for obstacles: a roof whose faces touch the disc
    with normals beta below the horizontal.  With tan beta < mu it may stay wedged (A ∩ C is
    non-empty) or fall; from the zero guess the step finds the fall."""
    cfg = config()
    cfg["packing"].update(mu=mu, n_discs=1)
    b = np.radians(beta_deg)
    normals = np.array([[np.cos(b), -np.sin(b)], [-np.cos(b), -np.sin(b)]])
    walls = [(tuple(-radius * n), tuple(n)) for n in normals]
    scene = make_scene([[0.0, 0.0]], radius, 1.0, walls=walls, gravity=(0.0, -9.81), mu=mu)
    h = cfg["packing"]["h"]
    c = rest_problem(scene, h).contacts
    assert c.n == 2
    wedged = ForcePolytope(h_matrix(scene, c), external_load(scene), c.mu).feasible()
    scene.prev_keys, scene.prev_impulse = c.key.copy(), wedged.reshape(-1, 2) * h
    st = fe.state_dataset(scene, {}, cfg).drop_dims("wall")
    return st.assign({"wall_point_x": ("wall", [w[0][0] for w in walls]), "wall_point_y": ("wall", [w[0][1] for w in walls]),
                      "wall_normal_x": ("wall", normals[:, 0]), "wall_normal_y": ("wall", normals[:, 1])}
                     ).assign_coords(wall=np.arange(2))


def test_equilibrium_test_differs_on_a_wedged_disc(tmp_path):
    """An equilibrium the step from the zero guess calls a fall: the sentence is false there."""
    v = cl.equilibrium_test(write(tmp_path, probes=probes.probe_dataset(roof_state())))
    assert v.verdict == DIFFERS
    assert "the packing: u_f = 0 from the warm guess only, A ∩ C ≠ ∅" in v.value, v.value


# ------------------------------------------------------------------ s4-outlines, s2-review-orders
def test_outline_controls(tmp_path, mini):
    u = points(mini["uniform"])
    spread = with_clouds(tmp_path / "a", mini, u[::25])            # 80 points over the whole set
    for f in (cl.fig3_outlines, cl.fig3_review_orders):
        v = f(spread)
        assert v.verdict == REPRODUCED, (f.__name__, v.value)
    v = cl.fig3_review_orders(spread)
    assert "(κ − 1)! = " in v.value and "80 zero-guess runs at rest reached 80 distinct solutions" in v.value
    assert "consistent by construction" in v.criterion
    c = u.mean(0)
    gathered = with_clouds(tmp_path / "b", mini, c + 0.05 * (u[::25] - c))   # a cloud a twentieth as wide
    for f in (cl.fig3_outlines, cl.fig3_review_orders):
        assert f(gathered).verdict == DIFFERS, f.__name__


# ------------------------------------------------------------------ s4-in-cones
def test_in_cones_controls(tmp_path, mini):
    assert cl.fig3_in_cones(write(tmp_path / "a", state=mini["state"], ensemble=mini["ensemble"])).verdict == REPRODUCED
    ens = mini["ensemble"].copy(deep=True)
    k = int(np.argmax(ens.force_n.values[0]))
    ens.force_t[0, k] = 1.2 * float(mini["state"].mu[k]) * float(ens.force_n[0, k])    # outside its sector
    v = cl.fig3_in_cones(write(tmp_path / "b", state=mini["state"], ensemble=ens))
    n = ens.sizes["run"]
    assert v.verdict == DIFFERS and f"{n - 1} of {n} converged runs" in v.value


# ------------------------------------------------------------------ s4-denser-boundary
def test_boundary_density_controls(tmp_path, mini):
    P, u = mini["P"], points(mini["uniform"])
    c = u.mean(0)
    # the figure's own NLGS runs (zero guess, random orders) on the small packing
    v = cl.fig3_boundary(write(tmp_path / "nlgs", **{k: mini[k] for k in ("state", "ensemble", "projection", "uniform")}))
    assert v.verdict == REPRODUCED, v.value
    on_boundary = to_boundary(P, u[1::50], c)
    v = cl.fig3_boundary(with_clouds(tmp_path / "a", mini, on_boundary))
    assert v.verdict == REPRODUCED and "zero-guess 100.0 %" in v.value
    # the same solutions moved halfway to the centre: in the interior, none near the boundary
    v = cl.fig3_boundary(with_clouds(tmp_path / "b", mini, c + 0.5 * (on_boundary - c)))
    assert v.verdict == DIFFERS and "zero-guess 0.0 %" in v.value
    # an unstructured sample for the solutions: no denser near the boundary than the reference
    frame = faces.hull_frame(P)
    x0, Z = frame[0], frame[1]
    rng = np.random.default_rng(0)
    fresh = P.uniform_samples(lambda k: np.random.default_rng(100 + k), 2, 200)[0]
    assert faces.depth(frame, P, fresh).min() > 0 and x0.shape[0] == Z.shape[0]
    assert cl.fig3_boundary(with_clouds(tmp_path / "c", mini, fresh[rng.permutation(len(fresh))])).verdict == DIFFERS


# ------------------------------------------------------------------ s4-ghost-images
def test_ghost_image_controls(tmp_path, mini):
    P, u = mini["P"], points(mini["uniform"])
    rng = np.random.default_rng(1)
    vertex = P.support(0, [1.0, 0.0])
    _, dims, _ = faces.face_classes(P, vertex[None])
    assert dims[0] == 0
    many = np.vstack([np.tile(vertex, (12, 1)), u[::40]])               # twelve solutions on one vertex
    v = cl.fig3_ghosts(with_clouds(tmp_path / "a", mini, many))
    assert v.verdict == REPRODUCED and "12 on a vertex" in v.value
    # solutions each on a different face: distinct vertices, one solution each, and interior points
    verts = np.unique(np.round([P.support(int(rng.integers(P.n_contacts)), rng.standard_normal(2))
                                for _ in range(40)], 12), axis=0)
    v = cl.fig3_ghosts(with_clouds(tmp_path / "b", mini, np.vstack([verts, u[::40]])))
    assert v.verdict == DIFFERS and "zero-guess none" in v.value
    assert cl.fig3_ghosts(with_clouds(tmp_path / "c", mini, u[::20])).verdict == DIFFERS


# ------------------------------------------------------------------ s4-dimension-A, s4-force-set
def projection_attrs(dim_a, dim_m, n_lp=100):
    return xr.Dataset({"area": ("contact", np.ones(5))}, coords={"contact": np.arange(5)},
                      attrs={"dimension_A": dim_a, "dimension_moreau": dim_m, "n_discs": 2, "n_contacts": 5,
                             "dimension_AC": dim_a, "bounded": 1, "n_lp_total": n_lp})


def test_dimension_controls(tmp_path):
    assert cl.fig3_dimension(write(tmp_path / "a", projection=projection_attrs(4, 4))).verdict == REPRODUCED
    v = cl.fig3_dimension(write(tmp_path / "b", projection=projection_attrs(5, 4)))
    assert v.verdict == DIFFERS and "rank H = 5 < 3N" in v.value


def test_exact_set_is_measured_beyond_the_paper(tmp_path):
    a = cl.fig3_exact(write(tmp_path / "a", projection=projection_attrs(4, 4, 100)))
    b = cl.fig3_exact(write(tmp_path / "b", projection=projection_attrs(3, 4, 250)))
    assert a.verdict == b.verdict == BEYOND
    assert "(100 LPs)" in a.value and "(250 LPs)" in b.value and "dim A ∩ C = 3" in b.value


# ------------------------------------------------------------------ s2-limit-depends-on-order
def test_limit_depends_on_order_controls(tmp_path):
    rng = np.random.default_rng(2)
    proj = xr.Dataset(attrs={"force_scale": 2.0})
    base = rng.uniform(0.5, 1.5, 8)
    distinct = base + 0.01 * rng.standard_normal((50, 8))                # each order its own limit
    one = base + 1e-10 * rng.standard_normal((50, 8))                    # one limit within the tolerance
    warm = base + 1e-10 * rng.standard_normal((5, 8))
    v = cl.limit_depends_on_order(write(tmp_path / "a", projection=proj,
                                        ensemble=ensemble_of({"zero": distinct, "random": one[:2], "warm": warm})))
    assert v.verdict == REPRODUCED and "reach 50 distinct limits" in v.value and "reach 1 distinct limit" in v.value
    v = cl.limit_depends_on_order(write(tmp_path / "b", projection=proj,
                                        ensemble=ensemble_of({"zero": one, "random": one[:2], "warm": warm})))
    assert v.verdict == DIFFERS and "reach 1 distinct limits" in v.value
    mostly = np.vstack([one[:40], distinct[:10]])                        # most orders give one limit
    v = cl.limit_depends_on_order(write(tmp_path / "c", projection=proj,
                                        ensemble=ensemble_of({"zero": mostly, "random": one[:2], "warm": warm})))
    assert v.verdict == DIFFERS and "the most shared by 40" in v.value


def test_judges_table():
    assert cl.JUDGES["s2-limit-depends-on-order"] == (cl.limit_depends_on_order,)
    assert len(cl.JUDGES) == 10 and all(len(f) == 1 for f in cl.JUDGES.values())
