"""The MD baseline, the stability table and the work-precision data.

Unit tests of :mod:`ncd.dynamics.md` run in a second; the others read the results of a DAG
run (fixture ``results``: the reduced configuration, or ``NCD_RESULTS_DIR``).
"""
import numpy as np
import pytest
import xarray as xr

import ncd
from ncd.dynamics.md import MD, MDParams, critical_step, restitution_from_zeta, zeta_from_restitution

R = 0.01


def bouncing_disc(e, k_n, speed=1.0):
    """A disc falling at ``speed`` onto a floor (no gravity), 0.1 radius away."""
    s = ncd.make_scene([[0.0, 1.1 * R]], R, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))], gravity=(0.0, 0.0),
                       vel=[[0.0, -speed]], e_n=e, mu=0.5)
    return s, MD(s, MDParams(k_n=k_n, clip=False))


# ------------------------------------------------------------------ MD baseline
@pytest.mark.parametrize("e", [0.9, 0.5, 0.2])
def test_md_bounce_restitution_and_contact_duration(e):
    """Linear spring-dashpot: rebound speed e v, contact time pi / (omega sqrt(1 - zeta^2))."""
    k_n = 1.0e3
    s, md = bouncing_disc(e, k_n)
    m = s.mass[0]
    zeta = float(zeta_from_restitution(e))
    h = critical_step(s, k_n) / 2000
    t_in = t_out = None
    for _ in range(100000):
        md.run(h, 1)
        if t_in is None and s.pos[0, 1] < R:
            t_in = s.time
        if t_in is not None and s.pos[0, 1] >= R:
            t_out = s.time
            break
    assert t_out is not None
    assert s.vel[0, 1] == pytest.approx(e, rel=5e-3)
    assert t_out - t_in == pytest.approx(np.pi / (np.sqrt(k_n / m) * np.sqrt(1 - zeta ** 2)), rel=5e-3)
    assert restitution_from_zeta(zeta) == pytest.approx(e, rel=1e-12)


def test_md_critical_step():
    """A disc compressed 20 % beyond its equilibrium overlap on an undamped spring (e = 1)
    oscillates about it, bounded for h < 2/omega and divergent above."""
    k_n = 1.0e4
    m = np.pi * R ** 2
    delta0 = m * 9.81 / k_n

    def resting(h, n):
        s = ncd.make_scene([[0.0, R - 1.2 * delta0]], R, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))],
                           e_n=1.0, mu=0.5)
        rep = MD(s, MDParams(k_n=k_n, k_t_ratio=0.0)).run(h, n, speed_limit=10.0)
        return s, rep

    hc = critical_step(resting(1e-6, 1)[0], k_n)
    assert hc == pytest.approx(2.0 / np.sqrt(k_n / m))
    s, rep = resting(0.9 * hc, 5000)
    assert not rep.diverged
    assert rep.max_overlap * R <= 2.0 * delta0       # stays in contact: a linear oscillation
    # above the critical step the oscillation grows until the disc is thrown off the floor
    s, rep = resting(1.1 * hc, 5000)
    energy = 0.5 * m * np.sum(s.vel[0] ** 2) + m * 9.81 * (s.pos[0, 1] - R)
    assert rep.diverged or energy > 1e3 * m * 9.81 * delta0
    _, rep = resting(1.5 * hc, 5000)
    assert rep.diverged and 0 < rep.diverged_step < 5000


def test_md_coulomb_slider_on_incline():
    """A sliding disc (mu < tan(alpha) / 3) accelerates at g (sin a - mu cos a)."""
    a = np.radians(20.0)
    mu = 0.05
    s = ncd.make_scene([[0.0, R]], R, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))],
                       gravity=(9.81 * np.sin(a), -9.81 * np.cos(a)), mu=mu)
    k_n = 1.0e4
    md = MD(s, MDParams(k_n=k_n))
    md.run(0.02 * critical_step(s, k_n), int(0.2 / (0.02 * critical_step(s, k_n))))
    acc = 9.81 * (np.sin(a) - mu * np.cos(a))
    assert s.pos[0, 0] == pytest.approx(0.5 * acc * s.time ** 2, rel=2e-3)


def test_md_forces_balance_weight_at_rest():
    """A damped disc settles on the floor: the floor's force equals its weight."""
    from ncd.dynamics.md import wall_reaction
    s = ncd.make_scene([[0.0, R]], R, 1.0, walls=[((0.0, 0.0), (0.0, 1.0))], mu=0.5)
    k_n = 1.0e3
    md = MD(s, MDParams(k_n=k_n))
    md.run(0.05 * critical_step(s, k_n), 20000)
    c, f = md.contact_forces()
    assert wall_reaction(s, c, f)[1] == pytest.approx(s.mass[0] * 9.81, rel=1e-6)


# ------------------------------------------------------------------ unconverged steps
def test_unconverged_steps_go_on_from_the_last_sweep():
    """The 10^6 stack at h = 1e-3 (NLGS contracts by 1 - 1e-6 per sweep: every step stops
    at max_sweeps).  Going on from the last sweep, as the study does (config
    ``stability.solver.keep_best: false``), gains no energy; going on from the iterate of
    smallest residual gains a sizeable part of E_s: the reason for the study's setting."""
    from pathlib import Path

    import yaml

    from ncd.studies.stability import measure as S

    cfg = yaml.safe_load((Path(__file__).resolve().parent.parent / "config.yaml").read_text())["stability"]
    assert cfg["solver"]["keep_best"] is False
    common = {k: v for k, v in cfg.items() if k != "cases"}
    case = {**cfg["cases"]["stack_1e6"], "h": [1e-3], "md_h_factors": []}     # CD at h = 1e-3 only
    growth = {}
    for keep_best in (False, True):
        row = S.run_case("stack_1e6", case, {**common, "solver": {**cfg["solver"], "keep_best": keep_best}})
        assert int(row.n_steps[0]) == 200 and int(row.unconverged_steps[0]) >= 100
        growth[keep_best] = float(row.energy_growth[0])       # the table's own measure
    assert growth[False] <= 1e-9
    assert growth[True] > 0.05


# ------------------------------------------------------------------ the stability table
@pytest.fixture(scope="module")
def table(results):
    return xr.load_dataset(results / "stability" / "table.nc")


def test_no_nan_reaches_a_file(results):
    files = sorted((results / "stability").glob("*.nc")) + sorted((results / "error_vs_runtime").glob("*.nc"))
    assert len(files) >= 3
    for path in files:
        ds = xr.load_dataset(path)
        for name, var in ds.data_vars.items():
            if var.dtype.kind == "f":
                assert np.all(np.isfinite(var.values)), f"{path.name}:{name} holds NaN or inf"


def test_table_covers_the_cases(table):
    kinds = set(table.kind.values)
    assert {"stack", "box", "chain", "impact_wall", "impact_disc", "hexagonal"} <= kinds
    cases = set(table.case.values)
    assert {"stack_1e3", "stack_1e6", "mu0", "mu10", "e1_chain"} <= cases
    assert set(table.method.values) == {"CD", "MD"}
    # h well above MD's critical step, very small and very large h
    assert table.h_over_hcrit.max() > 100
    assert table.h.where(table.method == "CD").min() <= 1e-5
    assert table.h.where(table.method == "CD").max() >= 0.1


def test_cd_bounded_where_md_diverges(table):
    """For every case, MD is unstable at some h at which (or above which) CD is stable."""
    cd = table.where(table.method == "CD", drop=True)
    md = table.where(table.method == "MD", drop=True)
    assert int((cd.diverged == 0).sum()) == cd.sizes["run"], "a CD run diverged"
    shown = 0
    for case in np.unique(table.case.values):
        md_bad = md.h.values[(md.case.values == case) & (md.stable.values == 0)]
        cd_ok = cd.h.values[(cd.case.values == case) & (cd.stable.values == 1)]
        if len(md_bad) and len(cd_ok) and cd_ok.max() >= md_bad.min():
            shown += 1
    assert shown == len(np.unique(table.case.values))
    # and MD does diverge above its critical step
    above = md.h_over_hcrit.values >= 2
    assert np.all(md.stable.values[above] == 0)


def test_energy_never_grows_for_e_below_one(table):
    cd = table.where((table.method == "CD") & (table.restitution < 1), drop=True)
    assert cd.sizes["run"] > 10
    assert float(cd.energy_growth.max()) <= 1e-9
    trace_growth = [float(np.max(cd.trace.values[k, : int(cd.trace_points.values[k])], initial=0.0))
                    for k in range(cd.sizes["run"])]
    assert max(trace_growth) <= 1e-9


def test_e1_chain_keeps_energy(table):
    cd = table.where((table.method == "CD") & (table.case == "e1_chain"), drop=True)
    assert cd.sizes["run"] >= 1
    assert float(np.abs(cd.energy_drift).max()) <= 1e-6


def test_impact_tunnels_only_at_steps_of_several_diameters(table):
    """CD misses a disc-disc contact only when the striker moves past the target in one step."""
    cd = table.where((table.method == "CD") & (table.kind == "impact_disc"), drop=True)
    speed = 100.0
    for h, tunnelled in zip(cd.h.values, cd.tunnelled.values):
        assert bool(tunnelled) == (speed * h > 4 * R), (h, tunnelled)


# ------------------------------------------------------------------ work-precision
@pytest.fixture(scope="module")
def nlgs(results):
    return xr.load_dataset(results / "error_vs_runtime" / "nlgs.nc")


def test_nlgs_tighter_tolerance_never_larger_error(nlgs):
    """Same guess, same order: a tighter tolerance runs at least as many sweeps, stops at a
    residual below its tolerance and never farther from the limit, to within the
    reference's own error.  The reference is a run too (residual ``reference_residual``):
    with the error per unit residual of the residual criterion at its tightest
    tolerance, its error is about that ratio times its residual (on the default slope
    ~2e-10 g h, which the finished runs, at residuals ~1e-14, sit at)."""
    assert {"packing28", "pile", "slope"} <= set(nlgs.state.values)
    for state in nlgs.state.values:
        for init in nlgs.init.values:
            tight = nlgs.sel(state=state, init=init, criterion="residual").sortby("tol").isel(tol=0)
            ref_res = float(nlgs.reference_residual.sel(state=state, init=init))
            floor = {key: float(tight[key]) / float(tight.residual) * ref_res
                     for key in ("error_velocity", "error_impulse")}
            for crit in nlgs.criterion.values:
                e = nlgs.sel(state=state, init=init, criterion=crit).sortby("tol", ascending=False)
                assert np.all(np.diff(e.sweeps.values) >= 0), (state, init, crit)
                conv = e.converged.values.astype(bool)
                assert conv.all(), (state, init, crit)
                if crit in ("residual", "anderson", "anderson_local"):
                    assert np.all(e.residual.values <= e.tol.values)
                if crit in ("anderson", "anderson_local"):
                    # the limit is plain NLGS's: accelerated runs may end elsewhere in an indeterminate set
                    continue
                for key in ("error_velocity", "error_impulse"):
                    v = e[key].values
                    assert np.all(v[1:] <= v[:-1] * (1 + 1e-9) + floor[key] + 1e-15), (state, init, crit, key, v)
        assert np.all(nlgs.reference_converged.sel(state=state).values == 1)


def test_nlgs_precision_is_bought_with_sweeps(nlgs):
    """From the loosest to the tightest tolerance the distance to the limit falls by 10^4 at least."""
    for state in nlgs.state.values:
        for init in nlgs.init.values:
            e = nlgs.sel(state=state, init=init, criterion="residual").sortby("tol", ascending=False)
            assert float(e.error_velocity[-1]) <= 1e-4 * float(e.error_velocity[0]), (state, init)
            assert int(e.sweeps[-1]) > int(e.sweeps[0])


def test_incline_cd_exact_md_converges(results):
    it = xr.load_dataset(results / "error_vs_runtime" / "integration.nc")
    inc = it.where(it.observable == "incline", drop=True)
    cd = inc.where(inc.method == "CD", drop=True)
    assert float(cd.error.max()) < 1e-10
    md = inc.where((inc.method == "MD") & (inc.diverged == 0), drop=True)
    for mu in np.unique(md.mu.values):
        m = md.where(md.mu == mu, drop=True)
        stiff = m.where(m.k_factor == m.k_factor.max(), drop=True)
        soft = m.where(m.k_factor == m.k_factor.min(), drop=True)
        assert float(stiff.error.min()) < float(soft.error.min())
    heap = it.where((it.observable == "heap") & (it.quantity == "reaction") & (it.method == "CD"), drop=True)
    assert heap.sizes["run"] >= 1
