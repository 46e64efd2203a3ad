"""The Snakemake DAG: validation before any job, incremental reruns, shard invariance."""
import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest
import xarray as xr
import yaml
from conftest import ROOT, copy_workflow, run_snakemake

SCHEMAS = ROOT / "workflow" / "schemas"
CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())
FIGURES = [f for f in ("fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile") if f in CONFIG]
# rules a figure target shares with the others: the HTML rendering and the reproduction page
SHARED = {"render_html", "html_mathjax", "index", "all", "code_stamp"}


def planned_jobs(proc):
    """Rule -> job count from the 'Job stats' table of a dry run."""
    text = proc.stdout + proc.stderr
    if "Nothing to be done" in text:
        return {}
    table = text.split("Job stats:", 1)[1]
    jobs = {}
    for line in table.splitlines()[3:]:
        m = re.match(r"^(\S+)\s+(\d+)\s*$", line)
        if not m:
            break
        if m.group(1) != "total":
            jobs[m.group(1)] = int(m.group(2))
    return jobs


def first_bounded_key(schema, path=()):
    """Path to the first property with a 'minimum' in a schema, and that minimum."""
    for key, sub in schema.get("properties", {}).items():
        if "minimum" in sub and sub.get("type") in ("number", "integer"):
            return path + (key,), sub["minimum"]
        found = first_bounded_key(sub, path + (key,))
        if found:
            return found
    return None


def nested(path, value):
    out = value
    for key in reversed(path):
        out = {key: out}
    return out


def write_overlay(tmp_path, data):
    p = tmp_path / "overlay.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


@pytest.fixture()
def fresh_repo(tmp_path):
    return copy_workflow(tmp_path / "repo")


def test_unknown_section_stops_before_any_job(fresh_repo, tmp_path):
    proc = run_snakemake(fresh_repo, "-n", extra_configs=[write_overlay(tmp_path, {"fig9_typo": {}})], check=False)
    assert proc.returncode != 0
    assert "fig9_typo" in proc.stdout + proc.stderr
    assert not (fresh_repo / "results").exists()


@pytest.mark.parametrize("figure", FIGURES)
def test_misspelled_key_stops_before_any_job(fresh_repo, tmp_path, figure):
    overlay = write_overlay(tmp_path, {figure: {"frobnication_typo": 1}})
    proc = run_snakemake(fresh_repo, "-n", extra_configs=[overlay], check=False)
    assert proc.returncode != 0
    assert "frobnication_typo" in proc.stdout + proc.stderr
    assert not (fresh_repo / "results").exists()


@pytest.mark.parametrize("figure", FIGURES)
def test_out_of_range_value_stops_naming_the_key(fresh_repo, tmp_path, figure):
    schema = yaml.safe_load((SCHEMAS / f"{figure}.schema.yaml").read_text())
    path, minimum = first_bounded_key(schema)
    overlay = write_overlay(tmp_path, {figure: nested(path, minimum - 1)})
    proc = run_snakemake(fresh_repo, "-n", extra_configs=[overlay], check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0
    assert path[-1] in out and "minimum" in out, out[-2000:]
    assert not (fresh_repo / "results").exists()


def test_second_run_does_nothing(dag_repo):
    assert planned_jobs(run_snakemake(dag_repo, "-n")) == {}


@pytest.mark.parametrize("figure", FIGURES)
def test_editing_a_notebook_reruns_only_its_notebook(dag_repo, figure):
    """An edit of a notebook (its content: Snakemake's code trigger) reruns its notebook rule only."""
    nb = dag_repo / "notebooks" / f"{figure}.ipynb"
    original = nb.read_text()
    st = nb.stat()
    data = json.loads(original)
    data["cells"].append({"cell_type": "markdown", "metadata": {}, "source": ["An edit."]})
    try:
        nb.write_text(json.dumps(data, indent=1))
        jobs = planned_jobs(run_snakemake(dag_repo, "-n"))
    finally:
        nb.write_text(original)
        os.utime(nb, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert set(jobs) == {f"{figure}_notebook", "render_html", "index", "all"}, jobs


@pytest.mark.parametrize("figure", FIGURES)
def test_changing_a_scene_parameter_reruns_that_scene_only(dag_repo, tmp_path, figure):
    schema = yaml.safe_load((SCHEMAS / f"{figure}.schema.yaml").read_text())
    path, minimum = first_bounded_key(schema)
    value = CONFIG[figure]
    reduced = yaml.safe_load((ROOT / "tests" / "config_reduced.yaml").read_text()).get(figure, {})
    for key in path:
        value = value[key]
    try:
        for key in path:
            reduced = reduced[key]
        value = reduced
    except (KeyError, TypeError):
        pass
    overlay = write_overlay(tmp_path, {figure: nested(path, value * 2 + 1)})
    jobs = planned_jobs(run_snakemake(dag_repo, "-n", extra_configs=[overlay]))
    assert jobs, "a parameter change must rerun something"
    # the figures whose rules read this section too (fig5's flows take fig2's scene and deposit)
    users = {figure} | {p.stem for p in (ROOT / "workflow" / "rules").glob("*.smk")
                        if p.stem != figure and f'section("{figure}")' in p.read_text()} | readers(figure)
    assert all(any(r.startswith(f) for f in users) or r in SHARED for r in jobs), (jobs, users)


def test_an_ensemble_does_not_depend_on_shards_threads_or_jobs(dag_repo, tmp_path):
    """fig3's merged ensemble rebuilt elsewhere with 3 shards per mode and two threads per
    shard (--set-threads) holds the same numbers as the DAG's (2 shards, one thread per
    shard); only the measured wall times may differ."""
    overlay = write_overlay(tmp_path, {"fig3_equilibrium": {"modes": {"zero": {"shards": 3},
                                                                      "random": {"shards": 3}}}})
    work = tmp_path / "work"
    run_snakemake(dag_repo, "-j2", "results/fig3_equilibrium/ensemble.nc", "--set-threads",
                  "fig3_equilibrium_explore=2", extra_configs=[overlay], workdir=work)
    ref = xr.load_dataset(dag_repo / "results" / "fig3_equilibrium" / "ensemble.nc")
    new = xr.load_dataset(work / "results" / "fig3_equilibrium" / "ensemble.nc")
    assert not list((work / "results" / "fig3_equilibrium" / "shards").glob("*.nc"))   # temp(): removed once merged
    logs = list((work / "results" / "logs" / "fig3_equilibrium").glob("explore_*_*-of-3.log"))
    assert len(logs) == 6 and all("threads 2" in f.read_text() for f in logs)
    assert ref.sizes["run"] > 100
    timing = [v for v in ref.data_vars if "wall_time" in v]
    xr.testing.assert_identical(ref.drop_vars(timing).drop_attrs(), new.drop_vars(timing).drop_attrs())


ALL_FIGURES = FIGURES + [f for f in ("stability", "error_vs_runtime") if f in CONFIG]
# the computation of each figure's package: an edit of it reruns that figure's jobs
OWN_MODULE = {"fig1_wedged": "figures/fig1_wedged/measure.py", "fig2_slope": "figures/fig2_slope/census.py",
              "fig3_equilibrium": "figures/fig3_equilibrium/measure.py", "fig4_pile": "figures/fig4_pile/measure.py",
              "fig4_history": "figures/fig4_history/analysis.py", "fig4_bank": "figures/fig4_bank/measure.py",
              "fig5_governing": "figures/fig5_governing/measure.py",
              "stability": "studies/stability/measure.py", "error_vs_runtime": "studies/error_vs_runtime/measure.py"}
# what only a figure's page reads: its plots and sentences (page.py or plots.py) and its claims
PAGE_ONLY = {"fig1_wedged": ("page.py", "claims.py"), "fig2_slope": ("page.py", "claims.py"),
             "fig3_equilibrium": ("plots.py", "claims.py"), "fig4_pile": ("plots.py", "claims.py"),
             "fig4_history": ("plots.py", "claims.py"), "fig4_bank": ("plots.py", "claims.py"),
             "fig5_governing": ("plots.py", "summary.py"),
             "stability": ("page.py", "claims.py"), "error_vs_runtime": ("page.py", "claims.py")}


def package_of(figure):
    return f"{'studies' if figure in ('stability', 'error_vs_runtime') else 'figures'}/{figure}"


@pytest.mark.parametrize("figure", ALL_FIGURES)
def test_a_figure_target_plans_only_its_own_rules(fresh_repo, figure):
    jobs = planned_jobs(run_snakemake(fresh_repo, "-n", figure))
    assert f"{figure}_notebook" in jobs
    assert all(r.startswith(figure) or r in SHARED for r in jobs), jobs


BUILT_ON = {("fig4_bank", "fig4_pile"), ("fig4_bank", "fig4_history")}     # (reader, data of)


def readers(figure):
    """The figures whose rules read this figure's data (fig4_bank reads the piles of
    fig4_pile and fig4_history): new data there rightly reruns them too."""
    return {p.stem for p in (ROOT / "workflow" / "rules").glob("fig*.smk")
            if p.stem != figure and f'"results/{figure}/' in p.read_text() or (p.stem, figure) in BUILT_ON}


def plan_after_editing(repo, rel):
    """The jobs a dry run plans after an edit of ``ncd/<rel>`` (a new mtime and new
    content: Snakemake skips a newer file whose checksum it recorded unchanged), undone
    afterwards with its mtime."""
    path = repo / "ncd" / rel
    original, st = path.read_text(), path.stat()
    try:
        path.write_text(original + "\n# an edit\n")
        os.utime(path, ns=(st.st_atime_ns, time.time_ns() + 10**12))     # newer than any output
        return planned_jobs(run_snakemake(repo, "-n"))
    finally:
        path.write_text(original)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))


@pytest.mark.parametrize("figure", ALL_FIGURES)
def test_editing_a_figure_module_reruns_that_figure_only(dag_repo, figure):
    """A newer module of a figure (or study) reruns that figure's computing rules and
    nothing of the other figures; a newer solver module reruns every figure."""
    jobs = plan_after_editing(dag_repo, OWN_MODULE[figure])
    assert any(r.startswith(figure) and not r.endswith("notebook") for r in jobs), jobs
    after = {figure} | readers(figure)
    assert all(any(r.startswith(f) for f in after) or r in SHARED for r in jobs), jobs
    if figure == ALL_FIGURES[0]:
        core = plan_after_editing(dag_repo, "solver/nlgs.py")
        assert {f"{f}_notebook" for f in ALL_FIGURES} <= set(core), core


@pytest.mark.parametrize("figure", ALL_FIGURES)
def test_editing_a_figures_plots_page_or_claims_reruns_only_its_notebook_and_pages(dag_repo, figure):
    """A figure's plots, page sentences and claims are read by its notebook (and its claims
    by the index): an edit of one plans that notebook, the page render and the index,
    no computation of any figure."""
    for name in PAGE_ONLY[figure]:
        jobs = set(plan_after_editing(dag_repo, f"{package_of(figure)}/{name}")) - {"all", "code_stamp"}
        assert f"{figure}_notebook" in jobs, (name, jobs)
        assert jobs <= {f"{figure}_notebook", "render_html", "index"}, (name, jobs)


def test_editing_the_exact_layer_reruns_the_history_exact_ranges_not_the_piles(dag_repo):
    """The pile construction imports nothing of ncd/exact: an edit there plans the exact
    ranges of fig4_history (and what reads them), never a construction."""
    jobs = plan_after_editing(dag_repo, "exact/interior_set.py")
    assert "fig4_history_exact" in jobs and "fig4_history_construct" not in jobs, jobs


def test_a_code_stamp_holds_the_hash_of_each_source_of_its_set(dag_repo):
    """A computing rule lists one stamp for its sources (results/code/<script>.sha256): the
    SHA-256 of every file its script imports, by path in the checkout; the lower layers and
    the figure's computation are in it, its page, plots, claims, ncd/pages and the other
    figures are not."""
    import hashlib
    lines = (dag_repo / "results" / "code" / "fig1_explore.sha256").read_text().splitlines()
    stamp = dict(reversed(line.split("  ", 1)) for line in lines)
    assert len(stamp) == len(lines) > 20
    assert {"ncd/solver/nlgs.py", "ncd/core/contacts.py", "ncd/figures/fig1_wedged/measure.py",
            "workflow/scripts/fig1_explore.py", "ncd/__init__.py", "ncd/figures/__init__.py"} <= set(stamp)
    assert not [p for p in stamp if p.startswith(("ncd/pages/", "ncd/figures/fig2", "ncd/studies/"))
                or p.endswith(("page.py", "plots.py", "claims.py"))]
    for path, digest in stamp.items():
        assert hashlib.sha256((dag_repo / path).read_bytes()).hexdigest() == digest, path


@pytest.mark.parametrize("module, rules", [
    ("pages/report.py", {"index"}),
    ("pages/render.py", {"render_html", "index", "html_mathjax"}),   # the MathJax copy is render.py's too
    ("pages/notebook.py", None),           # every notebook rule, render_html, index
])
def test_editing_a_page_module_reruns_only_page_rules(dag_repo, module, rules):
    """Page modules are inputs of the page rules only: no simulation, exploration or
    analysis is planned after an edit of one."""
    jobs = set(plan_after_editing(dag_repo, module)) - {"all", "code_stamp"}
    if rules is None:
        assert jobs and all(r.endswith("notebook") or r in ("render_html", "index") for r in jobs), jobs
        assert {f"{f}_notebook" for f in ALL_FIGURES} <= jobs, jobs
    else:
        assert jobs == rules, jobs


# --- shards, provenance, logs, interrupted runs ------------------------------------------

SHARDED = {"fig1_wedged": ("ensemble",), "fig2_slope": ("explore",), "fig3_equilibrium": ("modes", "zero"),
           "fig4_pile": ("ensemble",)}


@pytest.mark.parametrize("figure", [f for f in SHARDED if f in CONFIG])
def test_changing_only_shards_reruns_only_the_ensemble(dag_repo, tmp_path, figure):
    """A new shard count plans the figure's explore and merge jobs and what reads the
    merged file (analysis, notebook), never its simulation, projections or cuts."""
    overlay = write_overlay(tmp_path, {figure: nested(SHARDED[figure], {"shards": 3})})
    jobs = planned_jobs(run_snakemake(dag_repo, "-n", extra_configs=[overlay]))
    assert jobs.get(f"{figure}_explore", 0) >= 3 and f"{figure}_merge" in jobs, jobs
    allowed = {f"{figure}_{r}" for r in ("explore", "merge", "analyse", "census", "notebook")} | SHARED   # the census counts basins in the ensemble
    assert set(jobs) <= allowed, jobs


def test_an_ensemble_is_identical_with_its_attributes_whatever_the_shard_count(dag_repo, tmp_path):
    """fig3 and fig1 rebuilt with 3 shards: same data and same attributes (no shard
    count in the provenance), only the measured wall times differ."""
    overlay = write_overlay(tmp_path, {"fig3_equilibrium": {"modes": {"zero": {"shards": 3}}},
                                       "fig1_wedged": {"ensemble": {"shards": 3}}})
    work = tmp_path / "work"
    targets = ["results/fig3_equilibrium/ensemble.nc", "results/fig1_wedged/ensemble.nc"]
    run_snakemake(dag_repo, "-j2", *targets, extra_configs=[overlay], workdir=work)
    for target in targets:
        ref, new = xr.load_dataset(dag_repo / target), xr.load_dataset(work / target)
        assert "shards" not in ref.attrs["config_yaml"], target
        timing = [v for v in ref.data_vars if "wall_time" in v]
        xr.testing.assert_identical(ref.drop_vars(timing), new.drop_vars(timing))    # attributes included


def test_a_failing_job_writes_its_traceback_to_its_log(tmp_path):
    """An uncaught exception of a script reaches its ``log:`` file, not only the console."""
    (tmp_path / "fail.py").write_text(
        "from ncd.pipeline.jobs import start\n"
        "log = start(snakemake)\n"
        "log.info('about to fail')\n"
        "def deep(x):\n    raise ValueError(f'no such member: {x}')\n"
        "deep(42)\n")
    (tmp_path / "Snakefile").write_text(
        'rule fail:\n    output: "out.nc"\n    log: "logs/fail.log"\n    script: "fail.py"\n')
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-s", str(tmp_path / "Snakefile"), "-d", str(tmp_path),
                           "-j1", "--workflow-profile", "none"], capture_output=True, text=True)
    assert proc.returncode != 0
    log = (tmp_path / "logs" / "fail.log").read_text()
    assert "about to fail" in log and "Traceback (most recent call last)" in log, log
    assert "in deep" in log and "ValueError: no such member: 42" in log, log
    assert not (tmp_path / "out.nc").exists()


def test_the_scheduler_keeps_one_pending_reevaluation_whatever_the_wake_ups():
    """coalesce_reevaluations: many requests while one timer is pending wake the loop once;
    a request after that wake-up arms a new timer."""
    import threading

    from ncd.pipeline.scheduler import coalesce_reevaluations

    class Scheduler:
        def __init__(self):
            self._open_jobs = threading.Semaphore(0)

        def _schedule_reevalutation(self, delay):
            raise AssertionError("not patched")

    assert coalesce_reevaluations(Scheduler) and not coalesce_reevaluations(Scheduler)   # once only
    assert not coalesce_reevaluations(type("Other", (), {}))                             # another version
    s = Scheduler()
    for _ in range(50):
        s._schedule_reevalutation(0.05)
    time.sleep(0.5)
    assert s._open_jobs.acquire(blocking=False) and not s._open_jobs.acquire(blocking=False)
    s._schedule_reevalutation(0.05)
    time.sleep(0.5)
    assert s._open_jobs.acquire(blocking=False) and not s._open_jobs.acquire(blocking=False)


def test_the_scheduler_loop_runs_about_twice_per_job_not_once_per_finished_job_per_second(tmp_path):
    """Snakemake's loop with the Snakefile's patch: 12 one-second jobs one after the other
    take about 2 passes each (without it: 79 passes, the timers of each finished job
    adding one pass per second)."""
    assert "coalesce_reevaluations()" in (ROOT / "Snakefile").read_text()
    (tmp_path / "Snakefile").write_text(
        "from ncd.pipeline.scheduler import coalesce_reevaluations\n"
        "coalesce_reevaluations()\n"
        "rule all:\n    input: expand('out/{i}.txt', i=range(12))\n"
        "rule job:\n    output: 'out/{i}.txt'\n    shell: 'sleep 1; touch {output}'\n")
    proc = subprocess.run([sys.executable, "-m", "snakemake", "-s", str(tmp_path / "Snakefile"), "-d", str(tmp_path),
                           "-j1", "--workflow-profile", "none", "--verbose"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    log = proc.stdout + proc.stderr
    assert log.count("Finished job") == 13
    assert log.count("Waiting for running jobs to complete") <= 36, log.count("Waiting for running jobs to complete")


def test_sigterm_of_a_job_is_logged_and_runs_its_cleanup(tmp_path):
    """A job terminated by SIGTERM (Snakemake cancelling it) exits 143 through ``finally``."""
    code = ("import time, types\nfrom ncd.pipeline.jobs import start\n"
            f"log = start(types.SimpleNamespace(threads=1, rule='demo', log=[{str(tmp_path / 'j.log')!r}]))\n"
            "try:\n    print('ready', flush=True)\n    time.sleep(60)\n"
            f"finally:\n    open({str(tmp_path / 'cleaned')!r}, 'w').close()\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=30) == 143
    assert (tmp_path / "cleaned").exists()
    assert "terminated by signal 15" in (tmp_path / "j.log").read_text()


def start_snakemake(repo, workdir, *args):
    """``snakemake`` on ``repo``'s workflow in ``workdir`` (reduced config), in a new
    process group, its console to ``workdir/console.txt``."""
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "snakemake", "-s", str(repo / "Snakefile"), "-d", str(workdir), *args,
           "--configfile", str(repo / "config.yaml"), str(repo / "tests" / "config_reduced.yaml")]
    console = open(workdir / "console.txt", "w")
    return subprocess.Popen(cmd, stdout=console, stderr=subprocess.STDOUT, start_new_session=True)


def wait_for(predicate, timeout, what):
    t0 = time.monotonic()
    while not predicate():
        assert time.monotonic() - t0 < timeout, f"timed out waiting for {what}"
        time.sleep(0.2)


@pytest.mark.parametrize("how", ["SIGKILL snakemake", "SIGKILL group", "SIGTERM snakemake"])
def test_an_interrupted_run_reruns_without_flags_and_gives_the_same_file(dag_repo, tmp_path, how):
    """Kill Snakemake in the middle of an ensemble job (fig1's first shard), then a plain rerun:
    no --unlock, no --rerun-incomplete; no half-written output at any time; the
    interrupted job is redone and the merged file equals the uninterrupted run's."""
    from ncd.pipeline.jobs import _snakemake_processes

    work = tmp_path / "work"
    target = "results/fig1_wedged/ensemble.nc"
    logs = [work / f"results/logs/fig1_wedged/explore_ensemble_{k}-of-2.log" for k in (0, 1)]
    shards = [work / f"results/fig1_wedged/shards/ensemble_{k}-of-2.nc" for k in (0, 1)]
    proc = start_snakemake(dag_repo, work, "-j1", target)

    def started():
        return [k for k in (0, 1) if logs[k].exists() and "rule fig1_wedged_explore" in logs[k].read_text()]

    wait_for(started, 600, "the first shard to start")
    k = started()[0]                                # the job in flight (-j1: one at a time)
    shard, other = shards[k], shards[1 - k]
    assert not shard.exists()                       # it runs (a shard takes seconds): kill now
    if how == "SIGKILL group":                      # Snakemake and its jobs (a lost node, kill -9 of the session)
        os.killpg(proc.pid, signal.SIGKILL)
    else:                                           # Snakemake only: its job runs on, orphaned, or is cancelled
        proc.send_signal(getattr(signal, how.split()[0]))
    proc.wait(timeout=120)
    wait_for(lambda: not _snakemake_processes(work), 600, "orphaned jobs to end")
    console = (work / "console.txt").read_text()
    assert not (work / target).exists(), console[-3000:]
    for path in (work / "results").rglob("*.nc"):   # whatever was written is whole
        with xr.open_dataset(path) as ds:
            assert ds.sizes["run"] == 210, path
    if how != "SIGTERM snakemake":
        assert list((work / ".snakemake" / "locks").glob("*")), "a killed run leaves its locks"

    if how == "SIGTERM snakemake":                  # Snakemake lets its running job finish, starts no other
        assert "Will exit after finishing currently running jobs" in console, console[-3000:]
        assert shard.exists() and not other.exists()
    else:                                           # killed within the shard's job
        finished = set(re.findall(r"Finished jobid: \d+ \(Rule: (\w+)\)", console))
        assert finished <= {"code_stamp"}, console[-3000:]     # only the sources' stamp before it
        assert shard.exists() == (how == "SIGKILL snakemake")       # its orphan finished it
        finished_by_orphan = shard.exists()
    rerun = run_snakemake(dag_repo, "-j1", target, workdir=work)
    out = rerun.stdout + rerun.stderr
    redone = re.search(rf"output: results/fig1_wedged/shards/ensemble_{k}-of-2.nc\n(?:[^\n]*\n){{0,6}}?"
                       r"\s*reason: ([^\n]*)", out)
    if how == "SIGTERM snakemake":                  # the finished shard was recorded: kept
        assert not redone and f"ensemble_{1 - k}-of-2.nc" in out, out[-3000:]
    else:                                           # the interrupted job was redone: as incomplete when
        assert redone, out[-3000:]                  # its orphaned process finished the file, else as missing
        assert redone.group(1).startswith("Forced execution" if finished_by_orphan else "Missing output"), \
            redone.group(1)
    assert not list((work / "results").rglob("*.part"))
    ref, new = xr.load_dataset(dag_repo / target), xr.load_dataset(work / target)
    timing = [v for v in ref.data_vars if "wall_time" in v]
    xr.testing.assert_identical(ref.drop_vars(timing), new.drop_vars(timing))
