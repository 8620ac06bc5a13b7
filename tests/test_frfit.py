"""Vector fitting of measured FRFs (mutext.frfit) against models with known poles."""
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.examples import three_mass as tm
from mutext.frfit import fit_frf, fit_frf_auto
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
