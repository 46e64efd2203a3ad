# The rest of section 5 of Moreau (2005) in 2-D: cuts parallel to the free surface, the
# granular stress tensor (Love-Weber) and the reciprocity formula, on the piles already
# built by fig4_pile (the default pile) and fig4_history (every pile of both histories).
#   measure    surface-parallel cuts, windows, stress, reciprocity, mobilized friction of
#              every pile, bootstrap bands over piles            -> measures.nc
#   exact      exact angle ranges over A ∩ C at the surface-parallel cuts of the default
#              pile and the first exact.members of each history  -> exact/<pile>.nc
#   tilt       tilting test of the default pile and the first tilt.piles point-source piles:
#              the tilt at which each flank fails                -> tilt.nc
#   notebook   notebooks/fig4_bank.ipynb                         -> results/figures/fig4_bank.png|pdf
# Uses the names of fig4_pile.smk and fig4_history.smk (included before this file, FIGURES order):
# the configs that built the piles (CFG4_SIM, SIM_KEYS) and the pile files (piles_of(NH)).
BANK_FIG = "fig4_bank"
BANK_CFG = section(BANK_FIG)
BANK_DIR = f"results/{BANK_FIG}"
BANK_MEASURE_CFG = {k: v for k, v in BANK_CFG.items() if k not in ("exact", "tilt")}
BANK_EXACT = ["default"] + [f"{h}_{m:03d}" for h in ("point", "rain")
                            for m in range(min(BANK_CFG["exact"]["members"], CFGH["piles"]))]

BANK_HISTORY_PILES = f"{FH}/piles/n{NH}"
BANK_PILES = piles_of(NH)


def bank_pile(name):
    """The file of pile ``name`` (default: fig4_pile's construction; else a fig4_history pile)."""
    return "results/fig4_pile/construction.nc" if name == "default" else f"{BANK_HISTORY_PILES}/{name}.nc"


# the config sections that built the piles (their equilibrium problems for the exact LPs), bound now:
# a name of another rules file could be rebound by a later include before a params function runs
BANK_PILE_CFG = {True: dict(CFG4_SIM), False: {k: CFGH[k] for k in SIM_KEYS}}
BANK_EXACT_CFG = {k: v for k, v in BANK_CFG.items() if k not in ("analysis", "vertical_tol_deg", "failure_tol", "tilt")}
# the tilting test: its own section and the bootstrap of the bands; the point-source piles it tilts
BANK_TILT_CFG = {"tilt": BANK_CFG["tilt"], "analysis": BANK_CFG["analysis"]}
BANK_TILT_PILES = [f"{BANK_HISTORY_PILES}/point_{m:03d}.nc"
                   for m in range(min(BANK_CFG["tilt"]["piles"], CFGH["piles"]))]
BANK_TILT_PILE_CFG = {"default": BANK_PILE_CFG[True], "point": BANK_PILE_CFG[False]}


rule fig4_bank_measure:
    input:
        construction="results/fig4_pile/construction.nc",
        cuts="results/fig4_pile/cuts.nc",
        piles=BANK_PILES,
        code=code_of("fig4_bank_measure"),
    output:
        f"{BANK_DIR}/measures.nc",
    params:
        config=BANK_MEASURE_CFG,
    log:
        log(BANK_FIG, "measure"),
    benchmark:
        bench(BANK_FIG, "measure")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_bank_measure.py"


rule fig4_bank_exact:
    input:
        pile=lambda w: bank_pile(w.pile),
        cuts=lambda w: "results/fig4_pile/cuts.nc" if w.pile == "default" else [],   # the default pile's fits
        code=code_of("fig4_bank_exact"),
    output:
        f"{BANK_DIR}/exact/{{pile}}.nc",
    wildcard_constraints:
        pile=r"default|(point|rain)_\d+",
    params:
        config=BANK_EXACT_CFG,
        pile_config=lambda w: BANK_PILE_CFG[w.pile == "default"],
    log:
        log(BANK_FIG, "exact_{pile}"),
    benchmark:
        bench(BANK_FIG, "exact_{pile}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_bank_exact.py"


rule fig4_bank_tilt:
    input:
        construction="results/fig4_pile/construction.nc",
        cuts="results/fig4_pile/cuts.nc",
        piles=BANK_TILT_PILES,
        code=code_of("fig4_bank_tilt"),
    output:
        f"{BANK_DIR}/tilt.nc",
    params:
        config=BANK_TILT_CFG,
        pile_config=BANK_TILT_PILE_CFG,
    log:
        log(BANK_FIG, "tilt"),
    benchmark:
        bench(BANK_FIG, "tilt")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_bank_tilt.py"


rule fig4_bank_notebook:
    input:
        measures=f"{BANK_DIR}/measures.nc",
        exact=[f"{BANK_DIR}/exact/{p}.nc" for p in BANK_EXACT],
        tilt=f"{BANK_DIR}/tilt.nc",
        construction="results/fig4_pile/construction.nc",
        cuts="results/fig4_pile/cuts.nc",
        notebook=notebook_file(BANK_FIG),
        notebook_py=notebook_file(BANK_FIG, "py"),
        code=notebook_code("fig4_bank"),
    output:
        png=figure_output(BANK_FIG, "png"),
        pdf=figure_output(BANK_FIG, "pdf"),
    params:
        config=BANK_CFG,
    log:
        notebook=f"results/notebooks/{BANK_FIG}.ipynb",
    benchmark:
        bench(BANK_FIG, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_bank.ipynb"


rule fig4_bank:
    input:
        figure_targets(BANK_FIG),
