"""The benchmark suite: what it measures must be right; its speed is not asserted.

Unit checks of ncd.studies.bench.solver on small packings, and checks of the data of the
reduced DAG run (``snakemake -j2 bench`` in tests/conftest.py)."""
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

import ncd
from ncd.dynamics.explore import explore, run_parallel
from ncd.studies.bench import runs, speed_table
from ncd.studies.bench import solver as bench


@pytest.fixture(scope="module")
def packing():
    scene = bench.dense_packing(300)
    return scene, ncd.prepare_step(scene, bench.H)


def test_dense_packing_has_about_three_contacts_per_disc(packing):
    scene, problem = packing
    assert 290 <= scene.n_mobile <= 320
    assert 2.7 <= problem.contacts.n / scene.n_mobile <= 3.1


@pytest.mark.skipif(shutil.which("gcc") is None and shutil.which("cc") is None, reason="no C compiler")
def test_the_c_reference_runs_the_same_loop(packing, tmp_path):
    """Same packed arrays, same operations in the same order: the same impulses, bit for bit."""
    scene, problem = packing
    t_numba, imp = bench.nlgs_sweep_cost(scene, problem, 7, 1)
    t_c, imp_c = bench.c_sweep_cost(scene, problem, 7, tmp_path)
    assert t_numba > 0 and t_c > 0
    assert imp.sum() > 0
    np.testing.assert_array_equal(imp_c, imp)


def test_threads_give_the_same_ensemble_bit_for_bit(packing):
    scene, problem = packing
    settings = ncd.SolverSettings(tol=1e-5, max_sweeps=3000, check_every=10)
    one = explore(scene, problem, range(6), 11, settings=settings, threads=1)
    two = explore(scene, problem, range(6), 11, settings=settings, threads=2)
    assert len(set(one["sweeps"])) > 1          # the members differ from each other ...
    for k in ("impulse", "vel", "spin", "sweeps", "residual", "change", "converged"):
        np.testing.assert_array_equal(one[k], two[k], err_msg=k)   # ... not with the threads
    assert one["converged"].all()


def test_run_parallel_reports_progress_in_order_and_raises_task_errors():
    seen, done = [], []
    run_parallel(lambda k: seen.append(k), 5, threads=2, progress=lambda d, n: done.append((d, n)))
    assert sorted(seen) == list(range(5)) and done == [(k, 5) for k in range(1, 6)]

    def fail(k):
        if k == 3:
            raise RuntimeError("member 3 failed")
    with pytest.raises(RuntimeError, match="member 3"):
        run_parallel(fail, 6, threads=2)
    with pytest.raises(ValueError, match="threads"):
        run_parallel(fail, 2, threads=0)


def test_warm_start_needs_fewer_sweeps_than_the_zero_guess():
    ds = bench.sweeps_table({"sizes": [100, 300], "tol": 1e-4, "max_sweeps": 20000, "warm_steps": 3})
    assert ds.converged_zero.all() and ds.converged_warm.all()
    assert (ds.residual_zero <= 1e-4).all() and (ds.residual_warm <= 1e-4).all()
    assert (ds.sweeps_warm * 5 < ds.sweeps_zero).all()
    assert ds.sweeps_zero[1] > ds.sweeps_zero[0]        # more layers, more sweeps


def test_rule_times_reads_snakemake_benchmark_files(tmp_path):
    d = tmp_path / "fig9"
    d.mkdir()
    head = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    (d / "simulate.tsv").write_text(head + "12.5\t0:00:12\t250.5\t900\t200\t210\t0\t1\t95\t12\n")
    (d / "notebook.tsv").write_text(head + "3.0\t0:00:03\t-\t-\t-\t-\t-\t-\t-\t-\n")
    ds = runs.rule_times(d.glob("*.tsv"))
    assert list(ds.rule.values) == ["notebook", "simulate"]
    assert list(ds.figure.values) == ["fig9", "fig9"]
    np.testing.assert_allclose(ds.seconds, [3.0, 12.5])
    assert np.isnan(ds.max_rss_mb[0]) and ds.max_rss_mb[1] == 250.5


def _exact_file(path, history, member, contacts, n_lp, seconds, solver):
    path.parent.mkdir(parents=True, exist_ok=True)
    xr.Dataset({"n_lp": (("flank", "cut_position"), np.asarray(n_lp).reshape(2, -1))},
               attrs={"history": history, "member": member, "n_contacts": contacts, "lp_wall_time": seconds,
                      "config_yaml": yaml.safe_dump({"exact": {"solver": solver}})}).to_netcdf(path)


def test_exact_costs_reads_every_piles_exact_file(tmp_path):
    """One row per exact file, the size from its directory, the LPs summed over its cuts."""
    e = tmp_path / "fig4_history" / "exact"
    _exact_file(e / "n10000" / "rain_000.nc", "rain", 0, 14378, [6] * 18, 480.2, "clarabel")
    _exact_file(e / "n1000" / "point_001.nc", "point", 1, 1702, [7, 6, 6, 6], 3.5, "highs")
    ds = runs.exact_costs(list(e.glob("n*/*.nc")))
    assert list(ds.grains.values) == [1000, 10000] and list(ds.history.values) == ["point", "rain"]
    assert list(ds.member.values) == [1, 0] and list(ds.n_contacts.values) == [1702, 14378]
    assert list(ds.n_cuts.values) == [4, 18] and list(ds.n_lp.values) == [25, 108]
    assert list(ds.solver.values) == ["highs", "clarabel"]
    np.testing.assert_array_equal(ds.lp_seconds.values, [3.5, 480.2])


DRY_RUN = """Building DAG of jobs...
[Wed Nov 25 23:52:43 2026]
rule simulate:
    input: ncd/a.py
    output: results/fig9/trajectory.nc
    log: results/logs/fig9/simulate.log
    jobid: 3
    benchmark: results/benchmarks/fig9/simulate.tsv
    reason: Forced execution
    resources: tmpdir=/tmp
[Wed Nov 25 23:52:43 2026]
localrule explore:
    input: ncd/a.py, results/fig9/trajectory.nc
    output: results/fig9/shards/e_0-of-2.nc
    jobid: 4
    benchmark: results/benchmarks/fig9/explore_0-of-2.tsv
    wildcards: shard=0, n=2
    threads: 2
[Wed Nov 25 23:52:43 2026]
rule explore:
    input: ncd/a.py, results/fig9/trajectory.nc
    output: results/fig9/shards/e_1-of-2.nc
    jobid: 5
    benchmark: results/benchmarks/fig9/explore_1-of-2.tsv
    wildcards: shard=1, n=2
    threads: 2
[Wed Nov 25 23:52:43 2026]
rule notebook:
    input: results/fig9/shards/e_0-of-2.nc, results/fig9/shards/e_1-of-2.nc
    output: results/figures/fig9.png
    jobid: 6
    benchmark: results/benchmarks/fig9/notebook.tsv
[Wed Nov 25 23:52:43 2026]
rule all:
    input: results/figures/fig9.png
    jobid: 0
Job stats:
job      count
"""


def test_dry_run_jobs_and_the_critical_path(tmp_path):
    """Jobs, threads and dependencies read from a dry run's printout; each job's time alone
    is its wall time and its cost wall time x threads, whatever Snakemake's sampled cpu_time
    says (it misses children, and over-counts a notebook's kernel); the critical path is the
    longest chain."""
    jobs = runs.dry_run_jobs(DRY_RUN)
    assert [j["rule"] for j in jobs] == ["simulate", "explore", "explore", "notebook", "all"]
    assert [j["threads"] for j in jobs] == [1, 2, 2, 1, 1]
    assert jobs[2]["inputs"] == ["ncd/a.py", "results/fig9/trajectory.nc"] and jobs[4]["benchmark"] is None
    d = tmp_path / "results" / "benchmarks" / "fig9"
    d.mkdir(parents=True)
    head = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
    for name, wall, cpu in (("simulate", 12, 10), ("explore_0-of-2", 50, 60), ("explore_1-of-2", 50, 80),
                            ("notebook", 20, 900)):
        (d / f"{name}.tsv").write_text(head + f"{wall}\t0\t1\t1\t1\t1\t0\t0\t90\t{cpu}\n")
    ds = runs.dag_table(jobs, tmp_path)
    np.testing.assert_allclose(ds.cpu_s, [12, 100, 100, 20])
    np.testing.assert_allclose(ds.cpu_time_s, [10, 60, 80, 900])
    np.testing.assert_allclose(ds.alone_s, [12, 50, 50, 20])
    assert list(ds.critical.values) == [1, 1, 0, 1]
    assert list(ds.critical_order.values) == [0, 1, -1, 2]
    assert ds.attrs["critical_path_s"] == 82 and ds.attrs["cpu_s"] == 232
    assert runs.ideal_time(ds, cores=2) == 116
    per_fig, path, text = runs.dag_summary(ds.assign_attrs(cores=2))
    assert list(path.rule) == ["simulate", "explore_0-of-2", "notebook"] and float(per_fig.cpu_s.iloc[0]) == 232
    assert "critical path 82 s through 3 jobs" in text.lower() and "less than 116 s" in text


def test_speed_table_rows_round_trip(tmp_path):
    """The README's speed rows from a run's bench files, through the committed .tsv, to Markdown."""
    d = tmp_path / "bench"
    d.mkdir()
    xr.Dataset(attrs={"cpu_s": 1234.4, "critical_path_s": 456.7, "ideal_s": 617.25, "cores": 2}).to_netcdf(d / "dag.nc")
    n = np.array([1000, 10000, 100000])
    xr.Dataset({"n_discs": ("size", n), "ns_per_update": ("size", [11.0, 12.0, 14.0]),
                "ns_per_update_c": ("size", [10.0, 11.0, 13.0]), "step_s": ("size", 1e-6 * n ** 1.1),
                "build_s": ("size", 1e-7 * n)}, coords={"size": n}).to_netcdf(d / "core.nc")
    rows = speed_table.speed_rows(tmp_path)
    assert [r["value"] for r in rows] == ["1234", "457", "617", "12 / 11", "1.10", "1.00"]
    speed_table.write_speed_csv(rows, tmp_path / "speed.tsv")
    assert speed_table.read_speed_csv(tmp_path / "speed.tsv") == rows
    block = speed_table.speed_markdown(rows)
    text = "intro\n" + speed_table.speed_markdown([]) + "\nafter\n"
    assert speed_table.speed_block(speed_table.replace_speed_block(text, block)) == block
    assert "| NLGS contact update, N = 10000: numba / C | 12 / 11 | ns | `results/bench/core.nc` |" in block


def test_critical_path_refuses_a_cycle():
    with pytest.raises(ValueError, match="cycle"):
        runs.critical_path([1.0, 1.0], [(0, 1), (1, 0)])
    assert runs.critical_path([], []) == (0.0, [])


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="Linux only")
def test_peak_memory_sees_an_allocation():
    with bench.PeakMemory() as mem:
        a = np.ones(50_000_000 // 8)
        a.sum()
    assert mem.growth >= 0.9 * 50_000_000
    assert mem.peak >= mem.growth


# ----------------------------------------------------------- data of the DAG run
@pytest.fixture(scope="module")
def bench_results(results):
    d = results / "bench"
    if not (d / "core.nc").exists():
        pytest.skip(f"no benchmark results in {d} (run `snakemake -j2 bench`)")
    return {k: xr.load_dataset(d / f"{k}.nc") for k in ("core", "sweeps", "ensemble", "peer", "rules", "dag",
                                                         "exact_sets")}


def test_bench_core_data(bench_results):
    core = bench_results["core"]
    assert (core.n_contacts > 2.5 * core.n_discs).all()
    assert (core.ns_per_update > 0).all() and np.isfinite(core.ns_per_update).all()
    if np.isfinite(core.ns_per_update_c).all():
        assert (core.c_agrees == 1).all()
    assert (core.detect_s > 0).all() and (core.step_s > core.prepare_s).all()
    assert core.attrs["startup_import_s"] > 0 and "git_commit" in core.attrs


def test_bench_ensemble_is_identical_on_every_thread_count(bench_results):
    ens = bench_results["ensemble"]
    assert (ens["same_results"] == 1).all()
    assert len(set(ens.digest.values)) == 1
    assert ens.attrs["converged"] == ens.attrs["runs"]


def test_bench_rules_cover_every_figure(bench_results):
    rules = bench_results["rules"]
    figures = set(rules.figure.values)
    assert {"fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile"} <= figures
    for fig in figures:
        names = set(rules.rule.values[rules.figure.values == fig])
        assert any(n.endswith("notebook") for n in names), (fig, names)
    assert (rules.seconds > 0).all()


def test_bench_exact_sets_cover_every_exact_file(bench_results, results):
    """exact_sets.nc: a row per exact file of fig4_history written before it (the rule globs
    them when it runs: a size study's files appear once they exist), with the LP count and
    time the file records, and no row without its file."""
    costs = bench_results["exact_sets"]
    written = (results / "bench" / "exact_sets.nc").stat().st_mtime
    files = sorted((results / "fig4_history" / "exact").glob("n*/*.nc"))
    key = lambda f: (int(f.parent.name[1:]), *f.stem.split("_"))           # noqa: E731 (grains, history, member)
    rows = {(int(g), str(h), f"{int(m):03d}"): k for k, (g, h, m) in
            enumerate(zip(costs.grains.values, costs.history.values, costs.member.values))}
    assert set(rows) <= {key(f) for f in files}
    older = [f for f in files if f.stat().st_mtime <= written]
    assert older and {key(f) for f in older} <= set(rows)
    for f in files:
        if key(f) not in rows:
            continue
        e = xr.load_dataset(f)
        row = costs.isel(pile=rows[key(f)])
        assert str(row.history.values) == e.attrs["history"] and int(row.member) == int(e.attrs["member"])
        assert int(row.n_lp) == int(e.n_lp.sum()) and int(row.n_contacts) == int(e.attrs["n_contacts"])
        assert float(row.lp_seconds) == float(e.attrs["lp_wall_time"]) > 0


def test_tolerance_table_both_methods_reach_the_tolerance():
    """Time to tolerance: plain NLGS and NLGS + finishing stage, side by side."""
    from ncd.studies.bench.solver import tolerance_table
    ds = tolerance_table({"sizes": [100], "tolerances": [1e-6, 1e-10], "handoff": 1e-4, "max_sweeps": 100000})
    assert ds.converged.values.all()
    assert (ds.residual.values <= ds.tol.values[None, None, :]).all()
    assert (ds.finish_rounds.sel(solver="nlgs").values == 0).all()
    # NLGS converges at a steady rate on a dense packing: the finishing stage leaves it to NLGS (no LP)
    assert (ds.finish_rounds.sel(solver="nlgs+finish").values == 0).all()
    # Anderson acceleration: fewer sweeps than plain NLGS to every tolerance on the dense packing
    assert (ds.sweeps.sel(solver="anderson").values < ds.sweeps.sel(solver="nlgs").values).all()
    assert ds.seconds.attrs["units"] == "s"


def test_tolerance_problems_local_solves(results):
    """The figures' problems side by side: every run stopping as converged is at
    or below its tolerance; plain NLGS is at distance 0 from itself; a run with local exact
    solves enabled that made none is plain NLGS sweep for sweep (the chunks of the stall test
    do not change the sweeps; Anderson's do: no extrapolation after a chunk's last sweep); the warm-started
    Figure 2 step is there."""
    path = results / "bench" / "tolerance_problems.nc"
    if not path.exists():
        pytest.skip(f"no {path} (run `snakemake -j2 bench`)")
    ds = xr.load_dataset(path)
    assert {"pile", "fig2_step", "fig2_step_warm"} <= set(ds.problem.values)
    assert {"nlgs+local", "anderson+local"} <= set(ds.solver.values)
    conv = ds.converged.values == 1
    assert (ds.residual.values[conv] <= np.broadcast_to(ds.tol.values, ds.residual.shape)[conv] * (1 + 1e-12)).all()
    assert (ds.gap_to_nlgs.sel(solver="nlgs").values == 0).all()
    loc = ds.sel(solver="nlgs+local")
    none = loc.local_solves.values == 0
    assert np.array_equal(loc.sweeps.values[none], ds.sel(solver="nlgs").sweeps.values[none])
    assert (ds.local_solves.sel(solver=["nlgs", "anderson", "nlgs+finish"]).values == 0).all()
    assert ds.local_solves.attrs["units"] == "1" and ds.gap_to_nlgs.attrs["long_name"]


def test_power_law_recovers_an_exponent():
    n = np.array([1e3, 1e4, 1e5])
    p, c = bench.power_law(n, 2e-6 * n ** 1.25)
    assert abs(p - 1.25) < 1e-12 and abs(c / 2e-6 - 1) < 1e-9
    assert np.isnan(bench.power_law([1e3], [1.0])[0]) and np.isnan(bench.power_law([1, 2], [0.0, 1.0])[0])


def test_bench_dag_has_every_job_and_a_critical_path(bench_results):
    """dag.nc: every job of the default run with a benchmark file, CPU time at most wall
    time x threads, and a critical path from a first job to the index, in order, whose
    length is the sum of its jobs' times alone."""
    dag = bench_results["dag"]
    rules = bench_results["rules"]
    # every benchmarked job of the default DAG is there (the run may hold more: other targets)
    in_dag = set(zip(dag.figure.values.astype(str), dag.rule.values.astype(str)))
    benched = sum((f, r) in in_dag for f, r in zip(rules.figure.values.astype(str), rules.rule.values.astype(str)))
    stamps = int((dag.figure.values.astype(str) == "code").sum())       # the sources' stamps (code_stamp)
    assert stamps >= 1
    assert benched >= dag.sizes["job"] - stamps - 2 and dag.attrs["dag_jobs"] > dag.sizes["job"]   # 2: index, mathjax
    assert (dag.cpu_s <= dag.wall_s * dag.threads + 1e-9).all()
    np.testing.assert_allclose(dag.attrs["cpu_s"], float(dag.cpu_s.sum()))
    path = dag.where(dag.critical == 1, drop=True).sortby("critical_order")
    assert list(path.critical_order.values) == list(range(path.sizes["job"]))
    assert path.rule.values[-1] == "index"
    np.testing.assert_allclose(dag.attrs["critical_path_s"], float(path.alone_s.sum()), rtol=1e-9)
    assert dag.attrs["ideal_s"] >= max(dag.attrs["critical_path_s"], dag.attrs["cpu_s"] / dag.attrs["cores"]) - 1e-9


def test_bench_sampler_kinds_agree_on_the_same_slices(results):
    """sampler.nc: on the same slices of the run, random and coordinate directions are both
    uniform samplers, so where both kinds' chains agree their pooled eta_U must agree within
    the gap allowed between two chains of one kind (MIXED_GAP); a slice at every mu of the
    plates series with an indeterminate bounded slice; every time positive."""
    from ncd.figures.fig5_governing.unger import MIXED_GAP
    path = results / "bench" / "sampler.nc"
    if not path.exists():
        pytest.skip(f"no {path} (run `snakemake -j2 bench`)")
    s = xr.load_dataset(path)
    p = xr.load_dataset(results / "fig5_governing" / "packings.nc")
    ok = (p.kind.values == 0) & (p.bounded.values == 1) & (p.dim_AC_rank.values > 0)
    assert sorted(set(np.round(s.mu.values, 12))) == sorted(set(np.round(p.mu.values[ok], 12)))
    assert list(s.directions.values) == ["random", "coordinate"]
    assert (s.cpu_seconds.values > 0).all()
    both = (s.mixed.values == 1).all(axis=1)
    assert both.any()
    eta = s.eta_uniform.values[both]
    assert (np.abs(eta[:, 1] / eta[:, 0] - 1) <= MIXED_GAP).all(), eta
    np.testing.assert_array_equal(s.dimension.values, p.dim_AC_rank.values[s.analysis.values])


def test_speed_table_keeps_the_rows_of_absent_bench_files(tmp_path):
    """A run with dag.nc only updates the default run's rows and keeps core.nc's from the
    committed table, in table order; a row from a file no bench rule writes is refused."""
    d = tmp_path / "bench"
    d.mkdir()
    xr.Dataset(attrs={"cpu_s": 3810.2, "critical_path_s": 363.4, "ideal_s": 1905.1, "cores": 2}).to_netcdf(d / "dag.nc")
    old = [{"quantity": "default run: core time of all jobs (wall x threads)", "value": "1327", "unit": "s",
            "source": "results/bench/dag.nc"},
           {"quantity": "NLGS contact update, N = 10044: numba / C", "value": "18 / 15.6", "unit": "ns",
            "source": "results/bench/core.nc"}]
    rows = speed_table.merge_rows(speed_table.speed_rows(tmp_path), old, tmp_path)
    assert [r["value"] for r in rows] == ["3810", "363", "1905", "18 / 15.6"]
    assert speed_table.merge_rows([], old, tmp_path / "nothing") == old
    with pytest.raises(ValueError, match="other.nc"):
        speed_table.merge_rows([], old + [{**old[1], "source": "results/bench/other.nc"}], tmp_path)
    with pytest.raises(ValueError, match="new speed rows from .'other.nc'"):
        speed_table.merge_rows([{**old[1], "source": "results/bench/other.nc"}], old, tmp_path)
