"""Layer 7, figures: the analysis of each figure of the paper, one group of modules per
figure, each turning a config section into xarray Datasets.

A figure's module imports only modules of its own figure (:data:`FIGURE_MODULES`) and
the layers below; what two figures share lives in :mod:`ncd.scenes`.  The workflow reads
the same table: a figure's computing rules depend on the layers below and on its own
modules, so that editing one figure reruns no other.
"""
FIGURE_MODULES = {
    "fig1_wedged": ("wedged", "wedged_page"),
    "fig2_slope": ("census", "slope_page"),
    "fig3_equilibrium": ("equilibrium", "equilibrium_plots", "faces"),
    "fig4_pile": ("pile", "pile_exact", "pile_plots"),
    "fig4_history": ("history", "history_analysis", "history_exact", "history_plots", "history_size"),
    "fig4_bank": ("bank", "bank_claims", "bank_exact", "bank_plots"),
    "fig5_governing": ("governing", "governing_claims", "governing_exact", "governing_flow", "governing_line",
                       "governing_plot", "governing_summary", "governing_unger"),
}
