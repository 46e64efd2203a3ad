# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Figure 2 — dispersion of a grain's acceleration in a flow down a slope
#
# **What the paper says** (Moreau 2005, §3).  $N = 355$ discs flow on a ground under periodic
# lateral conditions, gravity as for a ground sloping down by 24°, friction 0.5, restitution
# 0, "in a phase of overall acceleration".  One step is investigated by repeated nonlinear
# Gauss–Seidel (NLGS) runs from the zero initial guess, each with a random review order:
# "the acceleration vector of a grain center is affected by a dispersion shown on the
# figure.  On the contrary, if the same exploration is performed with the contact forces of
# antecedent step taken as initial guess, almost no dispersion is visible."  The paper asks
# "why the dispersion produces a line, not an extended cloud" and suggests that "the
# disposition of contact points at which the sliding velocity equals zero may be
# determinant".
#
# **What was computed.**  The scene is built, deposited and released by `ncd.shared.slope`:
# polydisperse discs on a rough ground of glued discs (a flat wall would let the bottom layer
# roll), periodic along the ground; after the deposit gravity is tilted to 24° and the flow
# is stepped with warm starts (Moreau–Jean, $\theta = 1/2$).  At the investigated step the
# core problem is solved many times, (a) from the zero guess and (b) from the previous
# step's impulses, with the same random review orders.  A dispersion could be a true
# indeterminacy of the step or the iteration error of runs stopped at a finite tolerance,
# which can also look like a line: every run is therefore continued from tolerance to
# tolerance, and a grain's *spread* (the RMS distance of its accelerations to their mean over
# the runs) is followed as the tolerance tightens: a true indeterminacy keeps a fixed spread,
# an iteration error shrinks with the tolerance.

# %%
from pathlib import Path

import matplotlib
import xarray as xr
from IPython.display import HTML, Markdown, display

from ncd.figures.fig2_slope import census as cs
from ncd.figures.fig2_slope import page
from ncd.figures.fig2_slope.claims import JUDGES
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save
from ncd.shared import slope_analysis as sa

matplotlib.use("Agg")  # the figure is shown once, as the saved PNG
# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig2_slope", ["trajectory", "ensemble", "measures", "census"], globals().get("snakemake"))
cfg = _smk.params.config
traj, ens = xr.load_dataset(_smk.input.trajectory), xr.load_dataset(_smk.input.ensemble)
meas, census = xr.load_dataset(_smk.input.measures), xr.load_dataset(_smk.input.census)
results = results_dir(_smk)

# %%
Path(_smk.output.png).with_suffix(".caption.rst").write_text(page.caption(ens, meas))
save(page.plot(traj, ens, meas, cfg), _smk.output, dpi=100, show=True)

# %% [markdown]
# (a) The flow at the investigated step, each grain coloured by its zero-guess spread at the
# tightest tolerance; the grain of largest spread outlined in red; in black the contacts
# whose status (no contact, stick, slide) differs between the two most frequent solutions.
# (b, c) That grain's accelerations over the zero-guess and the warm-start runs, relative to
# the warm-start mean, one shade per tolerance (light: loose, dark: tightest), at the same
# scale, with the number of runs on each solution.  (d) Its spread and the median spread of
# the grains with a visible dispersion against the tolerance.
#
# ## The flow

# %%
display(Markdown(page.flow_sentence(traj, cfg)))
display(Markdown(claim_markdown("s3-overall-acceleration", results, JUDGES)))

# %% [markdown]
# ## True indeterminacy or iteration error?
#
# The verdict rule: *indeterminacy* when, over the last `analysis.decades` decades of
# tolerance, the zero-guess spread stays above `analysis.floor` $|g|$, shrinks by less than
# half per decade and at the tightest tolerance is at least `analysis.warm_ratio` times the
# warm-start spread; *iteration error* when it shrinks tenfold over those decades.

# %%
display(Markdown(page.spread_sentence(ens, meas, cfg)))
display(HTML(page.tolerance_table(ens, meas).to_html(index=False)))
display(Markdown(claim_markdown("s3-dispersion", results, JUDGES)))
display(Markdown(claim_markdown("s3-warm-no-dispersion", results, JUDGES)))
display(Markdown(claim_markdown("s2-warm-little-indeterminacy", results, JUDGES)))

# %%
display(Markdown(sa.warm_check(ens, cfg["analysis"]["solution_threshold"]) or "The warm runs are plain NLGS."))

# %% [markdown]
# ## Distinct solutions, and the census of the step's exact solutions
#
# At the tightest tolerance the runs are grouped into *distinct solutions* (whole acceleration
# fields that agree within `analysis.solution_threshold` $|g|$).  NLGS end points say which
# solutions NLGS reaches, not how many the step has: `census.nc` gathers exact solutions from
# the NLGS end points (zero-guess, warm-start and random-guess runs), from Lemke's method on
# the LCP form of the step and from contact-status patterns combining the switches seen
# between solutions, each polished to a residual of $10^{-12}$, counted by basin and
# restarted from a small perturbation.

# %%
cloud = sa.cloud_against_census(ens, census, int(meas.attrs["grain"]), "zero")
display(Markdown(page.solutions_sentence(meas, cfg) + "\n\n" + cs.census_text(census) + "\n\n"
                 + cs.cloud_text(cloud, int(meas.attrs["grain"]), float(ens.tol.min()), cfg["analysis"]["line_ratio"])))
display(Markdown(claim_markdown("s3-line", results, JUDGES)))
display(Markdown(claim_markdown("s2-random-guess-any-solution", results, JUDGES)))

# %% [markdown]
# ## Where the alternative is decided
#
# The contacts whose status differs between the two most frequent solutions tell where the
# alternative is decided; the network of contacts that stick in both solutions tells how
# the difference propagates.  For every grain we count the sticking links to the nearest
# switching contact.

# %%
display(Markdown(page.switch_sentence(meas, ens)))
if "switched" in meas:
    display(HTML(page.switch_table(meas, cfg).to_html(index=False)))
display(Markdown(claim_markdown("s3-sticking-determinant", results, JUDGES)))

# %% [markdown]
# ## How often is a step indeterminate?
#
# The paper notes that "in other numerical experiments of the same sort, no indetermination
# was visible".  A scan of the flow compares a few runs at regular steps.

# %%
display(Markdown(page.scan_sentence(traj, cfg)))
if "scan_step" in traj.dims:
    display(HTML(page.scan_table(traj).to_html(index=False)))

# %% [markdown]
# ## Differences from the paper

# %%
display(Markdown(page.differences_sentence(traj, ens, meas, cloud, cfg) + "  One step is one sample; the scan "
                 "above and `fig5_governing` (flows across parameters) count the steps with several solutions."))
