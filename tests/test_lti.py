"""LTI core: state space from M, C, K; LFTs and star products; H-infinity norm vs slycot."""
import control as ct
import numpy as np
import pytest

from mutext.errors import IllPosedError, ModelError
from mutext.lti import (balance_states, freqresp, hinf_norm, lft_lower, lft_matrix, lft_upper,
                        mck_to_ss, sigma_max, ss, star)


def _rand_stable(rng, n, m, p):
    sys = ct.rss(n, p, m)
    return ss(sys.A, sys.B, sys.C, rng.standard_normal((p, m)))


def _resp_close(G1, G2, omega, rtol=1e-9):
    R1, R2 = freqresp(G1, omega), freqresp(G2, omega)
    assert np.allclose(R1, R2, rtol=rtol, atol=rtol * np.abs(R2).max())


# ---------------------------------------------------------------- M, C, K

def test_mck_single_mass_analytic():
    m, c, k = 2.0, 3.0, 50.0
    G = mck_to_ss([[m]], [[c]], [[k]], inputs={"f": 0},
                  outputs={"x": 0, "v": ("velocity", 0), "a": ("acceleration", 0)})
    w = np.array([0.5, 5.0, 40.0])
    s = 1j * w
    H = freqresp(G, w)
    x = 1 / (m * s**2 + c * s + k)
    assert np.allclose(H[0, 0], x)
    assert np.allclose(H[1, 0], s * x)
    assert np.allclose(H[2, 0], s**2 * x)
    assert G.input_labels == ["f"] and G.output_labels == ["x", "v", "a"]


def test_mck_two_mass_static_gain():
    # chain ground - k2 - m2 - k1 - m1; static compliance from a force on m1
    k1, k2 = 450.0, 175.0
    K = np.array([[k1, -k1], [-k1, k1 + k2]])
    G = mck_to_ss(np.diag([1.0, 2.0]), None, K, inputs={"f": 0}, outputs={"x1": 0, "x2": 1})
    dc = -np.asarray(G.C) @ np.linalg.solve(np.asarray(G.A), np.asarray(G.B))
    assert np.allclose(dc.ravel(), [1 / k1 + 1 / k2, 1 / k2])


@pytest.mark.parametrize("M, msg", [
    ([[1.0, 0.0], [0.0, 0.0]], "positive definite"),
    ([[1.0, 0.5], [0.0, 1.0]], "symmetric"),
    ([[1.0, np.nan], [np.nan, 1.0]], "non-finite"),
])
def test_mck_rejects_bad_mass(M, msg):
    with pytest.raises(ModelError, match=msg):
        mck_to_ss(M, None, np.eye(2), inputs={"f": 0}, outputs={"x": 0})


def test_mck_rejects_bad_ports():
    with pytest.raises(ModelError, match="DOF index 5"):
        mck_to_ss(np.eye(2), None, np.eye(2), inputs={"f": 5}, outputs={"x": 0})
    with pytest.raises(ModelError, match="quantity"):
        mck_to_ss(np.eye(2), None, np.eye(2), inputs={"f": 0}, outputs={"x": ("jerk", 0)})
    with pytest.raises(ModelError, match="must be 2x2"):
        mck_to_ss(np.eye(2), None, np.eye(3), inputs={"f": 0}, outputs={"x": 0})


# ---------------------------------------------------------------- LFTs

def test_lower_lft_matches_formula_and_control_feedback():
    rng = np.random.default_rng(1)
    P = _rand_stable(rng, 5, 3, 3)   # w (2), u (1); z (2), y (1)
    K = _rand_stable(rng, 2, 1, 1)
    K = ss(K.A, K.B, K.C, 0.0 * np.asarray(K.D))  # interconnect() rejects algebraic loops
    CL = lft_lower(P, K, 1, 1)
    w = np.logspace(-2, 2, 15)
    Pw, Kw = freqresp(P, w), freqresp(K, w)
    for i in range(w.size):
        P11, P12, P21, P22 = Pw[:2, :2, i], Pw[:2, 2:, i], Pw[2:, :2, i], Pw[2:, 2:, i]
        Ki = Kw[:, :, i]
        ref = P11 + P12 @ Ki @ np.linalg.solve(np.eye(1) - P22 @ Ki, P21)
        assert np.allclose(freqresp(CL, w[i:i + 1])[:, :, 0], ref, rtol=1e-9, atol=1e-12)
    # python-control's interconnection (P with u = K y) gives the same closed loop
    Pl = ss(P.A, P.B, P.C, P.D, inputs=["w1", "w2", "u"], outputs=["z1", "z2", "y"])
    Kl = ss(K.A, K.B, K.C, K.D, inputs=["y"], outputs=["u"])
    ref = ct.interconnect([Pl, Kl], inplist=["w1", "w2"], outlist=["z1", "z2"])
    _resp_close(CL, ref, w)


def test_upper_lft_matches_formula():
    rng = np.random.default_rng(2)
    P = _rand_stable(rng, 4, 3, 3)
    D = ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[0.3]])
    F = lft_upper(P, D, 1, 1)
    w = np.logspace(-1, 1, 7)
    Pw = freqresp(P, w)
    for i in range(w.size):
        M = Pw[:, :, i]
        assert np.allclose(freqresp(F, w[i:i + 1])[:, :, 0], lft_matrix(M, [[0.3]], 1, 1, upper=True))


def test_star_product_associates_with_lfts():
    # (P * Q) closed by K equals P closed by (Q closed by K)
    rng = np.random.default_rng(3)
    P = _rand_stable(rng, 3, 2, 2)   # w, u1 -> z, y1
    Q = _rand_stable(rng, 2, 2, 2)   # y1, u2 -> u1, y2
    K = ss([[-2.0]], [[1.0]], [[0.5]], [[0.0]])
    left = lft_lower(star(P, Q, 1, 1), K, 1, 1)
    right = lft_lower(P, lft_lower(Q, K, 1, 1), 1, 1)
    _resp_close(left, right, np.logspace(-2, 2, 20), rtol=1e-8)


def test_lft_matrix_not_well_posed():
    with pytest.raises(IllPosedError, match="not well posed"):
        lft_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]), [[1.0]], 1, 1)


# ---------------------------------------------------------------- norms

@pytest.mark.parametrize("seed", range(40))
def test_hinf_norm_matches_slycot(seed):
    rng = np.random.default_rng(seed)
    n, m, p = rng.integers(1, 9), rng.integers(1, 4), rng.integers(1, 4)
    G = _rand_stable(rng, int(n), int(m), int(p))
    ref = ct.norm(G, "inf")
    ours = hinf_norm(G)
    assert ours.value == pytest.approx(ref, rel=1e-6)
    # the peak frequency really attains it
    if np.isfinite(ours.frequency):
        assert sigma_max(G, [ours.frequency])[0] == pytest.approx(ours.value, rel=1e-6)


def test_hinf_norm_lightly_damped_resonance():
    # a narrow resonance: a grid would miss it, the Hamiltonian method must not
    z, wn = 1e-4, 37.0
    G = ss([[0, 1], [-wn**2, -2 * z * wn]], [[0], [1]], [[1, 0]], [[0]])
    exact = 1 / (2 * z * wn**2 * np.sqrt(1 - z**2))
    assert hinf_norm(G).value == pytest.approx(exact, rel=1e-8)
    assert hinf_norm(G).frequency == pytest.approx(wn * np.sqrt(1 - 2 * z**2), rel=1e-6)


def test_hinf_norm_unstable_is_infinite_and_l_inf_on_request():
    G = ss([[1.0]], [[1.0]], [[1.0]], [[0.0]])      # 1/(s - 1)
    assert hinf_norm(G).value == np.inf
    assert hinf_norm(G, require_stable=False).value == pytest.approx(1.0, rel=1e-9)


def test_balance_states_keeps_transfer_function():
    rng = np.random.default_rng(5)
    G = _rand_stable(rng, 5, 2, 2)
    t = 10.0 ** rng.uniform(-4, 4, 5)
    Gb = ss(np.asarray(G.A) * t[None, :] / t[:, None], np.asarray(G.B) / t[:, None],
            np.asarray(G.C) * t[None, :], G.D)
    bal, _ = balance_states(Gb)
    _resp_close(bal, G, np.logspace(-2, 2, 11), rtol=1e-8)
    A = np.abs(np.asarray(bal.A))
    assert A.max() / A[A > 0].min() < np.abs(np.asarray(Gb.A)).max() / np.abs(np.asarray(Gb.A))[A > 0].min()
