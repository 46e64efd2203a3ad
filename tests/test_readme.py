"""The README is a user guide: its solver example runs, it keeps no hand-typed measured
numbers (it points to results/index.html and the bench page, built from the data), it
stays short, its pictures exist, config/README.md is up to date, docs/solvers.md has a
section per solver method, and neither uses words of the project's process.  Neither do
the other guides of docs/, the comments of the configuration files and the comments of
the code type measured numbers."""
import io
import re
import subprocess
import sys
import tokenize
from pathlib import Path

from ncd.studies.bench.speed_table import SPEED_START, read_speed_csv, speed_block, speed_markdown

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()
SOLVERS = ROOT / "docs" / "solvers.md"
DOCS = sorted((ROOT / "docs").glob("*.md"))         # markdown only: docs/speed.tsv is generated data
CONFIGS = [ROOT / "config.yaml", *sorted((ROOT / "config").glob("*.yaml"))]
# the code whose comments are scanned: the package, the workflow and the scripts
COMMENTED = (sorted((ROOT / "ncd").rglob("*.py")) + [ROOT / "Snakefile"] + sorted((ROOT / "workflow").rglob("*.smk"))
             + sorted((ROOT / "workflow" / "scripts").glob("*.py")) + sorted((ROOT / "scripts").glob("*.py")))
MAX_LINES = 220


def section(title, text=README):
    start = text.index(f"## {title}")
    end = text.find("\n## ", start + 3)
    return text[start:end if end > 0 else None]


def _newlines(match):
    return "\n" * match.group(0).count("\n")


def prose(text):
    """``text`` without fenced code blocks, inline code, HTML tags and the generated speed
    table (checked against its source by test_speed_table_is_the_generated_one); what is
    removed leaves its line breaks, so a line of the prose is that line of the file."""
    if SPEED_START in text:
        block = speed_block(text)
        text = text.replace(block, "\n" * block.count("\n"))
    text = re.sub(r"```.*?```", _newlines, text, flags=re.DOTALL)
    text = re.sub(r"`[^`\n]*`", "", text)
    return re.sub(r"<[^>]*>", _newlines, text)


def yaml_comments(text):
    """The comments of a YAML file, line for line: a line starting with ``#``, or the part
    of a line after `` # `` (keys and values are left out: they are parameters)."""
    out = []
    for line in text.splitlines():
        if line.lstrip().startswith("#"):
            out.append(line.lstrip()[1:])
        else:
            out.append(line.split(" # ", 1)[1] if " # " in line else "")
    return "\n".join(out)


def python_comments(text):
    """The ``#`` comments of a Python source, line for line (code and strings left out)."""
    out = [""] * (text.count("\n") + 1)
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT:
            out[tok.start[0] - 1] = tok.string[1:]
    return "\n".join(out)


# A number followed by a unit of time, a speed-up factor, a percentage or a count of
# what a run measures: hand-typed results, which belong on the generated pages.
MEASURED = re.compile(
    r"\d[\d.,]*\s*(?:[-–]\s*\d[\d.,]*\s*)?"
    r"(?:(?:s|sec|secs|seconds?|min|mins|minutes?|ms|µs|us|ns|h|hours?)\b|[x×](?![\w])|%"
    r"|\s*(?:sweeps?|tests?|jobs?|passed|failed|skipped|runs?|orders?)\b)", re.IGNORECASE)


def measured(name, text):
    """``name:line: match`` for every hand-typed measured number of ``text`` (a prose, or
    comments, whose lines are those of the file ``name``)."""
    return [f"{name}:{k}: {m.group(0).strip()}" for k, line in enumerate(text.split("\n"), 1)
            for m in MEASURED.finditer(line)]


COMMIT = re.compile(r"(?<![\w-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![\w-])")
ISSUE = re.compile(r"\bissues?\s*#?\s*\d+|#\d+\b", re.IGNORECASE)


def test_readme_example_matches_closed_form():
    code = re.search(r"## The solver in 15 lines\n\n```python\n(.*?)```", README, re.DOTALL).group(1)
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
    stripped = re.sub(r"<img[^>]*>|`[^`]*`|§\d|Fig\. \d|\d+°|\(\d\)", "", text)
    numbers = re.findall(r"\d[\d.,]*\s*(?:%|m/s|N\b|s\b|R\b)?", stripped)
    assert numbers == [], f"hand-typed numbers in the README's result table: {numbers}"


def test_no_hand_typed_measurements_anywhere():
    """No timing, speed-up, percentage or count of sweeps/tests/jobs in the README's prose:
    they are on results/index.html and results/html/bench.html, measured by the run."""
    found = [m.group(0) for m in MEASURED.finditer(prose(README))]
    assert not found, f"hand-typed measured numbers in README.md: {found}"
    assert "results/html/bench.html" in README and "snakemake -j2 bench" in README
    assert "docs/solvers.md" in README


def test_speed_table_is_the_generated_one():
    """The README's only measured numbers are the speed table, and it is exactly what
    scripts/speed_table.py generates from its source docs/speed.tsv (no time is checked)."""
    rows = read_speed_csv(ROOT / "docs" / "speed.tsv")
    assert speed_block(README) == speed_markdown(rows)
    assert all(r["source"].startswith("results/bench/") for r in rows)
    assert "scripts/speed_table.py" in section("Speed")
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "speed_table.py"), "--check"],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout


def test_no_measured_numbers_in_docs_config_comments_and_exact_comments():
    """The guides of docs/ (speed.tsv, generated data, is not one), the comments of
    config.yaml and config/*.yaml, and the ``#`` comments of the code (ncd/, the workflow, scripts/) say why in words and
    point to the pages that measure: no timing, speed-up, percentage or count typed there."""
    assert SOLVERS in DOCS and all(p.suffix == ".md" for p in DOCS)
    found = []
    for path in DOCS:
        found += measured(path.relative_to(ROOT).as_posix(), prose(path.read_text()))
    for path in CONFIGS:
        found += measured(path.relative_to(ROOT).as_posix(), yaml_comments(path.read_text()))
    for path in COMMENTED:
        found += measured(path.relative_to(ROOT).as_posix(), python_comments(path.read_text()))
    assert not found, "hand-typed measured numbers:\n" + "\n".join(found)


def test_measured_numbers_are_named_by_file_and_line():
    """A negative control: the scan of each kind of file catches a typed timing and names
    its line; numbers that are not measurements pass."""
    assert measured("a.md", prose("Intro.\n\n```\nx = 1\n```\nIt took 31 s.\n")) == ["a.md:6: 31 s"]
    yaml = "fig:\n  # built once; it took 31 s\n  runs: 200   # took 31 s\n  h: 2.0e-4   # s\n"
    assert measured("c.yaml", yaml_comments(yaml)) == ["c.yaml:2: 31 s", "c.yaml:3: 31 s"]
    code = 'TOL = 1e-9   # took 31 s\ns = "took 31 s"\n# took 31 s\n'
    assert measured("m.py", python_comments(code)) == ["m.py:1: 31 s", "m.py:3: 31 s"]
    for text in ("bounds below 1e-5 degree", "Figure 4", "§5", "(κ − 1)!", "10^4 grains", "`max_sweeps: 200000`",
                 "Moreau 2005, §2–§5"):
        assert not measured("a.md", prose(text)), text
    assert not measured("c.yaml", yaml_comments("  runs: 2000             # random initial guesses\n"
                                                "  h: 1.0e-3                # time step (s)\n"))


def test_measurement_pattern_catches_the_usual_forms():
    for text in ("took 29 min", "in 6 min 4 s", "0.25 s", "12 ns", "a 1.97× speed-up", "3x faster",
                 "27 %", "514 tests", "168 jobs", "150,930 sweeps", "139 passed", "2.6–6.9 s"):
        assert MEASURED.search(text), text
    for text in ("Python 3.11", "§3, Fig. 2", "Powders and Grains 2005", "hal-01824602", "10⁴ grains",
                 "layer 3", "2-D"):
        assert not MEASURED.search(text), text


def test_readme_is_short():
    n = len(README.splitlines())
    assert n <= MAX_LINES, f"README.md has {n} lines (at most {MAX_LINES}): move details to docs/"


def test_no_history_of_the_work():
    """No commit hashes, issue numbers or sessions: the README and the guides of docs/ say
    what is, not how it came to be."""
    for path in (ROOT / "README.md", *DOCS):
        text = path.read_text()
        assert not COMMIT.findall(text), f"{path.name}: commit hashes {COMMIT.findall(text)}"
        assert not ISSUE.findall(text), f"{path.name}: issue numbers {ISSUE.findall(text)}"
        assert "session" not in text.lower(), f"{path.name} mentions a session"
    assert COMMIT.search("a fresh clone of cbf73d9") and not COMMIT.search("(hal-01824602)")


def test_solvers_doc_has_a_section_per_method():
    text = SOLVERS.read_text()
    headings = [h.lower() for h in re.findall(r"^## (.+)$", text, re.MULTILINE)]
    for method, words in {"plain NLGS": ("nlgs",), "Anderson": ("anderson",), "local exact": ("local exact",),
                          "finishing stage": ("finishing",), "Lemke": ("lemke",),
                          "failed experiments": ("did not work",),
                          "hand-written code": ("hand-written",)}.items():
        assert any(all(w in h for w in words) for h in headings), f"docs/solvers.md lacks a section on {method}"
    for setting in ('accel="anderson"', "local_exact=True", 'finish="active_set"', "finish_tol", "keep_best",
                    "observable_tol", "check_every", "ncd.solver.lcp", "snakemake -j2 bench"):
        assert setting in text, setting


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
    assert "python -m venv .venv && . .venv/bin/activate" in text
    assert 'python -m pip install -e ".[test]" && snakemake -j2' in text and "\npytest\n" in text
    assert 'pytest -m "not pipeline"' in text
    for marker in ("`slow`", "`cluster`", "`pipeline`"):
        assert marker in text, marker


def test_layout_names_the_layers_and_the_import_check():
    text = section("Layout")
    import tomllib
    layers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]["layers"]
    for pkg in (n.strip() for layer in layers for n in layer.split("|")):
        assert f"`ncd/{pkg}`" in text, pkg
    assert "`ncd/figures/<config key>/`" in text
    for path in ("workflow/", "notebooks/", "tests/", "docs/"):
        assert path in text, path
    assert "lint-imports" in text and "tests/test_layers.py" in text


def test_no_process_words():
    for text in (README, SOLVERS.read_text()):
        for words in ("the issue", "design card", "helper", "the brief", "an earlier session"):
            assert words not in text.lower(), words


def test_config_reference_is_up_to_date():
    from ncd.pages.configdoc import TARGET, render
    assert TARGET.read_text() == render(), "config/README.md is stale: run `python -m ncd.pages.configdoc`"


def test_license_and_citation():
    assert "MIT License" in (ROOT / "LICENSE").read_text()
    cff = (ROOT / "CITATION.cff").read_text()
    assert "cff-version" in cff and "Indetermination in the numerical simulation of granular systems" in cff
