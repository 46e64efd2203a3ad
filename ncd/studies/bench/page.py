"""The speed report page: its figure, its tables and its sentences, from ``results/bench/*.nc``.

Every function takes the loaded Datasets of the bench rules (``core``, ``sweeps``,
``tolerance``, ``tolerance_problems``, ``ensemble``, ``peer``, ``rules``, ``dag``, ``profile``) and
returns what the page shows: HTML tables with formatted numbers, Markdown sentences whose
numbers come from the data, and the 2x2 figure (:func:`plot`).
"""
import numpy as np
import pandas as pd
import yaml

from ncd.studies.bench.profile import NOT_A_JOB, goal_status
from ncd.studies.bench.runs import dag_summary
from ncd.studies.bench.solver import scaling_table

TARGET_NS = 12.0        # the time per contact update set as this benchmark's target
TARGET_SPEEDUP = 1.8    # the ensemble speed-up on two threads set as its target
CORE_COLUMNS = ["n_discs", "n_contacts", "ns_per_update", "ns_per_update_c", "ratio", "c_agrees", "detect_ms",
                "prepare_ms", "step_ms", "step_sweeps", "step_us_per_disc", "peak_MB", "growth_MB"]


def number(x, digits=3):
    """``x`` with ``digits`` significant digits, and every digit of its integer part above them."""
    return f"{x:.0f}" if abs(x) >= 10**digits and np.isfinite(x) else f"{x:.{digits}g}"


def table(df, digits=3, index=True):
    """``df`` as an HTML table, floats with ``digits`` significant digits (:func:`number`)."""
    return df.to_html(index=index, float_format=lambda x: number(x, digits), na_rep="—")


def core_frame(core):
    """The ``core.nc`` table with the derived columns the page shows (ratio numba / C, ms, MB)."""
    tab = core.to_dataframe()
    tab["ratio"] = tab.ns_per_update / tab.ns_per_update_c
    for k in ("detect", "prepare", "step"):
        tab[f"{k}_ms"] = 1e3 * tab[f"{k}_s"]
    tab["step_us_per_disc"] = 1e6 * tab.step_s / tab.n_discs
    tab["peak_MB"] = tab.peak_memory / 2**20
    tab["growth_MB"] = tab.memory_growth / 2**20
    tab["interleaved_gain"] = tab.ns_per_update / tab.ns_per_update_interleaved
    return tab


def machine_sentence(core):
    a = core.attrs
    return (f"Machine: {a['machine']}, {a['cpu_count']} cores; python {a['python']}, numba {a['numba']}; "
            f"load average at start {float(a['loadavg_start']):.2f}.")


def core_table(core):
    return table(core_frame(core)[CORE_COLUMNS])


def sweep_sentence(core):
    """The sweep's cost per contact update, against C and the target, and the start-up times."""
    tab = core_frame(core)
    start = {k[8:]: float(v) for k, v in core.attrs.items() if k.startswith("startup_")}
    budget = yaml.safe_load(core.attrs["config_yaml"])["step_sweeps"]
    return (f"Sweep: **{tab.ns_per_update.min():.1f}–{tab.ns_per_update.max():.1f} ns** per contact update "
            f"(C: {tab.ns_per_update_c.min():.1f}–{tab.ns_per_update_c.max():.1f} ns; numba/C "
            f"{tab.ratio.min():.2f}–{tab.ratio.max():.2f}; the target set for this benchmark is {TARGET_NS:g} ns).  "
            f"Time per step per disc: {tab.step_us_per_disc.min():.1f}–{tab.step_us_per_disc.max():.1f} µs at a "
            f"budget of {budget} sweeps.  A fresh interpreter with a warm numba cache imports ncd in "
            f"{start['import_s']:.2f} s and makes its first step {start['first_step_s']:.2f} s later "
            f"(whole process {start['process_s']:.2f} s).")


def interleaved_table(core):
    return table(core_frame(core)[["n_discs", "ns_per_update", "ns_per_update_interleaved", "interleaved_gain"]])


def scaling_frame(core):
    """Seconds per quantity (rows) and size (columns), and the fitted exponent ``p``."""
    rows = scaling_table(core)
    df = pd.DataFrame({name: times for name, times, _ in rows}, index=core.n_discs.values).T
    df["fitted p"] = [p for _, _, p in rows]
    return df.rename_axis("seconds at N =")


def sweeps_table(sweeps):
    return table(sweeps.to_dataframe())


def sweeps_numbers(sweeps):
    """Exponent of the zero-guess sweeps against N (converged sizes), sizes that exhausted the
    budget, and the min–max ratios interleaved / sorted of sweeps and of wall time."""
    sw = sweeps.to_dataframe()
    ok = sw.converged_zero.astype(bool)
    slope = np.polyfit(np.log(sw.index[ok]), np.log(sw.sweeps_zero[ok]), 1)[0] if ok.sum() >= 2 else np.nan
    both = ok & sw.converged_interleaved.astype(bool)
    extra = (sw.sweeps_interleaved[both] / sw.sweeps_zero[both]).agg(["min", "max"])
    time_ratio = (sw.wall_time_interleaved[both] / sw.wall_time_zero[both]).agg(["min", "max"])
    return {"slope": float(slope), "exhausted": int((~ok).sum()), "warm": (int(sw.sweeps_warm.min()),
            int(sw.sweeps_warm.max())), "extra": tuple(extra), "time_ratio": tuple(time_ratio)}


def sweeps_sentence(sweeps):
    s, a = sweeps_numbers(sweeps), sweeps.attrs
    return (f"From the zero guess the sweeps to a residual of {a['tol']:g} grow like N^{s['slope']:.2f} (fit over "
            f"the converged sizes; {s['exhausted']} size(s) exhausted {a['max_sweeps']} sweeps): the load has to "
            f"cross the packing, whose height grows like N^0.5.  Warm-started after {a['warm_steps']} steps, "
            f"{s['warm'][0]}–{s['warm'][1]} sweeps suffice.  The interleaved order needs "
            f"{s['extra'][0]:.2f}–{s['extra'][1]:.2f} times the sweeps of the sorted order and "
            f"{s['time_ratio'][0]:.2f}–{s['time_ratio'][1]:.2f} times its wall time to the same residual.")


def ensemble_table(ens):
    return table(ens.to_dataframe())


def ensemble_sentence(ens):
    e, a = ens.to_dataframe(), ens.attrs
    same = "identical bit for bit" if bool((e.same_results == 1).all()) else "NOT identical"
    return (f"{a['runs']} zero-guess runs ({a['n_contacts']} contacts, mean {float(a['sweeps_mean']):.0f} sweeps, "
            f"{a['converged']} converged): speed-up **{float(e.speedup.iloc[-1]):.2f}×** on {int(e.index[-1])} "
            f"threads (target {TARGET_SPEEDUP:g}×); results {same} for every thread count.")


def peer_frame(peer):
    """The per-engine scalars of ``peer.nc``, one row per quantity, with its unit."""
    scalars = [v for v in peer.data_vars if peer[v].dims == ("engine",)]
    pt = peer[scalars].to_dataframe().T
    pt["unit"] = [peer[v].attrs.get("units", "") for v in pt.index]
    return pt


def peer_sentence(peer):
    cfg = yaml.safe_load(peer.attrs["config_yaml"])
    n_, p_ = peer.sel(engine="ncd"), peer.sel(engine="pymunk")

    def f(ds, k, scale=1.0):
        return float(ds[k]) * scale
    return (
        f"{cfg['n_discs']} discs poured one every {cfg['drop_every']} steps of {cfg['h'] * 1e3:g} ms, "
        f"{cfg['iterations']} Gauss–Seidel iterations per step in both (pymunk {peer.attrs['pymunk_version']}).  "
        f"Time per step: ncd **{f(n_, 'time_mean', 1e3):.3f} ms**, pymunk **{f(p_, 'time_mean', 1e3):.3f} ms** "
        f"(mean over the run; ratio {f(n_, 'time_mean') / f(p_, 'time_mean'):.2f}); with every disc in, "
        f"{f(n_, 'time_settle', 1e3):.3f} against {f(p_, 'time_settle', 1e3):.3f} ms.  "
        f"At rest the ground and walls carry {f(n_, 'ground_reaction'):.6f} (ncd) and "
        f"{f(p_, 'ground_reaction'):.6f} (pymunk) of the weight; Coulomb violation "
        f"{f(n_, 'coulomb_violation'):.1e} and {f(p_, 'coulomb_violation'):.1e}.  "
        f"Largest interpenetration over the run {f(n_, 'overlap_max'):.3f} d (ncd) and "
        f"{f(p_, 'overlap_max'):.3f} d (pymunk), at the end {f(n_, 'overlap_end'):.4f} d and "
        f"{f(p_, 'overlap_end'):.4f} d: Contact Dynamics does not correct positions, so a disc arriving "
        f"at speed v may sink by up to v h before its contact becomes active and keeps that overlap; "
        f"Chipmunk pushes overlaps out over later steps (its bias velocities), which also keeps its "
        f"pile creeping (final kinetic energy {f(p_, 'kinetic_energy'):.1e} against "
        f"{f(n_, 'kinetic_energy'):.1e} of Σ m g d).")


def tolerance_table(tol_ds):
    tt = tol_ds.to_dataframe().reset_index()
    return table(tt.pivot_table(index=["size", "tol"], columns="solver", values=["seconds", "sweeps", "converged"]))


def fastest_sentence(tol_ds):
    tt = tol_ds.to_dataframe().reset_index()
    fastest = tt.loc[tt.groupby(["size", "tol"]).seconds.idxmin()]
    return "Fastest to each tolerance: " + "; ".join(
        f"{r.size} discs, {r.tol:.0e}: {r.solver} ({r.seconds:.2f} s)" for r in fastest.itertuples()) + "."


def problems_table(tol_pb):
    tp = tol_pb.to_dataframe().reset_index()
    return table(tp.pivot_table(index=["problem", "tol", "order"], columns="solver", values=["seconds", "converged"]))


def reached_sentence(tol_pb):
    tp = tol_pb.to_dataframe().reset_index()
    reached = tp.groupby(["problem", "solver", "tol"]).converged.agg(["sum", "count"]).reset_index()
    return "Runs reaching each tolerance: " + "; ".join(
        f"{r.problem}, {r.solver}, {r.tol:.0e}: {int(r['sum'])} of {int(r['count'])}"
        for _, r in reached.iterrows()) + "."


def _range(values, fmt="d"):
    return f"{values.min():{fmt}}–{values.max():{fmt}}"


def local_frame(tol_pb):
    """Per problem and solver other than plain NLGS, at the tightest tolerance: runs converged,
    sweeps, speed-up over plain NLGS (runs where both converged), local solves, and the largest
    distance of the end point to plain NLGS's."""
    tight = float(tol_pb.tol.min())
    rows = []
    for problem in tol_pb.problem.values:
        d = tol_pb.sel(problem=problem, tol=tight)
        plain = d.sel(solver="nlgs")
        for solver in d.solver.values[1:]:
            e = d.sel(solver=solver)
            ok = (e.converged.values == 1) & (plain.converged.values == 1)
            speed = plain.seconds.values / e.seconds.values
            rows.append({"problem": problem, "solver": solver,
                         "converged": f"{int(e.converged.sum())} of {e.sizes['order']}",
                         "sweeps": _range(e.sweeps.values.astype(int)),
                         "plain NLGS sweeps": _range(plain.sweeps.values.astype(int)),
                         "speed-up": f"{speed[ok].min():.2g}–{speed[ok].max():.2g}" if ok.any() else "—",
                         "local solves": int(e.local_solves.max()),
                         "gap to plain NLGS (g h)": float(e.gap_to_nlgs.where(ok).max()) if ok.any() else np.nan})
    return pd.DataFrame(rows).set_index(["problem", "solver"])


def rules_frame(rules):
    rt = rules.to_dataframe()
    rt["name"] = rt.figure + "/" + rt.rule
    return rt


def rules_tables(rules):
    """The wall time and memory of every rule, and the sum of each figure's rules (HTML)."""
    rt = rules_frame(rules)
    per_figure = rt.groupby("figure").seconds.sum().to_frame("seconds (sum of the figure's rules)")
    return table(rt[["figure", "rule", "seconds", "max_rss_mb"]]), table(per_figure)


def rules_sentence(rules):
    rt = rules_frame(rules)
    return (f"{len(rt)} jobs, {rt.seconds.sum() / 60:.1f} CPU-job minutes in all (with -j2 two run at a time; "
            "the wall time of the whole run is in the README).")


def dag_tables(dag):
    """CPU and wall seconds per figure and the critical path (HTML), and the sentence."""
    per_fig, path, text = dag_summary(dag)
    return table(per_fig, digits=4), table(path, digits=4, index=False), text


def profile_frame(profile, dag=None):
    """Per figure of ``profile.nc`` (:mod:`ncd.studies.bench.profile`): its job CPU (core
    seconds) and its jobs' seconds on the critical path in the run of ``dag.nc`` (when
    given), then from the profiled run the samples, the share (%) of each category, kernels
    and solvers together, the goal's status (:func:`~ncd.studies.bench.profile.goal_status`)
    and the sampled CPU over the jobs' wall time (how much of the jobs' time the samples saw)."""
    df = pd.DataFrame(index=pd.Index(profile.figure.values.astype(str), name="figure"))
    if dag is not None:
        jobs = dag.to_dataframe()
        df["job CPU (s)"] = jobs.groupby("figure").cpu_s.sum().reindex(df.index)
        df["on the critical path (s)"] = jobs[jobs.critical == 1].groupby("figure").alone_s.sum() \
            .reindex(df.index).fillna(0.0)
        df.loc[df.index == NOT_A_JOB, "on the critical path (s)"] = np.nan
    df["samples"] = profile.samples.values
    for name, var in (("kernels", "kernel_share"), ("LP solvers", "solver_share"),
                      ("other compiled", "compiled_share"), ("Python", "python_share")):
        df[f"{name} (%)"] = 100 * profile[var].values
    df["kernels + solvers (%)"] = df["kernels (%)"] + df["LP solvers (%)"]
    df[f"goal (≥ {100 * float(profile.attrs['goal']):.0f} %)"] = goal_status(profile)
    if "job_wall_s" in profile:
        df["sampled CPU / job wall"] = profile.sampled_cpu_s.values / profile.job_wall_s.values
    return df


def hot_spots_frame(profile, top=3):
    """Per figure, its ``top`` innermost Python functions outside kernels and solvers, each
    with its share (%) of the figure's samples: where its Python and other compiled time is
    spent."""
    rows = {}
    for k, fig in enumerate(profile.figure.values.astype(str)):
        names, shares = profile.hot_function.values[k], profile.hot_share.values[k]
        rows[fig] = [f"{n} — {100 * x:.0f} %" if n else "" for n, x in zip(names[:top], shares[:top])]
    return pd.DataFrame.from_dict(rows, orient="index", columns=[str(r) for r in range(1, top + 1)]) \
        .rename_axis("figure")


def profile_sentence(profile):
    """The profiled run, the figures meeting the goal, and where the figure furthest from it
    spends the rest (Python, other compiled code, imports, numba's dispatch and cache loading)."""
    a = profile.attrs
    status = dict(zip(profile.figure.values.astype(str), goal_status(profile)))
    judged = [f for f, s in status.items() if s in ("met", "not met")]
    met = [f for f in judged if status[f] == "met"]
    inside = dict(zip(profile.figure.values.astype(str), (profile.kernel_share + profile.solver_share).values))
    text = (f"Profiled run: the {a.get('config_label', 'full')} counts, {float(a['rate']):g} samples per second, "
            f"{int(profile.samples.sum())} samples (py-spy could not read {int(a.get('pyspy_errors', 0))} stacks).  "
            f"{len(met)} of {len(judged)} figures with at least {int(a['min_samples'])} samples hold "
            f"{100 * float(a['goal']):.0f} % or more of their CPU inside kernels and LP solvers")
    if judged:
        worst = min(judged, key=inside.get)
        w = profile.sel(figure=worst)
        text += (f"; the furthest from it, {worst}, holds {100 * inside[worst]:.0f} % there and spends "
                 f"{100 * float(w.python_share):.0f} % in Python and {100 * float(w.compiled_share):.0f} % in other "
                 f"compiled code (imports {100 * float(w.import_share):.0f} %, numba's dispatch and cache loading "
                 f"{100 * float(w.numba_load_share):.0f} %, across categories)")
    if NOT_A_JOB in status:
        text += f".  Snakemake's own process: {float(profile.sampled_cpu_s.sel(figure=NOT_A_JOB)):.0f} s of CPU sampled"
    return text + "."


def exact_frame(costs):
    """Per size and history: piles, contacts, LPs per pile, the LP solver, and the LP time per
    pile (median and largest) of the exact angle ranges (:func:`ncd.studies.bench.solver.exact_costs`)."""
    df = costs.to_dataframe()
    g = df.groupby(["grains", "history"])
    return pd.DataFrame({"piles": g.size(), "contacts (mean)": g.n_contacts.mean().round().astype(int),
                         "cuts per pile": g.n_cuts.max(), "LPs per pile (mean)": g.n_lp.mean(),
                         "solver": g.solver.agg(lambda v: ", ".join(sorted(set(v)))),
                         "LP seconds per pile (median)": g.lp_seconds.median(),
                         "LP seconds per pile (largest)": g.lp_seconds.max()})


def exact_sentence(costs):
    """The LP time of one pile's exact angle ranges at each size computed, in one sentence."""
    frame = exact_frame(costs).reset_index()
    sizes = sorted(set(frame.grains))
    def pile(r):
        if r["piles"] == 1:
            return f"{r['history']} {number(r['LP seconds per pile (median)'], 2)} s (1 pile)"
        return (f"{r['history']} {number(r['LP seconds per pile (median)'], 2)} s (largest "
                f"{number(r['LP seconds per pile (largest)'], 2)} s, {r['piles']} piles)")

    parts = [", ".join(pile(r) for _, r in frame[frame.grains == n].iterrows()) + f" at {int(n)} grains"
             for n in sizes]
    text = "The exact angle ranges of one pile take, in LP time per pile (median): " + "; ".join(parts) + "."
    if len(sizes) < 2:
        text += (" No pile of another size has exact ranges in this run: the size study "
                 "(`snakemake -j2 fig4_history_size`, `config/large.yaml`: 10^4 grains) adds them.")
    return text


def _legend_below(ax, ncol=1):
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=ncol, frameon=False, fontsize=9)


def plot(core, sweeps, rules, top=15):
    """(a) time per contact update of the sweep, numba, C and interleaved; (b) time per step,
    preparation and detection against N; (c) sweeps against N; (d) the ``top`` slowest rules."""
    import matplotlib.pyplot as plt

    plt.rcParams.update({"font.size": 9.5})
    tab, sw = core_frame(core), sweeps.to_dataframe()
    fig, axes = plt.subplots(2, 2, figsize=(10, 10), layout="constrained")

    ax = axes[0, 0]
    ax.plot(tab.n_discs, tab.ns_per_update, "o-", label="ncd (numba)")
    ax.plot(tab.n_discs, tab.ns_per_update_c, "s--", label="same loop in C (gcc -O3 -ffp-contract=off)")
    ax.plot(tab.n_discs, tab.ns_per_update_interleaved, "^:", label="ncd, interleaved review order")
    ax.axhline(TARGET_NS, color="k", lw=0.8, ls=":", label=f"target {TARGET_NS:g} ns")
    ax.set_xscale("log")
    ax.set_ylim(0, None)
    ax.set(xlabel="discs", ylabel="ns per contact update", title="(a) NLGS sweep")
    _legend_below(ax)

    ax = axes[0, 1]
    ax.loglog(tab.n_discs, tab.step_s, "o-", label="step (warm, fixed budget)")
    ax.loglog(tab.n_discs, tab.prepare_s, "s-", label="step preparation (detection, W, q)")
    ax.loglog(tab.n_discs, tab.detect_s, "^-", label="detection")
    n = np.array([tab.n_discs.min(), tab.n_discs.max()], float)
    ax.loglog(n, tab.step_s.iloc[0] * n / n[0], "k:", lw=0.8, label="∝ N")
    ax.set(xlabel="discs", ylabel="s", title="(b) time per step")
    _legend_below(ax)

    ax = axes[1, 0]
    ax.loglog(sw.index, sw.sweeps_zero, "o-", label="zero guess")
    ax.loglog(sw.index, sw.sweeps_interleaved, "^--", label="zero guess, interleaved order")
    ax.loglog(sw.index, sw.sweeps_warm, "s-", label="warm start")
    ax.set(xlabel="discs", ylabel=f"sweeps to residual {sweeps.attrs['tol']:g}", title="(c) sweeps against N")
    _legend_below(ax)

    ax = axes[1, 1]
    slow = rules_frame(rules).sort_values("seconds", ascending=False).head(top)
    ax.barh(slow.name, slow.seconds)
    ax.invert_yaxis()
    ax.set(xlabel="s", title="(d) slowest rules of the figures' run")
    ax.tick_params(axis="y", labelsize=9)
    return fig
