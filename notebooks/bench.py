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
#   disc, `ncd.studies.bench.solver.dense_packing`), the time per contact update of the
#   numba NLGS sweep, and of **the same loop in C** (`ncd/studies/bench/c_sweep.c`, gcc
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
#   Gauss–Seidel iterations per step (`ncd.studies.bench.peer`);
# * `rules.nc`: the wall time of every rule of the figures' run, from Snakemake's
#   `benchmark:` files;
# * `dag.nc`: the CPU time of every job of the default run and the critical path of its
#   DAG (the job graph of a dry run, the times of the benchmark files);
# * `profile.nc`: the figures run again with the counts of `config/quick.yaml` under
#   py-spy, every sample of every job filed under its figure and under numba kernels, LP
#   solvers, other compiled code or Python (`ncd.studies.bench.profile`);
# * `exact_sets.nc`: the LPs and LP time of the exact angle ranges of every history pile
#   with an exact file (`ncd.studies.bench.solver.exact_costs`), the size study's included;
# * `sampler.nc`: Figure 5's uniform sampler with random and with coordinate directions on
#   the same slices (`ncd.figures.fig5_governing.sampler`).

# %%
import matplotlib
import xarray as xr
from IPython.display import HTML, Markdown, display

from ncd.figures.fig5_governing import sampler
from ncd.pages.notebook import paths, save
from ncd.studies.bench import page

matplotlib.use("Agg")  # the figure is shown once, as the saved PNG

# Snakemake's object, or by hand (from the repository or notebooks/) the files under results/
NAMES = ["core", "sweeps", "tolerance", "tolerance_problems", "ensemble", "peer", "rules", "dag", "profile",
         "exact_sets", "sampler"]
snakemake = paths("bench", NAMES, globals().get("snakemake"))
data = {name: xr.load_dataset(getattr(snakemake.input, name)) for name in NAMES}
core, sweeps, tol_ds, tol_pb = data["core"], data["sweeps"], data["tolerance"], data["tolerance_problems"]
display(Markdown(page.machine_sentence(core)))

# %%
save(page.plot(core, sweeps, data["rules"]), snakemake.output, dpi=100, show=True)

# %% [markdown]
# (a) Time per contact update of the NLGS sweep in numba, of the same loop in C, and of
# the sweep in the interleaved review order, with the target; (b) time per Moreau–Jean
# step, step preparation and contact detection against N, with a line $\propto N$;
# (c) sweeps to the residual of the sweeps benchmark against N; (d) the slowest rules of
# the figures' run (wall time).

# %% [markdown]
# ## The NLGS sweep against the same loop in C
#
# Time per contact update = time of a sweep / contacts, from the zero guess with the
# identity review order (contacts sorted by body pair).  `ratio` is numba over C.

# %%
display(HTML(page.core_table(core)))
display(Markdown(page.sweep_sentence(core)))

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
display(HTML(page.interleaved_table(core)))

# %% [markdown]
# ## Time against N
#
# Building a packing (`ncd.studies.bench.solver.dense_packing`: positions, radii, the scene's
# checks), preparing a step (detection, Delassus blocks), one NLGS sweep and one
# Moreau–Jean step (warm start, NLGS to the step tolerance within its sweep budget) at
# each size, and the exponent $p$ of the least-squares fit $t = c\,N^p$ (log–log).

# %%
display(HTML(page.table(page.scaling_frame(core))))

# %% [markdown]
# ## Sweeps against N

# %%
display(HTML(page.sweeps_table(sweeps)))
display(Markdown(page.sweeps_sentence(sweeps)))

# %% [markdown]
# ## Ensembles on two threads

# %%
display(HTML(page.ensemble_table(data["ensemble"])))
display(Markdown(page.ensemble_sentence(data["ensemble"])))

# %% [markdown]
# ## Side by side with pymunk on a poured pile

# %%
display(HTML(page.table(page.peer_frame(data["peer"]), digits=4)))
display(Markdown(page.peer_sentence(data["peer"])))

# %% [markdown]
# ## Time to tolerance: plain NLGS, NLGS + finishing stage, Anderson-accelerated NLGS
#
# One step from rest of each dense packing, zero guess: plain NLGS run to each tolerance,
# NLGS followed by the finishing stage (`ncd.solver.finish`: when NLGS's own rate predicts the
# tolerance beyond its budget, the iterate is projected by LP onto the solutions sharing its
# contact statuses, or, when there are none, onto the states at rest), and
# Anderson-accelerated NLGS (`ncd.solver.anderson`), to the same tolerance.

# %%
display(HTML(page.tolerance_table(tol_ds)))
display(Markdown(page.fastest_sentence(tol_ds)))

# %% [markdown]
# The same comparison on the figures' own problems: the pile's final state (Figure 4) and
# the investigated step of the slope flow (Figure 2), from the zero guess, for the identity
# review order and random ones. A run that does not reach the tolerance within the sweep
# budget counts as not converged (its time is the time spent).

# %%
display(HTML(page.problems_table(tol_pb)))
display(Markdown(page.reached_sentence(tol_pb)))

# %% [markdown]
# **Local exact solves** (`ncd.solver.local_exact`, methods `nlgs+local` and `anderson+local`):
# where the residual stops falling, the contacts that drift most and the other contacts of
# their grains are solved exactly by Lemke's method, the other impulses frozen, and the
# sweeps go on. Speed-up over plain NLGS at the tightest tolerance, per problem (min–max
# over the review orders), and the largest distance of the end point to plain NLGS's
# (`gap_to_nlgs`, end-of-step velocities over |g| h: 0 on plain NLGS's own solution):

# %%
display(HTML(page.table(page.local_frame(tol_pb))))

# %% [markdown]
# ## Wall time of every rule of the figures' run

# %%
rule_table, per_figure = page.rules_tables(data["rules"])
display(HTML(rule_table), HTML(per_figure))
display(Markdown(page.rules_sentence(data["rules"])))

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
per_fig, path, text = page.dag_tables(data["dag"])
display(HTML(per_fig), HTML(path), Markdown(text))

# %% [markdown]
# ## Where the CPU goes: kernels, LP solvers, Python
#
# The figures' jobs run again, with the realization counts of `config/quick.yaml`, in a
# scratch directory under `py-spy record --subprocesses --native` (`snakemake -j2
# bench_profile`).  Each sample of each job's processes (its script, or its notebook's
# nbconvert and kernel) is filed under the job's figure, read from the rules files, and
# under the code it was in, read from its stack below the innermost Python frame: a numba
# kernel (JIT code, which has no library), an LP solver (HiGHS, Clarabel, CLP), other compiled
# code (numpy, scipy, BLAS, libc, numba's type dispatch), or the Python interpreter.  The
# goal set for every figure: most of its CPU inside kernels and solvers, at least the
# share `GOAL` of `ncd.studies.bench.profile` (the column's heading); a figure with fewer
# than `MIN_SAMPLES` samples is not judged.  Job CPU and the seconds on the critical path
# are those of the run of the previous section; the shares are those of the profiled run.
# The last column is the sampled CPU over the jobs' wall time in the profiled run: below
# one where a job waits (for the disk, for the other job on the cores) or where py-spy
# attached to its process late.

# %%
profile = page.profile_frame(data["profile"], data["dag"])
display(HTML(page.table(profile)), Markdown(page.profile_sentence(data["profile"])))

# %% [markdown]
# The innermost Python functions of each figure's samples outside kernels and solvers,
# with their share of its samples: where its Python and other compiled time goes.

# %%
display(HTML(page.table(page.hot_spots_frame(data["profile"]))))

# %% [markdown]
# ## Exact sets of the history piles
#
# The exact angle ranges over A ∩ C at the cuts of a pile of `fig4_history`
# (`ncd.figures.fig4_history.exact`: per cut, min p, two Charnes–Cooper LPs with their
# certificates, and the largest vertical component), from the exact files of the run: the
# LPs, the solver (in the default run HiGHS's simplex, restarted from the previous basis, a
# Dinkelbach LP certifying each end; for the piles of 10⁴ grains Clarabel's interior point,
# each end certified by its LP's dual) and their wall time (one thread). The piles of 10⁴
# grains appear once the size study (`snakemake -j2 fig4_history_size`) has run.

# %%
display(HTML(page.table(page.exact_frame(data["exact_sets"]))), Markdown(page.exact_sentence(data["exact_sets"])))

# %% [markdown]
# ## Figure 5's uniform sampler: random against coordinate directions
#
# Figure 5 samples each slice's A ∩ C uniformly by hit-and-run in a rounded frame
# (`docs/governing.md`). A Gaussian direction costs O(d² + m d) a step; a coordinate of the
# rounded frame costs O(m). Both leave the uniform law invariant. Here both run on the same
# slices of this run (the first indeterminate one at each μ of the plates series), with the
# same settings and generators. For each: its CPU time (pilot, burn-in and redraws
# included), η_U, the two chains' gap and R-hat, and the points per chain the mixing check
# needed (`snakemake -j2 bench_sampler`).

# %%
cmp = data["sampler"]
display(HTML(page.table(sampler.frame(cmp), index=False)), Markdown(sampler.summary(cmp)))
