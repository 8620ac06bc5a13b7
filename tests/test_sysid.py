"""Free-decay identification (thesis eqs. 3.1-3.6) and the three-mass rig model."""
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.examples import three_mass
from mutext.examples.three_mass import AIR_DAMPER, TABLE_3_1
from mutext.lti import freqresp
from mutext.sysid import (cart_parameters, decay_estimate, identify_three_mass,
                          simulate_free_decay)


def test_decay_estimate_matches_analytic_sdof():
    m, k, c = 0.8113, 842.3, 5.2992
    est = decay_estimate(*simulate_free_decay(m, k, c))
    wn, z = np.sqrt(k / m), c / (2 * np.sqrt(k * m))
    assert est.omega_n == pytest.approx(wn, rel=1e-5)
    assert est.zeta_exact == pytest.approx(z, rel=1e-4)
    # eq. 3.1 measures the damped frequency
    assert est.omega == pytest.approx(wn * np.sqrt(1 - z * z), rel=1e-5)


def test_cart_mass_formula_gives_the_cart_not_the_weighted_cart():
    mc, mw, k = 0.6, 2.0, 1000.0
    bare = decay_estimate(*simulate_free_decay(mc, k, 0.5))
    heavy = decay_estimate(*simulate_free_decay(mc + mw, k, 0.5))
    p = cart_parameters(bare, heavy, mw, correct_damping=True)
    assert p.m_c == pytest.approx(mc, rel=1e-4)
    assert p.k_eq == pytest.approx(k, rel=1e-4)
    assert p.c == pytest.approx(0.5, rel=1e-3)


def test_identification_recovers_table_3_1_without_noise():
    _, table = identify_three_mass(TABLE_3_1, air_damper=AIR_DAMPER, noise=0.0, correct_damping=True)
    for row in table:
        assert abs(row["rel_error"]) < 1e-4, row


def test_thesis_formulas_are_close_but_biased():
    _, table = identify_three_mass(TABLE_3_1, air_damper=AIR_DAMPER, noise=0.0, correct_damping=False)
    errs = {r["name"]: abs(r["rel_error"]) for r in table}
    assert max(errs.values()) < 0.02
    assert errs["c1"] > 1e-3        # the approximate decrement shows on the lightest cart


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_identification_with_encoder_noise(seed):
    _, table = identify_three_mass(TABLE_3_1, air_damper=AIR_DAMPER, noise=2e-5, rng=seed, correct_damping=True)
    for row in table:
        tol = 0.05 if row["name"].startswith("c") else 0.01
        assert abs(row["rel_error"]) < tol, row


def test_bad_records_are_reported():
    t, y = simulate_free_decay(1.0, 100.0, 0.1, duration=0.05)
    with pytest.raises(ModelError, match="clear peak"):
        decay_estimate(t, y)
    with pytest.raises(ModelError, match="damping ratio"):
        simulate_free_decay(1.0, 100.0, 30.0)
    with pytest.raises(ModelError, match="same length"):
        decay_estimate(np.arange(10.0), np.zeros(9))
    bare = decay_estimate(*simulate_free_decay(1.0, 100.0, 0.1))
    with pytest.raises(ModelError, match="more slowly"):
        cart_parameters(bare, bare, 2.0)


def test_three_mass_chain_static_compliance():
    p = three_mass.TABLE_3_1
    G = freqresp(three_mass.mechanical_model(p), [0.0])[:, :, 0]
    # chain grounded through k3 at cart 3: a force on cart 1 loads all three springs in series
    assert G[0, 0].real == pytest.approx(1 / p.k1 + 1 / p.k2 + 1 / p.k3, rel=1e-12)
    assert G[1, 1].real == pytest.approx(1 / p.k3, rel=1e-12)


def test_three_mass_trials_difference_sits_on_cart_3():
    du = {n: t.Du for n, t in three_mass.TRIALS.items()}
    assert du["1a"]["dk"] == pytest.approx(186.0)
    assert du["1b"]["dk"] == pytest.approx(-186.0)
    assert du["2"]["dm"] == pytest.approx(1.0)
    assert du["3"]["dc"] == pytest.approx(5.0)
    assert (du["4"]["dm"], du["4"]["dc"], du["4"]["dk"]) == pytest.approx((1.0, 5.0, 186.0))
    for t in three_mass.TRIALS.values():
        Me, Ce, Ke = three_mass.matrices(t.engineering)
        Mt, Ct, Kt = three_mass.matrices(t.true)
        for dE in (Mt - Me, Ct - Ce, Kt - Ke):
            assert np.count_nonzero(dE[:2, :]) == 0 and np.count_nonzero(dE[:, :2]) == 0


def test_three_mass_rejects_bad_parameters():
    with pytest.raises(ModelError, match="m2 must be positive"):
        three_mass.matrices(three_mass.TABLE_3_1.with_(m2=0.0))


def test_air_damper_outside_c3_is_refused():
    with pytest.raises(ModelError, match="air_damper"):
        identify_three_mass(TABLE_3_1, air_damper=TABLE_3_1.c3 + 1.0)
