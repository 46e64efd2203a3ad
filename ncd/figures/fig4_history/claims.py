"""The history study's rows on the index: §5's dip and arching over ensembles of piles.
"""
from pathlib import Path

import xarray as xr

from ncd.shared.verdict import DIFFERS, REPRODUCED, judged


def _history_analysis(results):
    """The ensemble analysis of fig4_history with the smallest pile size (the default 10^3)."""
    paths = sorted(Path(results).glob("fig4_history/analysis_n*.nc"), key=lambda q: int(q.stem.split("_n")[-1]))
    if not paths:
        raise FileNotFoundError("fig4_history/analysis_n*.nc absent")
    return xr.load_dataset(paths[0]), f"fig4_history/{paths[0].name}"


def fig4_history_dip(results):
    an, rel = _history_analysis(results)
    s = an.isel(kernel=0)
    p, r = s.sel(history="point"), s.sel(history="rain")
    lo, hi = float(p.dip_lo), float(p.dip_hi)
    return judged(f"dip depth of the mean profile (flank minus centre, > 0 a dip, units of the mean ground stress W/2L) "
              f"over {an.sizes['pile']} point-source piles {float(p.dip_mean):.3f} [{lo:.3f}, {hi:.3f}] "
              f"(rain {float(r.dip_mean):.3f}; difference p = {float(s.dip_diff_p):.2g})",
              REPRODUCED if lo > 0 else DIFFERS, "a \"may\" over piles: the 95 % bootstrap band over point-source "
              "piles of the dip depth above 0", "s5-dip", rel)


def fig4_history_arching(results):
    an, rel = _history_analysis(results)
    p = an.sel(history="point")
    med = float(p.cut_deviation.median())
    lo, hi = float(p.deviation_median_lo.min()), float(p.deviation_median_hi.max())
    return judged(f"cut resultant minus flank slope over {an.sizes['pile']} point-source piles: median {med:.1f}° "
              f"(bootstrap bands of the per-cut medians within [{lo:.1f}°, {hi:.1f}°])",
              REPRODUCED if abs(med) <= 10 else DIFFERS, "median deviation within 10° of the free surface",
              "s5-parallel-to-surface", rel)


# the judging functions of this package's rows, by claim id (ncd.pages.claims renders them)
JUDGES = {
    "s5-dip": (fig4_history_dip,),
    "s5-parallel-to-surface": (fig4_history_arching,),
}
