# The rest of section 5 of Moreau (2005) in 2-D: cuts parallel to the free surface, the
# granular stress tensor (Love-Weber) and the reciprocity formula, on the piles already
# built by fig4_pile (the default pile) and fig4_history (every pile of both histories).
#   measure    surface-parallel cuts, windows, stress, reciprocity, mobilized friction of
#              every pile, bootstrap bands over piles            -> measures.nc
#   exact      exact angle ranges over A ∩ C at the surface-parallel cuts of the default
#              pile and the first exact.members of each history  -> exact/<pile>.nc
#   notebook   notebooks/fig4_bank.ipynb                         -> results/figures/fig4_bank.png|pdf
# Uses the names of fig4_pile.smk and fig4_history.smk (included before this file, FIGURES order):
# the configs that built the piles (CFG4_SIM, SIM_KEYS) and the pile files (piles_of(NH)).
FIGB = "fig4_bank"
CFGB = section(FIGB)
FB = f"results/{FIGB}"
CFGB_MEASURE = {k: v for k, v in CFGB.items() if k != "exact"}
BANK_EXACT = ["default"] + [f"{h}_{m:03d}" for h in ("point", "rain")
                            for m in range(min(CFGB["exact"]["members"], CFGH["piles"]))]

# the computing rules do not depend on the plots and the claims (editing them reruns the notebook only)
BANK_SOURCES = [f for f in ncd_sources(FIGB) if not f.endswith(("bank_plots.py", "bank_claims.py"))]


def bank_pile(name):
    """The file of pile ``name`` (default: fig4_pile's construction; else a fig4_history pile)."""
    return f"results/fig4_pile/construction.nc" if name == "default" else f"{FH}/piles/n{NH}/{name}.nc"


def bank_pile_config(name):
    """The config section that built pile ``name`` (its equilibrium problem for the exact LPs)."""
    return CFG4_SIM if name == "default" else {k: CFGH[k] for k in SIM_KEYS}


rule fig4_bank_measure:
    input:
        BANK_SOURCES,
        construction="results/fig4_pile/construction.nc",
        cuts="results/fig4_pile/cuts.nc",
        piles=piles_of(NH),
    output:
        f"{FB}/measures.nc",
    params:
        config=CFGB_MEASURE,
    log:
        log(FIGB, "measure"),
    benchmark:
        bench(FIGB, "measure")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_bank_measure.py"


rule fig4_bank_exact:
    input:
        BANK_SOURCES,
        pile=lambda w: bank_pile(w.pile),
        cuts="results/fig4_pile/cuts.nc",
    output:
        f"{FB}/exact/{{pile}}.nc",
    wildcard_constraints:
        pile=r"default|(point|rain)_\d+",
    params:
        config=lambda w: {k: v for k, v in CFGB.items() if k not in ("analysis", "vertical_tol_deg", "failure_tol")},
        pile_config=lambda w: bank_pile_config(w.pile),
    log:
        log(FIGB, "exact_{pile}"),
    benchmark:
        bench(FIGB, "exact_{pile}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_bank_exact.py"


rule fig4_bank_notebook:
    input:
        measures=f"{FB}/measures.nc",
        exact=[f"{FB}/exact/{p}.nc" for p in BANK_EXACT],
        construction="results/fig4_pile/construction.nc",
        cuts="results/fig4_pile/cuts.nc",
        notebook=notebook_file(FIGB),
        notebook_py=notebook_file(FIGB, "py"),
        pages=page_sources("notebook"),
        plots=[str(REL / "ncd" / "figures" / f"{m}.py") for m in ("bank_plots", "bank_claims")],
    output:
        png=figure_output(FIGB, "png"),
        pdf=figure_output(FIGB, "pdf"),
    params:
        config=CFGB,
    log:
        notebook=f"results/notebooks/{FIGB}.ipynb",
    benchmark:
        bench(FIGB, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_bank.ipynb"


rule fig4_bank:
    input:
        figure_targets(FIGB),
