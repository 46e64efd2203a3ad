"""Panels of Figure 5 (beyond the paper): Unger et al.'s eta_U on their random walk and on a
uniform sample beside the exact range ratio, the control series, coordination, convergence
of the walk, centrality of the history state (packings); indeterminate flow steps against
mu, h and slope, and why a line (flows).  Every line is in a legend, legends sit outside
the data (below each panel), panel letters are unique.
"""
import matplotlib.pyplot as plt
import numpy as np

from ncd.figures.fig5_governing.measure import eta_table, mixed_only
from ncd.figures.fig5_governing.summary import factor_table, fraction_table, line_counts
from ncd.figures.fig5_governing.unger import eta_curve

UNGER_PEAK_MU = 0.1     # Unger, Kertész & Wolf (2005): eta peaks near mu = 0.1, eta ∝ mu below
TITLE = "Beyond the paper: governing parameters of indeterminacy"
SERIES = {"eta_walk": ("η_U, their random walk", "C0", "o"),
          "eta_uniform": ("η_U, uniform sample (chains agree)", "C1", "s"),
          "eta_exact": ("exact range ratio (not η_U)", "0.45", "^")}


def _legend(ax, ncol=1):
    ax.legend(fontsize=12, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=ncol, frameon=False)


def _log_or_empty(ax, has_data, axes="xy"):
    """Log scales when there is something positive to draw, else one sentence (a run where
    every slice is determinate has no positive eta to put on a log axis)."""
    if has_data:
        for a in axes:
            getattr(ax, f"set_{a}scale")("log")
    else:
        ax.text(0.5, 0.5, "no non-zero value in this run", transform=ax.transAxes, ha="center")


def _band(ax, table, label, color, marker="o", ls="-"):
    ok = np.isfinite(table[:, 1]) & (table[:, 1] > 0)
    t = table[ok]
    if not len(t):
        return False
    ax.plot(t[:, 0], t[:, 1], marker=marker, color=color, ls=ls, label=label)
    half = np.nan_to_num(t[:, 2])
    ax.fill_between(t[:, 0], np.maximum(t[:, 1] - half, 0.2 * t[:, 1]), t[:, 1] + half, color=color, alpha=0.2,
                    lw=0)
    return True


def panel_eta(ax, ds, kind, letter, title):
    """eta_U (walk and uniform) and the exact range ratio against mu, 95 % bands over packings."""
    drawn = [_band(ax, eta_table(ds, var, kind), label, color, marker) for var, (label, color, marker)
             in SERIES.items()]
    ax.axvline(UNGER_PEAK_MU, color="k", ls=":", lw=1, label="Unger et al.: peak near μ = 0.1")
    t = eta_table(ds, "eta_walk", kind)
    ok = np.isfinite(t[:, 1]) & (t[:, 1] > 0)
    if ok.sum() > 1:                               # slope-1 guide through the smallest mu with data
        i = int(np.argmax(ok))
        ax.plot(t[i:i + 3, 0], t[i, 1] * t[i:i + 3, 0] / t[i, 0], "k--", lw=1, label="∝ μ (Unger et al.)")
    ax.set(xlabel="μ", ylabel="η", title=f"({letter}) {title}")
    _log_or_empty(ax, any(drawn))
    _legend(ax)


def panel_coordination(ax, ds, letter):
    """z without rattlers in the slice against mu, both series; isostatic values."""
    for kind, (label, color) in enumerate((("built at μ", "C0"), ("built frictionless", "C2"))):
        _band(ax, eta_table(ds, "z", kind), label, color)
    ax.axhline(3.0, color="k", ls=":", lw=1, label="z = 3 (isostatic, μ → ∞)")
    ax.axhline(4.0, color="k", ls="--", lw=1, label="z = 4 (isostatic, μ = 0)")
    ax.set(xscale="log", xlabel="μ", ylabel="z (rattlers left out)", title=f"({letter}) coordination in the slice")
    _legend(ax)


def panel_convergence(ax, ds, letter):
    """eta_U of the walk over its first n samples / its value over all, per packing (plates)."""
    cmap = plt.get_cmap("viridis")
    mus = np.unique(ds.mu.values)
    lo = np.log(mus.min())
    span = max(np.log(mus.max()) - lo, 1e-12)
    for j in np.nonzero(ds.kind.values == 0)[0]:
        ok = ds.walk_point.values[j] == 1
        s = np.stack([ds.walk_n.values[j][ok], ds.walk_t.values[j][ok]], axis=-1)
        k = int(ds.n_contacts[j])
        if len(s) < 4 or not np.isfinite(ds.eta_walk[j]) or ds.eta_walk[j] <= 0:
            continue
        n = np.arange(3, len(s) + 1)
        c = eta_curve(s[:, :k], n) / float(ds.eta_walk[j])
        ax.plot(n, c, color=cmap((np.log(ds.mu.values[j]) - lo) / span), lw=1)
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(np.log10(mus.min()), np.log10(mus.max())))
    plt.colorbar(sm, ax=ax, label="log10 μ")
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="value over all samples")
    ax.set(xlabel="samples of the walk", ylabel="η_U(n) / η_U(all)", title=f"({letter}) convergence of the walk")
    _legend(ax)


def panel_centrality(ax, ds, letter):
    """Distance to the centre of A ∩ C (RMS per contact / <|F|>): history state, walk samples,
    uniform samples, per packing against mu (plates)."""
    sel = (ds.kind.values == 0) & np.isfinite(ds.history_distance.values) & (ds.dim_AC_rank.values > 0)
    for var, label, color, marker in (("history_distance", "history (built) state", "C3", "o"),
                                      ("walk_distance", "random-walk samples (mean)", "C0", "x"),
                                      ("uniform_distance", "uniform samples (mean)", "C1", "s")):
        v = ds[var].values[sel]
        pos = v > 0
        ax.plot(ds.mu.values[sel][pos], v[pos], marker, color=color, ls="none", label=label, mfc="none")
    ax.set(xlabel="μ", ylabel="distance to the centre / ⟨|F|⟩", title=f"({letter}) centrality of the history state")
    _log_or_empty(ax, bool(sel.any()))
    _legend(ax)


FACTOR_LABEL = {"mu": ("μ", "linear"), "h": ("h (s)", "log"), "slope": ("slope (°)", "linear")}


def panel_flows(ax, flows, factor, letter):
    """Fraction of indeterminate steps among those of known outcome (left, 95 % Wilson interval
    over the steps, seeds pooled) and the mean largest spread of a grain's acceleration (right,
    / |g|, 95 % band over the seeds) against one factor."""
    label, scale = FACTOR_LABEL[factor]
    t = fraction_table(flows, factor, "indeterminate")
    ax.errorbar(t[:, 0], t[:, 1], yerr=[t[:, 1] - t[:, 2], t[:, 3] - t[:, 1]], marker="o",
                color="C0", capsize=3, label="indeterminate steps (95 % Wilson)")
    u = fraction_table(flows, factor, "unknown")
    ax.plot(u[:, 0], u[:, 1], "x:", color="0.5", label="unknown (unconverged)")
    ax.set(xscale=scale, xlabel=label, ylabel="fraction of scanned steps", ylim=(-0.02, 1.02),
           title=f"({letter}) flows against {label.split()[0]}")
    ax.set_xticks(t[:, 0], [f"{v:g}" for v in t[:, 0]])         # the settings only: no crowded minor labels
    ax.xaxis.set_minor_formatter(plt.NullFormatter())
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
        ax.plot([], [], "s-", color="C3", label="mean largest spread / |g| (right axis)")
    tw.tick_params(axis="y", labelsize=12, colors="C3")
    _legend(ax)


def panel_line(ax, flows, letter):
    """Ranks of the grain's acceleration cloud at the indeterminate steps, split by the
    cluster test (the grain's cluster has one degree of freedom, or more)."""
    ind = flows.indeterminate.values == 1
    rank, pred = flows.cloud_rank.values[ind], flows.predicted_line.values[ind] == 1
    x = np.arange(3)
    ax.bar(x - 0.2, [int(((rank == r) & pred).sum()) for r in x], 0.4, label="cluster with 1 degree of freedom")
    ax.bar(x + 0.2, [int(((rank == r) & ~pred).sum()) for r in x], 0.4, label="cluster with more")
    tc = line_counts(flows)["tested"]          # the verdict's numbers (s3-line): steps where it can fail
    ax.set(xticks=x, xticklabels=["point", "line", "area"], ylabel="indeterminate steps",
           title=f"({letter}) why a line: holds at {tc['holds']} of {tc['steps']}\n(steps with 3 solutions or more)")
    _legend(ax)


def figure(ds, flows=None):
    """The whole figure: packings (a-f) and, with ``flows``, the flow study (g-j); fonts of
    12 pt on a 16-inch figure stay near 9 pt when the page shrinks it to its width."""
    with plt.rc_context({"font.size": 12, "axes.titlesize": 13, "axes.labelsize": 12}):
        return _figure(mixed_only(ds), flows)     # uniform-sample measures where its chains agree


def _figure(ds, flows):
    fig = plt.figure(figsize=(16, 16 if flows is not None else 10.5), layout="constrained")
    subs = fig.subfigures(2 if flows is not None else 1, 1, height_ratios=[2, 1] if flows is not None else None,
                          squeeze=False)[:, 0]
    top = subs[0].subplots(2, 3)
    panel_eta(top[0, 0], ds, 0, "a", "η against μ, built at μ")
    panel_eta(top[0, 1], ds, 1, "b", "control: built frictionless")
    panel_coordination(top[0, 2], ds, "c")
    panel_convergence(top[1, 0], ds, "d")
    panel_centrality(top[1, 1], ds, "e")
    panel_walk_vs_uniform(top[1, 2], ds, "f")
    if flows is not None:
        bottom = subs[1].subplots(1, 4)
        for ax, factor, letter in zip(bottom[:3], ("mu", "h", "slope"), "ghi"):
            panel_flows(ax, flows, factor, letter)
        panel_line(bottom[3], flows, "j")
    for ax in fig.axes:             # log axes: labelled decades only (minor labels collide)
        if ax.get_xscale() == "log":
            ax.xaxis.set_minor_formatter(plt.NullFormatter())
    fig.suptitle(TITLE, fontsize=16)
    return fig


def panel_walk_vs_uniform(ax, ds, letter):
    """Per packing: eta_U of the walk against eta_U of the uniform sample (both series)."""
    for kind, (label, marker) in enumerate((("built at μ", "o"), ("built frictionless", "s"))):
        sel = (ds.kind.values == kind) & (ds.eta_walk.values > 0) & (ds.eta_uniform.values > 0)
        ax.scatter(ds.eta_uniform.values[sel], ds.eta_walk.values[sel], c=np.log10(ds.mu.values[sel]), s=20,
                   marker=marker, cmap="viridis", label=label)
    v = np.concatenate([ds.eta_walk.values, ds.eta_uniform.values])
    v = v[np.isfinite(v) & (v > 0)]
    if len(v):
        lim = [v.min() * 0.8, v.max() * 1.25]
        ax.plot(lim, lim, "k:", lw=1, label="equal")
    ax.set(xlabel="η_U, uniform sample", ylabel="η_U, random walk",
           title=f"({letter}) walk against uniform (colour: log10 μ)")
    _log_or_empty(ax, bool(len(v)))
    _legend(ax, ncol=1)


__all__ = ["UNGER_PEAK_MU", "TITLE", "panel_eta", "panel_coordination", "panel_convergence", "panel_centrality",
           "panel_flows", "panel_line", "panel_walk_vs_uniform", "figure"]
