"""The speed report page (ncd/studies/bench/page.py): its sentences quote the numbers of the
bench files, its tables are formatted HTML, its figure is readable at page width.

The datasets are small and built by hand, with the variables and attributes the bench
rules write.
"""
import matplotlib
import numpy as np
import xarray as xr
from figure_checks import problems

from ncd.studies.bench import page as BP

matplotlib.use("Agg")

N = np.array([1000, 10000, 100000])


def small_core():
    """Three sizes; numba 20, 22, 24 ns per update against C 10, 11, 12 ns (ratio 2)."""
    step = 1e-5 * N
    return xr.Dataset(
        {"n_discs": ("size", N), "n_contacts": ("size", 3 * N), "build_s": ("size", 1e-7 * N),
         "sweep_s": ("size", 6e-8 * N), "ns_per_update": ("size", [20.0, 22.0, 24.0]),
         "ns_per_update_c": ("size", [10.0, 11.0, 12.0]), "ns_per_update_interleaved": ("size", [10.0, 11.0, 48.0]),
         "c_agrees": ("size", [1, 1, 1]), "detect_s": ("size", 1e-7 * N), "prepare_s": ("size", 2e-7 * N),
         "step_s": ("size", step), "step_sweeps": ("size", [200, 200, 200]), "step_converged": ("size", [1, 1, 1]),
         "peak_memory": ("size", 2.0**20 * N / 100), "memory_growth": ("size", 2.0**20 * np.ones(3))},
        coords={"size": N},
        attrs={"machine": "x86_64", "cpu_count": 2, "python": "3.11", "numba": "0.60", "loadavg_start": 0.5,
               "startup_import_s": 1.5, "startup_first_step_s": 0.25, "startup_process_s": 2.0,
               "config_yaml": "sizes: [1000, 10000, 100000]\nstep_sweeps: 200\n"})


def small_sweeps():
    """Sweeps ~ N^0.5 from the zero guess; the largest size exhausts the budget."""
    n = np.array([100, 400, 1600])
    zero = np.array([100, 200, 20000])
    return xr.Dataset(
        {"sweeps_zero": ("size", zero), "sweeps_interleaved": ("size", 2 * zero), "sweeps_warm": ("size", [8, 9, 12]),
         "converged_zero": ("size", [1, 1, 0]), "converged_interleaved": ("size", [1, 1, 0]),
         "converged_warm": ("size", [1, 1, 1]), "wall_time_zero": ("size", [1.0, 2.0, 9.0]),
         "wall_time_interleaved": ("size", [1.5, 3.0, 9.0]), "wall_time_warm": ("size", [0.1, 0.1, 0.1])},
        coords={"size": n}, attrs={"tol": 1e-4, "max_sweeps": 20000, "warm_steps": 5})


def small_ensemble():
    return xr.Dataset({"wall_time": ("threads", [2.0, 1.1]), "speedup": ("threads", [1.0, 2.0 / 1.1]),
                       "same_results": ("threads", [1, 1]), "digest": ("threads", ["ab", "ab"])},
                      coords={"threads": [1, 2]},
                      attrs={"runs": 8, "n_contacts": 596, "sweeps_mean": 234.6, "converged": 8})


def small_peer():
    v = {"n_steps": [1448, 1448], "time_mean": [3e-3, 2e-4], "time_settle": [1e-3, 5e-5],
         "overlap_max": [0.2, 0.25], "overlap_end": [0.1, 0.18], "ground_reaction": [0.9, 0.7],
         "coulomb_violation": [0.0, 4.5e-16], "kinetic_energy": [1e-9, 1e-4]}
    ds = xr.Dataset({k: ("engine", np.array(x, float)) for k, x in v.items()}, coords={"engine": ["ncd", "pymunk"]},
                    attrs={"pymunk_version": "7.3.1",
                           "config_yaml": "n_discs: 40\ndrop_every: 32\nh: 0.001\niterations: 10\n"})
    ds["time_mean"].attrs["units"] = "s"
    ds["x"] = (("engine", "disc"), np.zeros((2, 3)))       # not a per-engine scalar: not in the table
    return ds


def small_tolerance():
    """Per solver (rows) and tolerance 1e-6, 1e-8, 1e-10 (columns): seconds of one size."""
    seconds = np.array([[[0.3, 0.2, 0.5], [0.1, 0.3, 0.4], [0.2, 0.1, 0.3]]])
    dims = ("size", "solver", "tol")
    return xr.Dataset({"seconds": (dims, seconds), "sweeps": (dims, np.full(seconds.shape, 10)),
                       "converged": (dims, np.ones(seconds.shape, int))},
                      coords={"size": [100], "solver": ["nlgs", "nlgs+finish", "anderson"], "tol": [1e-6, 1e-8, 1e-10]})


def small_problems():
    """One problem, two orders, plain NLGS and one local-exact solver; at the tightest
    tolerance the local solver is 2x and 4x faster, and order 1 of plain NLGS fails at 1e-10."""
    dims = ("problem", "order", "solver", "tol")
    seconds = np.ones((1, 2, 2, 2))
    seconds[0, :, 1, 1] = [0.5, 0.25]
    converged = np.ones((1, 2, 2, 2), int)
    sweeps = np.full((1, 2, 2, 2), 100)
    sweeps[0, :, 1, 1] = [30, 40]
    return xr.Dataset({"seconds": (dims, seconds), "converged": (dims, converged), "sweeps": (dims, sweeps),
                       "local_solves": (dims, np.full(seconds.shape, 3)), "gap_to_nlgs": (dims, np.full(seconds.shape, 1e-9))},
                      coords={"problem": ["pile"], "order": [0, 1], "solver": ["nlgs", "nlgs+local"], "tol": [1e-6, 1e-10]})


def small_rules():
    names = [f"rule_{k}" for k in range(20)]
    return xr.Dataset({"figure": ("job", ["fig2_slope"] * 10 + ["stability"] * 10), "rule": ("job", names),
                       "seconds": ("job", np.arange(20.0) * 3), "max_rss_mb": ("job", np.full(20, 200.0))})


def small_dag():
    return xr.Dataset({"figure": ("job", ["fig9"] * 3), "rule": ("job", ["simulate", "explore", "notebook"]),
                       "threads": ("job", [1, 2, 1]), "wall_s": ("job", [12.0, 50.0, 20.0]),
                       "cpu_s": ("job", [10.0, 80.0, 20.0]), "alone_s": ("job", [10.0, 40.0, 20.0]),
                       "critical": ("job", [1, 1, 1]), "critical_order": ("job", [0, 1, 2])},
                      attrs={"critical_path_s": 70.0, "cpu_s": 110.0, "jobs": 3, "cores": 2})


def test_sweep_sentence_quotes_the_core_table():
    text = BP.sweep_sentence(small_core())
    assert "**20.0–24.0 ns** per contact update" in text and "C: 10.0–12.0 ns; numba/C 2.00–2.00" in text
    assert "10.0–10.0 µs at a budget of 200 sweeps" in text
    assert "imports ncd in 1.50 s and makes its first step 0.25 s later (whole process 2.00 s)" in text
    assert "load average at start 0.50" in BP.machine_sentence(small_core())


def test_core_tables_are_formatted_html():
    html = BP.core_table(small_core())
    assert html.startswith("<table") and "<th>ratio</th>" in html and "<td>2</td>" in html
    assert "0.0200000" not in html                      # floats printed with 3 significant digits
    assert (BP.number(0.012345), BP.number(12345.6), BP.number(2e-6)) == ("0.0123", "12346", "2e-06")
    assert "<td>0.5</td>" in BP.interleaved_table(small_core())      # 24 / 48 at the largest size
    scaling = BP.scaling_frame(small_core())
    np.testing.assert_allclose(scaling["fitted p"], 1.0)
    assert list(scaling.columns[:-1]) == list(N)


def test_sweeps_sentence_fits_the_converged_sizes():
    s = BP.sweeps_numbers(small_sweeps())
    assert np.isclose(s["slope"], 0.5) and s["exhausted"] == 1 and s["warm"] == (8, 12)
    assert s["extra"] == (2.0, 2.0) and s["time_ratio"] == (1.5, 1.5)
    text = BP.sweeps_sentence(small_sweeps())
    assert "grow like N^0.50" in text and "1 size(s) exhausted 20000 sweeps" in text
    assert "after 5 steps, 8–12 sweeps suffice" in text and "2.00–2.00 times the sweeps" in text


def test_ensemble_and_peer_sentences():
    text = BP.ensemble_sentence(small_ensemble())
    assert "8 zero-guess runs (596 contacts, mean 235 sweeps, 8 converged)" in text
    assert "**1.82×** on 2 threads (target 1.8×)" in text and "identical bit for bit" in text
    peer = small_peer()
    text = BP.peer_sentence(peer)
    assert "40 discs poured one every 32 steps of 1 ms, 10 Gauss–Seidel iterations" in text
    assert "ncd **3.000 ms**, pymunk **0.200 ms**" in text and "ratio 15.00" in text
    frame = BP.peer_frame(peer)
    assert "x" not in frame.index and frame.loc["time_mean", "unit"] == "s"


def test_tolerance_sentences_and_local_table():
    assert BP.fastest_sentence(small_tolerance()) == (
        "Fastest to each tolerance: 100 discs, 1e-10: anderson (0.30 s); 100 discs, 1e-08: anderson "
        "(0.10 s); 100 discs, 1e-06: nlgs+finish (0.10 s).")
    assert "pile, nlgs+local, 1e-10: 2 of 2" in BP.reached_sentence(small_problems())
    row = BP.local_frame(small_problems()).loc[("pile", "nlgs+local")]
    assert row["speed-up"] == "2–4" and row["sweeps"] == "30–40" and row["plain NLGS sweeps"] == "100–100"
    assert row["converged"] == "2 of 2" and row["local solves"] == 3
    assert "<table" in BP.tolerance_table(small_tolerance()) and "<table" in BP.problems_table(small_problems())


def test_rules_and_dag_tables():
    text = BP.rules_sentence(small_rules())
    assert text.startswith(f"20 jobs, {np.arange(20.0).sum() * 3 / 60:.1f} CPU-job minutes")
    jobs, per_figure = BP.rules_tables(small_rules())
    assert jobs.count("<tr>") == 21 and "<td>435</td>" in per_figure      # 3 (10 + ... + 19)
    per_fig, path, text = BP.dag_tables(small_dag())
    assert "Critical path 70 s through 3 jobs" in text and path.count("<tr>") == 3      # one row per job of the path


def small_profile():
    """fig9: 800 kernel and 100 solver samples of 1000 (goal met); fig8: 300 kernel, 500 Python
    (200 of them importing) and 200 numpy samples of 1000 (not met); the scheduler: 50."""
    from ncd.studies.bench.profile import NOT_A_JOB
    counts = {"fig9": {"kernel": 800, "solver": 100, "compiled": 0, "python": 100},
              "fig8": {"kernel": 300, "solver": 0, "compiled": 200, "python": 500}, NOT_A_JOB: {"python": 50}}
    labels = ["fig9", "fig8", NOT_A_JOB]
    n = np.array([1000, 1000, 50])
    share = {c: np.array([counts[f].get(c, 0) for f in labels]) / n for c in ("kernel", "solver", "compiled", "python")}
    hot = np.array([["run (ncd/a.py)", "", ""], ["svd (numpy/linalg/_linalg.py)", "<module> (x.py)", ""],
                    ["<module> (snakemake)", "", ""]])
    return xr.Dataset({"samples": ("figure", n), **{f"{c}_share": ("figure", v) for c, v in share.items()},
                       "sampled_cpu_s": ("figure", n / 25.0), "job_wall_s": ("figure", [50.0, 80.0, np.nan]),
                       "import_share": ("figure", [0.0, 0.2, 0.0]), "numba_load_share": ("figure", [0.0, 0.05, 0.0]),
                       "hot_function": (("figure", "rank"), hot),
                       "hot_share": (("figure", "rank"), np.array([[0.1, 0, 0], [0.2, 0.1, 0], [1.0, 0, 0]]))},
                      coords={"figure": labels, "rank": [1, 2, 3]},
                      attrs={"rate": 25.0, "goal": 0.8, "min_samples": 200, "config_label": "quick",
                             "pyspy_errors": 7})


def test_profile_table_and_sentence():
    """The goal column says met for the kernel-bound figure and not met for the one in Python;
    job CPU and the critical path come from dag.nc, the shares from the profile."""
    frame = BP.profile_frame(small_profile(), small_dag())
    assert list(frame["goal (≥ 80 %)"]) == ["met", "not met", "—"]
    np.testing.assert_allclose(frame["kernels + solvers (%)"], [90.0, 30.0, 0.0])
    assert frame.loc["fig9", "job CPU (s)"] == 110.0 and frame.loc["fig9", "on the critical path (s)"] == 70.0
    assert np.isnan(frame.loc["fig8", "job CPU (s)"]) and frame.loc["fig8", "on the critical path (s)"] == 0.0
    np.testing.assert_allclose(frame["sampled CPU / job wall"].values[:2], [40.0 / 50.0, 40.0 / 80.0])
    assert "<td>met</td>" in BP.table(frame)
    text = BP.profile_sentence(small_profile())
    assert "the quick counts, 25 samples per second, 2050 samples (py-spy could not read 7 stacks)" in text
    assert "1 of 2 figures with at least 200 samples hold 80 % or more" in text
    assert ("the furthest from it, fig8, holds 30 % there and spends 50 % in Python and 20 % in other compiled "
            "code (imports 20 %, numba's dispatch and cache loading 5 %") in text
    assert "Snakemake's own process: 2 s of CPU sampled." in text
    hot = BP.hot_spots_frame(small_profile())
    assert hot.loc["fig8", "1"] == "svd (numpy/linalg/_linalg.py) — 20 %" and hot.loc["fig9", "2"] == ""


def small_exact(sizes=(1000, 10000)):
    """Two piles per history at 10^3 grains (LP seconds 2, 4 and 1, 3) and one at 10^4 (600, 300)."""
    rows = [(1000, "point", 2.0), (1000, "point", 4.0), (1000, "rain", 1.0), (1000, "rain", 3.0),
            (10000, "point", 600.0), (10000, "rain", 300.0)]
    rows = [r for r in rows if r[0] in sizes]
    col = lambda i: [r[i] for r in rows]                     # noqa: E731
    return xr.Dataset({"grains": ("pile", col(0)), "history": ("pile", col(1)), "member": ("pile", [0] * len(rows)),
                       "n_contacts": ("pile", [1700 if g == 1000 else 17000 for g in col(0)]),
                       "n_cuts": ("pile", [18] * len(rows)), "n_lp": ("pile", [110] * len(rows)),
                       "solver": ("pile", ["highs" if g == 1000 else "clarabel" for g in col(0)]),
                       "lp_seconds": ("pile", col(2))})


def test_exact_sets_table_and_sentence():
    frame = BP.exact_frame(small_exact())
    assert list(frame["piles"]) == [2, 2, 1, 1] and list(frame["solver"]) == ["highs", "highs", "clarabel", "clarabel"]
    np.testing.assert_array_equal(frame["LP seconds per pile (median)"], [3.0, 2.0, 600.0, 300.0])
    np.testing.assert_array_equal(frame["LP seconds per pile (largest)"], [4.0, 3.0, 600.0, 300.0])
    text = BP.exact_sentence(small_exact())
    assert "point 3 s (largest 4 s, 2 piles), rain 2 s (largest 3 s, 2 piles) at 1000 grains" in text
    assert "point 600 s (1 pile), rain 300 s (1 pile) at 10000 grains." in text and "size study" not in text
    assert "the size study" in BP.exact_sentence(small_exact((1000,)))


def test_bench_figure_is_readable():
    fig = BP.plot(small_core(), small_sweeps(), small_rules())
    assert problems(fig) == []
    titles = [ax.get_title() for ax in fig.axes]
    assert [t[:3] for t in titles] == ["(a)", "(b)", "(c)", "(d)"]
    assert len(fig.axes[3].patches) == 15                # the fifteen slowest rules


def test_sampler_table_and_sentence():
    """Two slices, coordinate directions 4 and 5 times cheaper, eta_U 2 % and 10 % apart:
    the sentence gives the median ratio, the totals and the largest difference."""
    import xarray as xr

    from ncd.figures.fig5_governing import sampler
    s = xr.Dataset({"cpu_seconds": (("case", "directions"), [[8.0, 2.0], [10.0, 2.0]]),
                    "eta_uniform": (("case", "directions"), [[0.10, 0.102], [0.20, 0.18]]),
                    "gap": (("case", "directions"), [[0.01, 0.02], [0.03, 0.01]]),
                    "rhat": (("case", "directions"), [[1.01, 1.02], [1.03, 1.05]]),
                    "per_chain": (("case", "directions"), [[1000, 1000], [1000, 4000]]),
                    "mixed": (("case", "directions"), [[1, 1], [1, 0]]),
                    "mu": ("case", [0.01, 0.1]), "dimension": ("case", [40, 90])},
                   coords={"directions": ["random", "coordinate"]})
    text = sampler.summary(s)
    assert "On 2 slices (dim(A ∩ C) 40–90)" in text and "median 1/4.5" in text
    assert "4 s against 18 s" in text and "median 6.0% (largest 10.0%)" in text
    assert "2 (random) and 1 (coordinate) of 2" in text
    df = sampler.frame(s)
    assert list(df["coordinate: points per chain"]) == [1000, 4000] and df.shape == (2, 12)
    assert "No indeterminate slice" in sampler.summary(s.isel(case=slice(0, 0)))
