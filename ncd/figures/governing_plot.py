"""Panels of figure 5 (issue 15): eta(mu) exact and Unger et al.'s way, dimensions, coordination."""
import matplotlib.pyplot as plt
import numpy as np

from .governing import KINDS, eta_table

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
    ax.set(xscale="log", xlabel="μ", ylabel="2κ / N", title="(c) coordination")
    ax.legend(fontsize=7)


def panel_unger_vs_exact(ax, ds):
    """(d) per packing: Unger et al.'s eta against the exact one (coloured by mu)."""
    sc = ax.scatter(ds.eta_exact.values, ds.eta_unger.values, c=np.log10(ds.mu.values), s=14, cmap="viridis")
    lim = [np.nanmin(ds.eta_unger.values) * 0.8, np.nanmax(ds.eta_exact.values) * 1.2]
    ax.plot(lim, lim, "k:", lw=1)
    ax.set(xscale="log", yscale="log", xlabel="η exact", ylabel="η Unger et al.'s way",
           title="(d) sampled against exact")
    plt.colorbar(sc, ax=ax, label="log10 μ")


def figure(ds):
    fig, axes = plt.subplots(2, 2, figsize=(10, 8), constrained_layout=True)
    panel_eta(axes[0, 0], ds)
    panel_dimension(axes[0, 1], ds)
    panel_coordination(axes[1, 0], ds)
    panel_unger_vs_exact(axes[1, 1], ds)
    return fig
