# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     notebook_metadata_filter: language_info
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
#   language_info:
#     name: python
# ---

# %% [markdown]
# # Error against run time: the cost of precision in Contact Dynamics and in MD
#
# **What the paper says** (Moreau 2005, §2).  In Contact Dynamics (CD) "the price to pay is
# that the core of the calculation at each time-step consists of a highly nonlinear and
# nonsmooth problem", solved by nonlinear Gauss–Seidel (NLGS) "until some convergence
# criterium is met"; "in case of dense collections of rigid bodies, one considerably
# accelerates convergence by starting from the values found for these impulsions at the
# antecedent step".  Molecular dynamics (MD) integrates smooth soft-contact forces with
# small explicit steps.
#
# **What we computed.**  (1) *NLGS at one step* ($h = 10^{-3}$ s) of three states built by
# `ncd.studies.error_vs_runtime.measure` (a settled packing of 28 discs in a box, a small settled pile,
# a step of a periodic slope flow at 24°: small stand-ins of the paper's states, not its
# configurations): for each initial guess (zero, or the previous step's impulses), stopping
# criterion and tolerance, the wall time (best of a few repeats), the sweeps and the distance
# to the limit of the same iteration run to a much tighter tolerance,
# $\max|u_f - u_f^*|/(|g|h)$ and $|s - s^*|/|s^*|$.  (2) *Time integration*: an observable
# with an exact or reference value against wall time, for CD over its step $h$ and for MD
# (`ncd.dynamics.md`) over $h = f\,h_\mathrm{crit}$ and the spring stiffness $k = c\,k_0$
# ($k_0$: an overlap of 1 % of a radius under the load): the distance travelled on an
# incline (closed form), the ground reaction of a settled heap (its weight), the mean
# velocity of a slope flow (CD at a fine step; CD at half that step measures the
# reference's own uncertainty).

# %%
from pathlib import Path

import matplotlib
import xarray as xr
from IPython.display import HTML, Markdown, display

from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save
from ncd.studies.error_vs_runtime import page
from ncd.studies.error_vs_runtime.claims import JUDGES

matplotlib.use("Agg")  # the figure is shown once, as the saved PNG
# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
snakemake = paths("error_vs_runtime", ["nlgs", "integration"], globals().get("snakemake"))
nl = xr.load_dataset(snakemake.input.nlgs)
df = xr.load_dataset(snakemake.input.integration).to_dataframe()
results = results_dir(snakemake)

# %%
Path(snakemake.output.png).with_suffix(".caption.rst").write_text(page.caption(nl, df))
save(page.plot(nl, df), snakemake.output, dpi=100, show=True)

# %% [markdown]
# (a–c) Distance of the end-of-step velocities to the limit against wall time, one point
# per tolerance, colour the initial guess, line style the stopping criterion.
# (d) Zero-guess sweeps over warm-start sweeps to reach each tolerance (residual criterion).
# (e–i) Error against wall time of CD over its step (black) and of MD over its step for
# each stiffness (colours); a zero error sits on the lower edge, the shaded band is the
# reference's own uncertainty.
#
# ## NLGS at one step: what was measured

# %%
display(Markdown(page.nlgs_sentences(nl)))
display(Markdown(claim_markdown("s2-warm-accelerates", results, JUDGES)))

# %% [markdown]
# The distance to the limit follows the natural-map residual up to a factor per state, so
# the residual is a usable stopping criterion.  Where the zero- and warm-started limits
# differ in impulses while their velocities agree to rounding, the step has several
# solutions with the same motion: the paper's indeterminacy of the contact forces.
#
# Every setting (state, guess, criterion, tolerance):

# %%
display(HTML(page.nlgs_table(nl).to_html(index=False)))

# %% [markdown]
# ## Time integration: CD against MD

# %%
display(Markdown(page.integration_sentences(df) + "\n\nEvery run (−1: a diverged MD run):"))
display(HTML(page.integration_table(df).to_html(index=False)))

# %% [markdown]
# On the incline CD's error stays at rounding level at any step, while MD has to resolve the
# contact stiffness; on the heap and the flow each method is limited by what the observable
# can resolve (undamped residual motion for the reaction, chaos for the mean velocity).
# Wall times are measurements on a shared machine; sweeps and `work` (contact updates: NLGS
# sweeps × contacts for CD, steps × candidate pairs for MD) are the reproducible cost.
