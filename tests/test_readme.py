"""The README: its solver example runs, it keeps no hand-typed result numbers (it points
to results/index.html, built from the data), its pictures exist, config/README.md is
up to date, and it uses no words of the project's process."""
import re
import subprocess
import sys
from pathlib import Path

from ncd.configdoc import TARGET, render

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()


def section(title):
    start = README.index(f"## {title}")
    end = README.find("\n## ", start + 3)
    return README[start:end if end > 0 else None]


def test_readme_example_matches_closed_form():
    code = re.search(r"## The solver in 15 lines\n\n```python\n(.*?)```", README, re.S).group(1)
    assert len(code.strip().splitlines()) <= 20
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    lines = out.strip().splitlines()
    assert len(lines) == 2
    for line, mode in zip(lines, ("slide", "roll")):
        a = float(re.search(r" a=([-\d.]+)", line).group(1))
        expected = float(re.search(rf"{mode} ([-\d.]+)", line).group(1))
        assert abs(a - expected) < 1e-3, line
        assert "converged=True" in line


def test_results_are_not_repeated_but_pointed_to():
    """The result table keeps no measured number: only § and figure numbers remain."""
    text = section("What is reproduced")
    assert "results/index.html" in text
    prose = re.sub(r"<img[^>]*>|`[^`]*`|§\d|Fig\. \d|\d+°|\(\d\)", "", text)
    numbers = re.findall(r"\d[\d.,]*\s*(?:%|m/s|N\b|s\b|R\b)?", prose)
    assert numbers == [], f"hand-typed numbers in the README's result table: {numbers}"


def test_readme_pictures_exist():
    shown = re.findall(r'<img src="(docs/[\w/]+\.(?:png|svg))"', README)
    thumbs = [s for s in shown if s.startswith("docs/thumbnails/")]
    assert len(thumbs) >= 6 and "docs/rulegraph.svg" in shown
    for rel in thumbs:
        data = (ROOT / rel).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5_000, rel
    svg = (ROOT / "docs" / "rulegraph.svg").read_text()
    for rule in ("render_html", "index", "html_mathjax"):
        assert f">{rule}<" in svg, f"docs/rulegraph.svg lacks rule {rule}: regenerate it"


def test_quick_start_has_a_virtual_environment_and_two_commands():
    text = section("Quick start")
    assert "python -m venv .venv" in text
    assert 'python -m pip install -e ".[test]" && snakemake -j2' in text and "\npytest\n" in text


def test_no_process_words():
    for words in ("the issue", "design card", "helper", "the brief"):
        assert words not in README.lower(), words


def test_config_reference_is_up_to_date():
    assert TARGET.read_text() == render(), "config/README.md is stale: run `python -m ncd.configdoc`"


def test_license_and_citation():
    assert "MIT License" in (ROOT / "LICENSE").read_text()
    cff = (ROOT / "CITATION.cff").read_text()
    assert "cff-version" in cff and "Indetermination in the numerical simulation of granular systems" in cff
