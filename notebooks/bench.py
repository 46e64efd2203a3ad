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
# # Benchmarks: ncd against the hardware, against itself on two threads, and against pymunk
#
# **Why.** Contact Dynamics trades a stiff ODE for a nonsmooth problem per step
# (Moreau 2005, section 2); its cost is the NLGS sweep, repeated many times per step in
# dense packings.  A reader choosing between ncd, LMGC90, Siconos or a game engine
# needs the cost of that sweep against what the machine can do, the growth of the
# sweeps with N, the use of both cores in ensembles, and a peer on the same work.
#
# **What we computed** (`snakemake -j2 bench`, section `bench` of `config.yaml`;
# every timing rule asks for both cores, so Snakemake runs it alone):
#
# * `core.nc`: on dense jittered triangular packings (about three contacts per
#   disc, `ncd.studies.bench.dense_packing`), the time per contact update of the
#   numba NLGS sweep, and of **the same loop in C** (`ncd/studies/c_sweep.c`, gcc
#   `-O3 -ffp-contract=off`, same packed arrays, same floating-point operations: it
#   returns the same impulses bit for bit, column `c_agrees`), contact detection, step preparation, the time per
#   Moreau–Jean step (warm start, fixed sweep budget) and the peak memory;
# * `sweeps.nc`: the sweeps needed to reach a fixed natural-map residual on one
#   step, from the zero guess and from the warm start;
# * `ensemble.nc`: one ensemble of zero-guess NLGS runs with random review
#   orders on 1 and 2 threads (`ncd.dynamics.explore.run_parallel`): speed-up and a digest
#   of every result, which must be the same;
# * `peer.nc`: a pile poured from a point source, the same scene in ncd and in
#   pymunk (Chipmunk2D, C, sequential impulses) with the same number of
#   Gauss–Seidel iterations per step (`ncd.studies.peer`);
# * `rules.nc`: the wall time of every rule of the figures' run, from Snakemake's
#   `benchmark:` files;
# * `dag.nc`: the CPU time of every job of the default run and the critical path of its
#   DAG (the job graph of a dry run, the times of the benchmark files).

# %%
import matplotlib
import numpy as np
import pandas as pd
import xarray as xr
import yaml

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from IPython.display import Markdown, display

from ncd.pages.notebook import paths, save
from ncd.studies.bench import dag_summary, scaling_table

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
snakemake = paths("bench", ["core", "sweeps", "tolerance", "tolerance_problems", "ensemble", "peer", "rules", "dag"], globals().get("snakemake"))

core = xr.load_dataset(snakemake.input.core)
sweeps = xr.load_dataset(snakemake.input.sweeps)
tol_ds = xr.load_dataset(snakemake.input.tolerance)
tol_pb = xr.load_dataset(snakemake.input.tolerance_problems)
ens = xr.load_dataset(snakemake.input.ensemble)
peer = xr.load_dataset(snakemake.input.peer)
rules = xr.load_dataset(snakemake.input.rules)
dag = xr.load_dataset(snakemake.input.dag)
print(f"machine: {core.attrs['machine']}, {core.attrs['cpu_count']} cores; python {core.attrs['python']}, "
      f"numba {core.attrs['numba']}; load average at start {core.attrs['loadavg_start']:.2f}")

# %% [markdown]
# ## The NLGS sweep against the same loop in C
#
# Time per contact update = time of a sweep / contacts, from the zero guess with the
# identity review order (contacts sorted by body pair).  `ratio` is numba over C.

# %%
tab = core.to_dataframe()
tab["ratio"] = tab.ns_per_update / tab.ns_per_update_c
tab["detect_ms"] = 1e3 * tab.detect_s
tab["prepare_ms"] = 1e3 * tab.prepare_s
tab["step_ms"] = 1e3 * tab.step_s
tab["step_us_per_disc"] = 1e6 * tab.step_s / tab.n_discs
tab["peak_MB"] = tab.peak_memory / 2**20
tab["growth_MB"] = tab.memory_growth / 2**20
cols = ["n_discs", "n_contacts", "ns_per_update", "ns_per_update_c", "ratio", "c_agrees", "detect_ms",
        "prepare_ms", "step_ms", "step_sweeps", "step_us_per_disc", "peak_MB", "growth_MB"]
with pd.option_context("display.width", 250, "display.float_format", "{:.3g}".format):
    display(tab[cols])
start = {k[8:]: v for k, v in core.attrs.items() if k.startswith("startup_")}
display(Markdown(
    f"Sweep: **{tab.ns_per_update.min():.1f}–{tab.ns_per_update.max():.1f} ns** per contact update "
    f"(C: {tab.ns_per_update_c.min():.1f}–{tab.ns_per_update_c.max():.1f} ns; numba/C "
    f"{tab.ratio.min():.2f}–{tab.ratio.max():.2f}; the target set for this benchmark is 12 ns).  Time per step per "
    f"disc: {tab.step_us_per_disc.min():.1f}–{tab.step_us_per_disc.max():.1f} µs at a budget of "
    f"{yaml.safe_load(core.attrs['config_yaml'])['step_sweeps']} sweeps.  A fresh interpreter with a warm numba cache imports ncd in "
    f"{start['import_s']:.2f} s and makes its first step {start['first_step_s']:.2f} s later "
    f"(whole process {start['process_s']:.2f} s)."))

# %% [markdown]
# **Where the time goes.** Gauss–Seidel is sequential: the update of a contact reads
# the velocities that the previous updates of its two discs wrote.  With contacts
# sorted by body pair, consecutive updates share a disc, so each waits for the last
# one's result (load, about twenty dependent floating-point operations, one division,
# store): the loop is bound by that latency, in C as in numba.  An order in which
# consecutive updates rarely share a disc (`interleaved`: every eighth contact, a
# cheap stand-in for the graph colouring of Box2D's solver) lets the processor overlap
# them, so a sweep is cheaper per update (column `ns_per_update_interleaved`), but
# NLGS then needs more sweeps for the same residual (next section) and the time to a
# tolerance is what counts.  The figures keep the sorted order (changing it would
# also change every result in the last bits, and with them which steps of the slope
# flow show indeterminacy).

# %%
tab["interleaved_gain"] = tab.ns_per_update / tab.ns_per_update_interleaved
with pd.option_context("display.float_format", "{:.3g}".format):
    display(tab[["n_discs", "ns_per_update", "ns_per_update_interleaved", "interleaved_gain"]])

# %% [markdown]
# ## Time against N
#
# Building a packing (`ncd.studies.bench.dense_packing`: positions, radii, the scene's
# checks), preparing a step (detection, Delassus blocks), one NLGS sweep and one
# Moreau–Jean step (warm start, NLGS to the step tolerance within its sweep budget) at
# each size, and the exponent $p$ of the least-squares fit $t = c\,N^p$ (log–log).

# %%
scaling = pd.DataFrame({name: times for name, times, _ in scaling_table(core)}, index=core.n_discs.values).T
scaling["fitted p"] = [p for _, _, p in scaling_table(core)]
with pd.option_context("display.float_format", "{:.3g}".format):
    display(scaling.rename_axis("seconds at N ="))

# %% [markdown]
# ## Sweeps against N

# %%
sw = sweeps.to_dataframe()
with pd.option_context("display.width", 250, "display.float_format", "{:.3g}".format):
    display(sw)
ok = sw.converged_zero.astype(bool)
slope = np.polyfit(np.log(sw.index[ok]), np.log(sw.sweeps_zero[ok]), 1)[0] if ok.sum() >= 2 else np.nan
both = ok & sw.converged_interleaved.astype(bool)
extra = (sw.sweeps_interleaved[both] / sw.sweeps_zero[both]).agg(["min", "max"])
time_ratio = (sw.wall_time_interleaved[both] / sw.wall_time_zero[both]).agg(["min", "max"])
display(Markdown(
    f"From the zero guess the sweeps to a residual of {sweeps.attrs['tol']:g} grow like "
    f"N^{slope:.2f} (fit over the converged sizes; {int((~ok).sum())} size(s) exhausted "
    f"{sweeps.attrs['max_sweeps']} sweeps): the load has to cross the packing, whose height "
    f"grows like N^0.5.  Warm-started after {sweeps.attrs['warm_steps']} steps, "
    f"{sw.sweeps_warm.min()}–{sw.sweeps_warm.max()} sweeps suffice.  The interleaved order needs "
    f"{extra['min']:.2f}–{extra['max']:.2f} times the sweeps of the sorted order and "
    f"{time_ratio['min']:.2f}–{time_ratio['max']:.2f} times its wall time to the same residual."))

# %% [markdown]
# ## Ensembles on two threads

# %%
e = ens.to_dataframe()
with pd.option_context("display.width", 250):
    display(e)
display(Markdown(
    f"{ens.attrs['runs']} zero-guess runs ({ens.attrs['n_contacts']} contacts, mean "
    f"{ens.attrs['sweeps_mean']:.0f} sweeps, {ens.attrs['converged']} converged): speed-up "
    f"**{float(e.speedup.iloc[-1]):.2f}×** on {int(e.index[-1])} threads (target 1.8×); results "
    f"{'identical bit for bit' if bool((e.same_results == 1).all()) else 'NOT identical'} for every thread count."))

# %% [markdown]
# ## Side by side with pymunk on a poured pile

# %%
scalars = [v for v in peer.data_vars if peer[v].dims == ("engine",)]
pt = peer[scalars].to_dataframe().T
pt["unit"] = [peer[v].attrs.get("units", "") for v in pt.index]
with pd.option_context("display.width", 250, "display.max_rows", 100, "display.float_format", "{:.4g}".format):
    display(pt)
pcfg = yaml.safe_load(peer.attrs["config_yaml"])
n_, p_ = peer.sel(engine="ncd"), peer.sel(engine="pymunk")
display(Markdown(
    f"{pcfg['n_discs']} discs poured one every {pcfg['drop_every']} steps of {pcfg['h'] * 1e3:g} ms, "
    f"{pcfg['iterations']} Gauss–Seidel iterations per step in both (pymunk {peer.attrs['pymunk_version']}).  "
    f"Time per step: ncd **{float(n_.time_mean) * 1e3:.3f} ms**, pymunk **{float(p_.time_mean) * 1e3:.3f} ms** "
    f"(mean over the run; ratio {float(n_.time_mean / p_.time_mean):.2f}); with every disc in, "
    f"{float(n_.time_settle) * 1e3:.3f} against {float(p_.time_settle) * 1e3:.3f} ms.  "
    f"At rest the ground and walls carry {float(n_.ground_reaction):.6f} (ncd) and "
    f"{float(p_.ground_reaction):.6f} (pymunk) of the weight; Coulomb violation "
    f"{float(n_.coulomb_violation):.1e} and {float(p_.coulomb_violation):.1e}.  "
    f"Largest interpenetration over the run {float(n_.overlap_max):.3f} d (ncd) and "
    f"{float(p_.overlap_max):.3f} d (pymunk), at the end {float(n_.overlap_end):.4f} d and "
    f"{float(p_.overlap_end):.4f} d: Contact Dynamics does not correct positions, so a disc arriving "
    f"at speed v may sink by up to v h before its contact becomes active and keeps that overlap; "
    f"Chipmunk pushes overlaps out over later steps (its bias velocities), which also keeps its "
    f"pile creeping (final kinetic energy {float(p_.kinetic_energy):.1e} against "
    f"{float(n_.kinetic_energy):.1e} of Σ m g d)."))

# %% [markdown]
# ## Time to tolerance: plain NLGS, NLGS + finishing stage, Anderson-accelerated NLGS
#
# One step from rest of each dense packing, zero guess: plain NLGS run to each tolerance,
# NLGS followed by the finishing stage (`ncd.solver.finish`: when NLGS's own rate predicts the
# tolerance beyond its budget, the iterate is projected by LP onto the solutions sharing its
# contact statuses, or, when there are none, onto the states at rest), and
# Anderson-accelerated NLGS (`ncd.solver.anderson`), to the same tolerance.

# %%
tt = tol_ds.to_dataframe().reset_index()
display(tt.pivot_table(index=["size", "tol"], columns="solver", values=["seconds", "sweeps", "converged"]))
fastest = tt.loc[tt.groupby(["size", "tol"]).seconds.idxmin()]
display(Markdown("Fastest to each tolerance: " + "; ".join(
    f"{r.size} discs, {r.tol:.0e}: {r.solver} ({r.seconds:.2f} s)" for r in fastest.itertuples()) + "."))

# %% [markdown]
# The same comparison on the figures' own problems: the pile's final state (Figure 4) and
# the investigated step of the slope flow (Figure 2), from the zero guess, for the identity
# review order and random ones. A run that does not reach the tolerance within the sweep
# budget counts as not converged (its time is the time spent).

# %%
tp = tol_pb.to_dataframe().reset_index()
display(tp.pivot_table(index=["problem", "tol", "order"], columns="solver",
                       values=["seconds", "converged"]))
reached = tp.groupby(["problem", "solver", "tol"]).converged.agg(["sum", "count"]).reset_index()
display(Markdown("Runs reaching each tolerance: " + "; ".join(
    f"{r.problem}, {r.solver}, {r.tol:.0e}: {int(r['sum'])} of {int(r['count'])}"
    for _, r in reached.iterrows()) + "."))


# %% [markdown]
# **Local exact solves** (`ncd.solver.local_exact`, methods `nlgs+local` and `anderson+local`):
# where the residual stops falling, the contacts that drift most and the other contacts of
# their grains are solved exactly by Lemke's method, the other impulses frozen, and the
# sweeps go on. Speed-up over plain NLGS at the tightest tolerance, per problem (min–max
# over the review orders), and the largest distance of the end point to plain NLGS's
# (`gap_to_nlgs`, end-of-step velocities over |g| h: 0 on plain NLGS's own solution):

# %%
tight = float(tol_pb.tol.min())
rows = []
for problem in tol_pb.problem.values:
    d = tol_pb.sel(problem=problem, tol=tight)
    for solver in d.solver.values[1:]:
        e = d.sel(solver=solver)
        ok = (e.converged.values == 1) & (d.sel(solver="nlgs").converged.values == 1)
        speed = d.sel(solver="nlgs").seconds.values / e.seconds.values
        rows.append({"problem": problem, "solver": solver, "converged": f"{int(e.converged.sum())} of {e.sizes['order']}",
                     "sweeps": f"{int(e.sweeps.min())}–{int(e.sweeps.max())}",
                     "plain NLGS sweeps": f"{int(d.sel(solver='nlgs').sweeps.min())}–{int(d.sel(solver='nlgs').sweeps.max())}",
                     "speed-up": f"{speed[ok].min():.2g}–{speed[ok].max():.2g}" if ok.any() else "—",
                     "local solves": int(e.local_solves.max()),
                     "gap to plain NLGS (g h)": float(e.gap_to_nlgs.where(ok).max()) if ok.any() else np.nan})
display(pd.DataFrame(rows).set_index(["problem", "solver"]))

# %% [markdown]
# ## Wall time of every rule of the figures' run

# %%
rt = rules.to_dataframe()
rt["name"] = rt.figure + "/" + rt.rule
per_figure = rt.groupby("figure").seconds.sum()
with pd.option_context("display.max_rows", 200, "display.width", 200):
    display(rt[["figure", "rule", "seconds", "max_rss_mb"]])
    display(per_figure.to_frame("seconds (sum of the figure's rules)"))
display(Markdown(f"{len(rt)} jobs, {rt.seconds.sum() / 60:.1f} CPU-job minutes in all (with -j2 two "
                 "run at a time; the wall time of the whole run is in the README)."))

# %% [markdown]
# ## CPU time and critical path of the default run
#
# Every job of `snakemake -j2` (the job graph of a dry run), with its CPU time (user +
# system) from its benchmark file and the time it would take alone on its threads (CPU
# time over threads).  Snakemake counts a notebook's kernel once per sample, so a CPU time
# above wall time × threads is capped there.  The critical path is the longest chain of
# jobs each waiting for the one before: no schedule is shorter, nor shorter than the CPU
# time over the cores.  Wall times are measured on a shared machine and include the
# waits for other processes; CPU times do not.

# %%
per_fig, path, text = dag_summary(dag)
display(per_fig)
display(path)
display(Markdown(text))

# %%
fig, axes = plt.subplots(2, 2, figsize=(13, 9))
ax = axes[0, 0]
ax.plot(tab.n_discs, tab.ns_per_update, "o-", label="ncd (numba)")
ax.plot(tab.n_discs, tab.ns_per_update_c, "s--", label="same loop in C (gcc -O3 -ffp-contract=off)")
ax.plot(tab.n_discs, tab.ns_per_update_interleaved, "^:", label="ncd, interleaved review order")
ax.axhline(12, color="k", lw=0.8, ls=":", label="target 12 ns")
ax.set_xscale("log")
ax.set_ylim(0, None)
ax.set_xlabel("discs")
ax.set_ylabel("ns per contact update")
ax.set_title("(a) NLGS sweep")
ax.legend()
ax = axes[0, 1]
ax.loglog(tab.n_discs, tab.step_s, "o-", label="step (warm, fixed budget)")
ax.loglog(tab.n_discs, tab.prepare_s, "s-", label="step preparation (detection, W, q)")
ax.loglog(tab.n_discs, tab.detect_s, "^-", label="detection")
n = np.array([tab.n_discs.min(), tab.n_discs.max()], float)
ax.loglog(n, tab.step_s.iloc[0] * n / n[0], "k:", lw=0.8, label="∝ N")
ax.set_xlabel("discs")
ax.set_ylabel("s")
ax.set_title("(b) time per step")
ax.legend(fontsize=8)
ax = axes[1, 0]
ax.loglog(sw.index, sw.sweeps_zero, "o-", label="zero guess")
ax.loglog(sw.index, sw.sweeps_interleaved, "^--", label="zero guess, interleaved order")
ax.loglog(sw.index, sw.sweeps_warm, "s-", label="warm start")
ax.set_xlabel("discs")
ax.set_ylabel(f"sweeps to residual {sweeps.attrs['tol']:g}")
ax.set_title("(c) sweeps against N")
ax.legend()
ax = axes[1, 1]
top = rt.sort_values("seconds", ascending=False).head(15)
ax.barh(top.name, top.seconds)
ax.invert_yaxis()
ax.set_xlabel("s")
ax.set_title("(d) slowest rules of the figures' run")
ax.tick_params(axis="y", labelsize=7)
fig.tight_layout()
save(fig, snakemake.output, dpi=120, show=True)
