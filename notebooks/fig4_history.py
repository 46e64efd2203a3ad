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
# # Beyond the paper (section 5): history as statistics — a point source against a rain, at matched shape
#
# **What the paper says (section 5).** Measurements on sand piles poured from a
# localized source show a ground-pressure minimum under the apex; the messages from
# history (the construction) shape the forces. The literature ties the dip to the
# construction history: Vanel et al., *Memories in sand*, PRE 60, R5040 (1999),
# find a dip under heaps poured from a localized source and none under heaps of the
# same shape built by raining sand through a sieve; Geng, Longhi, Behringer and
# Howell, PRE 64, 060301 (2001), find the same contrast in 2-D heaps of photoelastic
# discs. To attribute a difference to history, the heaps compared must have the same
# shape: this page states the shape match first, then the differences at that shape.
#
# **What we compute.** For each member $m$ of the ensemble, three piles of the *same*
# grains (same radii, inserted in the same order) on the *same* rough ground:
#
# 1. *point source*: Figure 4's construction (insertion sites above $x = 0$, a drop
#    height that rises with the pile), with up to three grains stacked per site at
#    each attempt (same speed);
# 2. *rain*: grains dropped at positions uniform under a sieve that follows the
#    growing heap (it spans the footprint of the settled grains, a few outliers left
#    out, and never narrows), from a height that rises with the heap: the grains land
#    on the heap, which grows at its angle of repose as the point source's does;
# 3. *layer*: grains dropped uniformly over $|x| \le L$ ($L$ the base half-width of
#    the member's point-source pile) from the first grain on, onto a **finite base**
#    (the member's ground discs with $|x| \le L$); grains that roll off its edges are
#    removed and counted. It deposits a flat-topped layer, not a heap: the shape that
#    differs, kept as the known difference the comparison must detect.
#
# Every pile is stepped until the warm equilibrium test of section 2 passes; its
# forces are the history forces. Per pile: the shape (flank slope, apex height, base
# half-width), the ground stress profile (Gaussian kernel average of the ground-contact
# forces against $x / L$, $L$ the pile's own base half-width from its flank fits, the
# layer's that of its base, in units of the mean stress $W / 2L$), the dip depth
# $M - m$ in the same unit (the neighbouring maxima $M$ minus the central minimum $m$:
# $> 0$ a dip, $< 0$ a hump; the dip depth of `fig4_pile` has the same unit and sign),
# and the resultant across vertical cuts along both flanks with its angle to the pile's
# own free surface. Bands are bootstrap resamples of the **piles**; differences between
# histories are permutation tests of the history labels over piles, checked on two
# controls (two halves of one history must not differ; the layer must differ from the heap).

# %%
from pathlib import Path

import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig4_history import plots as hp
from ncd.figures.fig4_history.claims import JUDGES
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import save, write_finding

try:
    snakemake  # noqa: F821 (injected by Snakemake's notebook directive)
    inp, out, cfg = snakemake.input, snakemake.output, snakemake.params.config  # noqa: F821
except NameError:  # by hand, from the repository root after `snakemake -j2 fig4_history`
    from types import SimpleNamespace

    import yaml
    cfg = yaml.safe_load(open("config.yaml"))["fig4_history"]
    n = cfg["grains"]["n"]
    inp = SimpleNamespace(analysis=f"results/fig4_history/analysis_n{n}.nc",
                          point=f"results/fig4_history/piles/n{n}/point_000.nc",
                          rain=f"results/fig4_history/piles/n{n}/rain_000.nc",
                          layer=f"results/fig4_history/piles/n{n}/layer_000.nc")
    out = SimpleNamespace(png="results/figures/fig4_history.png", pdf="results/figures/fig4_history.pdf",
                          finding="results/figures/fig4_history.finding.rst")
an = xr.load_dataset(inp.analysis)
results = Path(inp.analysis).resolve().parents[1]
piles = [xr.load_dataset(inp.point), xr.load_dataset(inp.rain), xr.load_dataset(inp.layer)]

# %%
save(hp.figure(an, piles), out, dpi=130, show=True)
write_finding(out, hp.finding(an))

# %% [markdown]
# **(a)** Member 0 of each history (the same grains). **(b)** The shape match: relative
# difference of the mean piles from the point source's, with its bootstrap band over
# piles, against the tolerance (grey strip); the same for two halves of the point piles.
# **(c)** Mean ground stress over the piles with its 95 % bootstrap band over piles.
# **(d)** Dip depth of every pile (dots) and of the mean profile with its basic bootstrap
# band (bars), for three kernel widths; $p$ is the permutation test of the difference
# between point source and rain. **(e)** Angle of the cut resultant minus the flank
# slope, median over piles (bars: bootstrap band of the median; shade: 25–75 % of the
# piles; thin lines: the exact range over $A \cap C$ of single piles).

# %%
display(Markdown(hp.shapes_text(an, cfg)))

# %%
display(Markdown(hp.comparison_text(an)))

# %%
display(Markdown(hp.stress_text(an)))

# %%
display(Markdown(claim_markdown("s5-dip", results, JUDGES)))

# %%
display(Markdown(hp.experiments_text(an)))

# %%
display(Markdown(claim_markdown("history-dip-contrast", results, JUDGES)))

# %%
display(Markdown(hp.arching_text(an)))

# %%
display(Markdown(claim_markdown("s5-parallel-to-surface", results, JUDGES)))

# %% [markdown]
# **Exact ranges (sections 4-5).** The history forces are one point of the set
# $A \cap C$ of force states that balance every grain within the Coulomb cones. For
# the first piles of each history the exact range of the cut resultant's angle over
# that set is computed by linear programs (HiGHS; thin vertical lines in the arching
# panel).

# %%
display(Markdown(hp.exact_text(an)))
