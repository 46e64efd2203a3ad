# ---
# jupyter:
#   jupytext:
#     cell_metadata_filter: -all
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
# # The bank of the pile: cuts parallel to the free surface, the stress tensor and the reciprocity formula (Moreau 2005, end of section 5)
#
# **What the paper says.** After the 2-D pile of Figure 4, Moreau recalls his 3-D
# simulations of pile construction: "Cuts are drawn in the bulk, either vertical (pieces
# of cylindric surfaces coaxial to the pile) or parallel to the free surface (pieces of
# conic surfaces). In the latter case, the transmitted force is found vertical, an easily
# explained feature amounting to the assertion, commonly made in Civil Engineering, that
# the peripheral bank lies in a state of *incipient failure*. For cylindric cuts, the
# transmitted force is found parallel to a generating line of the conical surface of the
# pile, revealing the same arching effect as in the foregoing 2D example. The author's
# interpretation is that these two observations are mathematically equivalent thanks to a
# *reciprocity formula* ensuing from the symmetry of the Cauchy stress, a tensor
# classically defined as an average over a granular sample covering the considered cuts."
# `fig4_pile` and `fig4_history` measure the vertical cuts; this page measures the rest, in
# two dimensions, on the same piles and their history forces (no pile is rebuilt).
#
# **What we compute.** On the default pile of `fig4_pile` and on every pile of
# `fig4_history` (point source and rain):
#
# 1. *Cuts parallel to the free surface.* On each flank, at $|x| = qL$ ($L$ the base
#    half-width of the member's point-source pile) and at several depths below the local free
#    surface (measured along the flank's normal), a segment parallel to the fitted flank.
#    Its resultant is the force of the grains with centres above it on the grains with
#    centres below, over the grain–grain contacts whose line of centres crosses it (the
#    convention of the vertical cuts). We keep its angle to the vertical and the weight of the
#    grains above it in the vertical strip over it.
# 2. *Exact ranges.* For the default pile and the first piles of each history, the exact range over
#    $A \cap C$ of each cut's angle to the vertical (linear-fractional programs, as for the
#    vertical cuts).
# 3. *The granular stress tensor.* The Love–Weber average over a window covering the cut (a
#    rectangle along the flank), compression positive,
#    $\sigma_{ij} = \frac{1}{A}\sum_{p \in W}\sum_{c \ni p} f^c_i\,(x_p - x_c)_j$: each contact
#    between two grains of the window counts with its branch vector $\ell$ ($f \otimes \ell$),
#    a contact with the ground with the grain's lever arm only. Its antisymmetric part is the
#    sum of the contact torques on the window's grains: zero at any equilibrium.
# 4. *The reciprocity formula.* With $n_s$ the outward normal of the surface-parallel cut and
#    $e$ the outward horizontal (the normal of a vertical cut), the force per unit length is
#    $\sigma e$ across the vertical cut and $-\sigma n_s$ across the surface-parallel one.
#    "The vertical cut's force is parallel to the surface" is $n_s\cdot\sigma e = 0$; "the
#    surface-parallel cut's force is vertical" is $e\cdot\sigma n_s = 0$. A symmetric
#    $\sigma$ makes them one statement.
# 5. *Incipient failure.* The friction angle $\varphi$ of the piles' own grains, measured by
#    tilting the default pile and the first point-source piles: gravity is turned towards one
#    flank step by step, each tilt held until the pile is back at rest, until the flank fails
#    at a tilt $\alpha_\mathrm{fail}$; $\varphi = \theta + \alpha_\mathrm{fail}$, $\theta$ the
#    flank's fitted slope. Beside it, the friction mobilized on the surface-parallel plane,
#    $\tau/\sigma_n$, against $\tan\theta$, against $\tan\varphi$ and against the friction of
#    the most loaded plane, $\sin\varphi_\sigma = (\sigma_1 - \sigma_2)/(\sigma_1 + \sigma_2)$;
#    the principal directions along the flank.
#
# Medians are over cuts and piles; bands are percentile bootstrap resamples of the **piles**.

# %%
from glob import glob
from pathlib import Path

import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig4_bank import claims as bc
from ncd.figures.fig4_bank import page as bpage
from ncd.figures.fig4_bank import plots as bp
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, save

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig4_bank", ["measures"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config
results = Path(inp.measures).parents[1]
ms = xr.load_dataset(inp.measures)
exact = {Path(p).stem: xr.load_dataset(p) for p in getattr(inp, "exact", None) or
         sorted(glob(str(results / "fig4_bank" / "exact" / "*.nc")))}
con = xr.load_dataset(getattr(inp, "construction", results / "fig4_pile" / "construction.nc"))
tilt_path = Path(getattr(inp, "tilt", results / "fig4_bank" / "tilt.nc"))
tilt = xr.load_dataset(tilt_path) if tilt_path.exists() else None


def claim(claim_id):
    """The verdict of a claim of the paper, the same object the index prints, under the anchor it links to."""
    return Markdown(claim_markdown(claim_id, results, bc.JUDGES))

# %%
fig = bp.figure(ms, exact, con, tilt)
save(fig, out)

# %%
display(Markdown(bp.caption(ms, tilt=tilt)))

# %% [markdown]
# ## <a id="surface-parallel-cuts"></a>Cuts parallel to the free surface

# %%
tol = float(ms.attrs["vertical_tol_deg"])
display(claim("s5-surface-parallel-vertical"))
display(Markdown(bpage.cuts_text(ms)))

# %% [markdown]
# ## <a id="exact-ranges"></a>Forced by the geometry? Exact ranges over $A \cap C$
#
# The history forces are one point of the set $A \cap C$ of force states that balance every
# grain within the Coulomb cones. Does every such state give a near-vertical force across the
# surface-parallel cuts, or only the history state?

# %%
display(Markdown(bpage.exact_text(exact, tol, ms)))

# %% [markdown]
# ## <a id="stress"></a>The granular stress tensor

# %%
display(Markdown(bpage.stress_text(ms, exact)))

# %% [markdown]
# ## <a id="reciprocity"></a>The reciprocity formula

# %%
display(claim("s5-reciprocity"))
display(Markdown(bpage.reciprocity_text(ms)))

# %% [markdown]
# ## <a id="incipient-failure"></a>Incipient failure: the tilting test and the stress state
#
# A bank "in a state of incipient failure" stands at the friction angle of its grains: tilted
# by a little more than nothing, it fails. Panels (h, i) tilt the piles (the default pile and
# the first point-source piles, each flank in turn).

# %%
display(claim("s5-incipient-failure"))
display(Markdown(bpage.tilt_text(tilt, ms)))
display(Markdown(bpage.failure_text(ms, tilt)))

# %% [markdown]
# ## <a id="three-d"></a>What the 2-D measurement can and cannot say about Moreau's 3-D piles

# %%
display(Markdown(bpage.three_d_text(ms)))
