"""`mutext demo rotor`: the Campbell diagram and the unbalance orbit it prints, checked apart."""
import json

import numpy as np
import pytest

from mutext.cli import main


@pytest.mark.slow
def test_demo_rotor_campbell_and_orbit(capsys):
    assert main(["demo", "rotor", "--json", "--points", "50"]) == 0
    out = json.loads(capsys.readouterr().out)
    cb, orb = out["campbell"], out["orbit"]
    # the 1x forward critical speed lies where 1x meets the first forward mode: rpm = 60 f
    crit = cb["critical_speeds_1x_forward"]
    assert len(crit) == 1
    assert crit[0]["speed_rpm"] == pytest.approx(60.0 * crit[0]["frequency_hz"], rel=1e-3)
    assert crit[0]["frequency_hz"] == pytest.approx(out["natural_frequencies_hz"]["healthy"][1], rel=0.01)
    # the 2x line meets the first forward mode at half that speed (rpm = 30 f: near 1020 rpm), where a
    # breathing crack's 2x response resonates; the 3x line at a third (rpm = 20 f)
    for k in (2, 3):
        first = cb[f"critical_speeds_{k}x_forward"][0]
        assert first["speed_rpm"] == pytest.approx(60.0 / k * first["frequency_hz"], rel=1e-3)
        assert first["frequency_hz"] == pytest.approx(out["natural_frequencies_hz"]["healthy"][1], rel=0.01)
        assert first["speed_rpm"] == pytest.approx(crit[0]["speed_rpm"] / k, rel=0.01)
    # the unbalance response peaks at the 1x forward critical speed (grid of 18 rpm); a little below the
    # 2x critical speed the breathing crack's 2x response dominates the orbit and makes an inner loop
    ub, br = out["unbalance"], out["breathing_orbit"]
    assert ub["peak_rpm"] == pytest.approx(crit[0]["speed_rpm"], abs=18.0)
    assert ub["peak_m"] == pytest.approx(max(ub["amplitude_m"]))
    a = br["amplitude_m"]
    assert a["2x"] > 3 * max(a["1x"], a["3x"]) and a["1x"] > br["healthy_1x_m"]
    assert br["loops"] >= 1
    # orbit: isotropic bearings give a forward circle of radius |H(F15 -> x13)| U Omega^2
    from mutext.rotor import data_path, load_model
    r = load_model(data_path("rotor.toml"))
    w = r.speed
    H = r.frf([w / (2 * np.pi)], inputs=["F15"], outputs=["x13"]).H[0, 0, 0]
    assert orb["direction"] == "forward"
    assert orb["semi_minor_m"] == pytest.approx(orb["semi_major_m"], rel=1e-6)
    assert orb["semi_major_m"] == pytest.approx(abs(H) * orb["kg_m"] * w ** 2, rel=0.02)


@pytest.mark.slow
def test_demo_rotor_plots_the_diagram_it_reports(tmp_path, capsys, monkeypatch):
    """With --plots the Campbell figure is drawn from the diagram whose critical speeds the report
    prints (computed once, at 49 speeds instead of 13): no second diagram is computed for it, and
    the finer grid moves no critical speed by more than 1 rpm."""
    import mutext.rotor.campbell_diagram as cdm
    calls = []
    real = cdm.campbell

    def counted(*a, **k):
        calls.append(len(a[1]))
        return real(*a, **k)
    monkeypatch.setattr(cdm, "campbell", counted)
    assert main(["demo", "rotor", "--json", "--points", "50", "--plots", str(tmp_path)]) == 0
    fine = json.loads(capsys.readouterr().out)["campbell"]
    assert calls == [49] and (tmp_path / "rotor_campbell.png").stat().st_size > 0
    assert main(["demo", "rotor", "--json", "--points", "50"]) == 0
    coarse = json.loads(capsys.readouterr().out)["campbell"]
    assert calls == [49, 13]
    for k in (1, 2, 3):
        a, b = fine[f"critical_speeds_{k}x_forward"], coarse[f"critical_speeds_{k}x_forward"]
        assert len(a) == len(b)
        assert all(abs(x["speed_rpm"] - y["speed_rpm"]) < 1.0 for x, y in zip(a, b))
