"""The pages of the two studies (stability, error against run time): their sentences count
what the tables hold, their figures are readable at page width, their labels say what the
variables hold.

Unit tests build small tables by hand; the ``results`` tests read a DAG run (the reduced
configuration, or ``NCD_RESULTS_DIR``).
"""
import re

import matplotlib
import numpy as np
import xarray as xr
from figure_checks import problems

from ncd.studies.stability import page as SP
from ncd.studies.stability.measure import OBSERVABLE_LABEL

matplotlib.use("Agg")


def small_table():
    """Six runs: CD accurate, CD sunk (0.5 r), CD tunnelled, CD at its sweep budget, MD
    stable, MD diverged; an e = 1 chain among them."""
    n = 6
    trace = np.zeros((n, 5))
    trace[5] = [0, 1, 10, 100, 1000]
    return xr.Dataset({
        "case": ("run", np.array(["e1_chain", "e1_chain", "impact_disc", "stack_1e6", "e1_chain", "e1_chain"])),
        "method": ("run", np.array(["CD", "CD", "CD", "CD", "MD", "MD"])),
        "h": ("run", np.array([1e-4, 1e-3, 1e-3, 1e-3, 1e-6, 1e-5])),
        "h_over_hcrit": ("run", np.array([0.5, 5.0, 50.0, 500.0, 0.05, 2.0])),
        "stable": ("run", np.array([1, 1, 1, 1, 1, 0])),
        "diverged": ("run", np.array([0, 0, 0, 0, 0, 1])),
        "nan": ("run", np.zeros(n, int)),
        "max_penetration": ("run", np.array([1e-3, 0.5, 3.0, 0.01, 0.01, 5.0])),
        "tunnelled": ("run", np.array([0, 0, 1, 0, 0, 0])),
        "unconverged_steps": ("run", np.array([0, 0, 0, 12, -1, -1])),
        "residual_max": ("run", np.array([1e-9, 1e-9, 1e-9, 1e-3, -1, -1])),
        "energy_drift": ("run", np.array([1e-9, -1e-3, -0.5, -0.1, -1e-4, 1e3])),
        "observable": ("run", np.array([0.4, 0.4, 1.0, 0.9, 0.9, 0.0])),
        "trace": (("run", "sample"), trace), "trace_points": ("run", np.full(n, 5)),
    })


def test_inaccurate_counts_each_reason():
    tab = small_table()
    assert SP.inaccurate(tab).tolist() == [False, True, True, True, False, False]
    c = SP.counts(tab)
    assert (c["cd"], c["cd_stable"], c["cd_inaccurate"], c["cd_accurate"]) == (4, 4, 3, 1)
    assert (c["pen"], c["tunnel"], c["budget"]) == (2, 1, 1)       # the tunnelled run also sank by 3 r
    assert (c["md_unstable"], c["md_unstable_min_ratio"], c["md_stable_max_ratio"]) == (1, 2.0, 0.05)


def test_caveat_sentence_states_the_left_out_runs():
    text = SP.caveat_sentence(small_table())
    assert "Of the 4 CD runs, 4 stay bounded" in text
    assert "3 of the stable ones are not accurate" in text
    assert "2 sink by more than 0.1 r" in text and "1 tunnel" in text and "1 stop NLGS" in text
    assert "leaves 1 accurate CD runs, up to h = 0.5 h_crit" in text


def test_chain_sentence_and_table():
    tab = small_table()
    assert "leaves at 0.4 of the striker's speed" in SP.chain_sentence(tab)
    df = SP.summary_table(tab)
    row = df[(df.case == "e1_chain") & (df.method == "CD")].iloc[0]
    assert (row.runs, row.stable, row["of which inaccurate"]) == (2, 2, 1)
    assert df.runs.sum() == tab.sizes["run"]


def test_stability_figure_is_readable():
    assert problems(SP.plot(small_table())) == []


def test_stability_page_rule_is_the_index_rule(results):
    """The page and the index count the same inaccurate runs (the study's claims import the page's rule)."""
    from ncd.studies.stability import claims

    tab = xr.load_dataset(results / "stability" / "table.nc")
    assert claims.inaccurate is SP.inaccurate
    c = SP.counts(tab)
    assert c["cd_accurate"] + c["cd_inaccurate"] == c["cd_stable"]
    assert max(c["pen"], c["tunnel"], c["budget"]) <= c["cd_inaccurate"] <= c["pen"] + c["tunnel"] + c["budget"]
    assert problems(SP.plot(tab)) == []


def test_stability_table_labels_its_observable_as_a_value(tmp_path):
    """What the study writes: ``observable`` labelled as the case's value, not its name."""
    from ncd.io.netcdf import write_dataset
    from ncd.studies.stability.measure import to_dataset

    row = dict(case="e1_chain", observable=0.4, observable_ref=1.0, max_penetration=0.0, trace=np.zeros(3),
               sweeps_mean=1.0, residual_max=1e-9)
    write_dataset(to_dataset([row], 3), tmp_path / "table.nc")
    back = xr.load_dataset(tmp_path / "table.nc")
    assert back.observable.attrs["long_name"] == OBSERVABLE_LABEL
    assert back.observable_ref.attrs["long_name"].startswith("value of the case's observable")


def test_stability_observable_label_says_it_holds_a_value(results):
    """``observable`` holds a number per run (its long_name once said "name of the
    observable"): the e = 1 chain's value is the last disc's speed over the striker's."""
    tab = xr.load_dataset(results / "stability" / "table.nc")
    assert tab.observable.attrs["long_name"] == OBSERVABLE_LABEL
    assert tab.observable.dtype.kind == "f"
    chain = (tab.case.values.astype(str) == "e1_chain") & (tab.method.values.astype(str) == "CD")
    assert chain.any() and np.all((tab.observable.values[chain] > 0) & (tab.observable.values[chain] < 1))
    assert re.search(r"speed", tab.observable.attrs["long_name"])


# ------------------------------------------------------------------ error against run time
def small_nlgs():
    """Two states, two guesses, two criteria, three tolerances; the warm start saves 4x on
    ``rest`` and costs 2x on ``flow``; the limits of ``rest`` differ in impulses only."""
    tol = np.array([1e-2, 1e-4, 1e-6])
    zero = np.array([10.0, 30.0, 50.0])
    sweeps = np.empty((2, 2, 2, 3))
    sweeps[0, 0], sweeps[0, 1] = zero, zero / 4          # rest: zero, warm
    sweeps[1, 0], sweeps[1, 1] = zero, zero * 2          # flow
    err = np.broadcast_to(tol, sweeps.shape) * 3.0
    dims = ("state", "init", "criterion", "tol")
    return xr.Dataset(
        {"sweeps": (dims, sweeps), "wall_time": (dims, sweeps * 1e-5), "residual": (dims, err / 3),
         "error_impulse": (dims, err), "error_velocity": (dims, err), "converged": (dims, np.ones(sweeps.shape, int)),
         "n_discs": ("state", [28, 160]), "n_contacts": ("state", [51, 215]),
         "limits_distance_impulse": ("state", [0.4, 1e-11]), "limits_distance_velocity": ("state", [1e-12, 1e-10])},
        coords={"state": ["rest", "flow"], "init": ["zero", "warm"], "criterion": ["residual", "change"], "tol": tol},
        attrs={"config_yaml": "nlgs: {reference: {tol: 1.0e-13}}"})


def small_integration():
    import pandas as pd

    rows = []
    for method, h, err, wall, k in (("CD", 1e-3, 1e-15, 0.1, 0.0), ("CD", 1e-2, 0.0, 0.01, 0.0),
                                    ("MD", 1e-5, 1e-3, 0.01, 1.0), ("MD", 1e-6, 1e-5, 0.1, 100.0)):
        rows.append(dict(observable="incline", quantity="distance", method=method, mu=0.05, angle=20.0, h=h,
                         h_over_hcrit=0.1, k_factor=k, value=1.0, reference=1.0, error=err, wall_time=wall,
                         work=10.0, diverged=0))
    for method, err, wall in (("CD", 1e-9, 0.5), ("MD", 1e-2, 0.05)):
        rows.append(dict(observable="heap", quantity="reaction", method=method, mu=0.5, angle=0.0, h=1e-3,
                         h_over_hcrit=0.1, k_factor=1.0 if method == "MD" else 0.0, value=1.0, reference=1.0,
                         error=err, wall_time=wall, work=10.0, diverged=0))
    for method, err in (("CD_reference", 0.0), ("CD_reference_check", 0.02), ("CD", 0.05), ("MD", 0.1)):
        rows.append(dict(observable="slope_flow", quantity="mean_velocity", method=method, mu=0.5, angle=24.0,
                         h=1e-3, h_over_hcrit=0.1, k_factor=1.0 if method == "MD" else 0.0, value=1.0,
                         reference=1.0, error=err, wall_time=0.1, work=10.0, diverged=0))
    return pd.DataFrame(rows)


def test_warm_start_saving_is_read_both_ways():
    from ncd.studies.error_vs_runtime import page as WP

    nl = small_nlgs()
    assert np.allclose(WP.sweep_ratios(nl).sel(state="rest"), 4.0)
    text = WP.nlgs_sentences(nl)
    assert "the warm start needs from 4 times fewer sweeps" in text
    assert "2 times more sweeps" in text
    assert "(tolerance 1e-13) differ by 4.0e-01 in impulses" in text
    assert text.count("the step's forces are indeterminate") == 1      # rest only: flow's limits agree
    assert "12 of 12" not in text and "24 of 24 settings converged" in text


def test_integration_sentences_and_tables():
    from ncd.studies.error_vs_runtime import page as WP

    df = small_integration()
    text = WP.integration_sentences(df)
    assert "CD's relative error is at most 1e-15" in text and "MD's runs from 0.001 down to 1e-05" in text
    assert "moves its mean velocity by 0.02" in text and "CD 0.05 (h = 1e-03 s); MD 0.1–0.1" in text
    assert len(WP.integration_table(df)) == len(df)
    assert len(WP.nlgs_table(small_nlgs())) == 24


def test_work_precision_figure_is_readable():
    from ncd.studies.error_vs_runtime import page as WP

    assert problems(WP.plot(small_nlgs(), small_integration())) == []


def test_work_precision_page_on_the_run(results):
    from ncd.studies.error_vs_runtime import page as WP

    nl = xr.load_dataset(results / "error_vs_runtime" / "nlgs.nc")
    df = xr.load_dataset(results / "error_vs_runtime" / "integration.nc").to_dataframe()
    assert problems(WP.plot(nl, df)) == []
    r = WP.sweep_ratios(nl)
    for st in nl.state.values:                      # the sentence quotes the extremes of the ratio
        assert f"{float(r.sel(state=st).max()):.2g} times fewer" in WP.nlgs_sentences(nl)


def test_captions_state_the_finding():
    """The report captions are sentences from the data (valid reStructuredText, no placeholder)."""
    from docutils.core import publish_parts

    from ncd.studies.error_vs_runtime import page as WP

    for text in (SP.caption(small_table()), WP.caption(small_nlgs(), small_integration())):
        assert "<" not in text and "TODO" not in text
        publish_parts(text, writer="html", settings_overrides={"report_level": 2, "halt_level": 2})
    assert "bounded in 4 of 4 runs" in SP.caption(small_table()) and "3 of its stable runs are inaccurate" in \
        SP.caption(small_table())
    assert "rest 4 to 4; flow 0.5 to 0.5" in WP.caption(small_nlgs(), small_integration())
