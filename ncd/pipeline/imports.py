"""The ncd imports of a file, read from its source: the layer contract's reader and the code
inputs of a workflow rule.

A rule's code inputs are the import closure of its script (or notebook) inside ``ncd/``:
the modules it imports, what they import in turn, the ``__init__.py`` of every package on
the way (Python runs them on import) and the data files a module names beside it (the
claims table, the C loop of the benchmark).  Derived from the code, so that no list of
modules is kept by hand and an edit reruns exactly the jobs whose code reads it.
Imports are read as text (AST), nothing is imported; a module loaded by name at run time
(``importlib``) is not followed.
"""
import ast
from pathlib import Path


def module_name(path, package):
    """The dotted name of ``path``, a file under the package folder ``package``."""
    parts = list(Path(path).relative_to(Path(package).parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path, package=None, root_name="ncd"):
    """``(target module, names, lineno, function_local)`` of every ``root_name`` import of the
    file ``path``; ``package`` (the package folder holding ``path``) resolves relative imports."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    key = (str(path), None if package is None else str(package), root_name, text)
    if key not in _FOUND:
        _FOUND[key] = _imports_in(text, path, package, root_name)
    return [(t, list(n), line, local) for t, n, line, local in _FOUND[key]]


# A workflow reads the closure of some sixty scripts and notebooks, most of which share the
# same modules: each file's source is parsed once per process (keyed by its text, so an
# edit is always seen) instead of once per closure it is in.
_FOUND = {}


def _imports_in(text, path, package, root_name):
    if package is not None and path.is_relative_to(Path(package).parent):
        mod = module_name(path, package)
        pkg = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
    else:
        pkg = ""
    found = []

    def ours(name):
        return name == root_name or name.startswith(root_name + ".")

    def walk(node, local):
        for child in ast.iter_child_nodes(node):
            inner = local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.ImportFrom):
                if child.level and pkg:
                    base = pkg.split(".")[:len(pkg.split(".")) - child.level + 1]
                    target = ".".join(base + ([child.module] if child.module else []))
                else:
                    target = child.module or ""
                if ours(target):
                    found.append((target, [a.name for a in child.names], child.lineno, local))
            elif isinstance(child, ast.Import):
                for a in child.names:
                    if ours(a.name):
                        found.append((a.name, [], child.lineno, local))
            walk(child, inner)
    walk(ast.parse(text, filename=str(path)), False)
    return tuple((t, tuple(n), line, local) for t, n, line, local in found)


def module_file(name, package):
    """The file of the dotted module ``name`` under the package folder ``package`` (a module
    file or a package's ``__init__.py``), or None."""
    base = Path(package).parent.joinpath(*name.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def data_files(path):
    """Non-Python files beside the module ``path`` that its source names (``"c_sweep.c"``)."""
    text = Path(path).read_text(encoding="utf-8")
    return [p for p in sorted(Path(path).parent.iterdir())
            if p.is_file() and p.suffix not in (".py", ".pyc") and f'"{p.name}"' in text]


def closure(sources, package):
    """Every file under ``package`` (the ``ncd`` folder) that the files ``sources`` need when
    run: the import closure, package ``__init__.py`` files included, plus the data files the
    modules name.  Sorted paths, as given by ``package``'s own form (relative stays relative)."""
    package = Path(package)
    seen, todo = set(), [Path(s) for s in sources]
    needed = set()
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        if path.is_relative_to(package):
            needed.add(path)
            needed.update(data_files(path))
        for target, names, _, _ in imports_of(path, package, package.name):
            modules = [target] + [f"{target}.{n}" for n in names]
            parts = target.split(".")
            modules += [".".join(parts[:k]) for k in range(1, len(parts))]      # parent packages
            for name in modules:
                found = module_file(name, package)
                if found is not None and found not in seen:
                    todo.append(found)
    return sorted(str(p) for p in needed)
