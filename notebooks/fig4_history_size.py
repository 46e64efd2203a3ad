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
# # Beyond the paper (section 5): history against size — piles of 10³ and 10⁴ grains
#
# **What the paper says (section 5).** Moreau's pile has about a thousand grains; the
# experiments it is set against (Vanel et al. 1999; Geng et al. 2001) hold many more.
# Whether a ground-pressure dip under the apex, or the arching of the forces across
# vertical cuts, depends on the size of the pile is a question a single pile cannot
# answer.
#
# **What we compute.** The ensembles of the history figure (point source and rain, the
# same grains per member) at each size: the default piles, and the piles of every
# config overlay listed in `fig4_history.size.overlays` (`config/large.yaml`: 10⁴ grains,
# the pouring scaled with the base width). Every pile is at rest (warm equilibrium
# test). Per size and history: the dip depth of the mean ground-stress profile with its
# bootstrap band over piles; per pile, the median over both flanks and all cut positions
# of the angle between the cut resultant and the pile's own flank slope (its mean over
# piles, with a bootstrap band); and a permutation test of the change from the smallest
# size, size labels shuffled among the piles. Abscissae are $x / L$ ($L$ the base
# half-width), so the sizes compare directly.

# %%
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig4_history import size_plots as hs
from ncd.pages.notebook import save, write_finding

try:
    snakemake  # noqa: F821 (injected by Snakemake's notebook directive)
    inp, out = snakemake.input, snakemake.output  # noqa: F821
except NameError:  # by hand, from the repository root after `snakemake -j2 fig4_history_size`
    from types import SimpleNamespace
    inp = SimpleNamespace(sizes="results/fig4_history/size.nc")
    out = SimpleNamespace(png="results/figures/fig4_history_size.png", pdf="results/figures/fig4_history_size.pdf",
                          finding="results/figures/fig4_history_size.finding.rst")
sz = xr.load_dataset(inp.sizes)
s = hs.summary(sz)

# %%
save(hs.figure(sz), out, dpi=130, show=True)
write_finding(out, hs.finding(sz))

# %% [markdown]
# **(a)** Dip depth $M - m$ of the mean ground-stress profile, in units of the mean
# stress $W / 2L$ (> 0 a dip; bars: 95 % bootstrap band over piles) against the grains
# per pile. **(b)** Arching: per pile, the median deviation of
# the cut resultant from the flank slope, averaged over piles (bars: bootstrap band).
# **(c)** Flank slope. **(d)** Median deviation over piles against the cut position, per
# size (dashed: the smaller).

# %%
g, piles = s["grains"], s["piles"]
rows = []
for h in sz.history.values:
    r = s[h]
    rows.append(f"| {h} | " + " | ".join(
        f"{r['dip_mean'][i]:.3f} [{r['dip_lo'][i]:.3f}, {r['dip_hi'][i]:.3f}]" for i in range(len(g))) + " | "
        + " | ".join(f"{r['arching_mean'][i]:.1f}° [{r['arching_lo'][i]:.1f}, {r['arching_hi'][i]:.1f}]"
                     for i in range(len(g))) + " | "
        + " | ".join(f"{r['surface_angle'][i]:.1f}°" for i in range(len(g))) + " |")
head = ("| history | " + " | ".join(f"dip, {n} grains" for n in g) + " | "
        + " | ".join(f"arching, {n} grains" for n in g) + " | " + " | ".join(f"flank, {n} grains" for n in g) + " |")
display(Markdown(f"""
**What we measured.** {piles[0]} piles per history of {g[0]} grains and {piles[-1]} of {g[-1]}
(dip depth $M - m$ of the mean profile in units of $W / 2L$, > 0 a dip, kernel {s['kernel']:g} d; brackets: 95 % bootstrap bands over piles):

{head}
|{'---|' * (1 + 3 * len(g))}
""" + "\n".join(rows)))

# %%
P, R = s["point"], s["rain"]


def verdict(p):
    return "a change" if p < 0.05 else "no significant change"


display(Markdown(f"""
**Dip against size.** From {g[0]} to {g[-1]} grains the dip of the mean profile changes by
{P['dip_change']:+.3f} for the point-source piles (permutation $p$ = {P['dip_p']:.2f}: {verdict(P['dip_p'])};
over the three kernels $p$ = {', '.join(f'{v:.2f}' for v in P['dip_p_kernels'].values())}) and by
{R['dip_change']:+.3f} for the rain ($p$ = {R['dip_p']:.2f}: {verdict(R['dip_p'])}).

**Arching against size.** The median deviation of the cut resultant from the flank slope
changes by {P['arching_change']:+.1f}° for the point source ($p$ = {P['arching_p']:.2f}: {verdict(P['arching_p'])})
and by {R['arching_change']:+.1f}° for the rain ($p$ = {R['arching_p']:.2f}: {verdict(R['arching_p'])}).

**Shape.** The point-source piles' flanks are {P['surface_angle'][0]:.1f}° and {P['surface_angle'][-1]:.1f}°
at the two sizes, their apex heights {P['apex_height'][0]:.0f} d and {P['apex_height'][-1]:.0f} d over base
half-widths of {P['half_width'][0]:.0f} d and {P['half_width'][-1]:.0f} d (cone ratios
{P['cone_ratio'][0]:.2f} and {P['cone_ratio'][-1]:.2f}). The rain deposits have flanks of
{R['surface_angle'][0]:.1f}° and {R['surface_angle'][-1]:.1f}° and cone ratios {R['cone_ratio'][0]:.2f} and
{R['cone_ratio'][-1]:.2f} (1: a cone; below: flat-topped).

**Shape match.** {hs.shape_text(sz)}

**Limits.** The large size has only {piles[-1]} piles per history: its bands are wide, and a change smaller than them is not resolved. A claim about
size rests on these bands, not on one pile.
"""))

# %% [markdown]
# **Exact ranges against size.** For the first piles of each history at each size
# (`exact.piles`), the range over A ∩ C of the angle of the resultant across every cut: two
# linear-fractional programs per cut, each end certified (the exact sets of the history page:
# a Dinkelbach LP after HiGHS's simplex; the piles of 10⁴ grains by Clarabel's interior point,
# each end bounded by its LP's dual). The history forces give one admissible angle, which must
# lie in the range.

# %%
display(Markdown(hs.exact_text(sz)))
