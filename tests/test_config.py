"""Config checks before any job: the ten malformed configs
that passed the JSON schemas, errors naming section and key, a missing section."""
import copy
import math

import pytest
import yaml
from conftest import ROOT, copy_workflow, run_snakemake

from ncd import InputError
from ncd.pipeline.config import ConfigError, check_config

SCHEMAS = ROOT / "workflow" / "schemas"
CONFIG = yaml.safe_load((ROOT / "config.yaml").read_text())
REDUCED = yaml.safe_load((ROOT / "tests" / "config_reduced.yaml").read_text())
QUICK = yaml.safe_load((ROOT / "config" / "quick.yaml").read_text())
REALIZATIONS = {"runs", "piles", "seeds", "random_runs", "per_mu", "control"}     # counts of ensemble members, piles, flows, packings
RULE_FILES = [f for f in CONFIG if (ROOT / "workflow" / "rules" / f"{f}.smk").exists() and f != "bench"]


def merged(base, overlay):
    """``overlay`` merged into a copy of ``base`` (mappings recursively, as Snakemake does)."""
    out = copy.deepcopy(base)
    for k, v in overlay.items():
        out[k] = merged(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def errors_of(overlay_yaml, drop=()):
    cfg = merged(CONFIG, yaml.safe_load(overlay_yaml) or {})
    for section in drop:
        cfg.pop(section)
    with pytest.raises(ConfigError) as info:
        check_config(cfg, RULE_FILES, SCHEMAS)
    return str(info.value)


def test_the_shipped_configs_pass():
    check_config(CONFIG, RULE_FILES, SCHEMAS)
    check_config(merged(CONFIG, REDUCED), RULE_FILES, SCHEMAS)
    assert issubclass(ConfigError, InputError) and issubclass(ConfigError, ValueError)


def leaves(tree, path=()):
    for key, value in tree.items():
        if isinstance(value, dict):
            yield from leaves(value, path + (key,))
        else:
            yield path + (key,), value


def test_the_quick_overlay_only_draws_fewer_realizations():
    """``config/quick.yaml`` keeps every size, tolerance, method and seed of config.yaml: it
    sets the run's label and realization counts only, each below the full run's (its members
    are then the full run's first ones)."""
    check_config(merged(CONFIG, QUICK), RULE_FILES, SCHEMAS)
    assert CONFIG["run"]["label"] == "full" and QUICK["run"] == {"label": "quick"}
    counts = [(p, v) for p, v in leaves(QUICK) if p != ("run", "label")]
    assert len(counts) >= 8
    for path, value in counts:
        default = CONFIG
        for key in path:
            default = default[key]
        assert path[-1] in REALIZATIONS, f"{'.'.join(path)} is not a realization count"
        assert type(value) is int and value < default, (path, value, default)


def test_a_quick_run_says_so_with_its_counts():
    """The notice of a quick run names its label and each figure's counts; the full run has none;
    a label outside full/quick is refused naming the key."""
    from ncd.pages.runscale import banner_html, counts
    quick = merged(CONFIG, QUICK)
    text = banner_html(quick, ["fig4_pile", "fig2_slope"])
    assert "A quick run" in text and "fig4_pile.ensemble.runs = 64" in text and "fig2_slope.explore.runs = 500" in text
    assert banner_html(CONFIG, ["fig4_pile"]) == ""
    assert ("fig4_history.piles", 16) in counts(CONFIG, "fig4_history")
    assert "run.label" in errors_of("run: {label: fast}")


# the ten configs that passed the schemas and planned jobs, with the text the error must hold
SLIPPED = [
    ("fig1_wedged: {mu: .nan}", "fig1_wedged.mu = nan"),
    ("fig1_wedged: {mu: .inf}", "fig1_wedged.mu = inf"),
    ("fig1_wedged: {h: .nan}", "fig1_wedged.h = nan"),
    ("fig1_wedged: {beta_deg: .nan}", "fig1_wedged.beta_deg = nan"),
    ("fig1_wedged: {ensemble: {runs: 8, shards: 9}}", "fig1_wedged.ensemble.shards = 9 must be <= "
                                                      "fig1_wedged.ensemble.runs = 8"),
    ("fig3_equilibrium: {modes: {warm: {runs: 3, shards: 4}}}", "fig3_equilibrium.modes.warm.shards = 4"),
    ("fig1_wedged: {ensemble: {force_min: 200.0, force_max: 100.0}}",
     "fig1_wedged.ensemble.force_min = 200.0 must be < fig1_wedged.ensemble.force_max = 100.0"),
    ("fig1_wedged: {sweep: {gamma_min_deg: 45.0, gamma_max_deg: 1.0}}",
     "fig1_wedged.sweep.gamma_min_deg = 45.0 must be < fig1_wedged.sweep.gamma_max_deg = 1.0"),
    ("fig1_wedged: {ensemble: {runs: 2000.0}}", "fig1_wedged.ensemble.runs = 2000.0: 2000.0 is not of type 'integer'"),
    (None, "config section 'fig1_wedged' is missing"),
]


@pytest.mark.parametrize("overlay, message", SLIPPED)
def test_a_config_that_slipped_through_is_refused_naming_the_key(overlay, message):
    text = errors_of(overlay or "", drop=() if overlay else ("fig1_wedged",))
    assert message in text, text
    assert text.count("\n") == 1, text          # one error, reported once


@pytest.mark.parametrize("overlay, message", [
    ("fig3_equilibrium: {packing: {gravity: [0.0, -.inf]}}", "fig3_equilibrium.packing.gravity.1 = -inf"),
    ("fig4_pile: {ensemble: {tol: .nan}}", "fig4_pile.ensemble.tol = nan"),
    ("bench: {core: {step_tol: .nan}}", "bench.core.step_tol = nan"),
    ("fig4_pile: {grains: {radius_min: 2.0e-3}}", "fig4_pile.grains.radius_min = 0.002 must be <= "),
    ("fig4_pile: {surface: {fit_range: [0.8, 0.2]}}", "fig4_pile.surface.fit_range = [0.8, 0.2]"),
    ("fig4_pile: {tolerance_study: {runs: 600}}", "fig4_pile.tolerance_study.runs = 600 must be <= "
                                                  "fig4_pile.ensemble.runs = 200"),
    ("fig2_slope: {flow: {step: 101}}", "fig2_slope.flow.step = 101 must be <= fig2_slope.flow.n_steps = 100"),
    ("fig3_equilibrium: {modes: {zero: {runs: 1.0e+4}}}", "fig3_equilibrium.modes.zero.runs = 10000.0"),
    ("fig3_equilibrium: {solver: {max_sweeps: 20000.5}}", "fig3_equilibrium.solver.max_sweeps = 20000.5"),
    ("fig4_history: {exact: {solver: cplex}}", "fig4_history.exact.solver = 'cplex'"),
])
def test_nonfinite_cross_field_and_integer_checks_everywhere(overlay, message):
    text = errors_of(overlay)
    assert message in text, text


def test_a_radius_range_may_be_degenerate_but_a_force_range_may_not():
    check_config(merged(CONFIG, {"fig4_pile": {"grains": {"radius_min": 1e-3, "radius_max": 1e-3}}}),
                 RULE_FILES, SCHEMAS)
    assert "force_min = 5.0 must be < " in errors_of("fig1_wedged: {ensemble: {force_min: 5.0, force_max: 5.0}}")


@pytest.mark.parametrize("section", [s for s in RULE_FILES if "tol" in CONFIG[s].get("solver", {})])
def test_a_schema_error_names_the_section(section):
    """``solver.tol`` exists in several sections: the message says which."""
    text = errors_of(f"{section}: {{solver: {{tol: 0}}}}")
    assert f"{section}.solver.tol = 0" in text and "exclusiveMinimum" in text, text


def test_every_error_is_reported_at_once():
    text = errors_of("fig1_wedged: {mu: .nan, ensemble: {runs: 2.5}}\nfig4_pile: {h: -1}")
    assert all(s in text for s in ("fig1_wedged.mu = nan", "fig1_wedged.ensemble.runs = 2.5", "fig4_pile.h = -1"))
    assert not math.isnan(CONFIG["fig1_wedged"]["mu"])      # the shipped config is untouched


@pytest.fixture()
def fresh_repo(tmp_path):
    return copy_workflow(tmp_path / "repo")


def test_snakemake_stops_before_any_job_naming_the_key(fresh_repo, tmp_path):
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("fig1_wedged: {mu: .nan}\n")
    proc = run_snakemake(fresh_repo, "-n", extra_configs=[overlay], check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "fig1_wedged.mu = nan: not a finite number" in out, out[-3000:]
    assert "Job stats" not in out and not (fresh_repo / "results").exists()


def test_a_removed_figure_section_stops_the_run(fresh_repo):
    """Without a figure's section the run stops naming the section (rather than planning without it)."""
    config = fresh_repo / "config.yaml"
    data = yaml.safe_load(config.read_text())
    del data["fig1_wedged"]
    config.write_text(yaml.safe_dump(data))
    reduced = fresh_repo / "tests" / "config_reduced.yaml"
    data = yaml.safe_load(reduced.read_text())
    data.pop("fig1_wedged", None)
    reduced.write_text(yaml.safe_dump(data))
    proc = run_snakemake(fresh_repo, "-n", check=False)
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "config section 'fig1_wedged' is missing" in out, out[-3000:]
    assert "Job stats" not in out
