"""The README's speed table, from the benchmark files of a run.

    python scripts/speed_table.py RESULTS_DIR   # read RESULTS_DIR/bench/*.nc, write docs/speed.tsv, update README.md
    python scripts/speed_table.py --check       # exit 1 when README.md's table is not the one docs/speed.tsv gives

RESULTS_DIR is the directory holding ``bench/`` after ``snakemake -j2 bench`` (``results``).
docs/speed.tsv keeps the numbers of the last regeneration, so that the README's table can be
checked against its source without the run (tests/test_readme.py).  The rows of a bench file
absent from RESULTS_DIR are kept from docs/speed.tsv (speed_table.merge_rows): a run of the
default target and ``bench_dag`` alone updates the default run's rows."""
import sys
from pathlib import Path

from ncd.studies.bench.speed_table import (
    merge_rows,
    read_speed_csv,
    replace_speed_block,
    speed_block,
    speed_markdown,
    speed_rows,
    write_speed_csv,
)

ROOT = Path(__file__).resolve().parent.parent
README, SOURCE = ROOT / "README.md", ROOT / "docs" / "speed.tsv"


def main(argv):
    if argv == ["--check"]:
        same = speed_block(README.read_text()) == speed_markdown(read_speed_csv(SOURCE))
        print("README.md's speed table matches docs/speed.tsv" if same
              else "README.md's speed table differs from docs/speed.tsv: run scripts/speed_table.py RESULTS_DIR")
        return 0 if same else 1
    if len(argv) != 1 or not (Path(argv[0]) / "bench").is_dir():
        print(__doc__)
        return 2
    rows = merge_rows(speed_rows(argv[0]), read_speed_csv(SOURCE), argv[0])
    write_speed_csv(rows, SOURCE)
    README.write_text(replace_speed_block(README.read_text(), speed_markdown(rows)))
    print(f"{len(rows)} rows from {argv[0]}/bench -> {SOURCE.relative_to(ROOT)}, README.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
