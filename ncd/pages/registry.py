"""Every figure's judging functions, for the index page: {figure: its ``claims.JUDGES``} in
the order of the pages.  The index reads all of them; a figure's page imports only its own
package's table, so that an edit of one figure's claims reruns that figure's page and the
index, not the other pages.
"""
from ncd.figures.fig1_wedged import claims as fig1_wedged
from ncd.figures.fig2_slope import claims as fig2_slope
from ncd.figures.fig3_equilibrium import claims as fig3_equilibrium
from ncd.figures.fig4_bank import claims as fig4_bank
from ncd.figures.fig4_history import claims as fig4_history
from ncd.figures.fig4_pile import claims as fig4_pile
from ncd.figures.fig5_governing import claims as fig5_governing
from ncd.studies.error_vs_runtime import claims as error_vs_runtime
from ncd.studies.stability import claims as stability

JUDGES_BY_FIGURE = {
    "fig1_wedged": fig1_wedged.JUDGES,
    "fig2_slope": fig2_slope.JUDGES,
    "fig3_equilibrium": fig3_equilibrium.JUDGES,
    "fig4_pile": fig4_pile.JUDGES,
    "fig4_history": fig4_history.JUDGES,
    "fig4_bank": fig4_bank.JUDGES,
    "fig5_governing": fig5_governing.JUDGES,
    "stability": stability.JUDGES,
    "error_vs_runtime": error_vs_runtime.JUDGES,
}
