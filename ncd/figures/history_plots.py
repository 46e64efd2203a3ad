"""Plots and prose numbers of fig4_history: ground stress, dip, arching.
"""
import matplotlib.pyplot as plt
import numpy as np

COLORS = {"point": "C3", "rain": "C0"}
LABELS = {"point": "point source", "rain": "rain"}


def plot_piles(ax, piles):
    """Final states of one pile per history (grains as discs, offset vertically)."""
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    d = piles[0].attrs["mean_diameter"]
    off = 0.0
    for ds in piles:
        h = ds.attrs["history"]
        circles = [Circle((x / d, (y + off) / d), r / d) for x, y, r in zip(ds.x.values, ds.y.values,
                                                                           ds.radius.values)]
        ax.add_collection(PatchCollection(circles, facecolor=COLORS[h], edgecolor="none", alpha=0.8))
        ax.text(0.02, (off + 0.5 * d) / d, f"{LABELS[h]}, pile {ds.attrs['member']}", fontsize=8,
                transform=ax.get_yaxis_transform())
        off += (ds.y.max().item() + 3 * d)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x / d")
    ax.set_yticks([])


def plot_stress(ax, an, kernel=None):
    """Mean ground stress against x / L with its bootstrap band over piles, per history."""
    k = an.kernel.values[0] if kernel is None else kernel
    for h in an.history.values:
        s = an.sel(history=h, kernel=k)
        ax.fill_between(an.xi, s.profile_lo, s.profile_hi, color=COLORS[h], alpha=0.25, lw=0)
        ax.plot(an.xi, s.profile_mean, color=COLORS[h],
                label=f"{LABELS[h]} ({an.sizes['pile']} piles)")
    ax.axhline(1.0, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("x / L (L: base half-width of the point-source pile)")
    ax.set_ylabel("ground stress / (W / 2L)")
    ax.set_title(f"kernel {k:g} d, {int(100 * an.attrs['level'])} % bootstrap band over piles", fontsize=9)
    ax.legend(fontsize=8)


def plot_dips(ax, an):
    """Dip depth per history and kernel width: piles (dots), mean profile with band (bar)."""
    ks = an.kernel.values
    for i, h in enumerate(an.history.values):
        s = an.sel(history=h)
        for j, k in enumerate(ks):
            x = j + (i - 0.5) * 0.3
            dj = s.dip.sel(kernel=k).values
            ax.plot(np.full(len(dj), x) + 0.04 * np.linspace(-1, 1, len(dj)), dj, ".", color=COLORS[h], ms=3,
                    alpha=0.5)
            lo, hi = float(s.dip_lo.sel(kernel=k)), float(s.dip_hi.sel(kernel=k))
            m = float(s.dip_mean.sel(kernel=k))
            # a bar from lo to hi, not an error bar: the dip of the mean profile (a min/max of
            # a mean) can lie outside its percentile bootstrap band (biased upwards by noise)
            ax.vlines(x, lo, hi, color=COLORS[h], lw=1.2)
            ax.plot(x, m, "o", color=COLORS[h], label=LABELS[h] if j == 0 else None)
    for j, k in enumerate(ks):
        ax.text(j, 0.97, f"p = {float(an.dip_diff_p.sel(kernel=k)):.3g}", ha="center", va="top", fontsize=7,
                transform=ax.get_xaxis_transform())
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xticks(range(len(ks)), [f"{k:g} d" for k in ks])
    ax.set_xlabel("kernel width")
    ax.set_ylabel("dip depth (M - m) / M  (< 0: hump)")
    ax.legend(fontsize=8)


def plot_arching(ax, an):
    """Median over piles of the cut resultant's deviation from the free-surface slope,
    band: 25-75 % of the piles (shaded) and bootstrap band of the median (bars); thin
    vertical lines: the exact range over A ∩ C of single piles (where computed)."""
    q = an.cut_position.values
    step = np.min(np.diff(q)) if len(q) > 1 else 0.1
    for i, h in enumerate(an.history.values):
        if "exact_computed" in an:
            done = np.nonzero(an.exact_computed.sel(history=h).values)[0]
            for j, m in enumerate(done):
                for f, sign in (("left", -1), ("right", 1)):
                    s = an.sel(history=h, pile=m, flank=f)
                    x = sign * q + (i - 0.5) * 0.35 * step + 0.3 * step * (j + 0.5) / max(len(done), 1) * sign
                    ax.vlines(x, s.exact_deviation_min, s.exact_deviation_max, color=COLORS[h], lw=0.6, alpha=0.6,
                              label=f"{LABELS[h]}: exact range, {len(done)} piles" if (j == 0 and f == "left")
                              else None)
        for f, sign in (("left", -1), ("right", 1)):
            s = an.sel(history=h, flank=f)
            x = sign * q
            ax.fill_between(x, s.deviation_q25, s.deviation_q75, color=COLORS[h], alpha=0.15, lw=0)
            ax.vlines(x, s.deviation_median_lo, s.deviation_median_hi, color=COLORS[h], lw=1.0)
            ax.plot(x, s.deviation_median, "o-", ms=3, color=COLORS[h], label=LABELS[h] if f == "left" else None)
    ax.axhline(0, color="0.6", lw=0.6)
    ax.set_xlabel("cut position x / L")
    ax.set_ylabel("resultant angle - flank slope (deg)")
    ax.legend(fontsize=8)


def figure(an, piles):
    fig = plt.figure(figsize=(11, 8), constrained_layout=True)
    gs = fig.add_gridspec(2, 3)
    plot_piles(fig.add_subplot(gs[0, :]), piles)
    plot_stress(fig.add_subplot(gs[1, 0]), an)
    plot_dips(fig.add_subplot(gs[1, 1]), an)
    plot_arching(fig.add_subplot(gs[1, 2]), an)
    return fig


def summary(an):
    """Numbers for the notebook prose, computed from analysis_n<n>.nc."""
    k0 = an.kernel.values[0]
    out = {"kernel": float(k0), "piles": an.sizes["pile"]}
    for h in an.history.values:
        s = an.sel(history=h, kernel=k0)
        out[h] = dict(dip=float(s.dip_mean), lo=float(s.dip_lo), hi=float(s.dip_hi),
                      dips_by_kernel={float(k): float(an.dip_mean.sel(history=h, kernel=k)) for k in an.kernel.values},
                      frac_dip=float((an.dip.sel(history=h, kernel=k0) > 0).mean()),
                      frac_by_kernel={float(k): float((an.dip.sel(history=h, kernel=k) > 0).mean())
                                      for k in an.kernel.values},
                      center=float(s.profile_mean.sel(xi=0.0, method="nearest")),
                      L=float(an.base_half_width.sel(history=h).mean() / an.attrs["mean_diameter"]),
                      fitL=float(an.fit_half_width.sel(history=h).mean() / an.attrs["mean_diameter"]),
                      slope=float(an.surface_angle.sel(history=h).mean()),
                      apex=float(an.apex_height.sel(history=h).mean()),
                      cone=float(an.cone_ratio.sel(history=h).mean()),
                      dev_median=float(an.cut_deviation.sel(history=h).median()),
                      dev_iqr=float(an.cut_deviation.sel(history=h).quantile(0.75)
                                    - an.cut_deviation.sel(history=h).quantile(0.25)),
                      arching=float((an.cut_deviation.sel(history=h) > 0).sum()
                                    / np.isfinite(an.cut_deviation.sel(history=h)).sum()),
                      empty_cuts=int(np.isnan(an.cut_deviation.sel(history=h)).sum()),
                      cuts=int(an.cut_deviation.sel(history=h).size))
    for h in an.history.values:
        out[h].update(grains=float(an.n_grains.sel(history=h).mean()),
                      grains_min=int(an.n_grains.sel(history=h).min()), grains_max=int(an.n_grains.sel(history=h).max()),
                      removed=float(an.n_removed.sel(history=h).mean()))
        if "exact_computed" in an and int(an.exact_computed.sel(history=h).sum()):
            e = an.sel(history=h).where(an.exact_computed.sel(history=h) == 1, drop=True)
            width = (e.exact_deviation_max - e.exact_deviation_min).values
            out[h].update(exact_piles=int(e.sizes["pile"]), exact_width_median=float(np.nanmedian(width)),
                          exact_width_max=float(np.nanmax(width)),
                          exact_all_positive=float(np.mean(e.exact_deviation_min.values > 0)),
                          exact_all_negative=float(np.mean(e.exact_deviation_max.values < 0)),
                          exact_undefined=float(np.mean(np.isnan(width))),
                          exact_confirmed=float(e.exact_confirmed.mean()) if "exact_confirmed" in e else np.nan)
    out["diff"] = float(an.dip_diff.sel(kernel=k0))
    out["diff_lo"], out["diff_hi"] = float(an.dip_diff_lo.sel(kernel=k0)), float(an.dip_diff_hi.sel(kernel=k0))
    out["p"] = {float(k): float(an.dip_diff_p.sel(kernel=k)) for k in an.kernel.values}
    return out
