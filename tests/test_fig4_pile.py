"""Figure 4 (Moreau 2005, section 5): the pile poured from a localized source.

Unit tests of the cut resultant and the ground measures on hand-built cases,
then checks on the figure data of a whole-DAG run (fixture ``results``).
"""
import numpy as np
import pytest
import xarray as xr
import yaml

import ncd
from ncd.core.contacts import Contacts, h_matrix, match_warm
from ncd.figures.fig4_pile import exact as pile_exact
from ncd.figures.fig4_pile import measure as pile
from ncd.shared import construction
from ncd.shared import cuts as cm
from ncd.shared import pile as pile_scenes

# Stated bounds of the figure-data tests
MAX_DEVIATION_DEG = 10.0     # resultant across the default cut vs the free-surface slope
WEIGHT_TOL = 1e-6            # history forces: ground reaction vs weight (relative)
MOMENTUM_TOL = 1e-6          # every run: ground_fy - weight = sum m u_f,y / h (relative to the weight)
RUN_WEIGHT_TOL = 1e-2        # every converged zero-guess run: ground reaction vs weight (relative)


# ------------------------------------------------------------------ unit tests
def _contacts(body_a, body_b, normal, point):
    n = len(body_a)
    return Contacts(body_a=np.array(body_a), body_b=np.array(body_b), normal=np.array(normal, float),
                    point=np.array(point, float), gap=np.zeros(n), arm_a=np.ones(n), arm_b=np.ones(n),
                    shift_b=np.zeros(n), key=np.arange(n), mu=np.full(n, 0.5), e_n=np.zeros(n), e_t=np.zeros(n))


def test_cut_resultant_of_one_contact_by_hand():
    # grain 0 at x = 1, grain 1 at x = -1; normal from b = 1 to a = 0 is +x, tangent +y
    pos = np.array([[1.0, 1.0], [-1.0, 1.0]])
    c = _contacts([0], [1], [[1.0, 0.0]], [[0.0, 1.0]])
    s = np.array([[2.0, 0.5]])                       # force on grain 0: (2, 0.5) / h = (4, 1)
    F, n = cm.cut_resultant(c, s, pos, 2, 0.0, +1, h=0.5)
    np.testing.assert_allclose(F, [4.0, 1.0], rtol=1e-14)
    assert n == 1
    F, n = cm.cut_resultant(c, s, pos, 2, 0.0, -1, h=0.5)   # bank on the left: the force on grain 1
    np.testing.assert_allclose(F, [-4.0, -1.0], rtol=1e-14)
    assert cm.cut_resultant(c, s, pos, 2, 2.0, +1, h=0.5)[1] == 0           # the cut crosses nothing
    assert cm.cut_resultant(c, s, pos, 2, 0.0, +1, h=0.5, y_lo=1.5)[1] == 0  # crossing below the segment
    with pytest.raises(ValueError, match="outer"):
        cm.cut_resultant(c, s, pos, 2, 0.0, 0)


def test_cut_ignores_ground_contacts_and_uses_the_crossing_height():
    # grain 0 (x = 0.5, y = 1) on ground disc 2 (x = -0.5, y = 0); grains 0 and 1 (x = -0.5, y = 3)
    pos = np.array([[0.5, 1.0], [-0.5, 3.0], [-0.5, 0.0]])
    nrm = [(pos[0] - pos[2]) / np.linalg.norm(pos[0] - pos[2]), (pos[0] - pos[1]) / np.linalg.norm(pos[0] - pos[1])]
    c = _contacts([0, 0], [2, 1], nrm, [[0, 0.5], [0, 2]])
    sign, y = cm.cut_weights(c, pos, 2, 0.0, +1)
    np.testing.assert_array_equal(sign, [0, 1])
    assert y[1] == pytest.approx(2.0, abs=1e-14)     # midpoint of the centre line
    assert cm.cut_weights(c, pos, 2, 0.0, +1, y_hi=1.9)[0].tolist() == [0, 0]


@pytest.fixture(scope="module")
def little_pile():
    """Six grains at rest on a rough ground: forces of the (warm) equilibrium test."""
    r = 0.5
    ground = np.column_stack([np.arange(-2.5, 2.51, 1.0), np.zeros(6)])      # grains sit in the valleys
    y = np.sqrt(0.75)
    pos = [[-1.0, y], [0.0, y], [1.0, y], [-0.5, 2 * y], [0.5, 2 * y], [0.0, 3 * y]]
    scene = ncd.make_scene(pos, r, 1.0, obstacle_pos=ground, obstacle_radius=r, mu=0.5, overlap_tolerance=0.5)
    for _ in range(300):
        ncd.step(scene, 1e-3, settings=ncd.SolverSettings(tol=1e-10))
    eq = ncd.equilibrium_test(scene, 1e-3, settings=ncd.SolverSettings(tol=1e-12, max_sweeps=100000), init="warm")
    assert eq.at_rest
    return scene, eq


@pytest.mark.parametrize("x_cut, outer", [(0.25, +1), (-0.25, -1), (0.7, +1), (-0.7, -1)])
def test_cut_resultant_balances_the_bank(little_pile, x_cut, outer):
    """The force across the cut, the ground reaction and the weight of the bank sum to zero."""
    scene, eq = little_pile
    c, nm = eq.contacts, scene.n_mobile
    F, n = cm.cut_resultant(c, eq.forces, scene.pos, nm, x_cut, outer)
    assert n >= 2
    bank = np.nonzero(np.where(scene.pos[:nm, 0] >= x_cut, 1, -1) == outer)[0]
    ground = np.isin(c.body_a, bank) & (c.body_b >= nm)
    ex, ey = cm.contact_force_components(c)
    G = np.array([np.sum(ex[ground] * eq.forces[ground]), np.sum(ey[ground] * eq.forces[ground])])
    W = scene.mass[bank].sum() * scene.gravity
    np.testing.assert_allclose(F + G + W, 0.0, atol=1e-8 * np.linalg.norm(W))
    assert np.linalg.norm(F) > 1e-3 * np.linalg.norm(W)


def test_ground_matrix_total_and_bins(little_pile):
    scene, eq = little_pile
    nm = scene.n_mobile
    edges = np.linspace(-4.0, 4.0, 9)
    g = cm.ground_matrix(eq.contacts, nm, edges) @ eq.forces.ravel()
    weight = scene.mass[:nm].sum() * 9.81
    assert g[1] == pytest.approx(weight, rel=1e-8)
    assert abs(g[0]) < 1e-8 * weight
    assert g[2:].sum() == pytest.approx(g[1], rel=1e-12)
    c, f = eq.contacts, eq.forces
    by_hand = np.zeros(len(edges) - 1)
    for k in range(c.n):
        if c.body_b[k] >= nm:                          # a ground disc
            fy = f[k, 0] * c.normal[k, 1] + f[k, 1] * c.normal[k, 0]      # t_y = n_x
            by_hand[int(np.floor(c.point[k, 0] - edges[0]))] += fy
    np.testing.assert_allclose(g[2:], by_hand, rtol=1e-12, atol=1e-12 * weight)
    assert np.count_nonzero(by_hand) >= 2


def test_surface_fit_recovers_a_triangle():
    x = np.linspace(-20.0, 20.0, 81)
    height = np.maximum(0.0, 8.0 - np.abs(x) * np.tan(np.radians(22.0)))
    fits = cm.fit_flanks(x, height, 0.0, (0.2, 0.8))
    for side in ("left", "right"):
        assert fits[side]["angle"] == pytest.approx(22.0, abs=1e-9)
        assert abs(fits[side]["toe"]) == pytest.approx(8.0 / np.tan(np.radians(22.0)), rel=1e-9)
    phi, dev = cm.flank_angles(np.cos(np.radians(22.0)), -np.sin(np.radians(22.0)), +1, 22.0)
    assert phi == pytest.approx(22.0) and dev == pytest.approx(0.0, abs=1e-12)


def test_warm_memory_survives_pouring(little_pile):
    """Appending grains keeps the warm-start impulses of the persisting contacts."""
    scene, _ = little_pile
    cfg = {"grains": {"density": 1.0}, "gravity": 9.81, "mu": 0.5, "mu_ground": 0.5,
           "construction": {"overlap_tolerance": 0.5}}
    nm = scene.n_mobile
    pos = np.vstack([scene.pos[:nm], [[5.0, 3.0]]])
    new = pile_scenes.pile_scene(cfg, pos, np.append(scene.radius[:nm], 0.5), scene.pos[nm:], scene.radius[nm:])
    construction.carry_warm(scene, new)
    old = ncd.detect_contacts(scene, 1e-9)
    now = ncd.detect_contacts(new, 1e-9)
    np.testing.assert_array_equal(match_warm(now, new.prev_keys, new.prev_impulse),
                                  match_warm(old, scene.prev_keys, scene.prev_impulse))


# ------------------------------------------------------------------ figure data
@pytest.fixture(scope="module")
def data(results):
    d = results / "fig4_pile"
    out = {n: xr.load_dataset(d / f"{n}.nc") for n in ("construction", "cuts", "ensemble", "tolerance", "exact")}
    out["cfg"] = yaml.safe_load(out["construction"].attrs["config_yaml"])
    return out


def _final(data):
    cfg = data["cfg"]
    scene = pile_scenes.final_scene(cfg, data["construction"])
    problem = pile_scenes.equilibrium_problem(cfg, scene, data["construction"])
    return scene, problem


def test_final_state_is_an_equilibrium(data):
    """History forces balance gravity on every grain and obey Coulomb's law; the stored
    equilibrium test passed."""
    con = data["construction"]
    assert con.attrs["at_rest"] == 1 and con.attrs["eq_converged"] == 1
    assert con.attrs["eq_max_velocity"] <= data["cfg"]["construction"]["velocity_tol"]
    assert con.sizes["grain"] == data["cfg"]["grains"]["n"]
    scene, problem = _final(data)
    f = np.column_stack([con.force_n.values, con.force_t.values])
    H = h_matrix(scene, problem.contacts)
    m = scene.mass[: scene.n_mobile]
    gravity = np.column_stack([np.zeros_like(m), -9.81 * m, np.zeros_like(m)]).ravel()
    imbalance = (H @ f.ravel() + gravity).reshape(-1, 3)
    scale = np.column_stack([m * 9.81, m * 9.81, m * 9.81 * scene.radius[: scene.n_mobile]])
    assert np.max(np.abs(imbalance) / scale) < 1e-5
    assert np.all(f[:, 0] >= 0) and np.all(np.abs(f[:, 1]) <= problem.contacts.mu * f[:, 0] * (1 + 1e-9) + 1e-12)


def test_ground_reaction_equals_the_weight(data):
    cuts, ens = data["cuts"], data["ensemble"]
    W = cuts.attrs["weight"]
    assert cuts.attrs["history_ground_fy"] == pytest.approx(W, rel=WEIGHT_TOL)
    assert abs(cuts.attrs["history_ground_fx"]) < WEIGHT_TOL * W
    conv = ens.converged.values.astype(bool)
    assert conv.sum() >= 0.9 * ens.sizes["run"], "most runs converge"
    fy = ens.ground_fy.values[conv]
    # momentum balance of the step: exact up to the solver residual
    np.testing.assert_allclose(fy - W, ens.unbalanced_fy.values[conv], atol=MOMENTUM_TOL * W)
    # the ground carries the weight, less the grains the zero-guess runs let move
    assert np.max(np.abs(fy / W - 1)) < RUN_WEIGHT_TOL
    np.testing.assert_allclose(ens.ground_pressure.values[conv] @ np.asarray(cuts.bin_hi - cuts.bin_lo), fy,
                               rtol=1e-10)


def test_every_run_records_the_solver(data):
    for name in ("ensemble", "tolerance"):
        ds = data[name]
        conv = ds.converged.values.astype(bool)
        tol = np.broadcast_to(ds.tol.values, conv.shape)
        assert np.all(ds.residual.values[conv] <= tol[conv])
        assert np.all(ds.sweeps.values[~conv] == ds.attrs["max_sweeps"])
        assert np.all(ds.wall_time.values > 0)


def test_members_do_not_depend_on_the_shard(data):
    """A member's run depends on its member number only: the tolerance study repeats
    members 0..k-1 of the ensemble with another shard count (plain NLGS: the same runs
    where the ensemble is not finished); the last member of a finished ensemble, re-run
    alone here, gives the same bits."""
    ens, tol = data["ensemble"], data["tolerance"]
    keys = ("cut_force_x", "cut_force_y", "ground_pressure", "sweeps", "residual", "converged")
    assert tol.attrs["finish"] == "none"
    if ens.attrs["finish"] == "none":
        assert float(ens.tol) in tol.tol.values
        t = tol.sel(tol=float(ens.tol))
        e = ens.sel(run=t.run.values)
        for k in keys:
            np.testing.assert_array_equal(t[k].values, e[k].values)
        return
    cfg = yaml.safe_load(ens.attrs["config_yaml"])
    last = int(ens.run.values[-1])
    again = pile.ensemble_shard(cfg, data["construction"], data["cuts"], [last], [float(ens.tol)],
                                int(ens.attrs["root_seed"]))
    for k in keys + ("outcome", "finish_correction"):
        np.testing.assert_array_equal(again[k].isel(tol=0).values[0], ens[k].sel(run=last).values)


def test_tolerance_study_copies_only_what_a_fresh_run_repeats(data):
    """The tolerance study runs a member again at a tighter tolerance only when its looser run
    converged above it; every other entry is copied.  A fresh run of two members at the
    tightest tolerance alone gives the same bits as the study's entries there."""
    tol = data["tolerance"]
    cfg = yaml.safe_load(tol.attrs["config_yaml"])
    last = float(tol.tol.values[-1])
    members = [int(m) for m in tol.run.values[:2]]
    fresh = pile.ensemble_shard(cfg, data["construction"], data["cuts"], members, [last],
                                int(tol.attrs["root_seed"]), finish="none")
    for k in ("cut_force_x", "cut_force_y", "ground_pressure", "sweeps", "residual", "converged", "outcome"):
        np.testing.assert_array_equal(fresh[k].isel(tol=0).values, tol[k].sel(tol=last, run=members).values)


@pytest.fixture(scope="module")
def warm(results):
    return xr.load_dataset(results / "fig4_pile" / "warm.nc")


def test_warm_runs_start_from_the_antecedent_forces(data, warm):
    """warm.nc explores the ensemble's problem with its solver settings and cuts, from the
    construction's last impulses (matched on the contacts of the final state, close to the history
    forces: the pile was at rest), with the review orders of another root seed."""
    ens = data["ensemble"]
    assert warm.attrs["init"] == "warm" and ens.attrs["init"] == "zero"
    assert warm.attrs["root_seed"] != ens.attrs["root_seed"]
    for k in ("max_sweeps", "check_every", "moving_tol", "finish", "finish_tol", "h", "weight"):
        np.testing.assert_equal(warm.attrs[k], ens.attrs[k], err_msg=k)
    assert float(warm.tol) == float(ens.tol)
    np.testing.assert_array_equal(warm.cut.values, ens.cut.values)
    assert warm.attrs["guess_matched"] >= 0.95 * data["construction"].sizes["contact"]
    assert warm.attrs["guess_offset"] < 1e-3
    assert warm.converged.values.all()


def test_warm_members_do_not_depend_on_the_shard(data, warm):
    """The last warm member, re-run alone (the construction replayed again), gives the same bits."""
    cfg = yaml.safe_load(warm.attrs["config_yaml"])
    guess = pile.antecedent(cfg, data["construction"])
    last = int(warm.run.values[-1])
    again = pile.ensemble_shard(cfg, data["construction"], data["cuts"], [last], [float(warm.tol)],
                                int(warm.attrs["root_seed"]), finish=warm.attrs["finish"], guess=guess)
    for k in ("cut_force_x", "cut_force_y", "ground_pressure", "sweeps", "residual", "outcome", "max_speed"):
        np.testing.assert_array_equal(again[k].isel(tol=0).values[0], warm[k].sel(run=last).values)


def test_default_cut_resultant_is_parallel_to_the_surface(data):
    cuts, ens = data["cuts"], data["ensemble"]
    k = int(np.nonzero(cuts.kind.values == "default")[0][0])
    assert cuts.n_crossing[k] >= 2
    assert abs(float(cuts.history_deviation[k])) < MAX_DEVIATION_DEG
    rest = pile_exact.rest_mask(ens)                 # converged at rest only
    if rest.any():
        fx = ens.cut_force_x.values[rest, k].mean()
        fy = ens.cut_force_y.values[rest, k].mean()
        _, dev = cm.flank_angles(fx, fy, int(cuts.outer[k]), float(cuts.surface_angle[k]))
        assert abs(dev) < MAX_DEVIATION_DEG


def test_cloud_against_the_exact_polygon_and_the_cut_sensitivity(data):
    """Section 5 compares the cloud with the change of the resultant when the cut moves by
    one diameter.  The cloud of the rest runs is a subset of the exact projection of
    A ∩ C: its diameter is at most the polygon's, and the polygon is not a point (the
    pile is indeterminate).  Whether the cloud is smaller than the cut change is measured
    and reported (the notebook states it from these numbers), not assumed: at the
    default size the finished runs' cloud is wider than the smaller of the two changes."""
    cuts, ens, ex = data["cuts"], data["ensemble"], data["exact"]
    W = ex.attrs["weight"]
    kind = list(cuts.kind.values)
    k, km, kp = kind.index("default"), kind.index("minus"), kind.index("plus")
    conv = pile_exact.rest_mask(ens)
    assert conv.sum() >= 2, f"{conv.sum()} run(s) converged at rest: no cloud"
    P = np.column_stack([ens.cut_force_x.values[conv, k], ens.cut_force_y.values[conv, k]])
    diameter = pile_exact.diameter(P)
    exact = pile_exact.diameter(pile_exact.polygon_of(ex, k))
    assert 0.0 < diameter <= exact + 1e-8 * W, f"cloud {diameter:.4g} N, exact polygon {exact:.4g} N"
    F = np.column_stack([cuts.history_fx.values, cuts.history_fy.values])
    change = min(np.linalg.norm(F[km] - F[k]), np.linalg.norm(F[kp] - F[k]))
    assert change > 1e-6 * W              # the shifted cuts cross other contacts


def test_every_run_is_classified(data):
    """Outcomes: rest, motion or unconverged, counted; a rest run is a solution whose grains
    are at rest (largest speed <= 1e-8 g h) and whose residual met the finishing tolerance."""
    ens = data["ensemble"]
    e = yaml.safe_load(ens.attrs["config_yaml"])["ensemble"]     # the exploration's own config
    oc = ens.outcome.values
    assert set(np.unique(oc)) <= {0, 1, 2} and ens.outcome.attrs["flag_meanings"] == "unconverged rest motion"
    rest = oc == 1
    finished = e.get("finish", "none") != "none"
    if finished:                     # the reduced pile: the finishing stage converges there
        assert rest.sum() >= 1
    if rest.any():
        assert ens.max_speed.values[rest].max() <= 1e-8
        assert ens.residual.values[rest].max() <= (e["finish_tol"] if finished else e["tol"])
    assert np.all(ens.max_speed.values[oc == 2] > 1e-8)
    assert np.all(~ens.converged.values[oc == 0])


def test_exact_polygons_contain_every_converged_rest_run(data):
    """Every rest run's resultant lies inside the exact polygon of the default and shifted
    cuts to 1e-8 of the pile's weight; at every cut (scan cuts included) its angle lies in
    the exact angle range and its F_y in the exact F_y range; the history resultant too
    (to the equilibrium test's accuracy).  The angle ranges (Dinkelbach) agree with the
    polygons' own angles where both exist."""
    ens, ex = data["ensemble"], data["exact"]
    W = ex.attrs["weight"]
    rest = pile_exact.rest_mask(ens)
    assert ex.sizes["cut"] == data["cuts"].sizes["cut"]
    poly = ex.n_vertices.values > 0
    assert poly[:3].all() and not poly[3:].any() and ex.sizes["cut"] > 10
    for k in np.nonzero(poly)[0]:
        _, out, cov = pile_exact.cloud_in_polygon(ex, ens, k, rest)
        assert out.max(initial=0.0) <= 1e-8 * W, f"cut {k}: {out.max() / W:.2e} W outside"
        assert 0.0 <= cov <= 1.0 + 1e-9
    outer = data["cuts"].outer.values
    fx, fy = ens.cut_force_x.values[rest], ens.cut_force_y.values[rest]
    phi = np.degrees(np.arctan2(-fy, outer * fx))
    lo, hi = ex.angle_min.values, ex.angle_max.values
    ok = np.isfinite(lo)
    assert ok.mean() > 0.5 and np.all(ex.angle_bound.values[ok] <= 1e-6)
    above = (phi[:, ok] - lo[ok] + 1e-6) % 360.0            # angles compared modulo 360 degrees
    assert np.all(above <= hi[ok] - lo[ok] + 2e-6)
    assert np.all(fy >= ex.fy_min.values - 1e-8 * W) and np.all(fy <= ex.fy_max.values + 1e-8 * W)
    assert np.nanmax(ex.history_outside.values) <= 1e-6 * W and np.nanmax(ex.history_angle_outside.values) <= 1e-6
    assert ex.attrs["polygon_angle_gap"] <= 1e-6
    assert (ex.exact.values[poly] == 1).all() and ex.n_lp[0] >= yaml.safe_load(ex.attrs["config_yaml"])["exact"]["n_dirs"]


def test_lp_vertices_are_admissible_and_the_dip_verdict_follows_the_numbers(data):
    ex = data["exact"]
    assert ex.attrs["vertex_equilibrium"] <= 1e-10 and ex.attrs["vertex_coulomb"] <= 1e-10
    assert np.all(ex.bin_min.values <= ex.bin_max.values + 1e-9)
    assert np.all(ex.kernel_min.values <= ex.kernel_history.values + 1e-6 * ex.attrs["weight"])
    assert np.all(ex.kernel_history.values <= ex.kernel_max.values + 1e-6 * ex.attrs["weight"])
    m = list(ex.choice.values).index(ex.attrs["dip_main_choice"])
    lo, hi = float(ex.dip_min[m]), float(ex.dip_max[m])
    assert lo - 1e-6 <= float(ex.dip_history[m]) <= hi + 1e-6
    geometry = "forced" if lo > 0 else ("excluded" if hi <= 0 else "allowed")
    assert ex.attrs["dip_geometry"] == geometry
    # the dip depth: flank minus centre of the kernel pressure (> 0 a dip), in units of W / 2L
    assert "W/2L" in ex.dip_history.attrs["long_name"] and "> 0 a dip" in ex.dip_history.attrs["long_name"]
    cuts = data["cuts"]
    unit = ex.attrs["weight"] / (cuts.attrs["right_toe"] - cuts.attrs["left_toe"])
    assert abs(ex.attrs["dip_unit"] - unit) <= 1e-9 * unit
    # the main choice is the kernel of kernel_history: its dip read off that curve (another grid)
    x, p, a = ex.x_kernel.values, ex.kernel_history.values, ex.attrs["dip_offset"]
    flank_minus_centre = 0.5 * (np.interp(-a, x, p) + np.interp(a, x, p)) - np.interp(0.0, x, p)
    assert abs(float(ex.dip_history[m]) - flank_minus_centre / unit) <= 0.01
    # every admissible state arches across a cut exactly when the largest F_y is negative
    assert np.array_equal(ex.all_arch.values.astype(bool), ex.fy_max.values < 0)


def test_rest_runs_ground_pressure_lies_in_its_exact_band(data):
    """Every rest run's binned ground pressure lies inside the exact range of its bin over
    A ∩ C (exact.nc, the bins of cuts.nc) to 1e-6 of the weight per bin width; the kernel
    estimate states its width."""
    ens, ex, cuts = data["ensemble"], data["exact"], data["cuts"]
    W = ex.attrs["weight"]
    width = (cuts.bin_hi - cuts.bin_lo).values
    rest = pile_exact.rest_mask(ens)
    p = ens.ground_pressure.values[rest]
    slack = 1e-6 * W / width
    assert np.all(p >= ex.bin_min.values - slack) and np.all(p <= ex.bin_max.values + slack)
    assert np.all(ex.bin_max.values - ex.bin_min.values >= -1e-9 * W / width)
    assert ex.attrs["kernel_width"] == pytest.approx(ex.attrs["mean_diameter"]
                                                     * yaml.safe_load(ex.attrs["config_yaml"])["exact"]["kernel_d"])


# ------------------------------------------------------------------ the page (ncd.figures.fig4_pile.plots)
@pytest.fixture(scope="module")
def page_run(data):
    from ncd.figures.fig4_pile import plots as pile_plots

    cfg = yaml.safe_load(data["cuts"].attrs["config_yaml"])
    return pile_plots.PileRun(data["construction"], data["cuts"], data["ensemble"], data["exact"], cfg)


def test_page_figure_is_legible(page_run):
    """Four panels lettered once each, no overlapping texts, fonts of at least 9 pt on an 11 in figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncd.figures.fig4_pile import plots as pile_plots
    from ncd.pages.notebook import MIN_FONT_PT, text_layout

    fig = pile_plots.figure(page_run)
    letters = [ax.get_title(loc="left")[:3] for ax in fig.axes]
    assert letters == ["(a)", "(b)", "(c)", "(d)"]
    lay = text_layout(fig)
    assert lay["overlaps"] == [] and lay["min_font_pt"] >= MIN_FONT_PT and lay["width_in"] <= 11
    plt.close(fig)


def test_page_sentences_follow_the_data(page_run, data):
    """The cloud sentence states the diameter of the rest runs' cloud and compares it with the
    changes of a cut moved by one diameter the way the numbers do; the tolerance study is one
    sentence when plain NLGS brings too few runs to rest; no sentence prints NaN."""
    from ncd.figures.fig4_pile import plots as pile_plots

    r = page_run
    P = r.cloud(r.K)
    text = pile_plots.cloud_text(r)
    assert f"{int(r.rest.sum())} converged at rest" in text
    if len(P):
        D = pile_exact.diameter(P)
        assert f"spans {D:.3f} N" in text
        word = "less than" if D < min(r.change) else ("more than" if D > max(r.change) else "between")
        assert word in text
    tol = data["tolerance"]
    tol_text = pile_plots.tolerance_text(r, tol)
    rest = [int(pile_exact.rest_mask(tol.isel(tol=j)).sum()) for j in range(tol.sizes["tol"])]
    assert ("too few for a cloud" in tol_text) == (min(rest) < 2)
    texts = [pile_plots.construction_text(r), pile_plots.arching_text(r), text, tol_text,
             pile_plots.pressure_text(r), pile_plots.exact_text(data["exact"], data["ensemble"], data["cuts"]),
             pile_plots.dip_sentence(data["exact"])]
    assert not [t for t in texts if "nan" in t.lower()]
    m = list(data["exact"].choice.values).index(data["exact"].attrs["dip_main_choice"])
    assert f"{float(data['exact'].dip_history[m]):+.3f} for the history forces" in texts[-1]
