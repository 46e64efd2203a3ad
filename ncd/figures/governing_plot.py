"""Panels of Figure 5: eta(mu) exact and Unger et al.'s way, dimensions, coordination
(packings); indeterminate flow steps against mu, h and slope, and why a line (flows).
"""
import matplotlib.pyplot as plt
import numpy as np

from ncd.figures.governing import KINDS, eta_table
from ncd.figures.governing_summary import factor_table, line_counts

UNGER_PEAK_MU = 0.1     # Unger, Kertész & Wolf (2005): eta peaks near mu = 0.1, eta ∝ mu below


def _band(ax, table, label, color, marker="o"):
    ok = np.isfinite(table[:, 1])
    t = table[ok]
    ax.plot(t[:, 0], t[:, 1], marker=marker, color=color, label=label)
    half = np.nan_to_num(t[:, 2])
    ax.fill_between(t[:, 0], t[:, 1] - half, t[:, 1] + half, color=color, alpha=0.2, lw=0)


def panel_eta(ax, ds, kinds=None):
    """(a) eta against mu with 95 % bands over packings; the published peak marked."""
    colors = {"plates": ("C0", "C1"), "box": ("C2", "C3")}
    for k in kinds or sorted(set(ds.kind.values.tolist())):
        name = KINDS[k]
        _band(ax, eta_table(ds, "eta_exact", k), f"exact, {name}", colors[name][0])
        _band(ax, eta_table(ds, "eta_unger", k), f"Unger et al.'s way, {name}", colors[name][1], "s")
    ax.axvline(UNGER_PEAK_MU, color="k", ls=":", lw=1, label="Unger et al.: peak")
    t = eta_table(ds, "eta_unger", 0)
    if len(t) > 1 and np.isfinite(t[0, 1]):       # slope-1 guide through the smallest mu
        ax.plot(t[:3, 0], t[0, 1] * t[:3, 0] / t[0, 0], "k--", lw=1, label="∝ μ")
    ax.set(xscale="log", yscale="log", xlabel="μ", ylabel="η", title="(a) indeterminacy η(μ)")
    ax.legend(fontsize=7)


def panel_dimension(ax, ds):
    """(b) dim (A ∩ C) / 2 kappa and the fraction of contacts fixed by statics."""
    for k in sorted(set(ds.kind.values.tolist())):
        _band(ax, eta_table(ds, "dim_ratio", k), f"dim(A∩C)/2κ, {KINDS[k]}", f"C{2 * k}")
        _band(ax, eta_table(ds, "fixed_fraction", k), f"fixed contacts, {KINDS[k]}", f"C{2 * k + 1}", "s")
    ax.set(xscale="log", xlabel="μ", ylabel="fraction", ylim=(0, None), title="(b) dimension, determinacy")
    ax.legend(fontsize=7)


def panel_coordination(ax, ds):
    """(c) coordination 2 kappa / N against mu (Unger et al.: eta falls as it drops)."""
    for k in sorted(set(ds.kind.values.tolist())):
        _band(ax, eta_table(ds, "coordination", k), KINDS[k], f"C{2 * k}")
    ax.axhline(3.0, color="k", ls=":", lw=1, label="z = 3 (bulk isostatic, μ → ∞)")
    ax.axhline(4.0, color="k", ls="--", lw=1, label="z = 4 (bulk isostatic, μ = 0)")
    ax.set(xscale="log", xlabel="μ", ylabel="2κ / N", title="(b) coordination")
    ax.legend(fontsize=7)


def panel_unger_vs_exact(ax, ds):
    """(d) per packing: Unger et al.'s eta against the exact one (coloured by mu)."""
    sc = ax.scatter(ds.eta_exact.values, ds.eta_unger.values, c=np.log10(ds.mu.values), s=14, cmap="viridis")
    lim = [np.nanmin(ds.eta_unger.values) * 0.8, np.nanmax(ds.eta_exact.values) * 1.2]
    ax.plot(lim, lim, "k:", lw=1)
    ax.set(xscale="log", yscale="log", xlabel="η exact", ylabel="η Unger et al.'s way",
           title="(a) sampled against exact")
    plt.colorbar(sc, ax=ax, label="log10 μ")


FACTOR_LABEL = {"mu": ("μ", "linear"), "h": ("h (s)", "log"), "slope": ("slope (°)", "linear")}


def panel_flows(ax, flows, factor):
    """(c) fraction of indeterminate scanned steps (left) and the mean largest spread of a
    grain's acceleration (right, / |g|) against one factor, 95 % bands over the seeds."""
    label, scale = FACTOR_LABEL[factor]
    t = factor_table(flows, factor, "indeterminate")
    band = np.nan_to_num(t[:, 2])
    ax.errorbar(t[:, 0], t[:, 1], yerr=[np.minimum(band, t[:, 1]), np.minimum(band, 1 - t[:, 1])], marker="o",
                color="C0", capsize=3, label="indeterminate steps (band clipped to [0, 1])")
    u = factor_table(flows, factor, "unknown")
    ax.plot(u[:, 0], u[:, 1], "x:", color="0.5", label="unknown (unconverged)")
    ax.set(xscale=scale, xlabel=label, ylabel="fraction of scanned steps", ylim=(-0.02, 1.02),
           title=f"(c) flows against {label.split()[0]}")
    base = {"mu": flows.mu, "h": flows.h, "slope": flows.slope_deg}[factor].values[flows.factor.values == 0]
    if len(base):
        ax.axvline(base[0], color="k", lw=0.8, ls=":", label="Figure 2's setting")
    tw = ax.twinx()
    sp = factor_table(flows, factor, "spread")
    ok = np.isfinite(sp[:, 1]) & (sp[:, 1] > 0)
    if ok.any():
        half = np.nan_to_num(sp[ok, 2])
        low = np.minimum(half, 0.9 * sp[ok, 1])          # a log axis: the band stops above zero
        tw.errorbar(sp[ok, 0], sp[ok, 1], yerr=[low, half], marker="s", color="C3", capsize=3)
        tw.set_yscale("log")
    tw.set_ylabel("mean largest spread / |g|", color="C3")
    ax.legend(fontsize=7, loc="upper left")


def panel_line(ax, flows):
    """(d) ranks of the grain's acceleration cloud at the indeterminate steps, split by the
    cluster test (the grain's cluster has one degree of freedom, or more)."""
    ind = flows.indeterminate.values == 1
    rank, pred = flows.cloud_rank.values[ind], flows.predicted_line.values[ind] == 1
    x = np.arange(3)
    one = [int(((rank == r) & pred).sum()) for r in x]
    more = [int(((rank == r) & ~pred).sum()) for r in x]
    ax.bar(x - 0.2, one, 0.4, label="cluster with 1 degree of freedom")
    ax.bar(x + 0.2, more, 0.4, label="cluster with more")
    c = line_counts(flows)
    ax.set(xticks=x, xticklabels=["point", "line", "area"], ylabel="indeterminate steps",
           title=f"(d) why a line: hypothesis holds at {c['holds']} of {c['steps']}")
    ax.legend(fontsize=7, loc="upper left")


def figure(ds, flows=None):
    rows = 1 if flows is None else 2
    fig, axes = plt.subplots(rows, 4, figsize=(18, 4.2 * rows), constrained_layout=True, squeeze=False)
    panel_eta(axes[0, 0], ds)
    panel_dimension(axes[0, 1], ds)
    panel_coordination(axes[0, 2], ds)
    panel_unger_vs_exact(axes[0, 3], ds)
    if flows is not None:
        for ax, factor in zip(axes[1, :3], ("mu", "h", "slope")):
            panel_flows(ax, flows, factor)
        panel_line(axes[1, 3], flows)
    return fig
