"""numba's cache follows every source of the kernel layers (ncd/core/jit.py).

numba keys a cached kernel on its own file: without the digest-named cache
directory, an edit of ``single_contact.py`` would leave the NLGS sweep of
``kernels.py`` (which inlines it) running the old machine code."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

PROBE = """
import numpy as np, ncd
from ncd.core.jit import cache_dir
W = np.diag([2.0, 3.0])
print(cache_dir())
print(ncd.solve_local(W, [-1.0, 0.5], 1.0).impulse.ravel().tolist())   # sticks
"""


def probe(pkg_parent):
    env = dict(os.environ, PYTHONPATH=str(pkg_parent), NUMBA_NUM_THREADS="1")
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run([sys.executable, "-c", PROBE], check=True, capture_output=True, text=True,
                         env=env, cwd=pkg_parent).stdout.split("\n")
    return out[0], out[1]


def test_an_edit_of_a_callee_module_reaches_the_cached_kernels(tmp_path):
    shutil.copytree(ROOT / "ncd", tmp_path / "ncd", ignore=shutil.ignore_patterns("__pycache__"))
    first_dir, first = probe(tmp_path)
    assert Path(first_dir).is_relative_to(tmp_path / "ncd" / "__pycache__")
    assert any(Path(first_dir).rglob("kernels.iterate_local*.nbi"))        # the kernels were cached
    assert probe(tmp_path) == (first_dir, first)                         # and are reused
    # an edit outside the kernel layers (a page module) keeps the cache: no recompilation
    page = tmp_path / "ncd" / "pages" / "report.py"
    page.write_text(page.read_text() + "\n# an edit\n")
    assert probe(tmp_path) == (first_dir, first)
    # change the single-contact law inside single_contact.py only: the cached NLGS kernel
    # of kernels.py must see it (here: every normal impulse doubled)
    solver = tmp_path / "ncd" / "solver" / "single_contact.py"
    text = solver.read_text()
    stick = "return rn, rt, STICK\n    # slide forward"      # solve_single_contact's (solve_local's) case
    assert text.count(stick) == 1
    solver.write_text(text.replace(stick, "return 2.0 * rn, rt, STICK\n    # slide forward"))
    second_dir, second = probe(tmp_path)
    assert second_dir != first_dir
    assert eval(second)[0] == 2.0 * eval(first)[0] != 0.0

