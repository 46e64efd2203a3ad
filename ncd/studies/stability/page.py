"""The stability page: its figure, its sentences and its table, from ``stability/table.nc``.

The page states what the table shows, including what it does not credit: a CD run that
stays bounded can still be wrong (it sinks by a tenth of a radius, tunnels through a
disc or stops NLGS at its sweep budget), so every count of usable CD runs says how many
bounded runs it leaves out and why (:func:`inaccurate`, the rule the index uses too).
"""
import numpy as np

STATUS_COLOURS = {"stable": "tab:green", "energy grows": "tab:orange", "diverged": "tab:red"}
PENETRATION_LIMIT = 0.1      # interpenetration / smallest radius above which a run is inaccurate


def inaccurate(tab):
    """Per run: stable but not accurate (interpenetration > 0.1 r, tunnelling, or NLGS
    stopped at its sweep budget on some step)."""
    return (tab.stable.values == 1) & ((tab.max_penetration.values > PENETRATION_LIMIT)
                                       | (tab.tunnelled.values == 1) | (tab.unconverged_steps.values > 0))


def status(tab):
    """Per run: ``stable``, ``energy grows`` (growth above the tolerance) or ``diverged``."""
    return np.where(tab.stable.values == 1, "stable",
                    np.where(tab.diverged.values == 1, "diverged", "energy grows"))


def counts(tab):
    """The numbers the page's sentences quote, per method and per reason of inaccuracy."""
    method = tab.method.values.astype(str)
    cd, md = method == "CD", method == "MD"
    bad = inaccurate(tab)
    stable = tab.stable.values == 1
    ratio = tab.h_over_hcrit.values
    accurate = cd & stable & ~bad
    md_unstable = md & ~stable
    return {
        "cd": int(cd.sum()), "md": int(md.sum()), "runs": len(method),
        "cd_bounded": int((cd & (tab.diverged.values == 0)).sum()), "cd_stable": int((cd & stable).sum()),
        "cd_inaccurate": int((cd & bad).sum()), "cd_accurate": int(accurate.sum()),
        "pen": int((cd & stable & (tab.max_penetration.values > PENETRATION_LIMIT)).sum()),
        "tunnel": int((cd & stable & (tab.tunnelled.values == 1)).sum()),
        "budget": int((cd & stable & (tab.unconverged_steps.values > 0)).sum()),
        "cd_accurate_max_ratio": float(ratio[accurate].max()) if accurate.any() else float("nan"),
        "md_unstable": int(md_unstable.sum()),
        "md_unstable_min_ratio": float(ratio[md_unstable].min()) if md_unstable.any() else float("nan"),
        "md_stable_max_ratio": float(ratio[md & stable].max()) if (md & stable).any() else float("nan"),
        "nan": int(tab.nan.values.sum()),
    }


def caveat_sentence(tab):
    """The page's own caveat: how many bounded CD runs are not accurate, and why."""
    c = counts(tab)
    return (f"Of the {c['cd']} CD runs, {c['cd_bounded']} stay bounded and {c['cd_stable']} are stable, but "
            f"**{c['cd_inaccurate']} of the stable ones are not accurate**: {c['pen']} sink by more than "
            f"{PENETRATION_LIMIT:g} r into a neighbour, {c['tunnel']} tunnel through a disc and {c['budget']} stop "
            f"NLGS at its sweep budget on some step (a run may have several of these faults). "
            f"That leaves {c['cd_accurate']} accurate CD runs, up to h = {c['cd_accurate_max_ratio']:.3g} h_crit "
            f"of MD. {c['md_unstable']} of the {c['md']} MD runs are unstable (diverged, or energy grown by more "
            f"than the tolerance), the first at h = {c['md_unstable_min_ratio']:.3g} h_crit; the largest stable "
            f"MD step is {c['md_stable_max_ratio']:.3g} h_crit. {c['nan']} runs met a non-finite state "
            f"(a flag in the file; no stored value is NaN).")


def _fmt_list(pairs):
    return ", ".join(f"{v:.2g} at h = {h:.0e} s" for h, v in pairs)


def case_notes(tab):
    """Markdown list: per case, where CD is not accurate and the measured reason."""
    case, method = tab.case.values.astype(str), tab.method.values.astype(str)
    bad = inaccurate(tab)
    out = []
    for name in dict.fromkeys(case):
        cd = (case == name) & (method == "CD")
        md = (case == name) & (method == "MD")
        md_ok = md & (tab.stable.values == 1)
        line = (f"* `{name}`: MD stable up to h = "
                + (f"{tab.h_over_hcrit.values[md_ok].max():.3g} h_crit" if md_ok.any() else "none of the tested steps")
                + f"; CD interpenetration / r {_fmt_list(zip(tab.h.values[cd], tab.max_penetration.values[cd]))}")
        if (tab.unconverged_steps.values[cd] > 0).any():
            line += (f"; {int(tab.unconverged_steps.values[cd].sum())} CD steps stopped at the sweep budget "
                     f"(largest residual {tab.residual_max.values[cd].max():.1e})")
        if (tab.tunnelled.values[cd] == 1).any():
            line += "; tunnelled at h = " + ", ".join(f"{h:.0e} s" for h in tab.h.values[cd & (tab.tunnelled.values == 1)])
        line += f" ({int((cd & bad).sum())} of {int(cd.sum())} CD runs inaccurate)."
        out.append(line)
    return "\n".join(out)


def chain_sentence(tab):
    """The e = 1 chain: energy kept, but the striker's momentum shared (not Newton's cradle)."""
    sel = (tab.case.values.astype(str) == "e1_chain") & (tab.method.values.astype(str) == "CD")
    if not sel.any():
        return "The e = 1 chain was not run."
    obs = tab.observable.values[sel]
    speeds = f"{obs.min():.2g}" if np.isclose(obs.min(), obs.max(), rtol=5e-3) else f"{obs.min():.2g}–{obs.max():.2g}"
    return (f"In the e = 1 chain ({int(sel.sum())} CD runs) the energy drifts by at most "
            f"{np.abs(tab.energy_drift.values[sel]).max():.1g} E_s, but the last disc leaves at "
            f"{speeds} of the striker's speed, where Newton's cradle gives 1: the touching "
            f"chain is one simultaneous multicontact collision, not a sequence of binary ones.")


def summary_table(tab):
    """One row per case and method (formatted strings): steps tried, stable, inaccurate, diverged."""
    import pandas as pd

    case, method = tab.case.values.astype(str), tab.method.values.astype(str)
    bad, st = inaccurate(tab), status(tab)
    rows = []
    for name in dict.fromkeys(case):
        for m in ("CD", "MD"):
            sel = (case == name) & (method == m)
            if not sel.any():
                continue
            r = tab.h_over_hcrit.values[sel]
            rows.append({"case": name, "method": m, "h / h_crit": f"{r.min():.2g} – {r.max():.2g}",
                         "runs": int(sel.sum()), "stable": int((st[sel] == "stable").sum()),
                         "of which inaccurate": int(bad[sel].sum()),
                         "energy grows": int((st[sel] == "energy grows").sum()),
                         "diverged": int((st[sel] == "diverged").sum())})
    return pd.DataFrame(rows)


def _symlog_ticks(lo, hi, linthresh):
    """Ticks every other decade on a symlog axis, so that labels never touch."""
    ticks = [0.0]
    for sign, bound in ((1, hi), (-1, lo)):
        top = abs(bound)
        if top <= linthresh:
            continue
        decades = np.arange(np.floor(np.log10(linthresh)), np.ceil(np.log10(top)) + 1)
        step = max(1, int(np.ceil(len(decades) / 4)))
        ticks += [sign * 10.0 ** d for d in decades[::step]]
    return sorted(ticks)


def plot(tab, energy_tolerance=0.05):
    """The four panels: (a) status per case and step, (b) interpenetration, (c) energy
    drift, (d) the e = 1 chain's energy over time.  Returns the figure."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    plt.rcParams.update({"font.size": 9.5})
    case, method = tab.case.values.astype(str), tab.method.values.astype(str)
    cases = list(dict.fromkeys(case))
    st, bad, ratio = status(tab), inaccurate(tab), tab.h_over_hcrit.values
    colours = np.array([STATUS_COLOURS[s] for s in st])
    fig, axes = plt.subplots(2, 2, figsize=(10, 8.4), layout="constrained")
    markers = {"CD": "o", "MD": "s"}

    ax = axes[0, 0]
    row = np.array([cases.index(c) for c in case])
    for m, dy in (("CD", -0.17), ("MD", 0.17)):
        sel = method == m
        ax.scatter(ratio[sel], row[sel] + dy, marker=markers[m], s=45, c=colours[sel], edgecolor="k", lw=0.5)
        ax.scatter(ratio[sel & bad], row[sel & bad] + dy, marker="x", s=35, color="k", lw=1.2)
    ax.axvline(1.0, color="k", lw=0.8, ls="--")
    ax.set_xscale("log")
    ax.set_yticks(range(len(cases)), cases)
    ax.set_ylim(len(cases) - 0.5, -0.5)
    ax.set_xlabel(r"$h / h_\mathrm{crit}$ ($h_\mathrm{crit} = 2/\omega$ of MD)")
    ax.set_title("(a) each run: CD above, MD below its case", fontsize=10)

    floor = 1e-16
    ax = axes[0, 1]
    for m in ("CD", "MD"):
        sel = method == m
        ax.scatter(ratio[sel], np.maximum(tab.max_penetration.values[sel], floor), marker=markers[m], s=30,
                   c=colours[sel], edgecolor="k", lw=0.5)
    ax.axhline(PENETRATION_LIMIT, color="k", lw=0.8, ls=":")
    ax.axhline(2.0, color="k", lw=0.8, ls="--")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$h / h_\mathrm{crit}$")
    ax.set_ylabel("largest interpenetration / r")
    ax.set_title("(b) interpenetration (dotted: 0.1 r; dashed: a diameter)", fontsize=10)

    ax = axes[1, 0]
    drift = tab.energy_drift.values
    for m in ("CD", "MD"):
        sel = method == m
        ax.scatter(ratio[sel], np.maximum(np.abs(drift[sel]), floor), marker=markers[m], s=30, c=colours[sel],
                   edgecolor="k", lw=0.5)
    gain = drift > 0
    ax.scatter(ratio[gain], np.maximum(drift[gain], floor), marker="+", s=70, color="k", lw=1)
    ax.axhline(energy_tolerance, color="k", lw=0.8, ls=":")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$h / h_\mathrm{crit}$")
    ax.set_ylabel(r"$|E_\mathrm{end} - E_0| / E_s$")
    ax.set_title("(c) energy drift (+: energy gained; dotted: tolerance)", fontsize=10)

    ax = axes[1, 1]
    chain = np.nonzero(case == "e1_chain")[0]
    lo = hi = 0.0
    for k, i in enumerate(chain):
        n = int(tab.trace_points.values[i])
        if n < 2:
            continue
        y = tab.trace.values[i, :n]
        lo, hi = min(lo, y.min()), max(hi, y.max())
        ax.plot(np.linspace(0, 1, n + 1)[1:], y, "-" if method[i] == "CD" else "--", color=f"C{k % 10}",
                label=f"{method[i]}, h = {ratio[i]:.2g} h_crit")
    linthresh = 1e-6
    ax.set_yscale("symlog", linthresh=linthresh)
    ax.set_yticks(_symlog_ticks(lo, hi, linthresh))
    ax.set_xlabel("t / duration")
    ax.set_ylabel(r"$(E - E_0)/E_s$")
    ax.set_title("(d) e = 1 chain: energy over time", fontsize=10)
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)

    handles = [Line2D([], [], ls="", marker="o", mfc=c, mec="k", label=s) for s, c in STATUS_COLOURS.items()]
    handles += [Line2D([], [], ls="", marker="x", color="k", label="stable, inaccurate"),
                Line2D([], [], ls="", marker="o", mfc="w", mec="k", label="CD"),
                Line2D([], [], ls="", marker="s", mfc="w", mec="k", label="MD")]
    fig.legend(handles=handles, loc="outside lower center", ncol=6, fontsize=9, frameon=False)
    return fig


def caption(tab):
    """The Snakemake report's caption (reStructuredText): the figure's finding, from the data."""
    c = counts(tab)
    return (f"**Stability (section 2).** Contact Dynamics stays bounded in {c['cd_bounded']} of {c['cd']} runs, up "
            f"to far above the critical step of molecular dynamics, but {c['cd_inaccurate']} of its stable runs are "
            f"inaccurate ({c['pen']} sink by more than {PENETRATION_LIMIT:g} r, {c['tunnel']} tunnel, {c['budget']} "
            f"reach the sweep budget); its accurate runs go up to h = {c['cd_accurate_max_ratio']:.3g} h_crit. "
            f"Molecular dynamics is unstable in {c['md_unstable']} of {c['md']} runs, from h = "
            f"{c['md_unstable_min_ratio']:.3g} h_crit. Details: ``results/html/stability.html``.\n")
