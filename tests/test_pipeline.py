"""The Snakemake DAG: validation before any job, incremental reruns, shard invariance."""
import json
import os
import re
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from conftest import ROOT, copy_workflow, run_snakemake

SCHEMAS = ROOT / "workflow" / "schemas"
CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())
FIGURES = [f for f in ("fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile") if f in CONFIG]


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
    assert set(jobs) == {f"{figure}_notebook", "render_html", "all"}, jobs


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
    assert all(r.startswith(figure) or r in ("render_html", "all") for r in jobs), jobs


def test_an_ensemble_does_not_depend_on_shards_threads_or_jobs(dag_repo, tmp_path):
    """fig3's merged ensemble rebuilt elsewhere with 3 shards per mode at -j1 (one thread
    per shard) holds the same numbers as the DAG's (2 shards, -j2: two threads per
    shard); only the measured wall times may differ."""
    overlay = write_overlay(tmp_path, {"fig3_equilibrium": {"modes": {"zero": {"shards": 3},
                                                                      "random": {"shards": 3}}}})
    work = tmp_path / "work"
    run_snakemake(dag_repo, "-j1", "results/fig3_equilibrium/ensemble.nc", extra_configs=[overlay], workdir=work)
    ref = xr.load_dataset(dag_repo / "results" / "fig3_equilibrium" / "ensemble.nc")
    new = xr.load_dataset(work / "results" / "fig3_equilibrium" / "ensemble.nc")
    assert len(list((work / "results" / "fig3_equilibrium" / "shards").glob("*_*-of-3.nc"))) == 6
    assert ref.sizes["run"] > 100
    timing = [v for v in ref.data_vars if "wall_time" in v]
    xr.testing.assert_identical(ref.drop_vars(timing).drop_attrs(), new.drop_vars(timing).drop_attrs())


def test_every_ncd_module_is_a_source_of_the_figures_that_import_it():
    """NCD_MODULES (common.smk) lists, per figure, the modules outside the core its
    rules depend on; a module imported by a listed one must be listed too, and every
    module of ncd/figures and ncd/studies belongs to some figure."""
    import ast
    text = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    modules = ast.literal_eval(re.search(r"NCD_MODULES = (\{.*?\n\})", text, re.S).group(1))
    listed = set()
    for figure, files in modules.items():
        listed.update(files)
        for f in files:
            if not f.endswith(".py"):
                continue
            tree = ast.parse((ROOT / "ncd" / f).read_text())
            pkg = f.split("/")[0]
            for node in ast.walk(tree):
                if isinstance(node, ast.ImportFrom):
                    mod = node.module or ""
                    if node.level == 1:            # from . import x / from .x import y
                        names = [mod] if mod else [a.name for a in node.names]
                        deps = [f"{pkg}/{n}.py" for n in names]
                    elif mod.startswith("ncd.figures.") or mod.startswith("ncd.studies."):
                        deps = [mod[4:].replace(".", "/") + ".py"]
                    else:
                        continue
                    for d in deps:
                        assert d in files, f"{figure}: {f} imports {d}, not in NCD_MODULES[{figure!r}]"
    own = {str(p.relative_to(ROOT / "ncd")) for d in ("figures", "studies") for p in (ROOT / "ncd" / d).iterdir()
           if p.suffix in (".py", ".c")}
    assert own == listed, own ^ listed


ALL_FIGURES = FIGURES + [f for f in ("stability", "error_vs_runtime") if f in CONFIG]
OWN_MODULE = {"fig1_wedged": "figures/wedged.py", "fig2_slope": "figures/slope_analysis.py",
              "fig3_equilibrium": "figures/equilibrium.py", "fig4_pile": "figures/cuts.py",
              "stability": "studies/stability.py", "error_vs_runtime": "studies/work_precision.py"}


@pytest.mark.parametrize("figure", ALL_FIGURES)
def test_a_figure_target_plans_only_its_own_rules(fresh_repo, figure):
    jobs = planned_jobs(run_snakemake(fresh_repo, "-n", figure))
    assert f"{figure}_notebook" in jobs
    assert all(r.startswith(figure) or r == "render_html" for r in jobs), jobs


@pytest.mark.parametrize("figure", ALL_FIGURES)
def test_editing_a_figure_module_reruns_that_figure_only(dag_repo, figure):
    """A newer ncd/figures (or studies) module reruns its figure's computing rules and
    nothing of the other figures; a newer core module reruns every figure."""
    def plan_after_touching(rel):
        # an edit (a new mtime and new content: Snakemake 9 skips a newer file whose
        # checksum it recorded unchanged), undone afterwards with its mtime
        path = dag_repo / "ncd" / rel
        original, st = path.read_text(), path.stat()
        try:
            path.write_text(original + "\n# an edit\n")
            os.utime(path, ns=(st.st_atime_ns, time.time_ns() + 10**12))     # newer than any output
            return planned_jobs(run_snakemake(dag_repo, "-n"))
        finally:
            path.write_text(original)
            os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))

    jobs = plan_after_touching(OWN_MODULE[figure])
    assert any(r.startswith(figure) and not r.endswith("notebook") for r in jobs), jobs
    assert all(r.startswith(figure) or r in ("render_html", "all") for r in jobs), jobs
    if figure == ALL_FIGURES[0]:
        core = plan_after_touching("nlgs.py")
        assert {f"{f}_notebook" for f in ALL_FIGURES} <= set(core), core
