"""Vector fitting of measured FRFs (mutext.frfit) against models with known poles."""
import doctest
import inspect

import numpy as np
import pytest
import scipy.linalg as sla

from three_mass_plain import half_gaps

import mutext.frfit as frfit
from mutext.errors import ModelError
from mutext.examples import three_mass as tm
from mutext.frfit import fit_frf, fit_frf_auto, noise_level, resonances
from mutext.lti import freqresp
from mutext.rig import measure

F = np.arange(0.2, 10.0, 0.02)
W = 2 * np.pi * F


def _rig():
    return tm.mechanical_model(tm.TABLE_3_1)


def test_exact_data_recovers_the_poles():
    T = _rig()
    G = freqresp(T, W)[0, 0]
    fit = fit_frf(W, G, 6)
    true_poles = np.sort_complex(np.linalg.eigvals(np.asarray(T.A, float)))
    got = np.sort_complex(np.linalg.eigvals(np.asarray(fit.system.A, float)))
    assert np.allclose(got, true_poles, rtol=1e-8)
    assert fit.residual < 1e-10
    # the state-space model and the pole-residue form agree, beyond the data band too
    w = np.logspace(-1, 3, 50)
    assert np.allclose(freqresp(fit.system, w)[0, 0], freqresp(T, w)[0, 0], rtol=1e-7)
    assert np.allclose(fit.response(w), freqresp(T, w)[0, 0], rtol=1e-7)


def test_noisy_data_residual_at_the_noise_level():
    T = _rig()
    frf = measure(T, "f1", "x1", F, noise=0.01, rng=3)
    fit = fit_frf_auto(W, frf.response, tol=0.02)
    assert fit.order == 6
    assert 0.007 < fit.residual < 0.013                     # circular noise of 1 % RMS
    G0 = freqresp(T, W)[0, 0]
    err = np.sqrt(np.mean(np.abs(fit.response(W) - G0) ** 2 / np.abs(G0) ** 2))
    assert err < 0.004                                       # averaging: well below the noise
    assert np.all(np.linalg.eigvals(np.asarray(fit.system.A, float)).real < 0)


def test_auto_order_reports_an_unreachable_tolerance():
    frf = measure(_rig(), "f1", "x1", F, noise=0.05, rng=1)
    fit = fit_frf_auto(W, frf.response, tol=1e-3, max_order=10)
    assert fit.notes and "no order up to 10" in fit.notes[0]
    assert np.all(np.linalg.eigvals(np.asarray(fit.system.A, float)).real < 0)


@pytest.mark.parametrize("omega, G, order, match", [
    (W, np.ones(W.size - 1), 4, "frequencies but"),
    (W[:3], np.ones(3), 2, "at least 4"),
    (-W, np.ones(W.size), 4, "positive"),
    (W, np.full(W.size, np.nan), 4, "non-finite"),
    (W, np.ones(W.size), 0, "positive integer"),
    (np.r_[W[:5], W[4]], np.ones(6), 2, "repeated"),
])
def test_bad_data(omega, G, order, match):
    with pytest.raises(ModelError, match=match):
        fit_frf(omega, G, order)


# --- measured resonances (mutext.frfit.resonances) ---------------------------
# A 3-DOF chain ground-k1-m1-k12-m2-k23-m3 (k1 = 50, k12 = 40, k23 = 30 kN/m),
# Rayleigh damping (zeta 1.5-2 %); its exact modes come from the eigenvalues of the first-order form
# computed with scipy, the FRF f1->x1 from the dynamic stiffness with numpy.

M3 = np.diag([1.0, 0.8, 0.6])
K3 = np.array([[9e4, -4e4, 0.0], [-4e4, 7e4, -3e4], [0.0, -3e4, 3e4]])
C3 = 4.0 * M3 + 6e-5 * K3
F3 = np.arange(0.5, 100.01, 0.5)                      # 0.5 Hz steps


def _dof_frf(M, C, K, f):
    w = 2 * np.pi * np.asarray(f)
    Z = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    return np.linalg.solve(Z, np.broadcast_to(np.eye(len(M))[:, :1], (w.size, len(M), 1)))[:, 0, 0]


def _exact_modes(M, C, K):
    n = len(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sla.solve(M, K), -sla.solve(M, C)]])
    lam = sla.eigvals(A)
    lam = np.sort_complex(lam[lam.imag > 0])
    lam = lam[np.argsort(np.abs(lam))]
    return np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)


def _noisy(H, rel, seed):
    e = np.random.default_rng(seed).standard_normal((2, H.size))
    return H + rel * np.abs(H) * (e[0] + 1j * e[1]) / np.sqrt(2)


def _one_mode(f, fn=30.0, zeta=0.02):
    w, wn = 2 * np.pi * np.asarray(f), 2 * np.pi * fn
    return 1.0 / (wn ** 2 - w ** 2 + 2j * zeta * wn * w)


def test_resonances_agree_with_the_exact_eigenvalues():
    fn, zn = _exact_modes(M3, C3, K3)
    H = _dof_frf(M3, C3, K3, F3)
    # 40 replicates pin the std down to ~11 %; six checks at 3 std then fail by
    # chance for about 2 % of noise seeds (measured over 100 seeds; 1.6 % if Gaussian)
    R = resonances(F3, _noisy(H, 0.01, 0), n_boot=40)
    assert len(R) == 3
    for r, f0, z0 in zip(R, fn, zn):
        assert 0 < r.freq_std < 0.01 * f0 and 0 < r.damping_std < 0.1 * z0     # sensible sizes
        assert abs(r.freq_hz - f0) <= 3 * r.freq_std
        assert abs(r.damping_ratio - z0) <= 3 * r.damping_std
        assert r.freq_hz == pytest.approx(abs(r.pole) / (2 * np.pi))
        assert r.damping_ratio == pytest.approx(-r.pole.real / abs(r.pole))
        assert r.peak == pytest.approx(abs(_dof_frf(M3, C3, K3, [f0])[0]), rel=0.05)
    # exact data: the poles themselves, and noise=0 gives zero uncertainty
    E = resonances(F3, H, noise=0.0)
    assert np.allclose([r.freq_hz for r in E], fn, rtol=1e-8)
    assert np.allclose([r.damping_ratio for r in E], zn, rtol=1e-6)
    assert all(r.freq_std == 0 and r.damping_std == 0 for r in E)


def test_noise_level_recovers_the_noise():
    H = _dof_frf(M3, C3, K3, F3)
    for seed in (1, 2, 3):
        assert noise_level(F3, _noisy(H, 0.01, seed)) == pytest.approx(0.01, rel=0.2)
    f = np.arange(1.0, 200.0, 0.25)
    assert noise_level(f, _noisy(_one_mode(f), 0.03, 4)) == pytest.approx(0.03, rel=0.2)
    assert noise_level(F3, H) < 1e-4                 # exact data: curvature alone is not noise


@pytest.mark.parametrize("rel", [0.01, 0.05])
def test_no_spurious_resonance_on_a_single_mode(rel):
    G = _noisy(_one_mode(F3), rel, 11)
    for order in (None, 16):                         # a deliberately high order patches noise
        R = resonances(F3, G, order=order, n_boot=0)
        assert len(R) == 1 and R[0].freq_hz == pytest.approx(30.0, rel=0.01)


def test_bootstrap_std_matches_the_scatter_of_repeated_measurements():
    # would fail with a zero (or badly scaled) bootstrap: the spread of the
    # estimates over independent noise realizations must match the reported std
    H = _one_mode(F3)
    R = [resonances(F3, _noisy(H, 0.02, 100 + k), n_boot=10, rng=k)[0] for k in range(12)]
    f_spread = np.std([r.freq_hz for r in R], ddof=1)
    z_spread = np.std([r.damping_ratio for r in R], ddof=1)
    assert 0.5 < f_spread / np.mean([r.freq_std for r in R]) < 2.0
    assert 0.5 < z_spread / np.mean([r.damping_std for r in R]) < 2.0


def test_resonances_band_and_determinism():
    G = _noisy(_dof_frf(M3, C3, K3, F3), 0.01, 5)
    a, b = resonances(F3, G, rng=3, n_boot=5), resonances(F3, G, rng=3, n_boot=5)
    assert a == b
    only = resonances(F3, G, band=(30.0, 50.0), n_boot=0)
    assert len(only) == 1 and 30 < only[0].freq_hz < 50 and np.isnan(only[0].freq_std)
    assert resonances(F3[::-1], G[::-1], rng=3, n_boot=5) == a      # order of the samples is irrelevant


@pytest.mark.parametrize("kw, match", [
    (dict(freq_hz=F3[:-1]), "frequencies but"),
    (dict(freq_hz=-F3), r"positive \(Hz\)"),
    (dict(band=(50.0, 30.0)), "fmin < fmax"),
    (dict(band=5.0), "band must be"),
    (dict(noise=-0.01), "noise must be finite"),
    (dict(n_boot=-1), "n_boot must be an integer"),
    (dict(max_order=1), "max_order must be an integer"),
    (dict(rng="x"), "rng must be"),
    (dict(order=0), "positive integer"),
])
def test_resonances_bad_input(kw, match):
    args = dict(freq_hz=F3, response=_one_mode(F3))
    args.update(kw)
    with pytest.raises(ModelError, match=match):
        resonances(args.pop("freq_hz"), args.pop("response"), **args)


def test_noise_level_bad_input():
    with pytest.raises(ModelError, match="at least 8"):
        noise_level(F3[:6], _one_mode(F3[:6]))
    with pytest.raises(ModelError, match="noise level: frequencies must be positive"):
        noise_level(-F3, _one_mode(F3))


def test_resonances_docstring_example():
    # the module that defines resonances (and noise_level) holds the example
    result = doctest.testmod(inspect.getmodule(resonances), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


# --- magnitude-only fits (mutext.frfit.fit_magnitude, the D scalings of mutext.dk) -----------

def test_magnitude_fit_of_non_minimum_phase_system_is_its_minimum_phase_factor():
    import control as ct
    # |G| of G = 2 (s - 3)(s^2 + 0.4 s + 4) / ((s + 0.5)(s^2 + 1.2 s + 25)) equals |G_mp|
    # with the zero at +3 reflected to -3: the fit must recover G_mp's zeros and poles
    G = ct.tf(2 * np.polymul([1, -3], [1, 0.4, 4]), np.polymul([1, 0.5], [1, 1.2, 25]))
    w = np.logspace(-2, 2.5, 120)
    mag = np.abs(freqresp(ct.ss(G), w)[0, 0])
    fit = frfit.fit_magnitude(w, mag, 3)
    assert fit.order == 3
    np.testing.assert_allclose(np.sort_complex(fit.zeros), np.sort_complex([-3, -0.2 + np.sqrt(3.96) * 1j,
                                                                            -0.2 - np.sqrt(3.96) * 1j]), rtol=1e-6)
    np.testing.assert_allclose(np.sort_complex(fit.poles), np.sort_complex(ct.poles(G)), rtol=1e-6)
    assert fit.gain == pytest.approx(2.0, rel=1e-6)
    # the realisation, checked by python-control: stable, minimum phase, the data's magnitude
    assert np.all(ct.poles(fit.sys).real < 0) and np.all(ct.zeros(fit.sys).real < 0)
    np.testing.assert_allclose(np.abs(ct.frequency_response(fit.sys, w).magnitude).ravel(), mag, rtol=1e-6)
    np.testing.assert_allclose(np.abs(ct.frequency_response(fit.inverse(), w).magnitude).ravel(), 1 / mag,
                               rtol=1e-6)


# --- upper envelopes (mutext.frfit.fit_envelope, the spread-shaped weights of mutext.mbi) ---------

# slow (8 CPU-s): fit_envelope in the default run through mbi's spread weight (test_mbi)
@pytest.mark.slow
def test_envelope_covers_a_spread_with_three_resonances():
    import control as ct
    # a three-mass rig with m3, c3, k3 each at +-10 %: three resonances of different height, and a
    # fall to almost zero beyond the last one
    w = np.logspace(np.log10(0.4), np.log10(300.0), 400)
    half = half_gaps("5", w, levels=3)
    fit = frfit.fit_envelope(w, half, floor=0.02)
    W_ = np.abs(ct.frequency_response(fit.sys, w).magnitude).ravel()       # realisation, by python-control
    env = np.maximum(half, 0.02 * half.max())
    assert np.all(W_ >= half * (1 - 1e-9))                                  # a cover: nothing undershot
    np.testing.assert_allclose(W_, np.abs(fit(w)), rtol=1e-8)
    # tight where it matters: at the widest spread within 5 %, and at low frequency within 25 %
    k = int(np.argmax(half))
    assert W_[k] < 1.05 * half[k]
    assert np.all(W_[w < 2.0] < 1.25 * half[w < 2.0])
    assert fit.error == pytest.approx(np.log(W_ / env).max(), rel=1e-6)
    # stable, minimum phase, biproper: a weight whose inverse can enter a plant
    assert np.all(ct.poles(fit.sys).real < 0) and np.all(ct.zeros(fit.sys).real < 0)
    assert np.all(ct.poles(fit.inverse()).real < 0) and fit.sys.D[0, 0] > 0


def test_envelope_bad_input_is_named():
    w = np.logspace(0, 1, 10)
    with pytest.raises(ModelError, match="equal length"):
        frfit.fit_envelope(w, np.ones(9))
    with pytest.raises(ModelError, match="not all zero"):
        frfit.fit_envelope(w, np.zeros(10))
    with pytest.raises(ModelError, match="not all zero"):
        frfit.fit_envelope(w, -np.ones(10))
    with pytest.raises(ModelError, match="need floor > 0"):
        frfit.fit_envelope(w, np.r_[0.0, np.ones(9)], floor=0.0)
    with pytest.raises(ModelError, match=r"floor must lie in \[0, 1\)"):
        frfit.fit_envelope(w, np.ones(10), floor=1.5)
    with pytest.raises(ModelError, match="frequencies must be positive"):
        frfit.fit_envelope(-w, np.ones(10))
    for bad in (-1, True, 2.5):
        with pytest.raises(ModelError, match="max_sections must be a non-negative integer"):
            frfit.fit_envelope(w, np.ones(10), max_sections=bad)
