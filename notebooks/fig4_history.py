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
# # Figure 4, history as statistics: piles from a point source and from a rain
#
# **What the paper says (section 5).** Measurements on sand piles poured from a
# localized source show a ground-pressure minimum under the apex; the messages from
# history (the construction) shape the forces. The literature ties the dip to the
# construction history: Vanel et al., *Memory in sandpiles*, PRE 60, R5040 (1999),
# find a dip under piles poured from a localized source and a maximum under piles
# built by raining sand through a sieve over the base; Geng, Longhi, Behringer and
# Howell, PRE 64, 060301 (2001), find the same contrast in 2-D piles of photoelastic
# discs (a small dip for a point source, a hump for a rain).
#
# **What we compute.** For each member $m$ of the ensemble, two piles of the *same*
# grains (same radii, inserted in the same order) on the *same* rough ground:
#
# 1. *point source*: Figure 4's construction (insertion sites above $x = 0$, a drop
#    height that rises with the pile), with up to three grains stacked per site at
#    each attempt (same speed);
# 2. *rain*: the grains dropped at positions uniform over $|x| \le L$, $L$ the base
#    half-width of the member's point-source pile, from a height that rises with the
#    deposit, onto a **finite base**: the member's ground discs with $|x| \le L$, as in
#    the experiments (sand rained through a sieve onto a base of finite size). Grains
#    that roll off the base edges are removed from the simulation once they have
#    fallen below the base, and counted.
#
# Every pile is stepped until the warm equilibrium test of section 2 passes; its
# forces are the history forces. Per pile: the ground stress profile (Gaussian kernel
# average of the ground-contact forces against $x / L$, $L$ the base half-width of the
# member's point-source pile from its flank fits, in units of the mean stress $W / 2L$), the dip depth
# $M - m$ in the same unit (the neighbouring maxima $M$ minus the central minimum $m$:
# $> 0$ a dip, $< 0$ a hump; the dip depth of `fig4_pile` has the same unit and sign), and the resultant across vertical cuts along both flanks with its angle to
# the pile's own free surface. Bands are bootstrap resamples of the **piles**.

# %%
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures import history_plots as hp
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
                          rain=f"results/fig4_history/piles/n{n}/rain_000.nc")
    out = SimpleNamespace(png="results/figures/fig4_history.png", pdf="results/figures/fig4_history.pdf",
                          finding="results/figures/fig4_history.finding.rst")
an = xr.load_dataset(inp.analysis)
piles = [xr.load_dataset(inp.point), xr.load_dataset(inp.rain)]
s = hp.summary(an)

# %%
save(hp.figure(an, piles), out, dpi=130, show=True)
write_finding(out, hp.finding(an))

# %% [markdown]
# **(a)** Member 0 of each history (the same grains). **(b)** Mean ground stress over
# the piles with its 95 % bootstrap band over piles. **(c)** Dip depth of every pile
# (dots) and of the mean profile with its basic bootstrap band (bars), for three kernel
# widths; $p$ is the permutation test of the difference between the histories.
# **(d)** Angle of the cut resultant minus the flank slope, median over piles (bars:
# bootstrap band of the median; shade: 25–75 % of the piles; thin lines: the exact
# range over $A \cap C$ of single piles).

# %%
P, R = s["point"], s["rain"]
k = s["kernel"]
display(Markdown(f"""
**Shapes.** The point-source piles have a base half-width $L$ of {P['L']:.1f} mean diameters,
an apex {P['apex']:.1f} d above the ground and flanks at {P['slope']:.1f}° on average
(apex / ($L$ tan flank) = {P['cone']:.2f}: 1 for a cone). The rain falls over $|x| \\le L$ onto
the finite base $|x| \\le L$; {R['removed']:.1f} of the {P['grains']:.0f} poured grains roll off
its edges on average, so the rained piles hold {R['grains_min']} to {R['grains_max']} grains
(the point-source piles {P['grains_min']} to {P['grains_max']}; the stresses are normalised by
each pile's own weight). The rained deposits are {R['apex']:.1f} d high with fitted flanks of
{R['slope']:.1f}° (apex / ($L$ tan flank) = {R['cone']:.2f}):
{'a flat layer over the base with steep edges, not a heap with flanks at the angle of repose' if R['slope'] < 0.5 * P['slope'] else 'heaps'}.
The grains are rained gently (perfectly inelastic impacts, drop height
{cfg['source']['drop_height_d']:g} d); the experiments' rain falls from higher, with bouncing
grains. Much faster impacts need a smaller time step here (the grains then overlap by more
than the overlap tolerance within one step); why the gentle rain builds a layer rather than
a heap was not studied.
Both histories are drawn against $x / L$ with the $L$ of the member's point-source pile.

**Ground stress ({s['piles']} piles per history, kernel {k:g} d).** Dip depth $M - m$ of the
mean profile, in units of the mean stress $W / 2L$ (> 0 a dip): point source {P['dip']:.3f} (95 % basic bootstrap band over piles {P['lo']:.3f} to {P['hi']:.3f}),
rain {R['dip']:.3f} ({R['lo']:.3f} to {R['hi']:.3f}); {100 * P['frac_dip']:.0f} % of the
point-source piles and {100 * R['frac_dip']:.0f} % of the rained piles have a dip of
their own. The difference point − rain is {s['diff']:.3f} (band {s['diff_lo']:.3f} to
{s['diff_hi']:.3f}; permutation p = {s['p'][k]:.3g}). With the other kernel widths the
dips of the mean profiles are
{', '.join(f"{kk:g} d: {P['dips_by_kernel'][kk]:.3f} / {R['dips_by_kernel'][kk]:.3f}" for kk in P['dips_by_kernel'])}
(point / rain), p = {', '.join(f"{s['p'][kk]:.3g}" for kk in s['p'])}.
A single pile's dip is a minimum of a noisy curve against maxima of the same curve, so it
is biased upwards when the kernel is narrow: the fraction of piles with a dip of their own is
{', '.join(f"{kk:g} d: {100 * P['frac_by_kernel'][kk]:.0f} % / {100 * R['frac_by_kernel'][kk]:.0f} %" for kk in P['frac_by_kernel'])}
(point / rain); only the mean profile over piles, with its band, carries a claim.
{hp.outside_text(an)}
Under the apex the mean stress is {P['center']:.2f} (point) and {R['center']:.2f} (rain)
times the mean stress W / 2L.

**Against the experiments.** Vanel et al. (1999) and Geng et al. (2001) report a dip
under point-source piles and a central maximum under rained piles. Here the
point-source dip is {'resolved (its band excludes 0)' if P['lo'] > 0 else 'not resolved (its band includes 0 or is negative)'},
and the rained deposit has {'a hump (negative dip, band below 0)' if R['hi'] < 0 else ('a resolved dip (band above 0), the opposite of the central maximum of the experiments' if R['lo'] > 0 else 'neither a resolved hump nor a resolved dip (band includes 0)')}.

**Arching.** Over all cuts and piles the resultant is on median {P['dev_median']:.1f}° (point)
and {R['dev_median']:.1f}° (rain) steeper than the flank (interquartile range
{P['dev_iqr']:.1f}° and {R['dev_iqr']:.1f}°); it is steeper than the free surface at
{100 * P['arching']:.0f} % and {100 * R['arching']:.0f} % of the cuts that cross a contact
({P['empty_cuts']} of {P['cuts']} point-source cuts and {R['empty_cuts']} of {R['cuts']} rain cuts,
near the toes, cross none and have no resultant direction). (Arching here means a
resultant steeper than the flank; the exact test of `fig4_pile` uses a weaker one, a
resultant that pushes the bank downward, $F_y < 0$.)
"""))

# %% [markdown]
# **Exact ranges (sections 4-5).** The history forces are one point of the set
# $A \cap C$ of force states that balance every grain within the Coulomb cones. For
# the first piles of each history the exact range of the cut resultant's angle over
# that set is computed by linear programs (HiGHS; thin vertical lines in the arching
# panel).

# %%
def exact_text(h):
    x = s[h]
    if "exact_piles" not in x:
        return f"{hp.LABELS[h]}: no exact ranges computed."
    return (f"{hp.LABELS[h]}, {x['exact_piles']} piles: the admissible angle at a cut spans "
            f"{x['exact_width_median']:.1f}° on median (at most {x['exact_width_max']:.1f}°); every admissible "
            f"state is steeper than the flank at {100 * x['exact_all_positive']:.0f} % of the cuts and every one "
            f"shallower at {100 * x['exact_all_negative']:.0f} %; at {100 * x['exact_undefined']:.0f} % the "
            f"admissible resultants surround zero (no angle range); the ranges are exact (a linear-fractional "
            f"program per end, each certified to 1e-6° at {100 * x['exact_confirmed']:.0f} % of the cuts).")


display(Markdown(" ".join(exact_text(h) for h in an.history.values)
                 + " The arching angle of one force state is thus one choice among many: the spread of the "
                   "history angles over piles is to be read against these ranges."))
