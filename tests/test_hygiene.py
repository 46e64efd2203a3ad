"""The tree speaks to a reader of the code: no references to a tracker the reader cannot
open, and the linter's rules (pyflakes, import order, pycodestyle errors) hold."""
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ISSUE = re.compile(r"\bissues? ?#?\d+|\bissues \d+ and \d+", re.I)
TEXT = (".py", ".smk", ".yaml", ".yml", ".md", ".toml", ".rst", ".ipynb", ".cfg", ".txt", ".c", ".sh")


def tracked_text_files():
    """The text files git tracks (committed or staged: ``--cached``), as they are in the
    work tree; never an untracked file, such as a virtual environment or a run's results."""
    out = subprocess.run(["git", "ls-files", "--cached", "-z"], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        pytest.skip("not a git checkout")
    names = [n for n in out.stdout.split("\0") if n.endswith(TEXT) or Path(n).name == "Snakefile"]
    return [ROOT / n for n in names if (ROOT / n).is_file()]


def test_no_issue_numbers_anywhere():
    found = []
    for path in tracked_text_files():
        for k, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if ISSUE.search(line):
                found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()[:100]}")
    assert found == [], "\n".join(found[:40])


def test_the_pattern_catches_the_usual_forms():
    word = "issue"                  # spelt apart, so that this file passes its own scan
    for text in (f"({word} 14)", f"{word.title()} #5", f"{word}s 12 and 15", f"see {word} 3"):
        assert ISSUE.search(text), text
    assert not ISSUE.search("an issue of scale")


def test_ruff_is_clean():
    exe = Path(sys.executable).with_name("ruff")
    exe = str(exe) if exe.exists() else shutil.which("ruff")
    if exe is None:
        pytest.skip("ruff is not installed (python -m pip install -e '.[test]')")
    run = subprocess.run([exe, "check", "--no-cache", "."], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
