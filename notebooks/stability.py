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
# # Stability: Contact Dynamics against molecular dynamics on stiff and extreme cases
#
# **What the paper says** (Moreau 2005, §2).  Contact Dynamics (CD) imposes the contact law
# on the end-of-step velocity: "such an implicit character secures numerical stability,
# allowing one to use considerably larger step-lengths than in MD methods.  The price to pay
# is that the core of the calculation at each time-step consists of a highly nonlinear and
# nonsmooth problem."
#
# **What we computed.**  Ten small cases (discs of radius $r = 0.01$ m: a light disc under a
# disc $10^3$ or $10^6$ times heavier, 12 discs falling in a box with $\mu = 0$, $\mu = 10$ or
# $e = 0.5$, an $e = 1$ chain, an impact at 100 m/s on a wall or a disc, a hexagonal packing
# at rest without and with an alert distance), each run by CD (`ncd.step`, $\theta = 1/2$,
# warm-started NLGS) at several steps $h$ and by the MD baseline `ncd.dynamics.md`
# (Cundall–Strack spring–dashpot, symplectic Euler) at $h = f\,h_\mathrm{crit}$,
# $h_\mathrm{crit} = 2/\omega$, with the stiffness set for an overlap of 1 % of a radius.
# A run is **stable** when it does not diverge and its energy grows by at most 5 % of the
# energy scale $E_s$; a stable run is **inaccurate** when it sinks by more than 0.1 r into a
# neighbour, tunnels through a disc or stops NLGS at its sweep budget on some step.

# %%
from pathlib import Path

import matplotlib
import xarray as xr
from IPython.display import HTML, Markdown, display

from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save
from ncd.studies.stability import page
from ncd.studies.stability.claims import JUDGES

matplotlib.use("Agg")  # the figure is shown once, as the saved PNG

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
snakemake = paths("stability", ["table"], globals().get("snakemake"))
tab = xr.load_dataset(snakemake.input.table)
results = results_dir(snakemake)

# %%
fig = page.plot(tab)
Path(snakemake.output.png).with_suffix(".caption.rst").write_text(page.caption(tab))
save(fig, snakemake.output, dpi=100, show=True)

# %% [markdown]
# (a) Every run: a circle per CD run above its case, a square per MD run below, coloured by
# status, crossed when stable but inaccurate; the dashed line is MD's critical step.
# (b) Largest interpenetration; (c) energy drift at the end of the run; (d) the energy of
# the $e = 1$ chain over time.
#
# ## What was measured

# %%
display(Markdown(page.caveat_sentence(tab)))
display(Markdown(claim_markdown("s2-stability", results, JUDGES)))

# %% [markdown]
# ## Restitution: a binary collision and a multicontact one
#
# The paper: connecting each impulse with "some weighted mean of $u_f$ and $u_i$" is, "in the
# special case of a binary collision, equivalent to the introduction of some Newton
# restitution coefficients, but in general offers the advantage of handling also
# multicontact situations".

# %%
display(Markdown(page.chain_sentence(tab)))
display(Markdown(claim_markdown("s2-inelastic", results, JUDGES)))
display(Markdown(claim_markdown("s2-restitution", results, JUDGES)))

# %% [markdown]
# ## Where CD is not accurate, and why
#
# * *Mass ratio $10^6$*: for the two contacts of the stack the Gauss–Seidel iteration
#   contracts by $1 - 10^{-6}$ per sweep, so no sweep budget reaches the tolerance; the
#   impulses stay too small and the heavy disc sinks into the light one.
# * *Large $h$*: CD does not correct positions; an approaching disc penetrates by up to its
#   displacement per step, and tunnels through a disc when it moves more than a diameter.
# * *Very large $h$ on a packing at rest*: with the default active-set slack a contact
#   whose gap opens by the residual velocity times $h/2$ leaves the active set for a step;
#   the alert distance of `hexagonal_alert` is the remedy.
# * *$\mu = 10$*: NLGS can cycle on a step (a contact flipping between sliding and open).
#
# Measured per case (steps $h$ in seconds):

# %%
display(Markdown(page.case_notes(tab) + "\n\nRuns per case and method:"))
display(HTML(page.summary_table(tab).to_html(index=False)))

# %% [markdown]
# **MD.** Symplectic Euler is stable for an undamped spring iff $h\omega < 2$; a dashpot
# lowers the bound to $h\omega \le 2(\sqrt{1+\zeta^2}-\zeta)$ ($0.83$ for $e = 0$,
# $\zeta = 1$), and a disc with several springs has a larger $\omega$: MD needs $h$ a
# fraction of $h_\mathrm{crit}$, and above it the energy grows by orders of magnitude
# within a few steps (panels a, c, d).  With $k_n$ set by the heavy disc of the $10^6$
# stack, MD pays the stiffness with $10^5$–$10^6$ steps.
