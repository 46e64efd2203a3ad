"""The sentences of the fig5_governing page computed from its data (``packings.nc``): the
study's numbers in one paragraph; the verdicts are in :mod:`.claims`."""
import numpy as np

from ncd.figures.fig5_governing.unger import MIXED_GAP, MIXED_RHAT


def _span(values, default):
    """``"a"`` or ``"a–b"`` of the finite values (``default`` when there are none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    lo, hi = (int(v.min()), int(v.max())) if len(v) else (default, default)
    return f"{lo}" if lo == hi else f"{lo}–{hi}"


DIRECTION_WORDS = {"random": "hit-and-run along Gaussian directions of a rounded frame",
                   "coordinate": "coordinate hit-and-run in a rounded frame (docs/governing.md)"}


def study_summary(ds, cfg):
    """One paragraph of the study's numbers: packings, slices, dimensions, boundedness, walk
    and uniform-sample acceptance (the page's first measured paragraph)."""
    p, u = cfg["packings"], cfg["uniform"]
    dim = ds.dim_AC_rank.values
    others = ", ".join(f"{m:.3g}" for m in ds.mu.values[ds.mixed.values == 0]) or "none"
    return (
        f"{ds.sizes['build']} packings of N = {p['n_discs']} discs, width {p['width_radii']} R, built by contact "
        f"dynamics in {int(ds.build_steps.min())}–{int(ds.build_steps.max())} steps of h = {p['h']:g} s (largest "
        f"interpenetration {float(ds.max_penetration.max()):.3f} R; every one passed the test from rest, largest "
        f"|u_f| = {float(ds.rest_velocity.max()):.1e} load h): {p['per_mu']} at each of {p['n_mu']} values of μ "
        f"from {p['mu_min']:g} to {p['mu_max']:g}, and {p['control']} frictionless (the control series, analysed at "
        f"every μ). The middle slice of {p['slice_radii']} R holds {int(ds.n_slice.min())}–{int(ds.n_slice.max())} "
        f"discs and {int(ds.n_contacts.min())}–{int(ds.n_contacts.max())} contacts; dim(A∩C) is "
        f"{int(dim.min())}–{int(dim.max())} (rank count and LP agree on {int((ds.dim_AC_lp == ds.dim_AC_rank).sum())} "
        f"of {ds.sizes['packing']} analyses); the rest forces are made exact on their active Coulomb rows in "
        f"{int(ds.rest_exact.sum())} of {ds.sizes['packing']} (the others, where that left C, keep their "
        f"round-off and the slice takes the loads they balance); the slice's A ∩ C is bounded in {int(ds.bounded.sum())} and the whole "
        f"cell's in {int(ds.bounded_cell.sum())} of them. Random walk: {ds.sizes['sample'] - 1} rounds per analysis, "
        f"{int(ds.walk_ok.sum() - ds.sizes['packing'])} of {(ds.sizes['sample'] - 1) * ds.sizes['packing']} relaxed states "
        f"points of A ∩ C (a failed round leaves the walk in place). Uniform sample: 2 chains of {_span(ds.uniform_per_chain, u['per_chain'])} "
        f"points from dispersed starts, {DIRECTION_WORDS[u.get('directions', 'random')]} (4 times longer, up to {u.get('max_per_chain', u['per_chain'])}, where "
        f"shorter chains did not agree), in the hull of the rank count (no thin direction dropped: its dimension is "
        f"dim(A∩C) by rank count in {int((ds.dim_uniform == ds.dim_AC_rank).sum())} of {int(ds.bounded.sum())}); they agree (η_U within {MIXED_GAP:.0%}, R-hat ≤ {MIXED_RHAT}) on "
        f"{int(ds.mixed.sum())} of {int(ds.bounded.sum())} analyses; the others (at μ = {others}) are left out of "
        "every uniform-sample number below and in the figure.")
