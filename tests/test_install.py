"""Installs that fit their use: ``pip install -e .`` gives the solver and its data formats,
the extras (workflow, bench, cluster, test, all) the rest; the README names every package
the install pulls in, CI runs the README's install in the README's environment, and the
public API is typed (``ncd/py.typed``, annotations on every public function)."""
import inspect
import re
import subprocess
import sys
import tomllib
import typing
from pathlib import Path

import pytest

import ncd

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
PROJECT = PYPROJECT["project"]
EXTRAS = PROJECT["optional-dependencies"]
README = (ROOT / "README.md").read_text()

# packages of the workflow, the benchmark and the tests, which the solver does not import
NOT_BASE = ("snakemake", "jupytext", "nbconvert", "nbclient", "ipykernel", "pymunk", "matplotlib",
            "snakemake-executor-plugin-slurm", "pytest")
# their import names, which no module of the lower layers may import when it is imported
EXTRA_MODULES = ("snakemake", "jupytext", "nbconvert", "nbclient", "nbformat", "ipykernel", "IPython",
                 "jupyter_server_mathjax", "matplotlib", "PIL", "meshio", "pyevtk", "pymunk", "pytest")
LOWER_LAYERS = ("core", "io", "solver", "exact", "dynamics")


def normalize(name):
    """A distribution name as PyPI compares them (PEP 503): case and runs of ``-_.`` folded."""
    return re.sub(r"[-_.]+", "-", name).lower()


def requirement_name(spec):
    """``"netCDF4>=1.6"`` -> ``"netcdf4"``; ``"ncd[workflow]"`` -> ``"ncd"``."""
    return normalize(re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", spec).group(1))


def requirements(specs):
    """The names of ``specs`` other than ncd's own extras (``ncd[workflow,bench]``)."""
    return {requirement_name(s) for s in specs} - {"ncd"}


def self_references(specs):
    """The extras of ncd that ``specs`` pull in: ``["ncd[workflow,bench]"]`` -> ``{"workflow", "bench"}``."""
    found = set()
    for s in specs:
        m = re.match(r"\s*ncd\s*\[([^\]]*)\]", s)
        if m:
            found |= {normalize(e.strip()) for e in m.group(1).split(",")}
    return found


def every_requirement():
    """Every distribution named by the base dependencies and by any extra."""
    names = requirements(PROJECT["dependencies"])
    for specs in EXTRAS.values():
        names |= requirements(specs)
    return names


def section(title, text):
    start = text.index(f"## {title}")
    end = text.find("\n## ", start + 3)
    return text[start:end if end > 0 else None]


def unnamed(names, text):
    """The names of ``names`` that ``text`` does not mention as a word (compared normalized)."""
    words = {normalize(w) for w in re.findall(r"[A-Za-z0-9](?:[A-Za-z0-9._-]*[A-Za-z0-9])?", text)}
    return sorted(n for n in names if normalize(n) not in words)


# ------------------------------------------------------------ what each install holds
def test_readme_names_every_dependency():
    text = section("Dependencies", README)
    missing = unnamed(every_requirement(), text)
    assert missing == [], f"README.md ## Dependencies does not name {missing}"
    for extra in EXTRAS:
        assert f"**{extra}**" in text, f"README.md ## Dependencies does not describe the extra {extra}"


def test_a_readme_missing_a_dependency_is_caught():
    text = section("Dependencies", README)
    names = every_requirement()
    assert {"netcdf4", "highspy", "cylp", "clarabel", "pyyaml", "jupyter-server-mathjax"} <= names
    for name in ("cylp", "clarabel", "netcdf4", "jupyter-server-mathjax"):
        cut = re.sub(re.escape(name).replace("\\-", "[-_.]"), "", text, flags=re.I)
        assert unnamed(names, cut) == [name], name
    # a name only as part of another word is not named: "pyyaml" is not "yaml"
    assert unnamed({"yaml"}, "PyYAML and jsonschema") == ["yaml"]
    assert unnamed({"netCDF4", "jupyter_server.mathjax"}, "netcdf4, Jupyter-Server-MathJax") == []


def test_base_install_is_the_solver_only():
    base = requirements(PROJECT["dependencies"])
    assert {"numpy", "scipy", "numba", "xarray", "netcdf4", "highspy", "cylp", "clarabel"} <= base
    assert base.isdisjoint(NOT_BASE), sorted(base & set(NOT_BASE))


def test_extras_fit_their_use():
    assert {"workflow", "bench", "cluster", "test", "all"} <= set(EXTRAS)
    workflow = requirements(EXTRAS["workflow"])
    assert {"snakemake", "jupytext", "nbconvert", "nbclient", "ipykernel", "matplotlib", "meshio",
            "pyevtk", "jupyter-server-mathjax"} <= workflow
    assert requirements(EXTRAS["bench"]) == {"pymunk", "py-spy"}
    assert "snakemake-executor-plugin-slurm" in requirements(EXTRAS["cluster"])
    assert "workflow" in self_references(EXTRAS["cluster"])
    assert {"workflow", "bench"} <= self_references(EXTRAS["test"])
    assert {"pytest", "ruff", "import-linter"} <= requirements(EXTRAS["test"])
    assert self_references(EXTRAS["all"]) == set(EXTRAS) - {"all"}
    for extra, specs in EXTRAS.items():
        assert self_references(specs) <= set(EXTRAS), extra


def test_snakemake_major_version_is_pinned():
    """The Snakefile patches Snakemake's scheduler loop (``ncd.pipeline.scheduler``), whose
    internals a new major version may move: the workflow extra bounds the major version."""
    spec = next(s for s in EXTRAS["workflow"] if requirement_name(s) == "snakemake")
    assert re.search(r"<\s*\d+", spec) and re.search(r">=\s*\d+", spec), spec


def test_installed_snakemake_has_what_the_scheduler_patch_replaces():
    """The Snakemake the pin admits has ``JobScheduler._schedule_reevalutation`` (sic) where
    the patch looks for it; without it the patch silently does nothing."""
    pytest.importorskip("snakemake")
    from importlib.metadata import version

    specifiers = pytest.importorskip("packaging.specifiers")
    spec = next(s for s in EXTRAS["workflow"] if requirement_name(s) == "snakemake")
    assert version("snakemake") in specifiers.SpecifierSet(spec[len("snakemake"):].strip()), version("snakemake")
    from snakemake.scheduling.job_scheduler import JobScheduler

    assert callable(getattr(JobScheduler, "_schedule_reevalutation", None))


def test_lower_layers_import_without_the_extras():
    """Every module of core, io, solver, exact and dynamics imports with the base
    dependencies alone: the packages of the extras are hidden (plots, VTK export and
    animation import theirs when called)."""
    code = f"""
import importlib, pkgutil, sys
for name in {EXTRA_MODULES!r}:
    sys.modules[name] = None          # import name -> ImportError
import ncd
for layer in {LOWER_LAYERS!r}:
    pkg = importlib.import_module("ncd." + layer)
    for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
        importlib.import_module(info.name)
ncd.step, ncd.make_scene, ncd.solve_local
print("ok")
"""
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr[-3000:]


# ------------------------------------------------------------ CI runs the README
def test_ci_installs_as_the_readme_says():
    """``.ci/run`` makes the README's virtual environment and runs its install and its tests."""
    quick = section("Quick start", README)
    block = re.search(r"```bash\n(.*?)```", quick, re.DOTALL).group(1)
    commands = [c.strip() for line in block.splitlines() for c in line.split(" && ")]
    ci = [line.split("#")[0].strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()]
    ci_commands = [c.strip() for line in ci if line for c in line.split(" && ")]
    for command in commands:
        if command.startswith("snakemake"):
            continue                  # pytest runs the DAG on a reduced configuration
        assert command in ci_commands, f".ci/run does not run the README's {command!r}"
    assert ci_commands[-1] == "pytest"


def test_the_readme_environment_is_ignored():
    for name in (".venv", "venv", ".ci-venv", ".tox"):
        run = subprocess.run(["git", "check-ignore", "-q", f"{name}/bin/python"], cwd=ROOT)
        if run.returncode == 128:
            pytest.skip("not a git checkout")
        assert run.returncode == 0, f".gitignore does not ignore {name}/"


# ------------------------------------------------------------ typed public API
def test_package_is_marked_typed():
    assert (ROOT / "ncd" / "py.typed").is_file()
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"].get("ncd", [])


def public_functions():
    """``(name, function)`` of every public function of ``ncd.__all__`` and every public
    method and property of its public classes."""
    found = []
    for name in ncd.__all__:
        value = getattr(ncd, name)
        if inspect.isfunction(value):
            found.append((name, value))
        elif inspect.isclass(value):
            for attr, member in vars(value).items():
                func = member.fget if isinstance(member, property) else member
                if inspect.isfunction(func) and not attr.startswith("_"):
                    found.append((f"{name}.{attr}", func))
    return found


def unannotated(func):
    """The parameters (and ``return``) of ``func`` without an annotation; ``self`` is exempt."""
    sig = inspect.signature(func)
    names = [p.name for k, p in enumerate(sig.parameters.values())
             if p.annotation is inspect.Parameter.empty and not (k == 0 and p.name in ("self", "cls"))]
    return names + (["return"] if sig.return_annotation is inspect.Signature.empty else [])


def test_public_functions_are_annotated():
    functions = public_functions()
    assert {"step", "make_scene", "solve_local", "project_cone", "Scene.copy"} <= {n for n, _ in functions}
    bare = {name: missing for name, func in functions if (missing := unannotated(func))}
    assert bare == {}, f"public functions with unannotated parameters or return: {bare}"
    for name, func in functions:
        typing.get_type_hints(func)          # every annotation names something that exists


def test_unannotated_function_is_caught():
    def partly(a: int, b, *, c=1) -> None:
        pass

    def bare(x):
        pass

    assert unannotated(partly) == ["b", "c"]
    assert unannotated(bare) == ["x", "return"]
