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
# # Figure 4 — the messages from history: a pile poured from a localized source (Moreau 2005, section 5)
#
# **What the paper says.** A 2-D pile "is constructed by pouring grains from a
# localized source onto horizontal ground". Measurements on such piles show that
# the ground pressure "does not relate to the height of material above", with
# possibly a local minimum under the apex: part of the weight of the central
# portion is carried by *arching* through the surrounding bank. A vertical cut
# is drawn through the bank; the resultant of the contact forces "exerted by
# grains with centers on one side upon antagonists on the other side" is
# "approximately parallel to the free surface". Repeated NLGS runs from the
# zero guess with random review orders, applied to the equilibrium problem of
# the final arrangement, give a cloud of end points of that resultant. The
# warm-started construction itself shows "practically no indeterminacy"; the
# cloud reveals the indeterminacy "ensuing in the final step from the decision
# of ignoring antecedent forces". It is small: the geometry alone carries the
# arching. And "varying slightly the cut position may produce changes in
# transmitted force of definitely larger amplitude than the above
# indetermination" — only 10 contacts cross the paper's cut.
#
# %%
import xarray as xr
from IPython.display import Markdown, display

from ncd.figures.fig4_pile import plots as pp
from ncd.figures.fig4_pile.claims import JUDGES
from ncd.pages.claims import claim_markdown
from ncd.pages.notebook import paths, results_dir, save, write_finding

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig4_pile", ["construction", "cuts", "ensemble", "tolerance", "exact"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config
results = results_dir(_smk)
data = {n: xr.load_dataset(getattr(inp, n)) for n in ("construction", "cuts", "ensemble", "tolerance", "exact")}
r = pp.PileRun(data["construction"], data["cuts"], data["ensemble"], data["exact"], cfg)
save(pp.figure(r), out, dpi=130, show=True)
write_finding(out, pp.finding(r))

# %% [markdown]
# **(a)** The pile at rest with the history forces (line width: normal force), the
# default cut (red), the cuts moved by one diameter (dotted), the history resultant
# across the default cut (arrow) and the end points of the zero-guess runs at rest
# (blue dots, same scale). **(b)** The resultants of the three cuts in force space: the
# history (stars), the runs at rest (dots) and the exact projection of $A \cap C$
# (shaded). **(c)** The angle of the resultant minus the free surface's slope across
# every cut position. **(d)** The ground pressure: binned history forces, the range of
# the runs, the weight of the column above, and a kernel average with its exact range
# over $A \cap C$ (beyond the paper).
#
# ## What we compute
#
# 1. *Construction* (`construction.nc`): polydisperse discs (radii uniform in
#    $[0.8, 1.2]$ mm) are poured from a row of insertion sites above $x = 0$
#    onto a rough ground (a row of touching fixed discs), with friction $\mu = 0.5$
#    everywhere and no restitution. Every step is a Moreau–Jean step with
#    warm-started NLGS; a batch of grains is inserted at the free sites every few
#    steps. The source stays a fixed drop height above the settled grains under
#    it (a funnel raised with the pile) so that impacts stay gentle. After the
#    last grain, stepping goes on until the equilibrium test of section 2
#    (one step from $u_i = 0$, warm guess) gives $u_f = 0$ within $10^{-6}\,g h$.
#    Its forces $r = s/h$ are the *history* forces.
# 2. *Free surface* (`cuts.nc`): the highest disc top per one-diameter bin, and
#    a straight line fitted to each flank between $20\,\%$ and $80\,\%$ of the apex
#    height: the angle of repose.
# 3. *Cut resultant*: for a vertical cut at $x_c$, the sum of the forces exerted
#    by the grains with centres on the axis side upon the grains with centres on
#    the bank side, over the grain–grain contacts whose line of centres crosses
#    the cut between the ground and the free surface (ground contacts never
#    cross). The default cut is halfway between axis and toe of the right flank;
#    the same for the cuts moved by $\pm$ one mean diameter and for a scan of
#    cuts every diameter across both flanks.
# 4. *Indeterminacy* (`ensemble.nc`): NLGS runs from the zero guess with random
#    review orders on the one-step problem from rest at the final state (the
#    problem of the equilibrium test), each recording sweeps, natural-map
#    residual, converged flag and wall time; per run we keep the resultants of
#    every cut, the ground force and pressure, and the end-of-step velocities'
#    summary (a run whose grains do not all stay at rest is not an equilibrium).
#    With `ensemble.finish: active_set` (the default) NLGS hands each run over
#    at the ensemble's tolerance to the finishing stage (`ncd.solver.finish`): the
#    iterate is projected (L1, an LP) on the one-step solutions sharing its
#    contact statuses, or else on the states at rest, and the projection is
#    kept only if it is an exact solution close to the iterate (relative L1
#    move at most `ncd.solver.finish.MAX_CORRECTION`). A run then
#    ends on an exact solution, at rest or with grains moving, and is
#    classified; only rest runs enter the clouds.
#    *Tolerance study* (`tolerance.nc`): the first members again (same review
#    orders), plain NLGS without finishing, at tolerances from $10^{-3}$ to
#    $10^{-6}$ (one sentence below).
#    *Warm guess* (`warm.nc`): the same problem explored from the antecedent
#    contact forces, the impulses of the construction's last step (the guess of
#    its equilibrium test; `construction.nc` keeps that test's solution, so the
#    rule replays the construction, checked bit for bit), with other random
#    review orders and the same solver settings.
# 5. *Beyond the paper*: the ground pressure profile (vertical ground force per
#    unit length) under the pile, history and ensemble band, against the weight
#    of the column of grains above each bin.

# %% [markdown]
# ## The construction

# %%
display(Markdown(pp.construction_text(r)))

# %% [markdown]
# ## Arching: the resultant across vertical cuts

# %%
display(Markdown(pp.arching_text(r)))

# %%
display(Markdown(claim_markdown("s5-parallel-to-surface", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-ten-contacts", results, JUDGES)))

# %% [markdown]
# ## The indetermination cloud of the default cut

# %%
display(Markdown(pp.cloud_text(r) + "\n\n" + pp.tolerance_text(r, data["tolerance"])))

# %%
display(Markdown(claim_markdown("s5-cloud", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-warm-construction", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-cloud-from-ignoring-antecedent", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-cut-position", results, JUDGES)))

# %% [markdown]
# ## The exact set of the final state
#
# The equilibrium forces of the final arrangement form the polytope
# $A \cap C$; every quantity above is a linear map of them, so its exact range
# is given by linear programs (HiGHS, `exact.nc`): the projection of
# $A \cap C$ on the plane of a cut resultant for the default and shifted cuts
# (a polygon, from support directions refined edge by edge; panel b); the range
# of the resultant's angle across every cut, a linear-fractional program
# $\min / \max\ q(r)/p(r)$ over $A \cap C$ solved by Dinkelbach's iteration;
# and the range of the ground pressure (panel d).

# %%
display(Markdown(pp.exact_text(data["exact"], data["ensemble"], data["cuts"])))

# %%
display(Markdown(claim_markdown("s5-geometry-enough", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s6-reassuring", results, JUDGES)))

# %% [markdown]
# ## Ground pressure
#
# The paper quotes measurements in which the ground pressure "does not relate to the
# height of material above", possibly with a minimum under the apex. The dip depth is
# the pressure beside the apex minus the pressure under it, in units of the mean
# ground stress $W / 2L$ ($2L$: toe to toe), $> 0$ a dip: the name, unit and sign of
# the dip depth on the `fig4_history` page, which repeats piles.

# %%
display(Markdown(pp.pressure_text(r) + "\n\n" + pp.dip_sentence(data["exact"])))

# %%
display(Markdown(claim_markdown("s5-pressure-not-height", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-arching-supports-weight", results, JUDGES)))

# %%
display(Markdown(claim_markdown("s5-dip", results, JUDGES)))

# %% [markdown]
# ## Where the reproduction differs
#
# The paper gives neither its number of grains, nor its time step, tolerance or
# source; ours are in `config.yaml`. Its cut crossed 10 contacts; ours are chosen
# halfway between the axis and the toe of the right flank. The source is raised with
# the pile so that impacts stay gentle. One pile is one sample: `fig4_history`
# repeats piles of two construction histories.
