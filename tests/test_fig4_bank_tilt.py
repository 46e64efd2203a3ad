"""The tilting test of the bank (ncd.figures.fig4_bank.tilt) and the one flank slope θ per pile.

A disc in the notch of two fixed discs falls over once gravity leans beyond the notch's half
angle, whatever its friction: tilted from a configuration already turned by theta0 it needs
theta0 less tilt (a steeper start fails sooner).  A small synthetic heap passes through the code
of fig4_pile (cuts.nc), of fig4_history (the fits stored in a pile file) and of fig4_bank
(measures, tilt): every one gives the same flank slopes, those of ncd.shared.pile.free_surface.
"""
import numpy as np
import pytest
import xarray as xr
import yaml

from ncd.core.scene import make_scene
from ncd.dynamics.stepper import equilibrium_test
from ncd.figures.fig4_bank import measure as bank
from ncd.figures.fig4_bank import tilt as tl
from ncd.io.netcdf import describe, missing_metadata
from ncd.shared.pile import construction_dataset, free_surface, make_ground, pile_scene
from ncd.solver.settings import SolverSettings

R = 1e-3
TILT = dict(step_deg=1.0, max_deg=45.0, hold=4.0, max_hold=40.0, check_every=5, displaced_d=0.5, grains=1,
            hysteresis_deg=2.0)


def notch(theta0, mu=0.5, spacing=1.1):
    """A mobile disc resting in the notch of two fixed discs ``2 spacing R`` apart (contact normals
    ``beta = asin(spacing / 2)`` from the vertical), the configuration turned by ``theta0`` so that
    its right side descends; returns the scene and beta in degrees."""
    beta = np.arcsin(spacing / 2)
    pts = np.array([[-spacing * R, 0.0], [spacing * R, 0.0], [0.0, 2 * R * np.cos(beta)]])
    a = np.radians(theta0)
    turn = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    pts = pts @ turn + np.array([10 * R, 0.0])        # the mobile disc on the right of the axis
    scene = make_scene(pts[2:], [R], 1000.0, obstacle_pos=pts[:2], obstacle_radius=[R, R], gravity=(0.0, -9.81),
                       mu=mu, mu_obstacle=mu)
    return scene, float(np.degrees(beta))


def notch_failure(theta0, mu=0.5):
    scene, beta = notch(theta0, mu)
    r = tl.tilt_flank(scene, 1, 1e-3, SolverSettings(tol=1e-10, max_sweeps=1000), TILT, 2 * R,
                      1e-3 * np.sqrt(9.81 * 2 * R))
    return r, beta


@pytest.mark.parametrize("mu", [0.5, 0.0])
def test_a_steeper_start_fails_after_less_tilt(mu):
    """The notch holds up to beta whatever the friction (one loaded contact cannot balance the
    torque); the test must find the first level above beta - theta0."""
    flat, beta = notch_failure(0.0, mu)
    steep, _ = notch_failure(10.0, mu)
    assert flat["failed"] and steep["failed"]
    assert beta < flat["alpha_fail"] <= beta + TILT["step_deg"]
    assert beta - 10.0 < steep["alpha_fail"] <= beta - 10.0 + TILT["step_deg"]
    # below the failing level the disc is back at rest in its notch after every tilt
    held = np.isfinite(flat["displaced"])
    assert np.all(flat["displaced"][held][:-1] == 0) and flat["displaced"][held][-1] >= 1
    assert np.all(flat["held"][held][:-1] < TILT["max_hold"])


def test_tilt_config_errors_name_the_key():
    with pytest.raises(ValueError, match="max_deg"):
        tl.check_tilt({**TILT, "max_deg": 0.5})
    with pytest.raises(ValueError, match="max_hold"):
        tl.check_tilt({**TILT, "max_hold": 1.0})
    with pytest.raises(ValueError, match="grains"):
        tl.check_tilt({k: v for k, v in TILT.items() if k != "grains"})
    with pytest.raises(ValueError, match="step_deg"):
        tl.check_tilt({**TILT, "step_deg": -1.0})
    assert tl.levels({**TILT, "step_deg": 0.5, "max_deg": 2.0}) == pytest.approx([0.5, 1.0, 1.5, 2.0])


# ------------------------------------------------------------------ one θ per pile
PILE_CFG = {
    "seed": 4, "grains": {"n": 0, "radius_min": 0.8e-3, "radius_max": 1.2e-3, "density": 1000.0},
    "ground": {"half_width_d": 20, "radius_min": 0.8e-3, "radius_max": 1.2e-3},
    "mu": 0.5, "mu_ground": 0.5, "gravity": 9.81, "h": 3.0e-4,
    "construction": {"settings": {"tol": 1.0e-3, "max_sweeps": 2000, "check_every": 10},
                     "equilibrium": {"tol": 1.0e-6, "max_sweeps": 20000, "check_every": 10},
                     "velocity_tol": 1.0e-6, "rest_speed": 3.0e-3, "overlap_tolerance": 0.25},
    "surface": {"bin_d": 1.0, "fit_range": [0.2, 0.8]},
    "cut": {"flank_fraction": 0.5, "shift_d": 1.0, "scan_step_d": 1.0, "segment": [0.0, 1.0]},
    "pressure": {"bin_d": 4.0},
}
BANK_CFG = {"positions": [0.3, 0.6], "depths_d": [1.0, 2.0], "length_d": 4.0, "window_d": 2.0,
            "ground_margin_d": 0.0}


@pytest.fixture(scope="module")
def heap():
    """A heap of equal discs on a triangular lattice, each row one grain shorter on the left and
    three on the right (flanks near 30° and 19°), apex over the axis, on a rough ground; its
    construction.nc as fig4_pile writes it (history forces of an equilibrium test)."""
    cfg = {**PILE_CFG, "grains": {**PILE_CFG["grains"], "n": 0}}
    rng = np.random.default_rng((0, cfg["seed"]))
    ground = make_ground(cfg, rng)
    r = 1.0e-3
    y_base = ground[1].max() + r + 1e-6
    width = 32
    pos = np.array([((k + j / 2) * 2 * r, y_base + j * np.sqrt(3) * r)
                    for j in range(width) for k in range(j, width - 3 * j)])
    pos[:, 0] -= pos[pos[:, 1].argmax(), 0]
    cfg["grains"]["n"] = len(pos)
    scene = pile_scene(cfg, pos, np.full(len(pos), r), *ground)
    eq = equilibrium_test(scene, cfg["h"], SolverSettings(**cfg["construction"]["equilibrium"]))
    rec = {k: np.zeros(1) for k in ("time", "n_grains", "kinetic_energy", "sweeps", "residual", "converged",
                                    "n_contacts", "max_penetration", "source_height", "wall_time")}
    ds = construction_dataset(cfg, scene, rec, ground, eq)
    ds.attrs["config_yaml"] = yaml.safe_dump(cfg, sort_keys=True)
    return cfg, ds


def test_every_page_reads_the_same_flank_slopes(heap):
    """fig4_pile's cuts.nc, a pile file's own fits (as fig4_history stores them), fig4_bank's
    measures and its tilting test give each flank of one pile the one slope of free_surface."""
    from ncd.figures.fig4_history.construct import base_half_width
    from ncd.figures.fig4_pile.measure import cuts_dataset

    cfg, ds = heap
    pos = np.column_stack([ds.x.values, ds.y.values])
    y0 = float(np.mean(ds.ground_radius.values))
    fits = free_surface(cfg, pos, ds.radius.values, y0)[2]
    want = np.array([fits["left"]["angle"], fits["right"]["angle"]])
    assert want == pytest.approx([30.0, 19.1], abs=3.0)        # the lattice's two flanks
    cuts = cuts_dataset(cfg, ds)                                    # fig4_pile
    np.testing.assert_array_equal([cuts.attrs["left_angle"], cuts.attrs["right_angle"]], want)
    stored = ds.copy()                                              # a pile file of fig4_history
    _, hfits = base_half_width(cfg, pos, ds.radius.values, y0)
    stored.attrs.update(y_ground=y0, point_half_width=0.1,
                        **{f"{f}_{q}": v for f in ("left", "right") for q, v in hfits[f].items()})
    for source, c in ((ds, cuts), (stored, None)):                  # fig4_bank, both kinds of pile
        geom = bank.pile_geometry(source, c)
        np.testing.assert_array_equal([geom["fits"]["left"]["angle"], geom["fits"]["right"]["angle"]], want)
        np.testing.assert_array_equal(bank.measure_pile(BANK_CFG, source, c)["surface_angle"], want)
    t = {**TILT, "step_deg": 0.5, "max_deg": 0.5, "hold": 1.0, "max_hold": 1.0, "grains": 10 ** 6}
    res = tl.tilt_pile(t, cfg, ds, cuts, "heap")
    np.testing.assert_array_equal(res["theta"], want)
    out = tl.tilt_dataset({"tilt": t, "analysis": {"bootstrap": 50, "level": 0.95, "seed": 1}},
                          [("default", "default", "construction.nc", res)])
    assert missing_metadata(describe(out)) == []           # as write_dataset writes it
    np.testing.assert_array_equal(out.theta.sel(pile="default").values, want)
    assert not out.failed.values.any() and np.isnan(out.theta_fail.values).all()


def test_a_pile_is_stepped_with_the_config_that_built_it(heap):
    cfg, ds = heap
    with pytest.raises(ValueError, match="'mu'"):
        tl.check_pile_config({**cfg, "mu": 0.3}, ds, "heap")
    with pytest.raises(ValueError, match="config_yaml"):
        tl.check_pile_config(cfg, ds.drop_attrs(), "heap")


# ------------------------------------------------------------------ the figure data
def test_data_tilt(results):
    t = xr.load_dataset(results / "fig4_bank" / "tilt.nc")
    assert missing_metadata(t) == []
    assert set(t.pile_history.values) == {"default", "point"}
    np.testing.assert_allclose(t.theta_fail.values, t.theta.values + t.alpha_fail.values)
    ms = xr.load_dataset(results / "fig4_bank" / "measures.nc")
    np.testing.assert_array_equal(t.theta.values, ms.surface_angle.sel(pile=t.pile.values).values)
    assert yaml.safe_load(t.attrs["config_yaml"])["tilt"]["step_deg"] == t.attrs["step_deg"]
