"""Figure 1 (section 1): the wedged disc — closed form, and checks on the figure data."""
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import xarray as xr
import yaml
from scipy.optimize import linprog

import ncd
from ncd.core.contacts import h_matrix
from ncd.figures.fig1_wedged.measure import Wedge, explore_shard
from ncd.io.netcdf import merge_shards, write_dataset

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = yaml.safe_load((ROOT / "config.yaml").read_text())["fig1_wedged"]


def wedge_of(beta_deg, mu, R=0.1, r=0.1):
    return Wedge(R, r, np.radians(beta_deg), mu, density=1.0, g=9.81)


def force_vectors(w, fn, ft):
    """Contact forces on B as vectors (..., 2 contacts, 2)."""
    return fn[..., None] * w.normals + ft[..., None] * w.tangents


def lp_normal_force(w, sense):
    """min (sense=1) or max (sense=-1) of N_0 over {H rho + F = 0, |rho_t| <= mu rho_n},
    with H from ncd.core.contacts.h_matrix of the actual scene (independent of the closed form)."""
    scene = w.scene()
    contacts = ncd.prepare_step(scene, 1e-3, 1.0).contacts
    assert contacts.n == 2
    H = h_matrix(scene, contacts).toarray()
    F = np.array([0.0, -w.weight, 0.0])
    mu = contacts.mu
    A_ub = sp.block_diag([np.array([[-m, 1.0], [-m, -1.0]]) for m in mu]).toarray()
    c = np.zeros(4)
    c[0] = sense
    return linprog(c, A_ub=A_ub, b_ub=np.zeros(4), A_eq=H, b_eq=-F, bounds=[(0, None), (None, None)] * 2,
                   method="highs")


# ---------------------------------------------------------------- closed form
@pytest.mark.parametrize("beta_deg, mu", [(20.0, 0.75), (10.0, 0.3), (35.0, 1.2), (5.0, 0.1), (20.0, 0.37)])
def test_n_min_and_forces_match_a_linear_program(beta_deg, mu):
    w = wedge_of(beta_deg, mu)
    assert w.wedging_possible
    lo = lp_normal_force(w, 1.0)
    assert lo.status == 0
    assert lo.x[0] == pytest.approx(w.n_min, rel=1e-7)
    fn, ft = w.forces(w.n_min)
    np.testing.assert_allclose(lo.x, np.column_stack([fn, ft]).ravel(), rtol=1e-6, atol=1e-9 * w.weight)
    assert lp_normal_force(w, -1.0).status == 3          # unbounded: N has no upper limit


@pytest.mark.parametrize("beta_deg, mu", [(20.0, 0.36), (20.0, 0.0), (40.0, 0.8), (10.0, 0.17)])
def test_no_wedged_state_below_the_friction_angle_threshold(beta_deg, mu):
    w = wedge_of(beta_deg, mu)
    assert np.degrees(w.gamma) < beta_deg and not w.wedging_possible
    assert lp_normal_force(w, 1.0).status == 2           # infeasible
    assert w.n_min == np.inf and w.segment[0] == w.segment[1]


def test_segment_of_I_direct_check():
    w = wedge_of(20.0, 0.75)
    y_bot, y_top = w.segment
    R, b, g = w.radius, w.beta, w.gamma
    assert y_bot == pytest.approx(R * np.sin(b))
    # top: the force at the cone edge rises at gamma - beta above the horizontal from P_0
    assert y_top == pytest.approx(R * np.sin(b) + R * np.cos(b) * np.tan(g - b), rel=1e-12)
    N = w.n_min * np.geomspace(1.0, 1e9, 400)
    fn, ft = w.forces(N)
    F = force_vectors(w, fn, ft)
    P = w.contact_points
    # equilibrium of forces and of moments about B's centre, Coulomb at both contacts
    scale = w.weight * N / w.n_min
    assert np.all(np.abs(F.sum(1) + [0.0, -w.weight]).max(1) <= 1e-12 * scale)
    torque = P[:, 0] * F[..., 1] - P[:, 1] * F[..., 0]
    assert np.all(np.abs(torque.sum(1)) <= 1e-12 * R * scale)
    assert np.all(np.abs(ft) <= w.mu * fn * (1 + 1e-12))
    ix, iy = w.intersection(fn, ft)
    assert np.all(np.abs(ix) <= 1e-9 * R * N / w.n_min)
    np.testing.assert_allclose(iy, w.y_of_n(N), rtol=1e-9)
    assert iy[0] == pytest.approx(y_top, rel=1e-12)          # top end reached at N_min
    assert np.all(np.diff(iy) < 0) and np.all(iy > y_bot)   # bottom end only approached
    assert iy[-1] - y_bot < 1e-8 * (y_top - y_bot)
    # conversely, every height inside the segment is a wedged state, none above it
    y = np.linspace(y_bot, y_top, 50)[1:]
    assert np.all(w.n_of_y(y) >= w.n_min * (1 - 1e-12))
    np.testing.assert_allclose(w.y_of_n(w.n_of_y(y)), y, rtol=1e-12)
    assert w.n_of_y(y_top + 1e-3 * R) < w.n_min


def test_brute_force_equilibrium_line():
    """Sample the equilibrium line N (any sign): Coulomb holds exactly for N >= N_min."""
    w = wedge_of(25.0, 0.9)
    N = np.linspace(-5, 40, 9001) * w.weight
    fn, ft = w.forces(N)
    ok = np.all((fn >= 0) & (np.abs(ft) <= w.mu * fn), axis=1)
    assert N[ok].min() == pytest.approx(w.n_min, abs=(N[1] - N[0]))
    assert np.all(ok == (N >= w.n_min))


def test_zero_force_state_is_free_fall_and_the_only_one_from_zero_guess():
    w = wedge_of(20.0, 0.75)
    scene = w.scene()
    problem = ncd.prepare_step(scene, 1e-3, 1.0)
    res, vel, spin = ncd.solve_problem(scene, problem)
    assert res.converged and np.all(res.impulse == 0.0)
    np.testing.assert_allclose(vel[0], [0.0, -w.g * 1e-3], rtol=1e-14)


def small_config(**ensemble):
    cfg = yaml.safe_load(yaml.safe_dump(DEFAULT))
    cfg["ensemble"].update(runs=30, zero_runs=6, **ensemble)
    return cfg


def test_ensemble_is_the_same_whatever_the_shard_count(tmp_path):
    cfg = small_config()
    merged = {}
    for n in (1, 4):
        paths = []
        for k in reversed(range(n)):
            cfg["ensemble"]["shards"] = n
            paths.append(tmp_path / f"ensemble_{k}-of-{n}.nc")
            write_dataset(explore_shard(cfg, k, n), paths[-1])
        merged[n] = merge_shards(paths)
    whole, parts = merged[1], merged[4]
    assert whole.attrs.keys() == parts.attrs.keys()
    for key, value in whole.attrs.items():
        np.testing.assert_array_equal(value, parts.attrs[key], err_msg=key)
    for name in whole.data_vars:
        if name != "wall_time":
            xr.testing.assert_identical(whole[name], parts[name])
    assert set(np.unique(whole.outcome)) == {0, 1}      # both outcomes occur among 30 random guesses
    assert np.all(whole.outcome.values[whole.zero_guess.values == 1] == 0)


def test_default_config_meets_the_issue():
    cfg = DEFAULT
    w = Wedge.from_config(cfg)
    assert w.wedging_possible                          # default mu inside the wedging range
    assert cfg["ensemble"]["runs"] + cfg["ensemble"]["zero_runs"] >= 2000 and cfg["ensemble"]["zero_runs"] > 0
    assert cfg["ensemble"]["shards"] > 1
    assert cfg["evolution"]["duration"] >= 1.0
    assert cfg["solver"]["criterion"] == "residual" and cfg["solver"]["tol"] <= 1e-10
    gam = np.linspace(cfg["sweep"]["gamma_min_deg"], cfg["sweep"]["gamma_max_deg"], cfg["sweep"]["n_gamma"])
    assert gam.min() < cfg["beta_deg"] < gam.max()


# ---------------------------------------------------------------- figure data
@pytest.fixture(scope="module")
def data(results):
    d = Path(results) / "fig1_wedged"
    ens = xr.load_dataset(d / "ensemble.nc")
    return {"ens": ens, "evo": xr.load_dataset(d / "evolutions.nc"), "sweep": xr.load_dataset(d / "sweep.nc"),
            "cfg": yaml.safe_load(ens.attrs["config_yaml"]), "wedge": Wedge.from_config(yaml.safe_load(ens.attrs["config_yaml"]))}


def test_ensemble_layout_and_closed_form_attributes(data):
    ens, w, cfg = data["ens"], data["wedge"], data["cfg"]
    assert ens.sizes["contact"] == 2
    assert ens.sizes["run"] == cfg["ensemble"]["runs"] + cfg["ensemble"]["zero_runs"]
    np.testing.assert_array_equal(ens.run.values, np.arange(ens.sizes["run"]))
    for v in ("force_n", "force_t"):
        assert ens[v].dims == ("run", "contact")
    for v in ("I_y", "outcome", "sweeps", "residual", "converged", "wall_time"):
        assert ens[v].dims == ("run",)
    assert ens.attrs["mu"] == w.mu and ens.attrs["h"] == cfg["h"]
    assert ens.attrs["I_y_bottom"] == pytest.approx(w.segment[0]) and ens.attrs["I_y_top"] == pytest.approx(w.segment[1])
    assert ens.attrs["I_y_bottom_reached"] == 0 and ens.attrs["I_y_top_reached"] == 1
    assert set(np.unique(ens.outcome.values)) <= {-1, 0, 1}
    # unconverged runs are never classified
    assert np.all(ens.outcome.values[ens.converged.values == 0] == -1)
    assert np.all(np.isnan(ens.I_y.values[ens.outcome.values != 1]))


def test_most_runs_converge_and_both_outcomes_occur(data):
    ens = data["ens"]
    conv = ens.converged.values == 1
    assert conv.mean() >= 0.99
    assert np.all(ens.residual.values[conv] <= ens.attrs["solver_tol"])
    rnd = conv & (ens.zero_guess.values == 0)
    assert 0.1 < (ens.outcome.values[rnd] == 1).mean() < 0.95


def test_every_wedged_run_satisfies_equilibrium_and_coulomb(data):
    ens, w = data["ens"], data["wedge"]
    wed = (ens.converged.values == 1) & (ens.outcome.values == 1)
    assert wed.sum() >= 20
    fn, ft = ens.force_n.values[wed], ens.force_t.values[wed]
    F = force_vectors(w, fn, ft)
    scale = w.weight * np.maximum(1.0, fn.max(1) / w.weight)
    assert np.all(np.abs(F.sum(1) + [0.0, -w.weight]).max(1) <= 1e-6 * scale)
    P = w.contact_points
    torque = (P[:, 0] * F[..., 1] - P[:, 1] * F[..., 0]).sum(1)
    assert np.all(np.abs(torque) <= 1e-6 * w.radius * scale)
    assert np.all(fn > 0)
    assert np.all(np.abs(ft) <= w.mu * fn * (1 + 1e-9))
    assert np.all(fn >= w.n_min * (1 - 1e-6))
    gh = w.g * ens.attrs["h"]
    assert np.all(np.hypot(ens.vel_x.values[wed], ens.vel_y.values[wed]) <= ens.attrs["velocity_tol"] * gh)


def test_every_I_lies_on_the_closed_form_segment_and_spans_it(data):
    ens, w = data["ens"], data["wedge"]
    wed = (ens.converged.values == 1) & (ens.outcome.values == 1)
    y_bot, y_top = w.segment
    iy, ix = ens.I_y.values[wed], ens.I_x.values[wed]
    assert np.all(np.abs(ix) <= 1e-6 * w.radius)
    assert np.all((iy > y_bot - 1e-9 * w.radius) & (iy <= y_top + 1e-9 * w.radius))
    np.testing.assert_allclose(iy, w.y_of_n(ens.force_n.values[wed].mean(1)), rtol=1e-6)
    # the segment is finite: its whole length counts (the bottom end is only a limit)
    assert (iy.max() - iy.min()) / (y_top - y_bot) >= 0.9


def test_zero_guess_runs_all_fall(data):
    ens, w = data["ens"], data["wedge"]
    zero = ens.zero_guess.values == 1
    assert zero.sum() >= 1
    assert np.all(ens.converged.values[zero] == 1) and np.all(ens.outcome.values[zero] == 0)
    assert np.all(ens.force_n.values[zero] == 0.0) and np.all(ens.force_t.values[zero] == 0.0)
    np.testing.assert_allclose(ens.vel_y.values[zero], -w.g * ens.attrs["h"], rtol=1e-12)


def test_threshold_sweep_changes_outcome_at_the_closed_form_angle(data):
    sw, beta = data["sweep"], data["cfg"]["beta_deg"]
    gam, frac = sw.gamma.values, sw.wedged_fraction.values
    assert sw.attrs["threshold_gamma_deg"] == pytest.approx(beta)
    assert np.all(sw.n_converged.values >= 0.99 * sw.sizes["run"])
    below, above = gam < beta, gam > beta
    assert below.any() and above.any()
    assert np.all(frac[below] == 0.0)                 # no wedged state exists (closed form)
    assert frac[above][0] > 0.0                        # the first angle above beta already wedges
    assert np.all(frac[above] > 0.0)
    step = np.diff(gam).max()
    assert gam[above][0] - beta <= step and beta - gam[below][-1] <= step


def test_evolutions_fall_and_stay_wedged(data):
    evo, w, cfg = data["evo"], data["wedge"], data["cfg"]
    t = evo.time.values
    assert t[-1] >= cfg["evolution"]["duration"] - 0.5 * cfg["h"]
    fall, stay = evo.sel(evolution="zero_guess"), evo.sel(evolution="wedged_warm")
    assert np.all(fall.converged.values == 1) and np.all(stay.converged.values == 1)
    # (a) free fall from the first step on
    np.testing.assert_allclose(fall.y.values, -0.5 * w.g * t ** 2, rtol=1e-9, atol=1e-12 * w.radius)
    assert np.all(fall.force_n.values == 0.0) and np.all(fall.n_contacts.values[2:] == 0)
    # (b) B stays put, with the wedged forces of the first guess, for the whole duration
    assert np.abs(stay.y.values).max() <= 1e-9 * w.radius and np.abs(stay.x.values).max() <= 1e-9 * w.radius
    assert np.all(stay.n_contacts.values[1:] == 2)
    fn0, ft0 = w.forces(cfg["evolution"]["wedge_factor"] * w.n_min)
    np.testing.assert_allclose(stay.force_n.values[1:], np.broadcast_to(fn0, stay.force_n.values[1:].shape), rtol=1e-8)
    np.testing.assert_allclose(stay.force_t.values[1:], np.broadcast_to(ft0, stay.force_t.values[1:].shape), rtol=1e-8)


# ---------------------------------------------------------------- the page
def test_page_sentences_count_the_runs(data):
    """The page's sentences quote the counts of the file, the left-out runs included."""
    from ncd.figures.fig1_wedged import page

    ens, w = data["ens"], data["wedge"]
    conv, zero, out = ens.converged.values == 1, ens.zero_guess.values == 1, ens.outcome.values
    text = page.ensemble_sentence(ens, w)
    n_rand, n_zero = int((~zero).sum()), int(zero.sum())
    assert (f"of the {n_rand} runs from random guesses, {int((out[conv & ~zero] == 0).sum())} fall, "
            f"{int((out[conv & ~zero] == 1).sum())} stay wedged") in text
    assert f"and {int((zero & ~conv).sum())} did not converge." in text
    assert f"of the {n_zero} runs from zero guesses" in text
    wed, n, _, _, iy = page.wedged_runs(ens)
    span = 100 * (iy.max() - iy.min()) / (w.segment[1] - w.segment[0])
    assert f"span {span:.1f} % of the segment" in text
    # the contact reviewed second decides: no random run below N_min there wedges
    second = 1 - ens.first_reviewed.values
    guess = ens.guess_force_n.values[np.arange(ens.sizes["run"]), second]
    assert not np.any(out[conv & ~zero & (guess < w.n_min)] == 1)
    assert "of the" in page.second_contact_sentence(ens, w) and ", 0 %." in page.second_contact_sentence(ens, w)


def test_page_figure_is_readable(data):
    from figure_checks import problems

    from ncd.figures.fig1_wedged import page

    assert problems(page.plot(data["ens"], data["evo"], data["sweep"], data["wedge"])) == []


def test_page_sweep_sentence_matches_the_closed_form_threshold(data):
    from ncd.figures.fig1_wedged import page

    swp, w = data["sweep"], data["wedge"]
    text = page.sweep_sentence(swp, w, data["cfg"]["ensemble"]["force_max"])
    assert "the wedged fraction is 0 at most below" in text
    assert f"{swp.sizes['gamma']} friction angles" in text


def test_report_caption_counts_the_runs(data):
    from docutils.core import publish_parts

    from ncd.figures.fig1_wedged import page

    ens, w = data["ens"], data["wedge"]
    text = page.caption(ens, data["sweep"], w)
    zero = ens.zero_guess.values == 1
    assert f"of {int(zero.sum())} zero-guess runs let the disc fall" in text
    assert f"{int((ens.outcome.values == 1).sum())} of {int((~zero).sum())} random-guess runs keep it wedged" in text
    publish_parts(text, writer="html", settings_overrides={"report_level": 2, "halt_level": 2})


def test_labels_say_what_the_variables_hold(data):
    """``wedged_fraction`` counts converged runs only (its label says so); the evolutions'
    ``angle`` is B's rotation in radians (it was labelled degrees): B, symmetric between the
    two obstacles, does not turn."""
    swp, evo = data["sweep"], data["evo"]
    conv = swp.converged == 1
    expect = ((swp.outcome == 1) & conv).sum("run") / conv.sum("run")
    np.testing.assert_allclose(swp.wedged_fraction.values, expect.values, equal_nan=True)
    assert "converged" in swp.wedged_fraction.attrs["long_name"]
    assert evo.angle.attrs["units"] == "rad" and "rotation" in evo.angle.attrs["long_name"]
    assert float(np.abs(evo.angle).max()) < 1e-9
