"""Sideband evidence (mutext.diagnose.sideband_evidence) on rotor sweeps at 10 Hz.

The data are the analyzer's FRFs of the finite-element rotor (harmonic balance,
checked against time integration in test_periodic.py); the detector only
receives the sweep, the healthy model's natural frequencies and the speed.
"""
import numpy as np
import pytest

from mutext.diagnose import sideband_evidence
from mutext.errors import ModelError
from mutext.rig import measure_rotor
from mutext.rotor import data_path, loads_model

TEXT = open(data_path("rotor.toml")).read()
SPEED_HZ = 10.0
NOISE = 5e-4


def rotor(extra="", text=TEXT):
    return loads_model(text + extra, base_dir=data_path(""))


def crack(law):
    return rotor(f"[[crack]]\nstation = 15\ndepth_ratio = 0.4\nbreathing = '{law}'\n")


@pytest.fixture(scope="module")
def modes():
    return rotor().natural_frequencies(n=6)


def sweep(model, seed=3, noise=NOISE):
    return measure_rotor(model, "i12", "x13", noise=noise, rng=seed)


@pytest.fixture(scope="module")
def mayes_sweep():
    """The sweep of the rotor with a breathing (mayes) crack, seed 3 (read-only for the tests)."""
    return sweep(crack("mayes"))


def test_breathing_crack_shows_once_per_revolution_sidebands(modes, mayes_sweep):
    ev = sideband_evidence(mayes_sweep, modes, SPEED_HZ)
    assert ev.verdict == "once per revolution"
    found = {(round(c.mode_hz), c.k): c for c in ev.found()}
    # the first mode's k = +-1 sidebands, at f_n -+ 10 Hz, where predicted
    first = min(m for m, _ in ev.modes)
    for k in (1, -1):
        c = found[(round(first), k)]
        assert c.freq_hz == pytest.approx(first - k * SPEED_HZ)
        assert c.relative_size > 3 * NOISE
    assert ev.noise == pytest.approx(NOISE, rel=0.3)
    assert "FOUND" in ev.summary()


def test_open_crack_shows_twice_per_revolution_only(modes):
    ev = sideband_evidence(sweep(crack("open")), modes, SPEED_HZ)
    assert ev.verdict == "twice per revolution"
    assert ev.orders_found == [2]


@pytest.mark.parametrize("case", ["healthy", "bearing"])
@pytest.mark.parametrize("seed", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_time_invariant_changes_show_none(modes, case, seed):
    model = rotor() if case == "healthy" else rotor(text=TEXT.replace("stiffness = 1.0e7", "stiffness = 0.8e7", 1))
    ev = sideband_evidence(sweep(model, seed), modes, SPEED_HZ)
    assert ev.verdict == "none", ev.summary()
    assert not ev.found()


def test_noise_above_the_sidebands_is_reported_not_guessed(modes):
    ev = sideband_evidence(sweep(crack("mayes"), noise=0.01), modes, SPEED_HZ)
    assert ev.detectable > 0.01
    assert ev.verdict in ("none", "once per revolution")


def test_bad_input(modes):
    d = sweep(rotor())
    with pytest.raises(ModelError, match="speed"):
        sideband_evidence(d, modes, 0.0)
    with pytest.raises(ModelError, match="FRF"):
        sideband_evidence([], modes, SPEED_HZ)
    with pytest.raises(ModelError, match="alpha"):
        sideband_evidence(d, modes, SPEED_HZ, alpha=2.0)


def test_diagnose_reports_the_sidebands_of_data_taken_at_speed(mayes_sweep):
    # the at-speed path of diagnose on the thesis rotor, without the breathing-crack fit (the slow
    # test_diagnose_reports_sidebands_for_data_taken_at_speed fits it): no crack among the hypotheses, so
    # no turning crack is fitted, and the sidebands are reported as what no time-invariant hypothesis holds
    from mutext.diagnose import diagnose
    from mutext.report import _html
    res = diagnose(data_path("rotor.toml"), [mayes_sweep], refit=1,
                   only=lambda h: h.kind == "stiffness" and h.station == 15)
    assert res.n_hypotheses == 1
    assert res.sidebands["verdict"] == "once per revolution" and res.sidebands["orders_found"] == [1]
    assert res.breathing is None
    assert any("the data show sidebands (once per revolution): the rotor is time-periodic" in n
               for n in res.notes), res.notes
    assert "sidebands" in res.report() and res.as_dict()["sidebands"]["orders_found"]
    lines = res.at_speed_lines()
    assert lines and "once per revolution" in lines[0]
    page = _html(res, [])
    assert "<h2>At speed</h2>" in page and "once per revolution" in page
    assert "crack turning with the shaft" not in page


@pytest.mark.slow
def test_diagnose_reports_sidebands_for_data_taken_at_speed():
    # about 25 CPU-s (the breathing-crack fit); the at-speed report path is in the default run by
    # test_diagnose_reports_the_sidebands_of_data_taken_at_speed (sideband evidence and the 'At speed'
    # section from a diagnosis with the hypotheses restricted, no crack fitted)
    # a breathing crack: the diagnosis names the crack's place and the sidebands say it breathes
    from mutext.diagnose import diagnose
    d = sweep(crack("mayes"), seed=5, noise=1e-3)
    res = diagnose(data_path("rotor.toml"), [d], refit=1,
                   only=lambda h: h.kind in ("crack", "stiffness") and h.station in (5, 15, 24))
    assert res.verdict.kind == "crack" and res.verdict.station == 15
    assert res.sidebands["verdict"] == "once per revolution"
    assert "sidebands" in res.report() and res.as_dict()["sidebands"]["orders_found"]
    # ... and the crack that turns with the shaft is fitted: its depth, at the noise, better held out
    b = res.breathing
    assert b["station"] == 15 and b["law"] == "mayes"
    assert abs(b["depth_ratio"] - 0.4) < max(3 * b["depth_std"], 0.01)
    assert b["misfit_left"] < 1.5
    assert b["held_out_error"]["rel"] < 0.5 * b["time_invariant_crack"]["held_out_error"]["rel"]
    assert "turns with the shaft" in res.report()
    # the HTML report says what the terminal says about the data taken at speed
    from mutext.report import _html
    page = _html(res, [])
    assert "<h2>At speed</h2>" in page and "once per revolution" in page
    assert "crack turning with the shaft" in page


@pytest.mark.slow
def test_diagnose_reports_no_sidebands_for_a_bearing_change_at_speed():
    # covered in the default run by test_time_invariant_changes_show_none (a bearing change at speed
    # shows no sidebands) and test_diagnose_reports_sidebands_for_data_taken_at_speed (diagnose
    # reports the sideband verdict)
    from mutext.diagnose import diagnose
    bear = rotor(text=TEXT.replace("stiffness = 1.0e7", "stiffness = 0.8e7", 1))
    res = diagnose(data_path("rotor.toml"), [sweep(bear, seed=6, noise=1e-3)], refit=1,
                   only=lambda h: h.kind in ("crack", "bearing", "stiffness") and h.station in (2, 15))
    assert res.sidebands["verdict"] == "none"


@pytest.mark.slow
def test_diagnose_breathing_crack_from_time_integrated_data():
    # data from the brute-force analyzer (time integration, the breathing law evaluated at every
    # step), not from the harmonic balance the diagnosis fits with
    from mutext.diagnose import diagnose
    from mutext.rig import measure, sweep_frequencies
    from mutext.rotor.periodic import periodic_rotor, stepped_sine
    f = sweep_frequencies()
    pr = periodic_rotor(crack("mayes"), inputs=["i12"], outputs=["x13"]).reduce(1000.0)
    td = stepped_sine(pr, f, settle_s=4.0, revolutions=10)
    d = measure(lambda w: td["H"], 0, 0, f, noise=1e-3, rng=9, input_station=12, output_station=13,
                input_quantity="current", speed_hz=SPEED_HZ)
    d.input_name, d.output_name = "i12", "x13"
    res = diagnose(data_path("rotor.toml"), [d], refit=1,
                   only=lambda h: h.kind in ("crack", "stiffness") and h.station in (5, 15, 24))
    assert res.sidebands["verdict"] == "once per revolution"
    b = res.breathing
    assert b["station"] == 15 and abs(b["depth_ratio"] - 0.4) < 0.01
    assert b["misfit_left"] < 2.0


# ----------------------------------------------------------------------------
# combination-frequency channels: the first-order evidence
# ----------------------------------------------------------------------------

def combo(model, noise, seed, speed_hz=SPEED_HZ, orders=(-1, 1)):
    return measure_rotor(model, "i12", "x13", noise=noise, rng=seed, combination=orders, speed_hz=speed_hz)


@pytest.mark.slow
def test_combination_response_finds_the_breathing_crack_where_sidebands_do_not(modes):
    # 3 % noise: the stepped-sine sidebands (second order in the crack) are lost in it, the
    # responses at f -+ F (first order) are not; at two speeds the orders are consistent
    chans = combo(crack("mayes"), 0.03, 5) + combo(crack("mayes"), 0.03, 6, speed_hz=12.0)
    alone = sideband_evidence(chans[0], modes, SPEED_HZ)
    assert alone.verdict == "none" and alone.source == "stepped sine"
    ev = sideband_evidence(chans, modes, SPEED_HZ)
    assert ev.source == "combination" and ev.stepped_sine_verdict == "none"
    assert ev.verdict == "once per revolution" and ev.orders_found == [1]
    assert len(ev.combination) == 4 and all(c.found and c.consistent for c in ev.combination)
    assert {c.speed_hz for c in ev.combination} == {10.0, 12.0}
    assert "combination-frequency channels" in ev.summary()
    # a gaping notch varies at 2x only: nothing at f -+ F, its response at f -+ 2F
    ev = sideband_evidence(combo(crack("gaping"), 0.03, 7, orders=(-2, -1, 1, 2)), modes, SPEED_HZ)
    assert ev.verdict == "twice per revolution", ev.summary()
    assert {c.k for c in ev.combination if c.found} == {-2, 2}


@pytest.fixture(scope="module")
def healthy():
    return rotor()


@pytest.mark.parametrize("seed", [1, pytest.param(2, marks=pytest.mark.slow), pytest.param(3, marks=pytest.mark.slow)])
def test_combination_channels_of_a_time_invariant_rotor_show_none(modes, healthy, seed):
    # the healthy rotor's combination channels hold the noise only: the F-test keeps its level
    ev = sideband_evidence(combo(healthy, 0.01, seed, orders=(-2, -1, 1, 2)), modes, SPEED_HZ)
    assert ev.source == "combination" and ev.verdict == "none", ev.summary()
    assert all(c.p_value > 1e-4 for c in ev.combination)


def test_combination_metadata_is_checked(modes, healthy):
    chans = combo(healthy, 0.01, 1, orders=(1,))
    chans[1].metadata["order"] = "one"
    with pytest.raises(ModelError, match="order"):
        sideband_evidence(chans, modes, SPEED_HZ)
    chans[1].metadata["order"] = "1"
    with pytest.raises(ModelError, match="no excitation-frequency FRF"):
        sideband_evidence(chans[1:], modes, SPEED_HZ)
    chans[1].speed_hz = None
    with pytest.raises(ModelError, match="speed_hz"):
        sideband_evidence(chans, modes, SPEED_HZ)


def test_fixed_frequency_line_is_not_read_as_a_combination_response(modes, healthy):
    # a 59.5 Hz line in the sensor, 30 x the noise, seen in the channel of order k where
    # f + k F = 59.5 Hz (it moves with the speed on the excitation axis): not a resonance shape
    # of the rotor at f + k F or f, so not evidence at either speed
    chans = []
    for F, seed in ((10.0, 1), (12.0, 2)):
        c = combo(healthy, 0.01, seed, speed_hz=F)
        for ch in c[1:]:
            k = int(ch.metadata["order"])
            near = np.abs(ch.freq_hz + k * F - 59.5) < 0.6
            assert near.sum() >= 2
            ch.response = ch.response + near * 30 * 0.01 * np.abs(c[0].response)
        chans += c
    ev = sideband_evidence(chans, modes, SPEED_HZ)
    assert ev.verdict == "none" and len(ev.combination) == 4, ev.summary()
    # a response shaped as the first mode at f + F (peak 30 % of the largest main response) is found:
    # the test can fail
    ch = chans[2]
    fn = min(modes)
    shape = 1.0 / (fn ** 2 - (ch.freq_hz + 10.0) ** 2 + 2j * 0.01 * fn * (ch.freq_hz + 10.0))
    ch.response = ch.response + shape * (0.3 * np.max(np.abs(chans[0].response)) / np.max(np.abs(shape)))
    ev = sideband_evidence(chans[:3], modes, SPEED_HZ)
    assert ev.verdict == "once per revolution", ev.summary()
