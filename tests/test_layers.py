"""The layer contract of ncd: imports go down only, no cycles, no private names across
modules, no figure package importing another figure's (nor a study another study's), no
function-local imports of ncd.

Two checkers read the same order: import-linter (``lint-imports``, configured in
pyproject.toml) and the AST reader of :mod:`ncd.pipeline.imports` (the one the workflow
reads a rule's code inputs with), which also sees the rules import-linter has no contract
for.  Both are shown to fail on a deliberately broken contract.
"""
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import ncd
from ncd.dynamics.stepper import step
from ncd.pipeline.imports import imports_of, module_name
from ncd.solver.single_contact import project_cone_py

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "ncd"
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
LAYERS = CONFIG["contracts"][0]["layers"]            # top first, as import-linter reads them
# the packages that must not import each other (the independence contracts)
INDEPENDENT = [c["modules"] for c in CONFIG["contracts"] if c["type"] == "independence"]


def layer_rank():
    """``{subpackage: rank}``, 0 the bottom; siblings (``a | b``) share a rank."""
    rank = {}
    for k, layer in enumerate(reversed(LAYERS)):
        for name in layer.split("|"):
            rank[name.strip()] = k
    return rank


def group_of(module):
    """The independent package (a figure's or a study's) that holds ``module``, or None."""
    for group in INDEPENDENT:
        for pkg in group:
            if module == pkg or module.startswith(pkg + "."):
                return pkg
    return None


def violations(package=PACKAGE):
    """Every breach of the contract in the package at ``package``, as readable lines."""
    rank = layer_rank()
    modules = {module_name(p, package): p for p in package.rglob("*.py")}
    out, edges = [], {m: set() for m in modules}
    for mod, path in sorted(modules.items()):
        if mod == "ncd":
            continue                                   # the public face imports from every layer
        layer = mod.split(".")[1]
        for target, names, line, local in imports_of(path, package):
            where = f"{path.relative_to(package.parent)}:{line}"
            # a name imported from a package may be a submodule: count the submodule
            targets = [f"{target}.{n}" for n in names if f"{target}.{n}" in modules] or [target]
            for t in targets:
                if t == "ncd":
                    out.append(f"{where}: {mod} imports the package's public face ncd (import from the layer)")
                    continue
                tl = t.split(".")[1]
                if tl not in rank:
                    out.append(f"{where}: {mod} imports {t}, which is in no layer")
                elif rank[tl] > rank[layer] or (rank[tl] == rank[layer] and tl != layer):
                    out.append(f"{where}: {mod} ({layer}) imports {t} ({tl}): upward or sideways")
                mine, theirs = group_of(mod), group_of(t)
                if mine and theirs and mine != theirs:
                    out.append(f"{where}: {mod} ({mine}) imports {t} of {theirs}")
                if t != mod and t in modules:
                    edges[mod].add(t)
            if local:
                out.append(f"{where}: {mod} imports {target} inside a function (import it at the top)")
            for n in names:
                if n.startswith("_") and not n.startswith("__") and target != mod:
                    out.append(f"{where}: {mod} imports the private name {target}.{n}")
    out += [f"import cycle: {' -> '.join(c)}" for c in cycles(edges)]
    return out


def cycles(edges):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, comps = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))
    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return comps


def test_the_package_keeps_the_contract():
    assert violations() == []


def test_every_subpackage_is_in_a_layer():
    subpackages = {p.parent.name for p in PACKAGE.glob("*/__init__.py")}
    assert subpackages == set(layer_rank())
    assert [p.name for p in PACKAGE.glob("*.py")] == ["__init__.py"]     # no module outside a layer


def test_every_figure_and_study_is_a_package_named_by_its_config_key():
    """A reader who knows the config key knows the folder: ncd/figures/<key>/ for each
    figure of config.yaml, ncd/studies/<key>/ for each study; no loose module beside them
    but the ones several share (ncd/studies/cases.py); each package is independent."""
    import yaml
    keys = set(yaml.safe_load((ROOT / "config.yaml").read_text()))
    figures = {p.parent.name for p in (PACKAGE / "figures").glob("*/__init__.py")}
    studies = {p.parent.name for p in (PACKAGE / "studies").glob("*/__init__.py")}
    assert figures | studies <= keys
    assert figures == {k for k in keys if k.startswith("fig")}
    assert [p.name for p in (PACKAGE / "figures").glob("*.py")] == ["__init__.py"]
    assert sorted(p.name for p in (PACKAGE / "studies").glob("*.py")) == ["__init__.py", "cases.py"]
    groups = {m for g in INDEPENDENT for m in g}
    assert groups == {f"ncd.figures.{f}" for f in figures} | {f"ncd.studies.{s}" for s in studies}


def copy_with(tmp_path, module, line):
    """A copy of the package with ``line`` appended to ``module`` (a path inside ncd/)."""
    shutil.copytree(PACKAGE, tmp_path / "ncd", ignore=shutil.ignore_patterns("__pycache__"))
    target = tmp_path / "ncd" / module
    target.write_text(target.read_text() + f"\n{line}\n")
    return tmp_path / "ncd"


@pytest.mark.parametrize("module, line, expected", [
    ("core/contacts.py", "from ncd.solver.settings import SolverSettings", "upward"),
    ("solver/lcp.py", "def later():\n    from ncd.dynamics.stepper import step", "upward"),
    ("solver/lcp.py", "def later():\n    from ncd.solver.kernels import sweep_discs", "inside a function"),
    ("exact/polygon.py", "from ncd.dynamics.explore import member_rng", "sideways"),
    ("solver/kernels.py", "from ncd.solver.nlgs import solve_local", "import cycle"),
    ("solver/nlgs.py", "from ncd.core.validate import _shape_text", "private name"),
    ("figures/fig4_history/construct.py", "from ncd.figures.fig5_governing.measure import eta_table",
     "imports ncd.figures.fig5_governing.measure of ncd.figures.fig5_governing"),
    ("studies/bench/page.py", "from ncd.studies.stability.page import inaccurate", "of ncd.studies.stability"),
    ("core/model.py", "import ncd", "public face"),
])
def test_the_checker_fails_on_a_broken_contract(tmp_path, module, line, expected):
    found = violations(copy_with(tmp_path, module, line))
    assert any(expected in v for v in found), found


def lint_imports(package_parent):
    exe = Path(sys.executable).with_name("lint-imports")
    if not exe.exists():
        exe = shutil.which("lint-imports")
    if exe is None:
        pytest.skip("import-linter is not installed (python -m pip install -e '.[test]')")
    return subprocess.run([str(exe), "--config", str(ROOT / "pyproject.toml"), "--no-cache"],
                          cwd=package_parent, capture_output=True, text=True,
                          env={"PYTHONPATH": str(package_parent), "PATH": "/usr/bin:/bin"})


def test_import_linter_keeps_the_contract():
    run = lint_imports(ROOT)
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"{len(CONFIG['contracts'])} kept, 0 broken" in run.stdout


def test_import_linter_fails_on_an_upward_import(tmp_path):
    copy_with(tmp_path, "core/contacts.py", "from ncd.solver.settings import SolverSettings")
    run = lint_imports(tmp_path)
    assert run.returncode != 0
    assert "ncd.core is not allowed to import ncd.solver" in run.stdout


def test_the_public_face_loads_its_names_on_first_use():
    """``import ncd`` alone imports no layer that needs numba (a page render or a shard
    merge does not pay for the stepper); every public name then resolves from its layer,
    and a misspelt one is an AttributeError naming it."""
    code = ("import sys, ncd; print('numba' in sys.modules, 'ncd.dynamics.stepper' in sys.modules); "
            "print(all(getattr(ncd, n) is not None for n in ncd.__all__), 'numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "False", "True", "True"]
    assert ncd.step is step and ncd.project_cone is project_cone_py and "step" in dir(ncd)
    with pytest.raises(AttributeError, match="'stpe'"):
        ncd.stpe
