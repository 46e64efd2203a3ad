"""results/index.html: claims read from the data, "not computed" when data are missing,
new figures listed, run times from the benchmark files."""
import numpy as np
import xarray as xr

from ncd.pages.report import CLAIMS, DIFFERS, NOT_COMPUTED, REPRODUCED, build_page, evaluate, fig1_threshold, run_times


def test_missing_data_gives_not_computed_and_the_page_builds(tmp_path):
    assert all(evaluate(c, tmp_path).verdict == NOT_COMPUTED for c in CLAIMS)
    page = build_page(tmp_path, ["fig1_wedged", "fig9_new"], {"fig1_wedged": {"mu": 0.75}})
    assert page.count("not computed") >= len(CLAIMS) and "fig9_new" in page and "config digest" in page


def _sweep(tmp_path, fractions):
    gamma = np.array([10.0, 15.0, 25.0, 30.0])
    ds = xr.Dataset({"wedged_fraction": ("gamma", np.array(fractions))}, coords={"gamma": gamma},
                    attrs={"threshold_gamma_deg": 20.0})
    (tmp_path / "fig1_wedged").mkdir(exist_ok=True)
    ds.to_netcdf(tmp_path / "fig1_wedged" / "sweep.nc")


def test_threshold_verdict_follows_the_data(tmp_path):
    _sweep(tmp_path, [0.0, 0.0, 0.4, 0.6])
    m = fig1_threshold(tmp_path)
    assert m.verdict == REPRODUCED and "first at 25.0°" in m.value
    _sweep(tmp_path, [0.0, 0.1, 0.4, 0.6])  # wedging below the threshold: the claim fails
    assert fig1_threshold(tmp_path).verdict == DIFFERS


def test_run_times_sum_the_benchmark_files(tmp_path):
    d = tmp_path / "benchmarks" / "fig1_wedged"
    d.mkdir(parents=True)
    for name, s in (("simulate", 2.5), ("notebook", 4.0)):
        (d / f"{name}.tsv").write_text(f"s\th:m:s\tmax_rss\n{s}\t0:00:0{int(s)}\t100\n")
    assert run_times(tmp_path, "fig1_wedged") == (2, 6.5)
    assert run_times(tmp_path, "absent") == (0, 0.0)
