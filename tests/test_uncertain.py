"""Uncertain parameters and LFT models (mutext.uncertain).

The central check is by sampling: the LFT closed with a normalised Delta must
equal the model rebuilt from M, C, K at the corresponding parameter values.
"""
import itertools

import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.lti import freqresp
from mutext.mu import Block, BlockStructure
from mutext.uncertain import UncertainParameter, uncertain_mck


def rel_diff(G1, G2):
    """Largest relative difference of two frequency responses, frequency by frequency."""
    return max(np.linalg.norm(G1[:, :, k] - G2[:, :, k]) / np.linalg.norm(G2[:, :, k])
               for k in range(G2.shape[2]))


def assert_lft_matches(U, deltas, omega, tol=1e-9):
    for d in deltas:
        G_lft = freqresp(U.close(d), omega)
        G_rebuilt = freqresp(U.at(U.values(d)), omega)
        err = rel_diff(G_lft, G_rebuilt)
        assert err < tol, f"delta={d}: LFT and rebuilt model differ by {err:.2e}"


# -- the two-mass model of the thesis (sec. 2.3) ----------------------------------

def two_mass(rel=0.02):
    def mck(v):
        M = np.diag([v["m1"], v["m2"]])
        K = np.array([[v["k1"], -v["k1"]], [-v["k1"], v["k1"] + v["k2"]]])
        return M, None, K
    params = [UncertainParameter("m1", 1.0, rel=rel), UncertainParameter("m2", 2.0, rel=rel),
              UncertainParameter("k1", 450.0, rel=rel), UncertainParameter("k2", 175.0, rel=rel)]
    return uncertain_mck(mck, params, inputs={"f_e": 0, "u": 1},
                         outputs={"x1": 0, "x2": 1, "a1": ("acceleration", 0)})


# natural frequencies are about 7.5 and 26.6 rad/s; stay clear of them
OMEGA_2M = np.array([0.5, 3.0, 15.0, 50.0, 200.0])


def test_two_mass_structure_and_channels():
    U = two_mass()
    assert U.structure == BlockStructure([Block.real(1, "m1"), Block.real(1, "m2"),
                                          Block.real(1, "k1"), Block.real(1, "k2")])
    assert U.repetitions == (1, 1, 1, 1)
    assert list(U.P.input_labels) == ["w_m1", "w_m2", "w_k1", "w_k2", "f_e", "u"]
    assert list(U.P.output_labels) == ["z_m1", "z_m2", "z_k1", "z_k2", "x1", "x2", "a1"]
    lo, hi = U.params[2].bounds
    assert lo == pytest.approx(441.0) and hi == pytest.approx(459.0)


def test_two_mass_lft_equals_rebuilt_model_at_samples_and_corners():
    U = two_mass()
    corners = [np.array(c) for c in itertools.product((-1.0, 1.0), repeat=4)]
    deltas = corners + list(U.sample(12, rng=1)) + [np.zeros(4)]
    assert_lft_matches(U, deltas, OMEGA_2M)


def test_lft_check_can_fail():
    # the comparison must detect a wrong parameter value (guards against a vacuous test)
    U = two_mass()
    d = np.array([1.0, -1.0, 1.0, -1.0])
    G_lft = freqresp(U.close(d), OMEGA_2M)
    wrong = U.values(d)
    wrong["k1"] *= 1.0 + 1e-6
    assert rel_diff(G_lft, freqresp(U.at(wrong), OMEGA_2M)) > 1e-8


def test_nominal_is_the_centre_model():
    U = two_mass()
    G0 = freqresp(U.close(np.zeros(4)), OMEGA_2M)
    assert rel_diff(G0, freqresp(U.nominal(), OMEGA_2M)) < 1e-12


# -- a damped three-DOF chain with a parameter of rank > 1 ----------------------------

def chain():
    """m1-k1-m2-k2-m3-k3-ground with dampers in parallel; ``ma`` is an added mass on
    carts 2 and 3 (rank 2), ``c`` a damping coefficient shared by all dampers (rank 3)."""
    def mck(v):
        M = np.diag([v["m1"], 2.6 + v["ma"], 2.6 + v["ma"]])
        k1, k2, k3 = v["k1"], v["k2"], v["k3"]
        K = np.array([[k1, -k1, 0], [-k1, k1 + k2, -k2], [0, -k2, k2 + k3]])
        c = v["c"]
        C = c * np.array([[1, -1, 0], [-1, 2, -1], [0, -1, 2]])
        return M, C, K
    params = [UncertainParameter("m1", 2.8, rel=0.05),
              UncertainParameter("ma", 0.5, range=(0.0, 1.5)),
              UncertainParameter("k1", 842.3, rel=0.1),
              UncertainParameter("k2", 806.5, abs=40.0),
              UncertainParameter("k3", 386.0, rel=0.2),
              UncertainParameter("c", 2.0, rel=0.5)]
    return uncertain_mck(mck, params, inputs={"f": 0, "u": 2},
                         outputs={"x1": 0, "v3": ("velocity", 2), "a2": ("acceleration", 1)})


def test_chain_repeated_blocks():
    U = chain()
    assert U.repetitions == (1, 2, 1, 1, 1, 3)
    kinds = [(b.kind, b.rows, b.name) for b in U.structure]
    assert kinds == [("real", 1, "m1"), ("real", 2, "ma"), ("real", 1, "k1"), ("real", 1, "k2"),
                     ("real", 1, "k3"), ("real", 3, "c")]
    assert U.nunc == 9
    assert "w_ma_2" in U.P.input_labels and "z_c_3" in U.P.output_labels
    # the range is used around its midpoint
    assert U.params[1].center == pytest.approx(0.75) and U.params[1].halfwidth == pytest.approx(0.75)


def test_chain_lft_equals_rebuilt_model():
    U = chain()
    rng = np.random.default_rng(5)
    corners = [np.array(c) for c in itertools.product((-1.0, 1.0), repeat=6)]
    picked = [corners[i] for i in rng.choice(len(corners), 16, replace=False)]
    deltas = picked + [np.ones(6), -np.ones(6)] + list(U.sample(10, rng=2))
    assert_lft_matches(U, deltas, np.array([0.3, 4.0, 11.0, 19.0, 33.0, 120.0]))


def test_delta_matrix_is_in_the_structure():
    U = chain()
    D = U.delta_matrix([0.1, -0.2, 0.3, 0.4, -0.5, 0.6])
    assert U.structure.contains(D)
    assert np.allclose(np.diag(D), [0.1, -0.2, -0.2, 0.3, 0.4, -0.5, 0.6, 0.6, 0.6])
    assert np.array_equal(U.delta_vector(D), [0.1, -0.2, 0.3, 0.4, -0.5, 0.6])
    D[1, 1] = 0.7                                   # breaks the repetition of "ma"
    with pytest.raises(ModelError, match="not in the structure"):
        U.delta_vector(D)
    with pytest.raises(ModelError, match="not in the structure"):
        U.delta_vector(1j * U.delta_matrix(np.ones(6)))


# -- parameters -------------------------------------------------------------------

def test_parameter_ranges():
    p = UncertainParameter("k", 450.0, rel=0.02)
    assert p.bounds == pytest.approx((441.0, 459.0))
    assert p.value(p.delta(455.0)) == pytest.approx(455.0)
    q = UncertainParameter("m", -2.0, rel=0.1)       # negative nominal: width uses |nominal|
    assert q.bounds == pytest.approx((-2.2, -1.8))
    r = UncertainParameter("c", 0.0, abs=0.3)
    assert r.bounds == pytest.approx((-0.3, 0.3))
    s = UncertainParameter("x", 1.0, range=(0.5, 3.0))
    assert (s.center, s.halfwidth) == pytest.approx((1.75, 1.25))


@pytest.mark.parametrize("kwargs, words", [
    (dict(rel=-0.1), ["k", "rel"]),
    (dict(rel=0.0), ["k", "rel"]),
    (dict(abs=-3.0), ["k", "abs"]),
    (dict(range=(460.0, 440.0)), ["k", "range"]),
    (dict(range=(500.0, 600.0)), ["k", "outside"]),
    (dict(range=(400.0, 500.0), abs=3.0), ["k", "abs or range"]),
    (dict(rel=float("nan")), ["k", "rel"]),
])
def test_bad_parameters(kwargs, words):
    with pytest.raises(ModelError) as exc:
        UncertainParameter("k", 450.0, **kwargs)
    for w in words:
        assert w in str(exc.value)


def test_zero_nominal_needs_absolute_range():
    with pytest.raises(ModelError, match="nonzero"):
        UncertainParameter("c", 0.0, rel=0.1)


# -- bad models ---------------------------------------------------------------------

P_MK = [UncertainParameter("m", 1.0), UncertainParameter("k", 100.0)]


def build(mck, params=P_MK):
    return uncertain_mck(mck, params, inputs={"f": 0}, outputs={"x": 0})


def test_parameter_that_does_not_appear():
    with pytest.raises(ModelError, match="parameter k does not change"):
        build(lambda v: (np.diag([v["m"]]), None, np.diag([100.0])))


def test_non_affine_parameter_is_named():
    with pytest.raises(ModelError) as exc:
        build(lambda v: (np.diag([v["m"]]), None, np.diag([v["k"] ** 2 / 100.0])))
    assert "parameter k" in str(exc.value) and "K" in str(exc.value)
    with pytest.raises(ModelError, match="parameter m"):
        build(lambda v: (np.diag([1.0 / v["m"]]), None, np.diag([v["k"]])))


def test_product_of_parameters_is_rejected():
    with pytest.raises(ModelError, match="jointly"):
        build(lambda v: (np.diag([v["m"]]), None, np.diag([v["k"] * v["m"]])))


def test_nonsquare_mass_matrix():
    with pytest.raises(ModelError, match="M must be a square"):
        build(lambda v: (np.array([[v["m"], 0.0, 0.0], [0.0, 1.0, 0.0]]), None,
                         np.diag([v["k"], 1.0])))


def test_stiffness_of_wrong_size():
    with pytest.raises(ModelError, match="K must be 2x2"):
        build(lambda v: (np.diag([v["m"], 1.0]), None, np.diag([v["k"]])))


def test_unknown_parameter_name_in_matrices():
    with pytest.raises(ModelError, match="'kk'"):
        build(lambda v: (np.diag([v["m"]]), None, np.diag([v["k"] + v["kk"]])))


def test_non_finite_matrix():
    with pytest.raises(ModelError, match="C contains non-finite"):
        build(lambda v: (np.diag([v["m"]]), np.array([[np.nan]]), np.diag([v["k"]])))


def test_mass_not_definite_at_a_corner():
    params = [UncertainParameter("m", 1.0, abs=1.5), UncertainParameter("k", 100.0)]
    with pytest.raises(ModelError, match="not positive definite at"):
        build(lambda v: (np.diag([v["m"]]), None, np.diag([v["k"]])), params)


def test_duplicate_names():
    with pytest.raises(ModelError, match="unique"):
        build(lambda v: (np.diag([v["m"]]), None, np.diag([v["m"]])),
              [UncertainParameter("m", 1.0), UncertainParameter("m", 2.0)])


def test_unknown_parameter_in_at():
    U = two_mass()
    with pytest.raises(ModelError, match="unknown parameter 'k9'"):
        U.at({"k9": 1.0})


def test_wrong_number_of_perturbations():
    U = two_mass()
    with pytest.raises(ModelError, match="expected 4"):
        U.close([0.0, 0.0])


# -- with the structured singular value ------------------------------------------------

def test_mu_lower_bound_finds_the_destabilising_parameters():
    # k3 = 386 +- 500 N/m: the grounded spring can vanish, at delta_k3 = -386/500, which puts
    # a pole at s = 0 (det K = k1 k2 k3 for the chain).  mu of P11(0) over the real parameter
    # structure is then 500/386, and the perturbation proving the lower bound must give
    # parameter values whose rebuilt model has that pole.
    from mutext.mu import mu_lower, mu_upper

    def mck(v):
        M = np.diag([v["m1"], 2.6, 2.6])
        k1, k2, k3 = v["k1"], v["k2"], v["k3"]
        K = np.array([[k1, -k1, 0], [-k1, k1 + k2, -k2], [0, -k2, k2 + k3]])
        return M, np.diag([5.3, 1.9, v["c3"]]), K
    params = [UncertainParameter("m1", 2.8, rel=0.05), UncertainParameter("k1", 842.3, rel=0.1),
              UncertainParameter("k2", 806.5, rel=0.1), UncertainParameter("k3", 386.0, abs=500.0),
              UncertainParameter("c3", 10.7, rel=0.2)]
    U = uncertain_mck(mck, params, inputs={"f": 0}, outputs={"x1": 0})
    n = U.nunc
    P11 = freqresp(U.P, [0.0])[:n, :n, 0]
    lo = mu_lower(P11, U.structure)
    assert lo.value == pytest.approx(500.0 / 386.0, rel=1e-6)
    delta = U.delta_vector(lo.Delta)
    assert np.abs(delta).max() == pytest.approx(386.0 / 500.0, rel=1e-6)
    values = U.values(delta)
    assert values["k3"] == pytest.approx(0.0, abs=1e-6)
    poles = np.linalg.eigvals(np.asarray(U.at(values).A))
    assert np.min(np.abs(poles)) < 1e-6
    assert mu_upper(P11, U.structure).value >= lo.value * (1 - 1e-9)
