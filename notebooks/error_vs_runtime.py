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
# **The claim (Moreau 2005, section 2).** Contact Dynamics (CD) is implicit and stable
# at large steps, "the price to pay is that the core of the calculation at each
# time-step consists of a highly nonlinear and nonsmooth problem", solved by nonlinear
# Gauss–Seidel (NLGS) "until some convergence criterium is met"; starting NLGS from
# the impulses of the antecedent step "considerably accelerates convergence" in dense
# collections.  MD integrates smooth soft-contact forces with small explicit steps.
#
# **What we computed.**
#
# 1. *NLGS at one step.*  On the core problem of the next step ($h = 10^{-3}$ s) of three
#    states built in `ncd.studies.work_precision` — a settled 28-disc packing in a box,
#    a small settled pile on a rough floor, and a step of a periodic slope flow at 24°
#    (their sizes are in the verdicts below) — every setting (initial guess zero or warm,
#    stopping criterion natural-map residual or impulse change, or NLGS with the finishing
#    stage of `ncd.solver.finish` (criterion `finish`: NLGS to $10^{-4}$, then, where NLGS's rate
#    is slow, the projection on the polyhedron of its contact statuses), or Anderson-accelerated
#    NLGS (criterion `anderson`, `ncd.solver.anderson`), or the same with local exact solves where
#    it stalls (criterion `anderson_local`, `ncd.solver.local_exact`), tolerance) gives one
#    point: its wall time (best of a few repeats), its sweeps, its relative natural-map
#    residual $|s - \mathrm{proj}_K(s - \rho\tilde U)|/\max(|s|, |\rho q|)$ and its
#    distance to the limit of the same iteration (same guess, same review order) run to
#    $10^{-13}$: $|s - s^*|/|s^*|$ and $\max|u_f - u_f^*|/(|g|h)$.
#    *Scope:* these states are generated here, not read from the figures' rules, so that
#    this target builds only its own inputs.  They are small stand-ins of the paper's
#    states (a packing, a pile, a slope step), not their configurations or sizes.
# 2. *Time integration.*  An observable with a known or reference value, against wall
#    time, for CD over $h$ and for MD (`ncd.dynamics.md`) over $h = f\,h_\mathrm{crit}$ and stiffness
#    $k = c\,k_0$ ($k_0$: overlap of 1 % of a radius under the load):
#    the distance travelled on an incline from rest (closed form: sliding
#    $a = g(\sin\alpha - \mu\cos\alpha)$, rolling $a = \tfrac23 g\sin\alpha$); a settled
#    heap (ground reaction = weight, packing fraction against the finest CD run); the mean
#    velocity of a slope flow at a fixed time against CD at a fine step and a tight
#    tolerance (and CD at half that step, to measure the reference's own uncertainty).

# %%
import matplotlib
import numpy as np
import pandas as pd
import xarray as xr

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker
from IPython.display import Markdown, display

from ncd.pages.notebook import paths, save

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
snakemake = paths("error_vs_runtime", ["nlgs", "integration"], globals().get("snakemake"))

nl = xr.load_dataset(snakemake.input.nlgs)
it = xr.load_dataset(snakemake.input.integration)
df = it.to_dataframe()
FLOOR = 1e-17
print(nl[["n_discs", "n_contacts", "limits_distance_impulse", "limits_distance_velocity"]].to_dataframe())
print(nl[["reference_sweeps", "reference_residual"]].to_dataframe())

# %% [markdown]
# ## NLGS at one step: the data

# %%
tab = nl[["sweeps", "wall_time", "residual", "error_impulse", "error_velocity", "converged"]].to_dataframe()
with pd.option_context("display.max_rows", 300, "display.float_format", "{:.3g}".format):
    display(tab)

# %% [markdown]
# ## Time integration: the data
#
# `error` is relative for the distance and the mean velocity, absolute for $R/W - 1$
# and the packing fraction; −1 marks a diverged MD run (with its step).  `work` counts
# contact updates: NLGS sweeps × contacts for CD, steps × candidate pairs for MD.

# %%
with pd.option_context("display.max_rows", 300, "display.width", 250, "display.float_format", "{:.4g}".format):
    display(df)

# %%
fig, axes = plt.subplots(3, 4, figsize=(17, 12.5))
init_color = {"zero": "tab:blue", "warm": "tab:orange"}
for j, state in enumerate(nl.state.values):
    d = nl.sel(state=state)
    for xkey, row in (("wall_time", 0), ("sweeps", 1)):
        ax = axes[row, j]
        for init in d.init.values:
            for crit, style in (("residual", "-"), ("change", ":"), ("finish", "-."), ("anderson", (0, (5, 1, 1, 1, 1, 1))),
                               ("anderson_local", (0, (1, 1)))):
                if crit not in d.criterion.values:
                    continue
                e = d.sel(init=init, criterion=crit)
                x = e[xkey].values * (1e3 if xkey == "wall_time" else 1)
                ax.plot(x, np.maximum(e.error_velocity, FLOOR), linestyle=style, marker="o", ms=4,
                        color=init_color[init], label=f"{init}, stop on {crit}: velocity error")
                ax.plot(x, np.maximum(e.error_impulse, FLOOR), linestyle=style, marker="^", ms=4, alpha=0.5,
                        color=init_color[init], label=f"{init}, stop on {crit}: impulse error")
                if crit == "residual":
                    ax.plot(x, np.maximum(e.residual, FLOOR), "--", color=init_color[init], lw=0.8,
                            label=f"{init}: natural-map residual")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("wall time (ms)" if xkey == "wall_time" else "sweeps")
        ax.set_title(f"({'abc'[j] if row == 0 else 'efg'[j]}) NLGS, {state}: "
                     f"{int(d.n_discs)} discs, {int(d.n_contacts)} contacts", fontsize=10)
        if j == 0:
            ax.set_ylabel("distance to the limit / residual")
axes[0, 0].legend(fontsize=6.5, loc="lower left")

ax = axes[0, 3]
x = np.arange(nl.sizes["state"])
ax.bar(x - 0.2, np.maximum(nl.limits_distance_impulse, FLOOR), 0.4, label="impulses |s0* - sw*| / |sw*|")
ax.bar(x + 0.2, np.maximum(nl.limits_distance_velocity, FLOOR), 0.4, label="velocities max|du| / (g h)")
ax.set_xticks(x, nl.state.values)
ax.set_yscale("log")
ax.set_title("(d) zero- vs warm-started limits (tol 1e-13)", fontsize=10)
ax.legend(fontsize=7)


def integration_panel(ax, sub, title, ylabel, reference_band=None, value=False):
    """Error (or value) against wall time: CD over h (black), MD over h/h_crit for each
    stiffness (colours), references (red stars).  Zero errors sit on the lower edge (v)."""
    key = "value" if value else "error"
    shown = sub[(sub.diverged == 0) & (sub.method != "CD_reference")]
    positive = shown[key][shown[key] > 0]
    low = max(FLOOR, positive.min() / 10) if len(positive) and not value else None

    def y(v):
        return np.maximum(v, low) if low is not None else v

    cd = sub[sub.method == "CD"].sort_values("h")
    ax.plot(cd.wall_time, y(cd[key]), "k-o", label="CD over h")
    for _, r in cd.iterrows():
        ax.annotate(f"{r.h:.0e}", (r.wall_time, y(r[key])), fontsize=6, xytext=(3, 3),
                    textcoords="offset points")
    md = sub[(sub.method == "MD") & (sub.diverged == 0)]
    cmap = plt.get_cmap("viridis")
    ks = sorted(md.k_factor.unique())
    for i, k in enumerate(ks):
        m = md[md.k_factor == k].sort_values("h")
        ax.plot(m.wall_time, y(m[key]), "--s", ms=4, color=cmap(i / max(len(ks) - 1, 1)),
                label=f"MD k = {k:g} k0 over h/h_crit")
    for _, r in sub[sub.method.str.startswith("CD_reference")].iterrows():
        if value or r.method != "CD_reference":
            ax.plot(r.wall_time, y(r[key]), "r*", ms=10, label=f"{r.method} h={r.h:.2g}")
    if value:
        ax.axhline(float(sub.reference.iloc[0]), color="r", lw=0.8, label="reference")
    if low is not None:
        zero = shown[shown[key] <= low]
        ax.plot(zero.wall_time, np.full(len(zero), low), "v", color="gray", ms=6, label="zero error")
        ax.set_yscale("log")
        ax.set_ylim(bottom=low / 2)
    if reference_band is not None and low is not None:
        ax.axhspan(low / 2, reference_band, color="r", alpha=0.08, label="reference uncertainty")
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=6.5)


inc = df[df.observable == "incline"]
heap = df[df.observable == "heap"]
slope = df[df.observable == "slope_flow"]
integration_panel(axes[1, 3], heap[heap.quantity == "reaction"], "(h) settled heap: ground reaction",
                  "|R / W - 1|")
mus = sorted(inc.mu.unique())
for j, mu in enumerate(mus[:2]):
    kind = "slides" if mu < np.tan(np.radians(20)) / 3 else "rolls"
    integration_panel(axes[2, j], inc[inc.mu == mu], f"({'ij'[j]}) incline, mu = {mu:g}: disc {kind}",
                      "|x(T) - x_exact| / x_exact")
integration_panel(axes[2, 2], heap[heap.quantity == "packing_fraction"],
                  "(k) settled heap: packing fraction (line: finest CD run)", "phi", value=True)
angle0 = slope.angle.iloc[0]
slope0 = slope[slope.angle == angle0]
check0 = slope0[slope0.method == "CD_reference_check"]
integration_panel(axes[2, 3], slope0, f"(l) slope flow at {angle0:g} deg: mean velocity at T",
                  "|v - v_ref| / v_ref", reference_band=float(check0.error.iloc[0]) if len(check0) else None)
fig.tight_layout()
save(fig, snakemake.output, dpi=100, show=True)

# %% [markdown]
# ## Verdicts (computed from the data above)

# %%
lines = []
# monotonicity: a tighter tolerance never gives a larger error at convergence
viol = 0
total = 0
for state in nl.state.values:
    for init in nl.init.values:
        for crit in nl.criterion.values:
            if crit in ("anderson", "anderson_local"):   # the limit need not be plain NLGS's in an indeterminate set
                continue
            e = nl.sel(state=state, init=init, criterion=crit).sortby("tol", ascending=False)
            conv = e.converged.values.astype(bool)
            for a in ("error_velocity", "error_impulse"):
                v = e[a].values[conv]
                total += max(len(v) - 1, 0)
                viol += int(np.sum(v[1:] > v[:-1] * (1 + 1e-9) + 1e-15))
            viol += int(np.sum(np.diff(e.sweeps.values) < 0))
lines.append(f"* **Monotone where theory says so**: over {total} tolerance pairs a tighter tolerance "
             f"gave a larger error or fewer sweeps {viol} times.")
lines.append("* **Sizes**: " + "; ".join(f"`{st}` {int(nl.n_discs.sel(state=st))} discs, "
                                          f"{int(nl.n_contacts.sel(state=st))} contacts" for st in nl.state.values) + ".")
ch_ratio = (nl.sel(criterion="change").sweeps / nl.sel(criterion="residual").sweeps).values
ch_err = np.log10(nl.sel(criterion="change").error_velocity / nl.sel(criterion="residual").error_velocity).values
lines.append(f"* **Impulse-change criterion** against the residual one, same state, guess and tolerance: "
             f"{ch_ratio.min():.2g}–{ch_ratio.max():.2g} times the sweeps, velocity distance to the limit "
             f"within {np.abs(ch_err).max():.1f} decades.")
for state in nl.state.values:      # cost of a decade of residual, and error per unit tolerance (zero guess)
    e = nl.sel(state=state, init="zero", criterion="residual").sortby("tol", ascending=False)
    per_decade = np.diff(e.sweeps.values) / np.diff(-np.log10(e.tol.values))
    ratio_v, ratio_s = e.error_velocity.values / e.tol.values, e.error_impulse.values / e.tol.values
    lines.append(f"* `{state}`, residual criterion, zero guess: a decade of tolerance costs "
                 f"{per_decade.min():.0f}–{per_decade.max():.0f} sweeps; the distance to the limit is "
                 f"{ratio_s.min():.2g}–{ratio_s.max():.2g} times the tolerance in impulses and "
                 f"{ratio_v.min():.2g}–{ratio_v.max():.2g} times in velocities (g h).")
tight = nl.tol.values.min()
r = nl.sel(tol=tight, criterion="residual")
for crit, label, inits, note in (
        ("anderson", "Anderson-accelerated NLGS** (`ncd.solver.anderson`)", ["zero"], ""),
        ("anderson_local", "Anderson with local exact solves** (`ncd.solver.local_exact`)", list(nl.init.values),
         " Figure 2's step, where plain NLGS stalls from the warm guess, is in the benchmark suite (`bench.html`).")):
    if crit not in nl.criterion.values:
        continue
    a = nl.sel(tol=tight, criterion=crit)
    lines.append(f"* **{label} to the tightest tolerance ({tight:.0e}): " + "; ".join(
        f"{st}, {init} guess: {int(a.sweeps.sel(state=st, init=init))} sweeps against "
        f"{int(r.sweeps.sel(state=st, init=init))} plain, "
        f"{1e3 * float(a.wall_time.sel(state=st, init=init)):.2g} ms against "
        f"{1e3 * float(r.wall_time.sel(state=st, init=init)):.2g} ms, velocity distance to plain "
        f"NLGS's limit {float(a.error_velocity.sel(state=st, init=init)):.1e} g h"
        for st in nl.state.values for init in inits) + "." + note)
tol_mid = nl.tol.values[np.argmin(np.abs(np.log10(nl.tol.values) + 6))]
for state in nl.state.values:
    d = nl.sel(state=state, criterion="residual", tol=tol_mid)
    z, w = int(d.sweeps.sel(init="zero")), int(d.sweeps.sel(init="warm"))
    lines.append(f"* `{state}`: at tol = {tol_mid:.0e}, zero guess {z} sweeps "
                 f"({1e3 * float(d.wall_time.sel(init='zero')):.3g} ms), warm guess {w} sweeps "
                 f"({1e3 * float(d.wall_time.sel(init='warm')):.3g} ms); velocity error "
                 f"{float(d.error_velocity.sel(init='zero')):.2g} (zero) and "
                 f"{float(d.error_velocity.sel(init='warm')):.2g} (warm) of g h.  The zero- and "
                 f"warm-started limits differ by {float(nl.limits_distance_impulse.sel(state=state)):.2g} "
                 f"in impulses and {float(nl.limits_distance_velocity.sel(state=state)):.2g} g h in velocities.")
cd_inc = inc[inc.method == "CD"]
md_inc = inc[(inc.method == "MD") & (inc.diverged == 0)]
lines.append(f"* **Incline**: CD is exact at every h (largest error {cd_inc.error.max():.1g}; the "
             f"theta-scheme integrates a constant acceleration exactly and the contact stays closed); "
             f"MD errors range from {md_inc.error.max():.2g} down to {md_inc.error.min():.2g}, decreasing "
             f"with h and with the stiffness (the soft contact's transient and overlap are a model error).")
cd_heap = heap[(heap.method == "CD") & (heap.quantity == "reaction")]
md_heap = heap[(heap.method == "MD") & (heap.quantity == "reaction") & (heap.diverged == 0)]
lines.append(f"* **Settled heap**: |R/W - 1| after the settling time: CD {cd_heap.error.min():.2g}–"
             f"{cd_heap.error.max():.2g}, MD {md_heap.error.min():.2g}–{md_heap.error.max():.2g} "
             f"(what remains is motion not yet damped, not a force error).  The packing fraction has no "
             f"exact value: its spread over runs, "
             f"{heap[heap.quantity == 'packing_fraction'].value.replace(0, np.nan).min():.3f}–"
             f"{heap[heap.quantity == 'packing_fraction'].value.max():.3f}, is the protocol's, not the solver's.")
for angle in slope.angle.unique():
    sl = slope[slope.angle == angle]
    check = sl[sl.method == "CD_reference_check"]
    cd_sl = sl[sl.method == "CD"].sort_values("h")
    md_sl = sl[(sl.method == "MD") & (sl.diverged == 0)]
    lines.append(f"* **Slope flow at {angle:g} deg**: reference v = {sl.reference.iloc[0]:.4g} m/s; halving "
                 f"the reference's step moves it by {float(check.error.iloc[0]):.2g} (relative), which bounds "
                 f"what any error below it means.  CD errors "
                 + ", ".join(f"{e:.2g} (h={h:.0e})" for h, e in zip(cd_sl.h, cd_sl.error))
                 + f"; MD {md_sl.error.min():.2g}–{md_sl.error.max():.2g}.")
lines.append(f"* **Wall time**: an MD run is one compiled loop (all its steps inside numba), a CD step "
             f"returns to Python and solves a nonsmooth problem; at equal simulated time MD at its stable "
             f"steps was {'cheaper' if md_heap.wall_time.median() < cd_heap.wall_time.median() else 'dearer'} "
             f"here (median {md_heap.wall_time.median():.2g} s against {cd_heap.wall_time.median():.2g} s "
             f"on the heap).  Wall times are measurements on a shared machine (noisy); sweeps and `work` "
             f"are the reproducible cost.")
display(Markdown("\n".join(lines)))

# %% [markdown]
# **Reading the diagrams.**
#
# *NLGS.*  Every point is a setting; moving down a curve costs sweeps (per decade: the
# verdicts above), and the distance to the limit follows the natural-map residual up to
# the per-state factors listed above, so the residual is a usable stopping criterion
# once that factor is known.  The impulse-change criterion is compared with it in the
# verdicts above.  The warm
# start can pay off on states at rest, whose previous impulses nearly solve the next
# step, and less on the slope step, where the previous step's impulses include
# collisions that the next step does not have (sweep ratios below).  The distance
# between the zero- and warm-started limits is the paper's indeterminacy made visible:
# where the impulses of the two limits differ while the velocities agree to rounding, the
# step has several solutions with the same motion (the set of equilibrium forces is a
# polytope, section 4); the measured distances are below.
#
# *Time integration.*  On the incline CD's error is at rounding level at any step: CD
# pays nothing for precision there, while MD has to resolve the contact stiffness.  On
# the heap and on the flow, each method's accuracy is limited by what the observable
# can resolve: undamped residual motion for the ground reaction, the deposition protocol
# for the packing fraction, chaos for the mean velocity.  MD needs $h$ a small fraction
# of $2/\omega$ (see the `stability` notebook) and its stiff runs cost
# proportionally to $\sqrt{k}$; CD's cost is set by the NLGS sweeps per step.

# %%
# the numbers behind the NLGS paragraph, from this run's data
def _tight_sweeps(state, init):
    return float(nl.sweeps.sel(state=state, init=init, criterion="residual").max())


Markdown("**Measured in this run** (tightest setting, residual criterion; limits at the reference tolerance): "
         + "; ".join(f"{st}: sweeps zero / warm start {_tight_sweeps(st, 'zero'):.0f} / {_tight_sweeps(st, 'warm'):.0f} "
                     f"(ratio {_tight_sweeps(st, 'zero') / max(_tight_sweeps(st, 'warm'), 1):.2g}), zero- vs warm-started "
                     f"limits: impulses {float(nl.limits_distance_impulse.sel(state=st)):.1e} (relative), velocities "
                     f"{float(nl.limits_distance_velocity.sel(state=st)):.1e} g h" for st in nl.state.values) + ".")
