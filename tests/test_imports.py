"""A rule's code inputs are read from the imports of its script (ncd.pipeline.imports): the
closure of each computing script holds its figure's computation and the layers below, never
a page, plot or claim module nor another figure's package; a notebook's closure holds its
own page modules and claims.  No list of modules is kept by hand, so these are the checks."""
from pathlib import Path

import pytest

from ncd.pipeline.imports import closure, imports_of

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "ncd"
SCRIPTS = ROOT / "workflow" / "scripts"
FIGURES = sorted(p.parent.name for p in (PACKAGE / "figures").glob("*/__init__.py"))
STUDIES = ["stability", "error_vs_runtime"]
PREFIX = {"fig1_wedged": "fig1_"}           # the other scripts are named <figure>_<rule>.py
PAGE_ROLES = ("page.py", "plots.py", "claims.py")


def package_dir(figure):
    return PACKAGE / ("studies" if figure in STUDIES else "figures") / figure


def scripts_of(figure):
    prefix = PREFIX.get(figure, f"{figure}_")
    return sorted(p for p in SCRIPTS.glob(f"{prefix}*.py") if not p.stem.startswith("fig1_") or figure == "fig1_wedged")


def rel(paths):
    return {str(Path(p).resolve().relative_to(ROOT)) for p in paths}


@pytest.mark.parametrize("figure", FIGURES + STUDIES)
def test_a_computing_script_needs_its_figures_computation_only(figure):
    scripts = scripts_of(figure)
    assert scripts, figure
    own = str(package_dir(figure).relative_to(ROOT))
    used = set()
    for script in scripts:
        files = rel(closure([script], PACKAGE))
        assert "ncd/__init__.py" in files and "ncd/pipeline/jobs.py" in files, script.name
        used |= files
        others = [f for f in files if f.startswith(("ncd/figures/fig", "ncd/studies/")) and not f.startswith(own + "/")
                  and f != "ncd/studies/cases.py" and f != "ncd/studies/__init__.py"]
        assert others == [], (script.name, others)
        pages = [f for f in files if f.startswith("ncd/pages/") or (f.startswith(own) and f.endswith(PAGE_ROLES))]
        assert pages == [], (script.name, pages)
    # some of its scripts run the figure's own computation (others may run a shared scene only)
    assert any(f.startswith(own + "/") and not f.endswith("__init__.py") for f in used), figure


@pytest.mark.parametrize("figure", FIGURES + STUDIES)
def test_a_notebook_needs_its_page_modules_and_claims_not_the_other_figures(figure):
    files = rel(closure([ROOT / "notebooks" / f"{figure}.py"], PACKAGE))
    own = str(package_dir(figure).relative_to(ROOT))
    assert "ncd/pages/claims.py" in files and "ncd/pages/paper_claims.yaml" in files, figure
    assert f"{own}/claims.py" in files, figure
    others = [f for f in files if f.startswith(("ncd/figures/fig", "ncd/studies/")) and not f.startswith(own + "/")
              and f not in ("ncd/studies/cases.py", "ncd/studies/__init__.py")]
    assert others == [], others
    assert "ncd/pages/registry.py" not in files


def test_the_index_reads_every_figures_claims():
    files = rel(closure([SCRIPTS / "index.py"], PACKAGE))
    for figure in FIGURES + STUDIES:
        assert f"{package_dir(figure).relative_to(ROOT)}/claims.py" in files, figure


def test_the_closure_follows_imports_packages_and_named_data_and_nothing_else(tmp_path):
    """A made-up package: a script importing ``pkg.a`` needs pkg/__init__.py, pkg/a.py, what
    a.py imports (``pkg.sub.b`` and so pkg/sub/__init__.py), the data file b.py names; not
    pkg/c.py, which nobody imports, nor a data file nobody names.  An edit is seen by the same
    process (each file's parse is remembered under its text, not its path)."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    for f in ("__init__.py", "sub/__init__.py", "c.py"):
        (pkg / f).write_text("")
    (pkg / "a.py").write_text("import os\nfrom pkg.sub import b\n")
    (pkg / "sub" / "b.py").write_text('TABLE = "table.yaml"\n')
    (pkg / "sub" / "table.yaml").write_text("x: 1\n")
    (pkg / "sub" / "other.yaml").write_text("y: 2\n")
    script = tmp_path / "run.py"
    script.write_text("from pkg import a\n")
    got = {str(Path(p).relative_to(tmp_path)) for p in closure([script], pkg)}
    assert got == {"pkg/__init__.py", "pkg/a.py", "pkg/sub/__init__.py", "pkg/sub/b.py", "pkg/sub/table.yaml"}
    (pkg / "a.py").write_text("from pkg import c\n")        # now c is needed, b is not
    got = {str(Path(p).relative_to(tmp_path)) for p in closure([script], pkg)}
    assert got == {"pkg/__init__.py", "pkg/a.py", "pkg/c.py"}
    assert [t for t, *_ in imports_of(script, None, "pkg")] == ["pkg"]
