"""The rotor with a breathing crack at speed (mutext.rotor.periodic, rig.measure_rotor).

The harmonic-balance result is checked against things written apart from it:
the time-invariant FRF of the finite-element model (crack closed or absent),
the full model (for the Ritz reduction), and a brute-force time integration
of the stepped-sine analyzer that evaluates the breathing law at every step
instead of using its Fourier series.
"""
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.rig import measure_rotor
from mutext.rotor import data_path, loads_model
from mutext.rotor.crack import breathing_fourier, breathing_weights
from mutext.rotor.periodic import (analyzer_combination, analyzer_frf, harmonic_convergence, harmonic_response,
                                   periodic_rotor, stepped_sine)

TEXT = open(data_path("rotor.toml")).read()


def rotor(extra=""):
    return loads_model(TEXT + extra, base_dir=data_path(""))


def cracked(law="mayes", depth=0.4, angle=0.0):
    return rotor(f"[[crack]]\nstation = 15\ndepth_ratio = {depth}\nbreathing = '{law}'\n"
                 f"orientation = {angle}\n")


@pytest.fixture(scope="module")
def mayes():
    r = cracked()
    pr = periodic_rotor(r, inputs=["i12"], outputs=["x13"])
    return r, pr, pr.reduce(1000.0)


def test_fourier_coefficients_of_the_laws():
    th = np.linspace(0, 2 * np.pi, 2001)
    for law, top in (("mayes", 3), ("open", 2)):
        c = breathing_fourier(law, 8)
        assert np.all(np.abs(c[np.abs(np.arange(-8, 9)) > top]) < 1e-14)
        # the series reproduces the law itself
        g = np.real(sum(c[m + 8][None, :] * np.exp(1j * m * th)[:, None] for m in range(-8, 9)))
        assert np.allclose(g, np.stack(breathing_weights(th, law), axis=1), atol=1e-12)
    # Gasch: open on half the turn; the mean of f cos^2 is 1/4 (analytic), the m = 1 term of
    # f cos^2 is (1/2pi) int_pi^2pi cos^2 t e^{-it} dt = j/(3 pi)
    c = breathing_fourier("gasch", 4)
    assert c[4, 0] == pytest.approx(0.25, abs=1e-6)
    assert c[5, 0] == pytest.approx(1j / (3 * np.pi), abs=1e-6)


def test_time_averaged_model_is_the_zeroth_harmonic(mayes):
    r, pr, _ = mayes
    f = np.array([25.0, 60.0, 150.0, 200.0])
    lti = r.frf(f, inputs=["i12"], outputs=["x13"]).H
    assert np.allclose(harmonic_response(pr, f, harmonics=0)(0), lti, rtol=1e-9, atol=0)


def test_closed_crack_and_no_crack_give_the_linear_frf():
    f = np.array([22.0, 33.5, 120.0, 191.0])
    lti = rotor().frf(f, inputs=["i12"], outputs=["x13"]).H
    for model in (cracked(depth=0.0), rotor()):
        H = analyzer_frf(periodic_rotor(model, inputs=["i12"], outputs=["x13"]), f, harmonics=3).H
        assert np.allclose(H, lti, rtol=1e-7, atol=0)   # the stiff FE solve: about 1e-9
    # the linear path of the rig is the model's FRF, exactly
    meas = measure_rotor(rotor(), "i12", "x13", f)
    assert np.array_equal(meas.response, lti[0, 0])
    assert (meas.input_station, meas.output_station, meas.input_quantity) == (12, 13, "current")


def test_ritz_reduction_keeps_the_sidebands(mayes):
    _, pr, red = mayes
    assert red.reduction_error < 1e-3
    f = np.array([23.5, 43.5, 180.5, 204.0])
    full, rr = harmonic_response(pr, f, harmonics=3), harmonic_response(red, f, harmonics=3)
    for k in (-1, 0, 1):
        assert np.max(np.abs(rr(k) - full(k))) <= 2e-3 * np.max(np.abs(full(k)))


def test_harmonic_truncation_converges(mayes):
    _, _, red = mayes
    rows = harmonic_convergence(red, np.arange(20.0, 225.0, 5.0), harmonics=(0, 1, 2, 4, 6, 8))
    change = {r["harmonics"]: r["max_change"] for r in rows}
    assert change[0] > 1e-3                 # the crack's time variation matters ...
    assert change[4] < 1e-3 and change[6] < 1e-5     # ... and converges fast (the default N = 6)


def test_time_integration_agrees_with_harmonic_balance(mayes):
    r, _, red = mayes
    f = np.array([23.5, 43.5, 53.5, 80.0, 204.0])
    hb = analyzer_frf(red, f, harmonics=6, settle_s=3.0, revolutions=10).H[0, 0]
    td = stepped_sine(red, f, settle_s=3.0, revolutions=10, steps_per_rev=7000)
    assert td["steps_per_rev"] == 7000
    err = np.abs(td["H"] - hb) / np.abs(hb)
    effect = np.abs(hb - r.frf(f, inputs=["i12"], outputs=["x13"]).H[0, 0]) / np.abs(hb)
    assert np.all(err < 2e-4), err
    # the check can fail: the crack changes these points by far more than the tolerance (53.5 Hz,
    # f1 + 2 x 10 Hz, is driven by the twice-per-revolution asymmetry, which c44 reduces: 16x)
    assert np.all(effect[[0, 1, 2, 4]] > 10 * 2e-4), effect


@pytest.mark.slow
def test_time_integration_closed_crack_and_gasch():
    f = np.array([23.5, 43.5, 190.0])
    pr0 = periodic_rotor(cracked(depth=0.0), inputs=["i12"], outputs=["x13"]).reduce(1000.0)
    td = stepped_sine(pr0, f, settle_s=4.0, revolutions=10)
    lti = rotor().frf(f, inputs=["i12"], outputs=["x13"]).H[0, 0]
    assert np.all(np.abs(td["H"] - lti) / np.abs(lti) < 2e-4)
    prg = periodic_rotor(cracked("gasch"), inputs=["i12"], outputs=["x13"]).reduce(1000.0)
    # the switching law's harmonics decay like 1/m, so the truncation converges like 1/N:
    # N = 24 leaves 0.4 % at the second mode, N = 64 about 0.1 %
    hb = analyzer_frf(prg, f, harmonics=64, settle_s=4.0, revolutions=10).H[0, 0]
    td = stepped_sine(prg, f, settle_s=4.0, revolutions=10)
    assert np.all(np.abs(td["H"] - hb) / np.abs(hb) < 3e-3)


# slow (3 CPU-s): the analyzer's window term; the time integration against harmonic balance stays in the
# default run
@pytest.mark.slow
def test_analyzer_window_term_at_half_multiples_of_the_speed(mayes):
    # where 2 f is a multiple of the speed, the negative-frequency half of the real excitation
    # reaches the correlation: the result depends on the excitation phase
    _, _, red = mayes
    f = np.array([25.0, 25.25])
    a = analyzer_frf(red, f, excitation_phase=0.0).H[0, 0]
    b = analyzer_frf(red, f, excitation_phase=0.7).H[0, 0]
    assert abs(a[0] - b[0]) > 1e-4 * abs(a[0])
    td = stepped_sine(red, f[:1], settle_s=3.0, revolutions=10, excitation_phase=0.7, steps_per_rev=7000)
    hb = analyzer_frf(red, f[:1], settle_s=3.0, revolutions=10, excitation_phase=0.7, harmonics=6).H[0, 0]
    assert abs(td["H"][0] - hb[0]) < 2e-4 * abs(hb[0])


def test_bad_input_is_named():
    with pytest.raises(ModelError, match="breathing"):
        rotor("[[crack]]\nstation = 15\ndepth_ratio = 0.4\nbreathing = 'wobbly'\n")
    slow = loads_model(TEXT.replace("speed_rpm = 600", "speed_rpm = 0") +
                       "[[crack]]\nstation = 15\ndepth_ratio = 0.4\nbreathing = 'mayes'\n",
                       base_dir=data_path(""))
    with pytest.raises(ModelError, match="running speed"):
        periodic_rotor(slow)
    _, pr = None, periodic_rotor(cracked(), inputs=["i12"], outputs=["x13"])
    with pytest.raises(ModelError, match="harmonics"):
        harmonic_response(pr, [30.0], harmonics=-1)
    with pytest.raises(ModelError, match="frequencies"):
        analyzer_frf(pr, [float("nan")])
    with pytest.raises(ModelError, match="cutoff"):
        pr.reduce(-5.0)
    with pytest.raises(ModelError, match="no input port 'no-such-port'.*i12"):
        stepped_sine(pr, [30.0], in_port="no-such-port")
    with pytest.raises(ModelError, match="no output port 'x99'.*x13"):
        stepped_sine(pr, [30.0], out_port="x99")


def test_crack_quadrature_points_are_checked():
    from mutext.rotor.crack import crack_compliance_dimensionless
    with pytest.raises(ModelError, match="n_quad"):
        rotor("[[crack]]\nstation = 15\ndepth_ratio = 0.4\nn_quad = 0\n")
    with pytest.raises(ModelError, match="n_quad"):
        crack_compliance_dimensionless(0.3, n_quad=0)


# ----------------------------------------------------------------------------
# combination frequencies f + k F (the off-diagonal harmonic transfer functions)
# ----------------------------------------------------------------------------

def test_combination_responses_are_the_off_diagonal_htfs(mayes):
    _, _, red = mayes
    f = np.array([23.5, 25.0, 43.5, 80.0])
    hb = analyzer_combination(red, f, (-2, -1, 0, 1, 2), harmonics=6)
    hr = harmonic_response(red, f, harmonics=8)
    # order 0 is the analyzer's FRF; away from 2 f = m F the window terms vanish and H_k remains
    assert np.allclose(hb[0].H, analyzer_frf(red, f, harmonics=8).H, rtol=1e-12, atol=0)
    away = [0, 2, 3]
    for k in (-2, -1, 1, 2):
        assert np.allclose(hb[k].H[0, 0, away], hr(k)[0, 0, away], rtol=1e-9, atol=0)
    # at 25 Hz (2 f = 5 F) the window term changes H_-1 by 7 % (the time integration below confirms
    # it; it grows with the asymmetry c55 - c44: 29 % with c55 alone): the check can fail
    assert abs(hb[-1].H[0, 0, 1] - hr(-1)[0, 0, 1]) > 0.05 * abs(hr(-1)[0, 0, 1])
    # a gaping notch varies at 2x only: no response at f +/- F, a clear one at f +/- 2 F
    gap = periodic_rotor(cracked("gaping"), inputs=["i12"], outputs=["x13"]).reduce(1000.0)
    g = analyzer_combination(gap, f[[0, 2]], (-1, 1, 2))
    h0 = np.abs(analyzer_frf(gap, f[[0, 2]]).H[0, 0])
    assert np.all(np.abs(g[1].H[0, 0]) < 1e-12 * h0) and np.all(np.abs(g[-1].H[0, 0]) < 1e-12 * h0)
    assert np.all(np.abs(g[2].H[0, 0]) > 1e-3 * h0)
    with pytest.raises(ModelError, match="orders must be integers"):
        analyzer_combination(red, f, (1.5,))


@pytest.mark.slow
def test_combination_responses_agree_with_time_integration(mayes):
    # the analyzer in software: the response correlated at f + k F after 6 s settling
    _, _, red = mayes
    f = np.array([23.5, 25.0, 43.5, 80.0])
    hb = analyzer_combination(red, f, (-2, -1, 1, 2), settle_s=6.0, revolutions=10, excitation_phase=0.7)
    td = stepped_sine(red, f, settle_s=6.0, revolutions=10, excitation_phase=0.7, orders=(-2, -1, 1, 2))
    for k in (-2, -1, 1, 2):
        a, b = hb[k].H[0, 0], td["H_orders"][k]
        assert np.all(np.abs(b - a) < 1e-3 * np.abs(a)), (k, np.abs(b - a) / np.abs(a))
        # not lost under the main line (the smallest, order 2 at 80 Hz, is 6e-5 of it: the 2x terms
        # shrink with the asymmetry c55 - c44)
        assert np.all(np.abs(a) > 3e-5 * np.abs(td["H"]))
    # at 25 Hz (2 f = 5 F) the window term moves H_-1 by 7.3 % (phase 0.7): the integration confirms it
    hr = harmonic_response(red, f[1:2], harmonics=8)
    assert abs(td["H_orders"][-1][1] - hr(-1)[0, 0, 0]) > 0.05 * abs(hr(-1)[0, 0, 0])


def test_measure_rotor_records_combination_channels(tmp_path):
    from mutext.rig import read_frf, write_frf
    r = cracked()
    f = np.arange(30.0, 40.01, 0.5)
    chans = measure_rotor(r, "i12", "x13", f, combination=(-1, 1), speed_hz=12.0)
    assert [c.metadata.get("order") for c in chans] == [None, "-1", "1"]
    assert all(c.speed_hz == 12.0 for c in chans)
    ref = analyzer_combination(periodic_rotor(r, inputs=["i12"], outputs=["x13"], speed=2 * np.pi * 12.0)
                               .reduce(1000.0, band_hz=(30.0, 40.0)), f, (-1, 1))
    assert np.allclose(chans[2].response, ref[1].H[0, 0], rtol=1e-9)
    back = read_frf(write_frf(tmp_path / "c.csv", chans[1]))
    assert back.metadata["order"] == "-1" and back.speed_hz == 12.0
    # a time-invariant rotor: zero at the combination frequencies, only the noise there
    clean = measure_rotor(rotor(), "i12", "x13", f, combination=(1,))
    assert np.all(clean[1].response == 0)
    noisy = measure_rotor(rotor(), "i12", "x13", f, combination=(1,), noise=0.01, rng=1)
    ratio = np.abs(noisy[1].response) / np.abs(noisy[0].response)
    assert 0.002 < np.median(ratio) < 0.02
    with pytest.raises(ModelError, match="combination"):
        measure_rotor(r, "i12", "x13", f, combination=(0,))
    with pytest.raises(ModelError, match="speed_hz"):
        measure_rotor(r, "i12", "x13", f, speed_hz=-1.0)
