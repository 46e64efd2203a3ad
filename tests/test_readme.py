"""The README's solver example runs and prints the closed-form accelerations."""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_readme_example_matches_closed_form():
    text = (ROOT / "README.md").read_text()
    code = re.search(r"## The solver in 15 lines\n\n```python\n(.*?)```", text, re.S).group(1)
    assert len(code.strip().splitlines()) <= 20
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    lines = out.strip().splitlines()
    assert len(lines) == 2
    for line, mode in zip(lines, ("slide", "roll")):
        a = float(re.search(r" a=([-\d.]+)", line).group(1))
        expected = float(re.search(rf"{mode} ([-\d.]+)", line).group(1))
        assert abs(a - expected) < 1e-3, line
        assert "converged=True" in line


def test_readme_thumbnails_exist_for_every_figure():
    readme = (ROOT / "README.md").read_text()
    figures = ["fig1_wedged", "fig2_slope", "fig3_equilibrium", "fig4_pile", "stability", "error_vs_runtime"]
    shown = re.findall(r'<img src="(docs/thumbnails/[\w]+\.png)"', readme)
    assert shown == [f"docs/thumbnails/{f}.png" for f in figures]
    for rel in shown:
        data = (ROOT / rel).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5_000, rel
