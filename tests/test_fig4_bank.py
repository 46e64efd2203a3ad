"""The bank of the piles (Moreau 2005, end of section 5): cuts parallel to the free surface,
the Love-Weber stress and the reciprocity formula.

Unit tests on constructed packings (an infinite-slope layer solved exactly, a uniform
lattice), then checks on the figure data of a whole-DAG run (fixture ``results``).
"""
import numpy as np
import pytest
import xarray as xr
import yaml

from ncd.core.contacts import Contacts, detect_contacts, h_matrix
from ncd.core.scene import make_scene
from ncd.exact.exact_set import ExactSet
from ncd.figures.fig4_bank import claims as bank_claims
from ncd.figures.fig4_bank import stress as st
from ncd.io.netcdf import missing_metadata
from ncd.pipeline.config import ConfigError, check_config
from ncd.shared import cuts as cm
from ncd.shared.verdict import VERDICTS, Verdict

# Stated bounds
ROUND_OFF = 1e-9          # relative: an LP vertex balances every grain to about 1e-13 of the weights
LATTICE_TOL = 0.03        # relative: Love-Weber vs a straight cut 40 d long in a uniform lattice (edge effects ~ d/L)
ASYMMETRY_TOL = bank_claims.ASYMMETRY_TOL


# ------------------------------------------------------------------ constructed packings
def rotation(angle_deg):
    a = np.radians(angle_deg)
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def slope_layer(theta=12.0, layers=4, columns=10, radius=1e-3, mu=0.5, g=9.81):
    """A triangular packing of equal discs on a row of touching fixed discs, periodic along x,
    under gravity tilted by ``theta``: an infinite slope seen in its own frame (the slope is
    y = const).  Returns the scene, its contacts and an exact equilibrium (an LP vertex of A ∩ C)."""
    R = radius
    period = 2 * R * columns
    base = np.column_stack([2 * R * np.arange(columns) + 0.5 * R, np.zeros(columns)])
    pos = np.array([[(2 * R * k + 0.5 * R + (R if j % 2 else 0.0)) % period, j * np.sqrt(3) * R]
                    for j in range(1, layers + 1) for k in range(columns)])
    gravity = g * np.array([np.sin(np.radians(theta)), -np.cos(np.radians(theta))])
    scene = make_scene(pos, np.full(len(pos), R), 1000.0, obstacle_pos=base, obstacle_radius=np.full(columns, R),
                       gravity=tuple(gravity), mu=mu, period=period)
    c = detect_contacts(scene, alert=1e-9 * R)
    nm = scene.n_mobile
    F = np.zeros((nm, 3))
    F[:, :2] = scene.mass[:nm, None] * gravity[None, :]
    es = ExactSet(h_matrix(scene, c), F.ravel(), c.mu)
    # a lattice holds self-stresses (A ∩ C is unbounded): a positive weight on the normal forces is bounded
    cost = np.zeros((c.n, 2))
    cost[:, 0] = 1.0 + np.random.default_rng(7).uniform(0.0, 0.5, c.n)
    _, r = es.minimize(cost.ravel())
    return scene, c, r, gravity


@pytest.fixture(scope="module")
def layer():
    return slope_layer()


def test_infinite_slope_cut_carries_the_slab_vertically(layer):
    """The force across a cut parallel to the slope (the whole period) is the weight of the slab
    above it, along gravity, to round-off, for any admissible force state (here an LP vertex)."""
    scene, c, r, gravity = layer
    nm = scene.n_mobile
    theta = np.degrees(np.arctan2(gravity[0], -gravity[1]))
    to_physical = rotation(-theta)                        # gravity -> (0, -g): the slope falls towards +x
    np.testing.assert_allclose(to_physical @ gravity, [0.0, -np.hypot(*gravity)], atol=1e-12)
    np.testing.assert_allclose(to_physical @ [1.0, 0.0], st.flank_frame(theta, 1)[0], atol=1e-15)
    ys = np.unique(np.round(scene.pos[:nm, 1], 12))
    for y_cut in 0.5 * (ys[1:] + ys[:-1]):
        seg = ((0.0, y_cut), (1.0, 0.0), 1e3, (0.0, 1.0))   # longer than the period: every crossing counts once
        M, n = st.segment_matrix(c, scene.pos, nm, [seg])
        assert n[0] > 0
        F = to_physical @ (M @ r)
        slab = float(np.sum(scene.mass[:nm][scene.pos[:nm, 1] > y_cut])) * np.hypot(*gravity)
        assert -F[1] == pytest.approx(slab, rel=ROUND_OFF)
        assert abs(float(st.angle_to_vertical(F[0], F[1], 1))) < 1e-7      # degrees


def test_stress_symmetric_at_an_lp_vertex_and_reciprocity_exact(layer):
    """At an exact equilibrium every grain balances its moments: the Love-Weber stress of any
    window is symmetric to round-off, and so both sides of the reciprocity formula agree."""
    scene, c, r, gravity = layer
    nm, R = scene.n_mobile, scene.radius[0]
    wins = [st.rectangle((x, y), (np.cos(a), np.sin(a)), 3 * R, 2 * R)
            for x, y, a in ((5 * R, 3 * R, 0.0), (9 * R, 4 * R, 0.3), (12 * R, 5 * R, -0.2))]
    S, counts = st.stress_matrix(c, scene.pos, nm, wins)
    assert counts.min() > 3
    sig = st.as_tensors(S @ r)
    assert np.abs(st.asymmetry(sig)).max() < ROUND_OFF
    n_s, e = st.flank_frame(20.0, 1)[1], np.array([1.0, 0.0])
    a, b = st.reciprocity(sig, np.tile(n_s, (3, 1)), np.tile(e, (3, 1)))
    p = 0.5 * (sig[:, 0, 0] + sig[:, 1, 1])
    np.testing.assert_allclose(a / p, b / p, atol=ROUND_OFF)
    # moments unbalanced by one contact's tangential force: the asymmetry is the sum of the torques
    # on the window's grains over its area (both grains of the contact in the window: twice)
    k = np.nonzero(c.body_a == int(np.argmin(np.hypot(*(scene.pos[:nm] - wins[0][0]).T))))[0][0]
    r2 = r.copy()
    r2[2 * k + 1] += 1e-3
    inside = st.in_rectangle(scene.pos[:nm], wins[0])
    b = c.body_b[k]
    assert inside[c.body_a[k]] and 0 <= b < nm and inside[b]
    torque = -(c.arm_a[k] + c.arm_b[k]) * 1e-3
    sig2 = st.as_tensors(S[:4] @ r2)[0]
    assert sig2[0, 1] - sig2[1, 0] == pytest.approx(torque / (4 * 3 * R * 2 * R), rel=1e-9)


def test_reciprocity_fails_by_the_asymmetry():
    rng = np.random.default_rng(3)
    for outer in (1, -1):
        sig = rng.normal(size=(5, 2, 2))
        n = np.array([st.flank_frame(a, outer)[1] for a in rng.uniform(5, 35, 5)])
        e = np.tile([outer, 0.0], (5, 1))
        a, b = st.reciprocity(sig, n, e)
        np.testing.assert_allclose(a - b, outer * n[:, 1] * (sig[:, 1, 0] - sig[:, 0, 1]), atol=1e-14)
        sym = 0.5 * (sig + np.swapaxes(sig, 1, 2))
        a, b = st.reciprocity(sym, n, e)
        np.testing.assert_allclose(a, b, atol=1e-14)


def lattice(n=60, radius=1.0):
    """A triangular lattice of touching equal discs (n x n), no equilibrium needed."""
    R = radius
    pos = np.array([[2 * R * k + (R if j % 2 else 0.0), j * np.sqrt(3) * R] for j in range(n) for k in range(n)])
    scene = make_scene(pos, np.full(len(pos), R), 1.0, gravity=(0.0, 0.0))
    return scene, detect_contacts(scene, alert=1e-9 * R)


def test_love_weber_equals_the_traction_of_a_cut_in_a_uniform_region():
    """Contact forces f = S l (l the branch vector) on a triangular lattice: a uniform stress
    sigma = sqrt(3) S (sum of l (x) l over a grain's three contacts, over its area), which the
    Love-Weber sum of a window gives and whose traction -sigma m a straight cut carries."""
    scene, c = lattice()
    nm = scene.n_mobile
    S0 = np.array([[1.0, 0.3], [0.1, 2.0]])
    ell = scene.pos[c.body_a] - scene.pos[c.body_b]
    f = ell @ S0.T
    r = np.column_stack([np.einsum("ki,ki->k", f, c.normal), np.einsum("ki,ki->k", f, c.tangent)]).ravel()
    expected = np.sqrt(3) * S0
    centre = scene.pos[:nm].mean(axis=0)
    sig = st.as_tensors(st.stress_matrix(c, scene.pos, nm, [st.rectangle(centre, (1.0, 0.0), 30.0, 30.0)])[0] @ r)[0]
    np.testing.assert_allclose(sig, expected, rtol=LATTICE_TOL, atol=LATTICE_TOL * np.abs(expected).max())
    for angle in (0.0, 17.0, 40.0, 90.0, 133.0):
        u = rotation(angle) @ [1.0, 0.0]
        m = np.array([-u[1], u[0]])
        seg = (centre + 0.37 * m, u, 20.0, m)
        F = st.segment_matrix(c, scene.pos, nm, [seg])[0] @ r / 40.0
        np.testing.assert_allclose(F, -expected @ m, atol=LATTICE_TOL * np.abs(expected).max())


def test_segment_cut_is_the_vertical_cut_of_fig4_pile(layer):
    scene, c, r, _ = layer
    nm, R = scene.n_mobile, scene.radius[0]
    flat = Contacts(**{**c.__dict__, "shift_b": np.zeros(c.n)})     # fig4_pile's cuts know no period
    for x_cut, outer in ((6.3 * R, 1), (11.1 * R, -1)):
        C, n1 = cm.cut_matrix(flat, scene.pos, nm, [(x_cut, outer, 0.0, 5 * R)])
        M, n2 = st.segment_matrix(flat, scene.pos, nm, [st.vertical_segment(x_cut, outer, 0.0, 5 * R)])
        assert n1[0] == n2[0] > 0
        np.testing.assert_allclose((C - M).toarray(), 0.0, atol=1e-15)


def test_plane_stress_of_an_infinite_slope_and_principal_directions():
    # a slab at depth z under a slope theta: -sigma n_s is the weight gamma z cos(theta) per unit length, vertical
    theta, gz = 25.0, 3.0
    t, n = st.flank_frame(theta, 1)
    # any symmetric sigma with sigma n = gz cos(theta) e_y: add k t (x) t
    base = gz * np.cos(np.radians(theta)) * (np.outer([0, 1], n) + np.outer(n, [0, 1]) - (n[1]) * np.outer(n, n))
    for k in (0.0, 1.0, 4.0):
        sig = base + k * np.outer(t, t)
        np.testing.assert_allclose(sig @ n, gz * np.cos(np.radians(theta)) * np.array([0.0, 1.0]), atol=1e-12)
        s_n, tau = st.plane_stress(sig[None], n, t)
        assert tau[0] / s_n[0] == pytest.approx(np.tan(np.radians(theta)), rel=1e-12)
    # principal: diag(3, 1) rotated so that its major axis leans by 30 degrees from the vertical towards +x
    d = rotation(-30.0) @ np.diag([1.0, 3.0]) @ rotation(-30.0).T
    s1, s2, beta, sin_phi = st.principal(d[None])
    assert (s1[0], s2[0], beta[0], sin_phi[0]) == pytest.approx((3.0, 1.0, 30.0, 0.5))


def test_slope_at_the_limit_leans_its_major_direction_by_45_minus_half_theta():
    """A vertical force on the surface-parallel planes fixes sigma up to k t (x) t; the Mohr circle
    touching tan(theta) there (the least mobilized friction, sin phi = sin theta) puts the major
    direction 45 - theta/2 degrees from the vertical, leaning towards the axis: the principal
    directions of a bank at incipient failure, against which the page reads its own."""
    from scipy.optimize import minimize_scalar
    for theta in (16.0, 25.0):
        t, n = st.flank_frame(theta, 1)
        base = np.cos(np.radians(theta)) * (np.outer([0, 1], n) + np.outer(n, [0, 1]) - n[1] * np.outer(n, n))
        sin_phi = lambda k: st.principal((base + k * np.outer(t, t))[None])[3][0]  # noqa: E731
        k = minimize_scalar(sin_phi, bounds=(-0.5, 5.0), method="bounded", options={"xatol": 1e-12}).x
        assert np.degrees(np.arcsin(sin_phi(k))) == pytest.approx(theta, abs=1e-6)
        beta = st.principal((base + k * np.outer(t, t))[None])[2][0]
        assert beta == pytest.approx(-(45.0 - theta / 2), abs=1e-4)


def test_config_section_is_checked(tmp_path):
    from pathlib import Path
    root = Path(__file__).resolve().parent.parent
    cfg = yaml.safe_load((root / "config.yaml").read_text())
    check_config({"fig4_bank": cfg["fig4_bank"]}, ["fig4_bank"], root / "workflow" / "schemas")
    bad = {**cfg["fig4_bank"], "depths_d": [1.0, -2.0]}
    with pytest.raises(ConfigError, match="depths_d"):
        check_config({"fig4_bank": bad}, ["fig4_bank"], root / "workflow" / "schemas")


def test_claims_without_data_are_not_computed(tmp_path):
    for f in (bank_claims.claim_surface_force_vertical, bank_claims.claim_reciprocity,
              bank_claims.claim_incipient_failure):
        v = f(tmp_path)
        assert isinstance(v, Verdict) and v.verdict == "not computed" and v.anchor


# ------------------------------------------------------------------ the figure data
@pytest.fixture(scope="module")
def data(results):
    d = results / "fig4_bank"
    return xr.load_dataset(d / "measures.nc"), {p.stem: xr.load_dataset(p) for p in sorted((d / "exact").glob("*.nc"))}


def test_data_labelled_and_complete(data):
    ms, exact = data
    assert missing_metadata(ms) == []
    for e in exact.values():
        assert missing_metadata(e) == []
    assert set(ms.pile_history.values) == {"default", "point", "rain", "layer"}
    assert ms.valid.sum() > 0
    assert "default" in exact and any(k.startswith("point_") for k in exact) and any(k.startswith("rain_") for k in exact)


def test_data_angles_and_loads_consistent(data):
    ms, _ = data
    ok = ms.valid.values.astype(bool)
    outer = np.broadcast_to(np.array([-1, 1])[None, :, None, None], ok.shape)
    psi = st.angle_to_vertical(ms.force_x.values, ms.force_y.values, outer)
    np.testing.assert_allclose(psi[ok], ms.angle_to_vertical.values[ok], atol=1e-10)
    assert np.all(np.isnan(ms.angle_to_vertical.values[~ok]))
    # a column of the bank carries about its own weight (the infinite-slope balance)
    assert 0.7 < np.nanmedian(ms.load_ratio.values) < 1.3


def test_data_stress_symmetric_and_reciprocity(data):
    ms, exact = data
    ok = ms.valid.values.astype(bool)
    assert np.nanmax(np.abs(ms.asymmetry.values)) <= ASYMMETRY_TOL
    np.testing.assert_allclose(ms.reciprocity_vertical.values[ok], ms.reciprocity_surface.values[ok],
                               atol=ASYMMETRY_TOL)
    # the traction of the window stress reproduces the stored stress components
    sig = np.stack([ms.sigma_xx, ms.sigma_xy, ms.sigma_yx, ms.sigma_yy], -1).reshape(ok.shape + (2, 2))
    e = np.broadcast_to(np.array([[-1.0, 0.0], [1.0, 0.0]])[None, :, None, None, :], ok.shape + (2,))
    tv = np.einsum("...ij,...j->...i", sig, e)
    np.testing.assert_allclose(tv[ok][:, 0], ms.traction_v_x.values[ok], rtol=1e-12)
    for e_ds in exact.values():
        assert np.nanmax(e_ds.vertex_asymmetry.values) <= ASYMMETRY_TOL


def test_data_exact_ranges_contain_the_history(data):
    _, exact = data
    for name, e in exact.items():
        ok = np.isfinite(e.angle_min.values)
        assert ok.sum() > 0, name
        assert np.all(e.angle_min.values[ok] <= e.angle_max.values[ok])
        assert np.nanmax(e.history_outside.values) < 1e-3, name       # degrees: the history is admissible
        assert np.all(e.fy_min.values[ok] <= e.fy_max.values[ok] + 1e-12)


def test_claims_and_page(results):
    """Each claim is printed on the page under the anchor of its section and the paper-claim anchor
    of the index, with its verdict and value."""
    import html as html_lib
    import re

    html = (results / "html" / "fig4_bank.html").read_text(encoding="utf-8")
    for claim_id, (f,) in bank_claims.JUDGES.items():
        v = f(results)
        assert v.verdict in VERDICTS and v.verdict != "not computed"
        assert v.value and v.criterion and all((results / p).exists() for p in v.data)
        assert f'id="{v.anchor}"' in html
        at = html.find(f'id="claim-{claim_id}"')
        assert at > 0, claim_id
        block = html_lib.unescape(re.sub(r"<[^>]+>", "", html[at:at + 20000]))
        assert v.verdict in block and v.value[:60] in block, claim_id
    assert bank_claims.claim_reciprocity(results).verdict == "consistent"
