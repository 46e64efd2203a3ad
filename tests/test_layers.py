"""The layer contract of ncd: imports go down only, no cycles, no private names across
modules, no figure importing another figure's modules, no function-local imports of ncd.

Two checkers read the same order: import-linter (``lint-imports``, configured in
pyproject.toml) and the AST reader below, which also sees the rules import-linter has
no contract for.  Both are shown to fail on a deliberately upward import.
"""
import ast
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import ncd
from ncd.dynamics.stepper import step
from ncd.solver.single_contact import project_cone_py

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "ncd"
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
LAYERS = CONFIG["contracts"][0]["layers"]            # top first, as import-linter reads them


def layer_rank():
    """``{subpackage: rank}``, 0 the bottom; siblings (``a | b``) share a rank."""
    rank = {}
    for k, layer in enumerate(reversed(LAYERS)):
        for name in layer.split("|"):
            rank[name.strip()] = k
    return rank


def module_name(path, package):
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path, package):
    """``(target module, names, lineno, function_local)`` of every ncd import of ``path``."""
    mod = module_name(path, package)
    pkg = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
    found = []

    def walk(node, local):
        for child in ast.iter_child_nodes(node):
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.ImportFrom):
                if child.level:
                    base = pkg.split(".")[:len(pkg.split(".")) - child.level + 1]
                    target = ".".join(base + ([child.module] if child.module else []))
                else:
                    target = child.module or ""
                if target == "ncd" or target.startswith("ncd."):
                    found.append((target, [a.name for a in child.names], child.lineno, local))
            elif isinstance(child, ast.Import):
                for a in child.names:
                    if a.name == "ncd" or a.name.startswith("ncd."):
                        found.append((a.name, [], child.lineno, local))
            walk(child, inner)
    walk(ast.parse(path.read_text()), False)
    return found


def violations(package=PACKAGE):
    """Every breach of the contract in the package at ``package``, as readable lines."""
    from ncd.figures import FIGURE_MODULES
    rank = layer_rank()
    figure_of = {f"ncd.figures.{m}": fig for fig, mods in FIGURE_MODULES.items() for m in mods}
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
                if t in figure_of and mod in figure_of and figure_of[t] != figure_of[mod]:
                    out.append(f"{where}: {mod} ({figure_of[mod]}) imports {t} of {figure_of[t]}")
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


def test_every_figure_module_belongs_to_one_figure():
    from ncd.figures import FIGURE_MODULES
    listed = [m for mods in FIGURE_MODULES.values() for m in mods]
    present = sorted(p.stem for p in (PACKAGE / "figures").glob("*.py") if p.stem != "__init__")
    assert sorted(listed) == present


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
    ("figures/history.py", "from ncd.figures.governing import eta_table", "imports ncd.figures.governing of"),
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
    assert "1 kept, 0 broken" in run.stdout


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
