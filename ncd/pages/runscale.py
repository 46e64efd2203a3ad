"""The scale of a run: its label and the realization counts each figure used.

``config.yaml`` is the full reproduction (``run.label: full``); the overlay
``config/quick.yaml`` lowers the realization counts (``run.label: quick``).  A quick run
says so at the top of the index and of every page, with the counts each figure used, so
that no band narrower in the full run is read as the full run's.  :data:`COUNTS` lists,
per figure, the config keys that count realizations (runs, piles, flows) or set the size
a verdict rests on.
"""
import html

COUNTS = {
    "fig1_wedged": (("ensemble", "runs"), ("ensemble", "zero_runs"), ("sweep", "runs")),
    "fig2_slope": (("explore", "runs"), ("census", "random_runs")),
    "fig3_equilibrium": (("modes", "zero", "runs"), ("modes", "random", "runs"), ("modes", "warm", "runs")),
    "fig4_pile": (("ensemble", "runs"), ("tolerance_study", "runs"), ("warm_ensemble", "runs")),
    "fig4_history": (("piles",), ("exact", "piles"), ("grains", "n")),
    "fig4_bank": (("tilt", "piles"),),
    "fig5_governing": (("packings", "n_discs"), ("packings", "per_mu"), ("packings", "control"),
                       ("walk", "samples"), ("uniform", "per_chain"), ("flows", "seeds")),
}


def label(config):
    """``full`` or ``quick`` (the ``run`` section; a config without one is the full run's)."""
    return (config.get("run") or {}).get("label", "full")


def counts(config, figure):
    """``[(key, value)]``: the realization counts of ``figure`` in ``config`` (``section.key``
    names; a key absent from the config is left out)."""
    out = []
    for path in COUNTS.get(figure, ()):
        node = config.get(figure, {})
        for key in path:
            node = node.get(key) if isinstance(node, dict) else None
        if node is not None:
            out.append((".".join((figure,) + path), node))
    return out


def banner_html(config, figures):
    """The notice at the top of a quick run's index or page (``figures``: the ones it
    shows), empty for the full run."""
    if label(config) == "full":
        return ""
    rows = "; ".join(f"{html.escape(k)} = {v}" for f in figures for k, v in counts(config, f))
    return ("<div class='ncd-quick' style='background:#fff3cd;border:1px solid #e0c36b;padding:.5em 1em;"
            "margin:.5em 0'><b>A quick run</b> (<code>run.label: "
            f"{html.escape(label(config))}</code>, config/quick.yaml): fewer realizations than the full "
            "reproduction (<code>snakemake -j2</code> with config.yaml alone), so its bands are wider and a "
            f"verdict may differ. Counts used: {rows or 'as in config.yaml'}.</div>")
