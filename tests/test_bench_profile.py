"""The sampled profile of the figures' jobs (ncd/studies/bench/profile.py): each py-spy sample
falls in the right category (numba kernel, LP solver, other compiled code, Python), each
process is filed under its job's figure read from the rules files, the goal is judged both
ways, and a real py-spy recording of a small numba script finds its kernel.

The raw lines are written by hand in the format py-spy 0.4 writes with ``--subprocesses
--native --format raw`` (seen on a recording of a parent process starting a child that runs
an njit kernel with cache=True, highspy and numpy)."""
import json
import pickle
import shutil
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

from ncd.studies.bench import profile as P

ROOT = Path(__file__).resolve().parent.parent
RULES = ROOT / "workflow" / "rules"
SNAKEMAKE = 'process 100:"/venv/bin/python /venv/bin/snakemake -j2"'
JOB = 'process 101:"/venv/bin/python /w/.snakemake/scripts/tmpab12cd34.fig1_explore.py"'
LIBC = "0x7fb217c4524a (libc.so.6)"


def category(line):
    (sample,) = P.parse_raw(line)
    return P.classify(sample.frames)


# ------------------------------------------------------------------ the categories
def test_a_numba_kernel_is_the_anonymous_frame_under_the_projects_code():
    kernel = f"{JOB};{LIBC};<module> (tmpab12cd34.fig1_explore.py:12);run (ncd/solver/nlgs.py:40);0x7fb2183e0088 (?) 7"
    assert category(kernel) == "kernel"
    # a kernel calling libm or numba's helpers is still the kernel
    assert category(f"{JOB};<module> (tmpab12cd34.fig1_explore.py:12);0x7fc5a95c016f (?);exp (libm.so.6) 2") == "kernel"
    assert category(f"{JOB};<module> (a.py:3);0x7fc5a95c016f (?);numba_sin (numba/mathnames.h:1) 1") == "kernel"


def test_an_unknown_address_under_a_library_is_no_kernel():
    """py-spy shows an address of a library it has not mapped yet as ``(?)`` too: under
    importlib (an extension module initialized), subprocess or llvmlite it is that library."""
    for inner in ("_call_with_frames_removed (<frozen importlib._bootstrap>:241)",
                  "Popen._execute_child (subprocess.py:1883)", "_make_opaque_ref (llvmlite/binding/ffi.py:40)"):
        assert category(f"{JOB};<module> (a.py:1);{inner};0x7feed51c6af4 (?);vfork (libc.so.6) 1") == "compiled", inner
    # no Python frame at all: unknown code, not a kernel; nor under a console script's frame
    assert category(f"{JOB};0x7f6a76ff194d (?);0x7f6a770e83dd (?) 1") == "compiled"
    assert P.frame_kind("<module> (snakemake:8)") == "python" and P.frame_kind("Py_DECREF (object.h:537)") == "native"
    assert category(f"{SNAKEMAKE};<module> (jupyter-nbconvert:8);0x7feed51c6af4 (?) 1") == "compiled"


def test_lp_solvers_are_found_by_their_libraries():
    for frame in ("Highs::run (highspy/_core.cpython-311-x86_64-linux-gnu.so)",
                  "0x7fb2049835a1 (scipy/optimize/_highspy/_core.cpython-311-x86_64-linux-gnu.so)",
                  "0x7f00 (clarabel/clarabel.abi3.so)", "ClpSimplex::dual (cylp.libs/libClp-d417d148.so.1.14.11)",
                  "HEkkDual::iterate (HEkkDual.cpp:120)"):
        line = f"{JOB};<module> (a.py:1);solve (ncd/exact/cone.py:10);{frame};memcpy (libc.so.6) 3"
        assert category(line) == "solver", frame
    # scipy's Python wrapper of HiGHS is Python, an import of highspy is no solving
    assert category(f"{JOB};linprog (scipy/optimize/_linprog.py:600);_highs_wrapper "
                    "(scipy/optimize/_highspy/_highs_wrapper.py:40) 1") == "python"
    assert category(f"{JOB};<module> (a.py:1);_call_with_frames_removed (<frozen importlib._bootstrap>:241);"
                    "0x7fcf285337a1 (highspy/_core.cpython-311-x86_64-linux-gnu.so) 1") == "compiled"


def test_numpy_is_other_compiled_code_and_bytecode_is_python():
    assert category(f"{JOB};<module> (a.py:29);svd (numpy/linalg/_linalg.py:1841);"
                    "dgemv_kernel_4x4 (libscipy_openblas64_-32a4b2a6.so) 1") == "compiled"
    assert category(f"{JOB};{LIBC};<module> (a.py:3);pure (a.py:9) 4") == "python"
    # the interpreter's own native code (the garbage collector) is Python's time
    assert category(f"{JOB};{LIBC};<module> (a.py:3);gc_collect_main (libpython3.11.so.1.0) 13") == "python"
    # a thread seen only at its libc root (starting or ending) is the interpreter's
    assert category(f"{JOB};{LIBC} 1") == "python"


def test_a_child_process_carries_its_chain_of_processes():
    line = ('process 27227:"python parent.py";process 27232:"/work/main/.venv/bin/python child.py";'
            "0x7fb217c4524a (libc.so.6);<module> (child.py:22);0x7fb2183e0088 (?) 4\n\n")
    (s,) = P.parse_raw(line)
    assert s.processes == ((27227, "python parent.py"), (27232, "/work/main/.venv/bin/python child.py"))
    assert s.frames == ("0x7fb217c4524a (libc.so.6)", "<module> (child.py:22)", "0x7fb2183e0088 (?)")
    assert s.count == 4 and P.classify(s.frames) == "kernel"
    with pytest.raises(ValueError, match="line 1 of the py-spy output"):
        P.parse_raw("process 1:\"python\";<module> (a.py:1)\n")


def test_hot_functions_drop_line_numbers_and_wrapper_names():
    assert P.hot_function(("<module> (tmpgnsg42dx.merge_shards.py:3)",)) == "<module> (merge_shards.py)"
    assert P.hot_function(("a (ncd/solver/nlgs.py:3)", "0x7f (?)")) == "a (ncd/solver/nlgs.py)"
    assert P.hot_function((LIBC,)) == "(native)"


# ------------------------------------------------------------------ jobs and figures
def test_rules_files_give_each_script_its_figure():
    table = P.rules_table(RULES)
    assert P.figure_of("fig1_explore.py", table) == "fig1_wedged"
    assert P.figure_of("fig2_slope.ipynb", table) == "fig2_slope"
    assert P.figure_of("code_stamp.py", table) == "code"            # as dag.nc names it: its benchmark folder
    assert P.figure_of("index.py", table) == "index"
    # the rules shared by the figures file their jobs under the figure wildcard
    assert P.figure_of("render_html.py", table, "render_html", {"figure": "fig4_pile"}) == "fig4_pile"
    # a script several figures run needs the job's rule (from its wrapper)
    assert P.figure_of("merge_shards.py", table, "fig2_slope_merge") == "fig2_slope"


def test_an_unknown_or_ambiguous_job_is_an_error_naming_it():
    """Negative controls: an unknown script raises (it is not filed under an 'unknown' bucket,
    which would hide a rules file the parser missed); Snakemake's own processes, which run no
    job, go to the (snakemake) row."""
    table = P.rules_table(RULES)
    with pytest.raises(ValueError, match="'no_such_script.py' of a job is run by no rule"):
        P.figure_of("no_such_script.py", table)
    with pytest.raises(ValueError, match="'merge_shards.py' is run by rules of several figures"):
        P.figure_of("merge_shards.py", table)
    with pytest.raises(ValueError, match="rule 'no_such_rule'"):
        P.figure_of("fig1_explore.py", table, "no_such_rule")
    with pytest.raises(ValueError, match="runs 'fig1_explore.py'"):
        P.figure_of("fig1_sweep.py", table, "fig1_wedged_explore")
    with pytest.raises(ValueError, match="wildcard"):
        P.figure_of("render_html.py", table)
    assert P.sample_figures(P.parse_raw(f"{SNAKEMAKE};<module> (snakemake:8) 3"), table) == [P.NOT_A_JOB]


def test_rules_table_reads_benchmark_folders_and_finds_new_rules(tmp_path):
    (tmp_path / "figx.smk").write_text(textwrap.dedent('''\
        FIGX = "figx"

        rule figx_a:
            """A rule whose docstring says script: nothing."""
            output: "a"
            benchmark:
                bench(FIGX, "a")
            script:
                "../scripts/figx_a.py"

        rule figx_b:
            output: "b"
            benchmark: "results/benchmarks/other/b.tsv"
            notebook: "../../notebooks/figx.ipynb"

        rule figx_c:
            output: "c"
            script:
                "../scripts/figx_c.py"

        rule figx:
            input: "a", "b", "c"
        '''))
    table = P.rules_table(tmp_path)
    assert set(table) == {"figx_a", "figx_b", "figx_c"}
    assert [table[r].figure for r in ("figx_a", "figx_b", "figx_c")] == ["figx", "other", "figx"]
    assert table["figx_b"].script == "figx.ipynb" and table["figx_a"].source == "figx.smk"


def write_wrapper(path, rule, wildcards=None, body=""):
    """A wrapper as Snakemake writes it: a preamble unpickling the ``snakemake`` object."""
    obj = pickle.dumps(SimpleNamespace(rule=rule, wildcards=wildcards or {}))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"import pickle, types;snakemake = pickle.loads({obj!r})\n{body}")
    return path


def test_wrappers_name_the_rule_of_a_shared_script(tmp_path):
    scripts = tmp_path / ".snakemake" / "scripts"
    wrapper = write_wrapper(scripts / "tmpq1w2e3r4.merge_shards.py", "fig3_equilibrium_merge")
    nb = scripts / "tmpz9x8c7v6.fig4_pile.ipynb"
    preamble = f"import pickle;snakemake = pickle.loads({pickle.dumps(SimpleNamespace(rule='fig4_pile_notebook'))!r})"
    nb.write_text(json.dumps({"cells": [{"cell_type": "code", "source": [preamble, "\n"]}]}))
    raw = (f'{SNAKEMAKE};process 7:"python {wrapper}";<module> (tmpq1w2e3r4.merge_shards.py:3) 5\n'
           f'{SNAKEMAKE};process 8:"python jupyter-nbconvert --execute --to notebook {nb}";'
           'process 9:"python -m ipykernel_launcher -f /tmp/k.json";<module> (123.py:1);0x7f (?) 2\n'
           f"{SNAKEMAKE};<module> (snakemake:8) 1\n")
    samples = P.parse_raw(raw)
    assert P.read_wrapper(wrapper) == ("fig3_equilibrium_merge", {})
    # bytes holding a quote are written in double quotes (Snakemake writes the pickle's repr)
    quoted = write_wrapper(scripts / "tmpa1b2c3d4.render_html.py", "render_html", {"figure": "fig1_wedged", "q": "'"})
    assert 'loads(b"' in quoted.read_text()
    assert P.read_wrapper(quoted) == ("render_html", {"figure": "fig1_wedged", "q": "'"})
    assert P.sample_figures(samples, P.rules_table(RULES)) == ["fig3_equilibrium", "fig4_pile", P.NOT_A_JOB]
    wrapper.unlink()                   # Snakemake's cleanup: the shared script alone says too little
    with pytest.raises(ValueError, match="several figures"):
        P.sample_figures(samples, P.rules_table(RULES))


# ------------------------------------------------------------------ the table and the goal
def small_profile():
    """fig1_wedged: 900 kernel, 60 solver, 40 Python samples; fig2_slope: 300 kernel, 700 numpy;
    stability: 50 kernel samples (too few); Snakemake: 10."""
    job = {f: f'process 2:"python /w/.snakemake/scripts/tmp0000aaaa.{s}"' for f, s in
           (("fig1_wedged", "fig1_explore.py"), ("fig2_slope", "fig2_slope_explore.py"),
            ("stability", "stability_simulate.py"))}
    lines = [f"{job['fig1_wedged']};<module> (x.py:1);run (ncd/solver/nlgs.py:4);0x7f01 (?) 900",
             f"{job['fig1_wedged']};<module> (x.py:1);Highs::run (highspy/_core.so) 60",
             f"{job['fig1_wedged']};<module> (x.py:1);_find_and_load (<frozen importlib._bootstrap>:1176) 40",
             f"{job['fig2_slope']};<module> (x.py:1);run (ncd/solver/nlgs.py:4);0x7f01 (?) 300",
             f"{job['fig2_slope']};<module> (x.py:1);svd (numpy/linalg/_linalg.py:1841);dgesdd (libopenblas.so) 700",
             f"{job['stability']};<module> (x.py:1);run (ncd/solver/nlgs.py:4);0x7f01 (?) 50",
             f"{SNAKEMAKE};<module> (snakemake:8) 10"]
    samples = P.parse_raw("\n".join(lines))
    figures = P.sample_figures(samples, P.rules_table(RULES))
    return P.profile_table(samples, figures, rate=25, order=["fig2_slope", "fig1_wedged", "stability"])


def test_profile_table_counts_every_sample_once():
    ds = small_profile()
    assert list(ds.figure.values) == ["fig2_slope", "fig1_wedged", "stability", P.NOT_A_JOB]
    assert list(ds.samples.values) == [1000, 1000, 50, 10] and ds.attrs["samples"] == 2060
    total = sum(ds[f"{c}_share"] for c in P.CATEGORIES)
    np.testing.assert_allclose(total.values, 1.0)
    f1 = ds.sel(figure="fig1_wedged")
    assert (float(f1.kernel_share), float(f1.solver_share), float(f1.python_share)) == (0.9, 0.06, 0.04)
    assert float(f1.import_share) == 0.04 and float(ds.sel(figure="fig2_slope").compiled_share) == 0.7
    np.testing.assert_allclose(ds.sampled_cpu_s.values, ds.samples.values / 25)
    assert ds.hot_function.sel(figure="fig2_slope").values[0] == "svd (numpy/linalg/_linalg.py)"
    assert float(ds.hot_share.sel(figure="fig2_slope", rank=1)) == 0.7


def test_goal_is_judged_both_ways():
    """Positive control fig1_wedged (0.96 inside kernels and solvers): met; negative control
    fig2_slope (0.3): not met; 50 samples: not judged; the scheduler: no job."""
    assert P.goal_status(small_profile()) == ["not met", "met", "too few samples", "—"]
    ds = small_profile()
    ds.attrs["goal"] = 0.97                                     # the same data against a higher goal
    assert P.goal_status(ds)[1] == "not met"


def test_capped_overlay_lowers_counts_and_never_raises_them():
    config = {"run": {"label": "full"}, "fig2_slope": {"explore": {"runs": 2000, "tol": 1e-6}, "shards": 4},
              "fig4_history": {"piles": 4}}
    quick = {"run": {"label": "quick"}, "fig2_slope": {"explore": {"runs": 500}}, "fig4_history": {"piles": 8}}
    out = P.capped(config, quick)
    assert out["run"] == {"label": "quick"} and out["fig2_slope"] == {"explore": {"runs": 500, "tol": 1e-6}, "shards": 4}
    assert out["fig4_history"]["piles"] == 4 and config["fig2_slope"]["explore"]["runs"] == 2000


def test_recording_counts_reads_py_spys_last_line():
    text = "py-spy> Stopped sampling\npy-spy> Wrote raw flamegraph data to 'raw.txt'. Samples: 390 Errors: 92\n"
    assert P.recording_counts(text) == (390, 92)
    with pytest.raises(ValueError, match="Samples: N Errors: M"):
        P.recording_counts("py-spy> failed")


def test_job_wall_sums_each_figures_benchmark_files(tmp_path):
    bench = tmp_path / "results" / "benchmarks"
    for rel, s in (("fig1_wedged/a.tsv", 1.5), ("fig1_wedged/b.tsv", 2.0), ("index.tsv", 0.25)):
        (bench / rel).parent.mkdir(parents=True, exist_ok=True)
        (bench / rel).write_text(f"s\th:m:s\tmax_rss\n{s}\t0:00:01\t6.3\n")
    assert P.job_wall(sorted(bench.rglob("*.tsv"))) == {"fig1_wedged": 3.5, "index": 0.25}


# ------------------------------------------------------------------ a real recording
KERNEL = '''
import time
import numba
import psutil

@numba.njit(cache=True)
def kernel(n):
    s = 0.0
    for i in range(n):
        s += (i % 7) * 0.5
    return s

kernel(10)
t = time.time()
# three times as long as everything before it (interpreter, imports, compilation), and at least
# two seconds: the kernel's share of the job is then at least 3/4 however slow or busy the machine
duration = max(2.0, 3.0 * (t - psutil.Process().create_time()))
while time.time() - t < duration:
    kernel(5_000_000)
'''


def test_a_real_recording_finds_the_kernel_of_a_job(tmp_path):
    """py-spy records a parent starting a job's wrapper (a script with Snakemake's preamble and
    an njit kernel run, after its first call, for three times the wall time the job took to
    reach it and at least two seconds): the job is filed under its figure from a rules file,
    more than half of its samples inside the kernel (3/4 expected; start-up, imports and
    compilation take the rest), and the parent under (snakemake)."""
    if shutil.which("py-spy") is None:
        pytest.skip("py-spy is not installed (the bench extra)")
    rules = tmp_path / "rules"
    rules.mkdir()
    (rules / "figk.smk").write_text('rule figk_kernel:\n    output: "k"\n    script:\n        "../scripts/figk_kernel.py"\n')
    wrapper = write_wrapper(tmp_path / "w" / ".snakemake" / "scripts" / "tmpk3rn3l00.figk_kernel.py", "figk_kernel",
                            body=KERNEL)
    parent = tmp_path / "parent.py"
    parent.write_text(f"import subprocess, sys\nsubprocess.run([sys.executable, {str(wrapper)!r}], check=True)\n")
    raw = tmp_path / "raw.txt"
    try:
        _, printout = P.record([sys.executable, parent], raw, rate=100, cwd=tmp_path)
    except RuntimeError as err:
        if "ptrace" in str(err).lower() or "permission" in str(err).lower():
            pytest.skip(f"py-spy cannot attach here: {err}")
        raise
    samples = P.parse_raw(raw.read_text())
    ds = P.profile_table(samples, P.sample_figures(samples, P.rules_table(rules), str(rules)), rate=100)
    assert list(ds.figure.values)[0] == "figk" and P.NOT_A_JOB in ds.figure.values
    fig = ds.sel(figure="figk")
    assert int(fig.samples) >= 100                                   # two seconds of kernel at 100 per second
    assert float(fig.kernel_share) > 0.5, ds[["samples", "kernel_share", "python_share", "compiled_share"]]
    assert float(fig.solver_share) == 0.0
    total, errors = P.recording_counts(printout)
    assert total >= int(ds.samples.sum()) - errors


# ------------------------------------------------------------------ the run's file
def test_profile_file_of_the_run(results):
    """profile.nc of the bench run: every sample of a figure in one category, the figures those
    of the rules files, and the recording's provenance without a time stamp."""
    path = results / "bench" / "profile.nc"
    if not path.exists():
        pytest.skip(f"no {path} (run `snakemake -j2 bench_profile`)")
    ds = xr.load_dataset(path)
    np.testing.assert_allclose(sum(ds[f"{c}_share"] for c in P.CATEGORIES).values, 1.0)
    known = {r.figure for r in P.rules_table(RULES).values()} - {"{figure}"} | {P.NOT_A_JOB}
    assert set(ds.figure.values.astype(str)) <= known
    assert "fig1_wedged" in set(ds.figure.values.astype(str))     # every config profiles it (the test run: it alone)
    assert "py-spy record --subprocesses --native" in ds.attrs["command"]
    assert ds.attrs["config_label"] == "quick" and ds.attrs["rate"] > 0
    assert not any("date" in k or "time" in k for k in ds.attrs)
    assert (ds.samples >= 0).all() and int(ds.samples.sum()) <= ds.attrs["pyspy_samples"]


def test_py_spy_missing_is_a_clear_error(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(RuntimeError, match=r"py-spy is not installed"):
        P.py_spy()
