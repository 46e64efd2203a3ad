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
# # Figure 3 — indetermination clouds of 28 discs at rest (Moreau 2005, section 4)
#
# **What the paper says.** A collection of $N = 28$ frictional discs is in
# equilibrium under gravity. With $\kappa$ contacts, the contact forces form a
# vector $\rho \in \mathbf{R}^{2\kappa}$; the $3N$ equilibrium equations restrict
# it to an affine subspace $A$ of dimension $2\kappa - 3N$, Coulomb's law to the
# product $C$ of the friction sectors $C_\alpha$, so the set of equilibrium
# forces is the convex polyhedron $A \cap C$ and the possible values of one
# contact force form the projection of $A \cap C$ on that contact's plane.
# Repeated NLGS runs of one step from $u_i = 0$, each with a random review
# order, draw a dot per solution; the clouds "provide outlines of the
# projections", and show "ghost images of edges and vertices" of the
# high-dimensional polyhedron: the points are "a little denser in the vicinity
# of the boundary of $A \cap C$". Section 2 names the other exploration
# (random initial guesses from a plausible range) and notes that warm-started
# runs (the antecedent step's impulses as guess) show very little indeterminacy.
#
# **What we compute.** A packing of 28 polydisperse discs deposited in a box
# (floor and two walls, all frictional with $\mu = 0.5$; the wall contacts are
# contacts of $A \cap C$ like the others) until the warm equilibrium test of
# section 2 gives $u_f = 0$; on its contacts, three ensembles of NLGS runs
# converged to a natural-map residual $\le 10^{-8}$ (relative): zero guess with
# random review orders (the paper's figure), random guesses with a fixed order,
# warm guess with random orders. Unlike the paper we also compute $A \cap C$
# exactly: its dimension, its boundedness and the exact projection on every
# contact's force plane by linear programming (HiGHS), and a sample drawn
# *uniformly* from $A \cap C$ (hit-and-run), the neutral reference against which
# the density of the NLGS clouds is judged.

# %%
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from IPython.display import Markdown
from matplotlib.patches import Circle

from ncd.exact.polygon import outside_distance
from ncd.figures import equilibrium as fe
from ncd.figures import faces
from ncd.pages.notebook import paths, save

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
_smk = paths("fig3_equilibrium", ["state", "ensemble", "projection", "uniform"], globals().get("snakemake"))
inp, out, cfg = _smk.input, _smk.output, _smk.params.config

state = xr.load_dataset(inp.state)
ens = xr.load_dataset(inp.ensemble)
proj = xr.load_dataset(inp.projection)
uni = xr.load_dataset(inp.uniform)
P = fe.polytope_of(state)
shown = [int(k) for k in np.atleast_1d(proj.attrs["displayed_order"])]
h = state.attrs["h"]

# %% [markdown]
# ## The packing and the polyhedron $A \cap C$

# %%
kappa, N = state.sizes["contact"], state.sizes["disc"]
print(f"N = {N} discs, kappa = {kappa} contacts ({state.attrs['n_wall_contacts']} with walls), "
      f"deposited in {state.attrs['deposit_steps']} steps of h = {h:g} s; "
      f"warm equilibrium test |u_f| = {state.attrs['rest_max_velocity']:.1e} |g| h, "
      f"largest interpenetration {state.attrs['max_penetration'] / state.radius.min().item():.1e} r_min")
print(f"2 kappa - 3N = {proj.attrs['dimension_moreau']}, dim A = 2 kappa - rank H = {proj.attrs['dimension_A']}, "
      f"dim A ∩ C = {proj.attrs['dimension_AC']}, bounded: {bool(proj.attrs['bounded'])}")
print(f"contacts whose force is zero at every equilibrium: {int(proj.implicit_zero.sum())}; "
      f"always sliding: {int(proj.implicit_sliding.sum())}")
nv = proj.n_vertices.values
print(f"projections: {int((nv == 1).sum())} points (determinate forces), {int((nv == 2).sum())} segments, "
      f"{int((nv >= 3).sum())} polygons (up to {nv.max()} vertices); all exact (inner = outer): "
      f"{bool(proj.exact.all())}; {proj.attrs['n_lp_total']} LPs; largest outer - inner area "
      f"{np.nanmax((proj.outer_area - proj.area).values) / np.nanmax(proj.area.values):.1e} of the largest area")
print("displayed contacts:", ", ".join(f"{k} (discs {int(state.body_a[k])}-{int(state.body_b[k])}, "
                                      f"area {float(proj.area[k]):.3g} N^2)" for k in shown))

# %% [markdown]
# When $\operatorname{rank} H < 3N$ (a disc whose equations are dependent, e.g.
# one resting on a single contact) the dimension of $A$ exceeds Moreau's count
# $2\kappa - 3N$; we report both. $A \cap C$ is bounded because the LP
# "maximize $\sum r_n$ over self-stresses in $C$" has optimum 0: with gravity and
# a floor, no nonzero set of contact forces in the Coulomb sectors balances itself.
#
# ## Convergence of the NLGS runs

# %%
modes = fe.MODES
subsets = {m: fe.mode_subset(ens, m) for m in modes}
for m, ds in subsets.items():
    sw, wt = ds.sweeps.values, ds.wall_time.values
    print(f"{m:>6}: {ds.sizes['run']} runs, {int(ds.converged.sum())} converged "
          f"(residual <= {ens.attrs['solver_tol']:g}), sweeps median {np.median(sw):.0f} "
          f"[{sw.min()}, {sw.max()}], wall time median {1e3 * np.median(wt):.2f} ms, "
          f"total {wt.sum():.1f} s; max |u_f| = {ds.max_velocity.max().item():.1e} |g| h")

# %% [markdown]
# Every converged run is a solution of the one-step problem with $u_f \approx 0$,
# hence an element of $A \cap C$: the checks below measure how far the points are
# from equilibrium, from the Coulomb sectors and from the exact polygons.

# %%
conv = ens.isel(run=np.nonzero(ens.converged.values == 1)[0])
rho = np.stack([conv.force_n.values, conv.force_t.values], -1).reshape(conv.sizes["run"], -1)
eq_res, coulomb = P.violations(rho) if len(rho) else (np.full(1, np.nan), np.full(1, np.nan))
outside = max((outside_distance(np.column_stack([conv.force_n.values[:, k], conv.force_t.values[:, k]]),
                                fe.polygon(proj, k)).max() for k in range(kappa)), default=np.nan) \
    if conv.sizes["run"] else np.nan
print(f"converged runs: max equilibrium residual {eq_res.max():.1e}, max Coulomb violation {coulomb.max():.1e} "
      f"(relative to the largest weight {P.scale:.3g} N); farthest point outside its exact polygon "
      f"{outside / P.scale:.1e} weights")

# %% [markdown]
# Residual against wall time: one run per mode replayed sweep by sweep budget
# (left), and the wall time of every run (right).

# %%
fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
colors = {"zero": "C0", "random": "C1", "warm": "C2", "uniform": "C7"}
for m in modes:
    run = int(subsets[m].run[0])
    budget = np.unique(np.geomspace(1, max(2, 1.2 * subsets[m].sweeps.max().item()), 14).astype(int))
    hist = fe.convergence_history(state, cfg, m, run, budget)
    ax[0].loglog(np.maximum(hist[:, 2], 1e-6), np.maximum(hist[:, 1], 1e-17), "o-", ms=3, color=colors[m],
                 label=f"{m} (run {run})")
    ax[1].scatter(subsets[m].sweeps, 1e3 * subsets[m].wall_time, s=3, color=colors[m], label=m)
ax[0].axhline(ens.attrs["solver_tol"], color="k", lw=0.8, ls=":")
ax[0].set(xlabel="wall time (s)", ylabel="natural-map residual (relative)", title="convergence")
ax[1].set(xlabel="sweeps", ylabel="wall time (ms)", xscale="log", yscale="log", title="every run")
ax[0].legend(fontsize=8)
ax[1].legend(fontsize=8, markerscale=4)
fig.tight_layout()
plt.show()

# %% [markdown]
# ## Coverage, spread and density of the clouds
#
# For each displayed contact and each mode: *coverage* = area of the convex hull
# of the cloud / area of the exact polygon; *spread* = RMS distance of the points
# to their mean (N); *near boundary* = fraction of points within $0.05\sqrt{\text{area}}$
# of the polygon's boundary, to compare with the uniform sample of $A \cap C$.

# %%
rows = fe.cloud_measures(ens, proj, uni, shown)
print(f"{'contact':>7} {'mode':>8} {'points':>7} {'coverage':>9} {'spread (N)':>11} {'near bdry':>9}")
for r in rows:
    print(f"{r['contact']:>7} {r['mode']:>8} {r['points']:>7} {r['coverage']:>9.3f} {r['spread']:>11.3e} "
          f"{r['near_boundary']:>9.3f}")

# %% [markdown]
# The 2-D projection hides where a point lies in $\mathbf{R}^{2\kappa}$. The
# dimension of the face of $A \cap C$ that carries each solution (from the
# Coulomb conditions it satisfies with equality: a contact without force, a
# sliding contact) tells directly whether NLGS lands on the boundary: a uniform
# point is interior (face dimension $= \dim A \cap C$) with probability one.

# %%
d_ac = int(proj.attrs["dimension_AC"])
fig, ax = plt.subplots(figsize=(6, 3.2))
width = 0.2
for i, (m, ds) in enumerate(list(subsets.items()) + [("uniform", uni)]):
    pts = np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)
    dims = faces.face_census(P, pts)[0]          # every run, not a sample
    frac = np.bincount(dims, minlength=d_ac + 1)[: d_ac + 1] / len(dims)
    ax.bar(np.arange(d_ac + 1) + (i - 1.5) * width, frac, width, color=colors[m], label=m)
    print(f"{m:>8}: face dimension distribution (0..{d_ac}):", np.round(frac, 3))
ax.set(xlabel="dimension of the face of A ∩ C holding the solution", ylabel="fraction of points")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()

# %% [markdown]
# ## The figure
#
# Left: the packing (line widths: normal forces at rest) with the displayed
# contacts circled. Right: each displayed contact's force plane in local
# coordinates (tangential $r_t$ across, normal $r_n$ up; the force on disc $a$
# is $r_n n + r_t t$), with the Coulomb sector $C_\alpha$ (grey), the exact
# projection of $A \cap C$ (shaded polygon) and one dot per solution. Insets
# magnify clouds too small to see at the polygon's scale.

# %%
fig = plt.figure(figsize=(15, 3.6 * len(shown) + 0.8), layout="constrained")
gs = fig.add_gridspec(len(shown), 5, width_ratios=[1.6, 1, 1, 1, 1])
axp = fig.add_subplot(gs[:, 0])
for i in range(N):
    axp.add_patch(Circle((state.x[i].item(), state.y[i].item()), state.radius[i].item(), fc="0.9", ec="0.4", lw=0.6))
fmax = np.abs(state.rest_force_n.values).max()
for k in range(kappa):
    a, b = int(state.body_a[k]), int(state.body_b[k])
    pa = np.array([state.x[a].item(), state.y[a].item()])
    pb = np.array([state.x[b].item(), state.y[b].item()]) if b >= 0 else np.array(
        [state.point_x[k].item(), state.point_y[k].item()])
    axp.plot(*np.c_[pa, pb], color="k", lw=0.3 + 2.5 * state.rest_force_n[k].item() / fmax)
width_box = state.attrs["width"]
top = float((state.y + state.radius).max()) * 1.05
axp.plot([0, 0, width_box, width_box], [top, 0, 0, top], color="k", lw=1.5)
for j, k in enumerate(shown):
    axp.plot(state.point_x[k], state.point_y[k], "o", ms=10, mfc="none", mec=f"C{3 + j}", mew=2.5)
    axp.annotate(f"α = {k}", (state.point_x[k].item(), state.point_y[k].item()), xytext=(7, 7),
                 textcoords="offset points", color=f"C{3 + j}", fontsize=11, weight="bold")
axp.set_aspect("equal")
axp.set_xlim(-0.03 * width_box, 1.03 * width_box)
axp.set_ylim(-0.03 * width_box, top)
axp.set_title(f"N = {N} discs, κ = {kappa} contacts\n2κ - 3N = {proj.attrs['dimension_moreau']}, "
              f"dim A = {proj.attrs['dimension_A']}, dim A ∩ C = {proj.attrs['dimension_AC']}", fontsize=10)
axp.axis("off")

groups = list(subsets.items()) + [("uniform", uni)]
titles = {"zero": "zero guess, random orders\n(the paper's figure)", "random": "random guesses, fixed order",
          "warm": "warm start, random orders", "uniform": "uniform in A ∩ C (hit-and-run)"}
for j, k in enumerate(shown):
    poly = fe.polygon(proj, k)
    mu = state.mu[k].item()
    poly = 1e3 * poly                                     # mN
    rn_max = poly[:, 0].max() * 1.08
    sector = np.array([[-mu * rn_max * 2, rn_max * 2], [0, 0], [mu * rn_max * 2, rn_max * 2]])
    for i, (m, ds) in enumerate(groups):
        ax = fig.add_subplot(gs[j, i + 1])
        ax.fill(*sector.T, color="0.92", zorder=0)
        ax.plot(*sector.T, color="0.5", lw=0.8)
        ax.fill(poly[:, 1], poly[:, 0], fc=f"C{3 + j}", alpha=0.18, ec=f"C{3 + j}", lw=1.2)
        if m != "uniform":
            ds = ds.isel(run=np.nonzero(ds.converged.values == 1)[0])
        ft, fn = 1e3 * ds.force_t.values[:, k], 1e3 * ds.force_n.values[:, k]
        style = dict(ms=1.2 if m == "warm" else 0.7, alpha=min(0.8, 1000 / max(len(ft), 1)), color="k")
        ax.plot(ft, fn, "o", mew=0, **style)
        r = next(r for r in rows if r["contact"] == k and r["mode"] == m)
        ax.text(0.03, 0.97, f"coverage {r['coverage']:.3f}\nspread {r['spread']:.1e} N", transform=ax.transAxes,
                fontsize=7.5, va="top")
        pad = 0.06 * rn_max
        ax.set_xlim(min(poly[:, 1].min(), 0) - pad, max(poly[:, 1].max(), 0) + pad)
        ax.set_ylim(-0.04 * rn_max, rn_max)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
        ax.xaxis.set_major_locator(plt.MaxNLocator(3))
        box = np.ptp(np.c_[ft, fn], axis=0).max() if len(ft) else 0.0
        if m == "zero" and 0 < box < 0.15 * rn_max:      # a small cloud: magnify it
            ins = ax.inset_axes([0.52, 0.04, 0.45, 0.4])
            ins.fill(poly[:, 1], poly[:, 0], fc=f"C{3 + j}", alpha=0.18, ec=f"C{3 + j}", lw=1.0)
            ins.plot(ft, fn, "o", mew=0, **style)
            c = np.array([ft.mean(), fn.mean()])
            ins.set_xlim(c[0] - 0.6 * box, c[0] + 0.6 * box)
            ins.set_ylim(c[1] - 0.6 * box, c[1] + 0.6 * box)
            ins.set_xticks([])
            ins.set_yticks([])
            ins.set_title(f"×{rn_max / box:.0f}", fontsize=7, pad=1)
            ax.indicate_inset_zoom(ins, edgecolor="0.3")
        if j == 0:
            ax.set_title(f"{titles[m]}\n{r['points']} points", fontsize=9)
        if i == 0:
            ax.set_ylabel(f"α = {k} (discs {int(state.body_a[k])}-{int(state.body_b[k])}):  r_n (mN)", fontsize=8.5)
        if j == len(shown) - 1:
            ax.set_xlabel("r_t (mN)", fontsize=8.5)
fig.suptitle("Moreau (2005) Fig. 3: indetermination clouds of two contact forces, with the exact projection "
             "of A ∩ C (shaded) inside the Coulomb sector (grey)", fontsize=11)
save(fig, out, dpi=150)
plt.show()

# %% [markdown]
# ## What we measured, and where the reproduction differs
#
# The text below is written from this run's data when the notebook runs; its claims
# are checked by `tests/test_fig3_equilibrium.py`.

# %%
pa = proj.attrs
n_conv = {m: int(ds.converged.sum()) for m, ds in subsets.items()}
cov = {m: [r["coverage"] for r in rows if r["mode"] == m] for m in modes}
extra = int(pa["dimension_A"]) - int(pa["dimension_moreau"])
why = (f"but rank $H$ = {3 * N - extra} < $3N$ (a disc whose equations are dependent, e.g. one resting on the "
       "floor only, whose horizontal-force and moment equations both say $r_t = 0$); hence " if extra > 0 else "and ")
tight = int(pa["dimension_AC"]) < int(pa["dimension_A"])
Markdown(f"""
* **$A \\cap C$ exactly.** The deposited packing has $\\kappa$ = {kappa} contacts ({state.attrs['n_wall_contacts']}
  with walls) for $N$ = {N} discs: $2\\kappa - 3N$ = {pa['dimension_moreau']}, {why}$\\dim A = 2\\kappa -
  \\operatorname{{rank}} H$ = {pa['dimension_A']}, and $\\dim A \\cap C$ = {pa['dimension_AC']}
  ({'some Coulomb condition is tight at every equilibrium' if tight else 'no Coulomb condition is tight at every equilibrium'}).
  It is {'bounded' if pa['bounded'] else 'unbounded'}. Its {kappa} projections are {int((nv == 1).sum())} point(s)
  (forces fixed by statics), {int((nv == 2).sum())} segment(s) and {int((nv >= 3).sum())} polygon(s);
  {'every one is exact' if bool(proj.exact.all()) else f'{int((~proj.exact.values.astype(bool)).sum())} are not exact'}
  (inner hull of the support points and outer intersection of the supporting half-planes agree to
  {np.nanmax((proj.outer_area - proj.area).values) / np.nanmax(proj.area.values):.0e} of the largest area).
* **Every converged run lies in $A \\cap C$.** Converged runs (natural-map residual
  $\\le$ {ens.attrs['solver_tol']:g}): {', '.join(f'{m} {n_conv[m]}/{subsets[m].sizes["run"]}' for m in modes)};
  median sweeps {', '.join(f'{m} {np.median(subsets[m].sweeps.values):.0f}' for m in modes)}. The converged points
  satisfy equilibrium to {np.max(eq_res):.0e} and Coulomb's law to {np.max(coulomb):.0e} of the largest weight,
  and lie within {outside / P.scale:.0e} weights of their exact polygons, so every point of the clouds is an
  admissible force state: their spread is indeterminacy of the equilibrium forces, not unfinished iterations.
* **Zero guess with random orders (the paper's figure).** Its clouds cover
  {', '.join(f'{c:.1%}' for c in cov['zero'])} of the exact projections of the displayed contacts
  ({', '.join(str(k) for k in shown)}): the $(\\kappa - 1)!$ review orders reach limits close to each other.
  {'Moreau' + chr(39) + 's statement that this exploration generates "a significant outline of the solution set" '
   'does not hold for this packing; the exact polygons show how much it misses.' if max(cov['zero']) < 0.5 else
   'This outlines a large part of the solution set, as Moreau says.'}
* **Random initial guesses** (section 2's other exploration; normal impulses uniform in
  $[0, \\max s_n^{{\\text{{rest}}}}]$, tangential ones uniform in the sector, fixed review order) cover
  {', '.join(f'{c:.1%}' for c in cov['random'])} of the same polygons, at a median cost of
  {1e3 * np.median(subsets['random'].wall_time.values):.1f} ms per run
  (zero guess: {1e3 * np.median(subsets['zero'].wall_time.values):.1f} ms).
* **Warm start** (the impulses of the last deposition step): median {np.median(subsets['warm'].sweeps.values):.0f}
  sweeps, spread {', '.join(f'{r["spread"]:.0e}' for r in rows if r['mode'] == 'warm')} N on the displayed
  contacts: the "very little indeterminacy" of section 2.
""")

# %% [markdown]
# * **Ghost images.** Measured over every run (next cell): where the NLGS
#   solutions lie among the faces of $A \cap C$, which contacts carry no force
#   and which slide at the Coulomb limit. A uniform point is interior with
#   probability one. The lines inside the random-guess clouds are projections of
#   faces, as Moreau suggests. In the force plane the contrast is less simple
#   (the fraction of points near the polygon's boundary depends on the contact),
#   because a projection mixes faces and interior.
# * **Differences.** The paper gives neither its packing nor its friction
#   coefficient, time step or tolerance; ours are stated in `config.yaml`
#   ($\mu = 0.5$ as in section 3 for discs and walls). Its packing is not
#   ours, so $\kappa$, $\dim A$ and the shapes of the clouds differ. The two
#   displayed contacts are our choice: the largest exact polygons between two
#   mobile discs not sharing a disc. We draw each force in its contact's local
#   frame $(r_t, r_n)$; the paper draws "a dot at the extremity" of each force,
#   presumably as a vector in the plane of the packing.

# %%
# Ghost images, measured over every run of each mode (ncd.figures.faces)
face_modes = {m: np.stack([ds.force_n.values, ds.force_t.values], -1).reshape(len(ds.force_n), -1)
              for m, ds in subsets.items()}
Markdown(faces.face_text(faces.face_summary(P, face_modes)))
