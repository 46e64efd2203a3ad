"""ncd against pymunk (Chipmunk2D) on a small poured pile (:mod:`ncd.studies.bench.peer`).

40 discs on a ground 15 diameters wide, the default h = 1 ms and 10 sweeps per
step: about 3,500 steps per engine, a few seconds in all.  The bounds were
calibrated on root seeds 0-7 (measured values in the comments).
"""
import numpy as np
import pytest

from ncd.core.errors import InputError
from ncd.studies.bench.peer import DEFAULTS, SLOP_D, compare

pytest.importorskip("pymunk")

SMALL = {"n_discs": 40, "ground_width": 15}


@pytest.fixture(scope="module")
def small():
    return compare(SMALL)


def test_same_scene_and_ncd_at_rest(small):
    ds, cfg = small, {**DEFAULTS, **SMALL}
    ncd_, pm = ds.sel(engine="ncd"), ds.sel(engine="pymunk")
    # identical discs in both engines, as read back from each engine's objects
    r = ds["radius"].values
    mass = cfg["density"] * np.pi * r ** 2
    for e in (ncd_, pm):
        np.testing.assert_array_equal(e["radius_built"].values, r)
        np.testing.assert_allclose(e["mass"].values, mass, rtol=1e-14)
        np.testing.assert_allclose(e["moment"].values, 0.5 * mass * r ** 2, rtol=1e-14)
        assert int(e["n_on_ground"]) == SMALL["n_discs"]           # the walls keep every disc
    assert int(ncd_["n_steps"]) == int(pm["n_steps"]) == 39 * 64 + 1000
    # ncd ends exactly at rest (KE ~1e-34 measured): the last step's ground and wall
    # impulses then balance the weight to rounding (|1 - R/W| ~1e-16 measured); 1e-6
    # would still pass a last step a little off rest, 1 % would be far too loose
    assert float(ncd_["kinetic_energy"]) < 1e-20
    assert float(ncd_["ground_reaction"]) == pytest.approx(1.0, abs=1e-6)
    # NLGS solves each contact exactly in the Coulomb cone (measured 0)
    assert float(ncd_["coulomb_violation"]) < 1e-9
    assert float(ncd_["residual"]) < 1e-10                        # measured ~1e-16
    # ncd never corrects positions: an approaching disc penetrates at most v h before
    # Moreau's rule activates its contact, and no disc moves faster than a fall from the
    # release point (at most pile height + 2 d_max above the ground).  Measured
    # 0.05-0.067 d against a bound of ~0.12 d; a tolerance of 1e-3 d is out
    # of reach for any h that pours 1000 discs in a minute.
    v_max = np.sqrt(2 * cfg["gravity"] * (float(ncd_["pile_height"]) + 3) * cfg["diameter"])
    assert 0 < float(ncd_["overlap_max"]) < v_max * cfg["h"] / cfg["diameter"]
    assert float(ncd_["overlap_end"]) <= float(ncd_["overlap_max"])


def test_pymunk_values(small):
    pm = small.sel(engine="pymunk")
    for v in small.data_vars:
        if v != "residual":
            assert np.all(np.isfinite(pm[v].values)), v
    # Chipmunk's small pile is at rest too (KE <= 3e-10 of m g d measured): the ground
    # reaction is within 1e-6 of the weight on the 8 seeds; 1e-3 (not 10 %) still fails
    # on a sign or a missed wall arbiter (the wall friction alone carried 1.6 % in a trial)
    assert float(pm["kinetic_energy"]) < 1e-6
    assert float(pm["ground_reaction"]) == pytest.approx(1.0, abs=1e-3)
    # Chipmunk clamps |j_t| <= (sqrt(mu))^2 j_n per contact (3e-16 measured: rounding)
    assert float(pm["coulomb_violation"]) < 1e-9
    # its bias velocities push overlaps out down to collision_slop (1e-3 d): 1.1-1.6e-3 d
    # left at the end (slop + about g h^2 = 1e-4 d), against 0.05-0.07 d during the pour
    assert float(pm["overlap_end"]) < 3 * SLOP_D
    assert float(pm["overlap_max"]) > 10 * float(pm["overlap_end"])
    assert int(pm["n_contacts"]) >= SMALL["n_discs"]             # every disc carried


@pytest.mark.parametrize("key, value", [("n_discs", 0), ("diameter", -0.01), ("mu", 0.0), ("h", 0.0),
                                        ("iterations", 0), ("drop_every", -8), ("settle", 0.0),
                                        ("ground_width", 0), ("size_ratio", 0.5), ("nsteps", 3)])
def test_bad_cfg_names_the_key(key, value):
    with pytest.raises(InputError, match=rf"^{key}\b"):
        compare({**SMALL, key: value})
