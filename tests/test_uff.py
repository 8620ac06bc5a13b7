"""Universal File Format data set 58 in and out (mutext.uff; mutext.rig.read_frf / read_frfs dispatch)."""
from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

pyuff = pytest.importorskip("pyuff")

from mutext.response import FRF
from mutext.rig import FRFFileError, read_frf, read_frfs, write_frf
from mutext.uff import G0, LBF, read_uff58, write_uff58

# a 1-DOF oscillator: m = 2 kg, k = 8e4 N/m, c = 30 N s/m
M, K, C = 2.0, 8.0e4, 30.0
F_EVEN = np.arange(5.0, 60.0 + 0.25, 0.25)          # even grid, exact in E13.5


def receptance(f):
    w = 2 * np.pi * np.asarray(f, dtype=float)
    return 1.0 / (K - M * w ** 2 + 1j * C * w)


def _pyuff_file(path, sets):
    """Write data sets with pyuff itself (not with mutext's writer)."""
    path = os.fspath(path)
    open(path, "w").close()
    pyuff.UFF(path).write_sets(sets, mode="add")
    return path


def _set58(data, x=F_EVEN, *, even=True, rsp_node=1, rsp_dir=1, ref_node=1, ref_dir=1, func_type=4,
           ord_type=12, den_type=13, ord_lab="NONE", den_lab="NONE", abs_lab="Hz"):
    return pyuff.prepare_58(
        binary=0, func_type=func_type, rsp_node=rsp_node, rsp_dir=rsp_dir, ref_node=ref_node, ref_dir=ref_dir,
        data=data, x=np.asarray(x, dtype=float), id1="made by pyuff", rsp_ent_name="NONE", ref_ent_name="NONE",
        abscissa_spacing=1 if even else 0, abscissa_spec_data_type=18, abscissa_axis_units_lab=abs_lab,
        ordinate_spec_data_type=ord_type, ordinate_axis_units_lab=ord_lab,
        orddenom_spec_data_type=den_type, orddenom_axis_units_lab=den_lab)


def _channel(**kw):
    f = np.arange(20.0, 225.0 + 0.5, 0.5)
    args = {"input_station": 1, "output_station": 3, "speed_hz": 10.0, "input_name": "f1", "output_name": "x3",
                "output_direction": "y", "metadata": {"rig": "bench"}}
    args.update(kw)
    return FRF(f, receptance(f) * (1 + 0.1j), **args)


# ---------------------------------------------------------------------------- round trips

@pytest.mark.parametrize("ordinate", ["displacement", "velocity", "acceleration"])
@pytest.mark.parametrize("quantity", ["force", "current"])
def test_round_trip_binary_is_exact(tmp_path, ordinate, quantity):
    h = _channel(input_quantity=quantity)
    p = write_uff58(tmp_path / "h.uff", [h], ordinate=ordinate, binary=True)
    g = read_frf(p)
    np.testing.assert_allclose(g.freq_hz, h.freq_hz, rtol=1e-12, atol=0)
    np.testing.assert_allclose(g.response, h.response, rtol=1e-12, atol=0)
    assert (g.input_station, g.output_station) == (1, 3)
    assert (g.input_direction, g.output_direction) == ("x", "y")
    assert (g.input_name, g.output_name, g.speed_hz) == ("f1", "x3", 10.0)
    assert g.input_quantity == quantity and g.unit == ("m/N" if quantity == "force" else "m/A")
    assert g.source == p and g.metadata["uff_dataset"] == "1"
    assert ordinate in g.metadata["uff_conversion"]


def test_round_trip_ascii_through_mutext_csv(tmp_path):
    """CSV -> FRF -> UFF 58 (ASCII) -> FRF -> CSV: frequencies exact, values to the 12 digits of E20.12."""
    h = read_frf(write_frf(tmp_path / "h.csv", _channel(), output_unit="um"))
    p = write_uff58(tmp_path / "h.unv", h, ordinate="acceleration")
    g = read_frf(p)
    np.testing.assert_array_equal(g.freq_hz, h.freq_hz)
    np.testing.assert_allclose(g.response, h.response, rtol=1e-11, atol=0)
    back = read_frf(write_frf(tmp_path / "back.csv", g))
    np.testing.assert_allclose(back.response, h.response, rtol=1e-11, atol=0)
    assert (back.input_station, back.output_station, back.output_direction) == (1, 3, "y")
    assert back.metadata["uff_conversion"].startswith("acceleration per force")


def test_ascii_abscissa_that_e13_cannot_hold_warns(tmp_path):
    f = np.geomspace(1.0, 100.0, 9)
    h = FRF(f, receptance(f), input_station=1, output_station=1)
    with pytest.warns(UserWarning, match="binary=True"):
        write_uff58(tmp_path / "g.uff", h)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = read_frf(write_uff58(tmp_path / "g.uff", h, binary=True))
    np.testing.assert_array_equal(g.freq_hz, f)


# ---------------------------------------------------------------------------- files written by pyuff

def test_pyuff_acceleration_per_force_is_read_as_receptance(tmp_path):
    w = 2 * np.pi * F_EVEN
    acc = -w ** 2 * receptance(F_EVEN)                      # m/s^2/N
    p = _pyuff_file(tmp_path / "acc.uff", [_set58(acc, ord_type=12, ord_lab="m/s^2", den_lab="N")])
    g = read_frf(p)
    np.testing.assert_array_equal(g.freq_hz, F_EVEN)
    np.testing.assert_allclose(g.response, receptance(F_EVEN), rtol=1e-10)
    assert g.input_quantity == "force" and g.unit == "m/N"
    assert "divided by -omega^2" in g.metadata["uff_conversion"]


def test_pyuff_velocity_per_force_uneven_is_read_as_receptance(tmp_path):
    f = np.array([3.0, 4.5, 7.0, 9.0, 10.0, 12.5, 20.0, 31.0])
    vel = 1j * 2 * np.pi * f * receptance(f) * 1e3          # mm/s per N, label holding the whole ratio
    p = _pyuff_file(tmp_path / "vel.uff", [_set58(vel, x=f, even=False, ord_type=11, ord_lab="mm/s/N")])
    g = read_frf(p)
    np.testing.assert_array_equal(g.freq_hz, f)
    np.testing.assert_allclose(g.response, receptance(f), rtol=1e-10)
    assert "divided by j*omega" in g.metadata["uff_conversion"]
    assert "scaled by 0.001" in g.metadata["uff_conversion"]


@pytest.mark.parametrize("label, kind, to_file", [
    ("g/N", 12, lambda H, w: -w ** 2 * H / G0),
    ("(m/s2)/N", 12, lambda H, w: -w ** 2 * H),
    ("mm/N", 8, lambda H, w: H * 1e3),
    ("in/lbf", 8, lambda H, w: H / 0.0254 * LBF),
])
def test_units_labels(tmp_path, label, kind, to_file):
    H = receptance(F_EVEN)
    p = _pyuff_file(tmp_path / "u.uff", [_set58(to_file(H, 2 * np.pi * F_EVEN), ord_type=kind, ord_lab=label)])
    np.testing.assert_allclose(read_frf(p).response, H, rtol=1e-10)


def test_unlabelled_units_follow_a_units_data_set_164(tmp_path):
    """No units labels: SI, or the unit system of a data set 164 in the file (here inch, pound-force)."""
    H = receptance(F_EVEN)
    units = pyuff.prepare_164(units_code=7, units_description="IN (inch, lbf)", temp_mode=1,
                              length=1 / 0.0254, force=1 / LBF, temp=1.0, temp_offset=273.15)
    p = _pyuff_file(tmp_path / "in.uff", [units, _set58(H / 0.0254 * LBF, ord_type=8, abs_lab="NONE")])
    g = read_frf(p)
    np.testing.assert_allclose(g.response, H, rtol=1e-10)
    assert "data set 164" in g.metadata["uff_conversion"]
    p = _pyuff_file(tmp_path / "si.uff", [_set58(H, ord_type=8, abs_lab="NONE")])
    np.testing.assert_allclose(read_frf(p).response, H, rtol=1e-10)


def test_current_reference_is_flagged_by_the_units_label(tmp_path):
    H = receptance(F_EVEN)
    p = _pyuff_file(tmp_path / "i.uff", [_set58(H * 1e3, ord_type=8, ord_lab="um", den_type=1, den_lab="mA")])
    g = read_frf(p)
    assert g.input_quantity == "current" and g.unit == "m/A"
    np.testing.assert_allclose(g.response, H, rtol=1e-10)           # um/mA -> m/A: x 1e-6 / 1e-3
    p = _pyuff_file(tmp_path / "bad.uff", [_set58(H, ord_type=8, den_type=13, den_lab="A")])
    with pytest.raises(FRFFileError) as e:
        read_frf(p)
    assert e.value.field == "orddenom_spec_data_type"


def test_node_mapping_and_negative_direction(tmp_path):
    H = receptance(F_EVEN)
    p = _pyuff_file(tmp_path / "m.uff", [_set58(H, ord_type=8, rsp_node=101, rsp_dir=-2, ref_node=7, ref_dir=1)])
    g = read_frf(p, mapping={101: 3, 7: 1})
    assert (g.input_station, g.output_station) == (1, 3)
    assert (g.input_direction, g.output_direction) == ("x", "y")
    np.testing.assert_allclose(g.response, -H, rtol=1e-10)
    assert "sign flipped" in g.metadata["uff_conversion"]
    assert (g.metadata["uff_rsp_node"], g.metadata["uff_rsp_dir"]) == ("101", "-2")
    # both negative: no flip; default mapping: station = node
    p2 = _pyuff_file(tmp_path / "m2.uff", [_set58(H, ord_type=8, rsp_node=4, rsp_dir=-1, ref_node=2, ref_dir=-1)])
    g2 = read_frf(p2)
    assert (g2.input_station, g2.output_station) == (2, 4)
    np.testing.assert_allclose(g2.response, H, rtol=1e-10)
    with pytest.raises(FRFFileError, match="node 7 is not in the node -> station mapping") as e:
        read_frf(p, mapping={101: 3})
    assert (e.value.field, e.value.dataset) == ("ref_node", 1)


def test_several_data_sets_through_read_frfs(tmp_path):
    H = receptance(F_EVEN)
    nodes = pyuff.prepare_15(node_nums=[1, 2, 3], def_cs=[0, 0, 0], disp_cs=[0, 0, 0], color=[0, 0, 0],
                             x=[0.0, 1.0, 2.0], y=[0.0, 0.0, 0.0], z=[0.0, 0.0, 0.0])
    sets = [nodes] + [_set58(H * (k + 1), ord_type=8, rsp_node=k + 1) for k in range(3)]
    p = _pyuff_file(tmp_path / "many.uff", sets)
    frfs = read_frfs(p)
    assert [h.output_station for h in frfs] == [1, 2, 3]
    assert [h.metadata["uff_dataset"] for h in frfs] == ["2", "3", "4"]
    for k, h in enumerate(frfs):
        np.testing.assert_allclose(h.response, H * (k + 1), rtol=1e-10)
    with pytest.raises(FRFFileError, match="use read_frfs"):
        read_frf(p)
    # mixed list of CSV and UFF files, kept in order
    csv = write_frf(tmp_path / "one.csv", frfs[0])
    assert len(read_frfs([csv, p])) == 4
    # written by write_uff58: several FRFs in one file
    q = write_uff58(tmp_path / "w.uff", frfs, binary=True)
    np.testing.assert_array_equal([h.response for h in read_uff58(q)], [h.response for h in frfs])


def test_uff_is_recognised_by_content(tmp_path):
    h = _channel()
    p = write_uff58(tmp_path / "h.uff", h)
    other = tmp_path / "export.txt"
    other.write_bytes(p.read_bytes())
    np.testing.assert_allclose(read_frf(other).response, h.response, rtol=1e-11)


# ---------------------------------------------------------------------------- malformed files

def _raises(path, field, dataset, match, **kw):
    with pytest.raises(FRFFileError, match=match) as e:
        read_frf(path, **kw)
    assert e.value.field == field and e.value.dataset == dataset
    assert str(path) in str(e.value)
    if dataset is not None:
        assert f"data set {dataset}" in str(e.value)
    return e.value


def test_not_a_uff_file(tmp_path):
    p = tmp_path / "x.uff"
    p.write_text("freq_hz,re,im\n1,2,3\n")
    _raises(p, None, None, "not a Universal File")


def test_no_data_set_58(tmp_path):
    nodes = pyuff.prepare_15(node_nums=[1], def_cs=[0], disp_cs=[0], color=[0], x=[0.0], y=[0.0], z=[0.0])
    _raises(_pyuff_file(tmp_path / "n.uff", [nodes]), None, None, "no data set 58")


def test_function_type_not_an_frf(tmp_path):
    p = _pyuff_file(tmp_path / "t.uff", [_set58(receptance(F_EVEN), func_type=1)])
    _raises(p, "func_type", 1, "not a frequency response function")


def test_real_only_ordinate(tmp_path):
    p = _pyuff_file(tmp_path / "r.uff", [_set58(np.abs(receptance(F_EVEN)))])
    _raises(p, "ord_data_type", 1, "real-only")


def test_non_positive_and_non_increasing_frequencies(tmp_path):
    # an analyzer's 0 Hz line is dropped with a note (tests/test_analyzer_files.py); no line above 0 Hz is an error
    f0 = np.array([-1.0, -0.5, 0.0])
    _raises(_pyuff_file(tmp_path / "z.uff", [_set58(np.ones(3) + 0j, x=f0)]), "abscissa_min", 1,
            "no frequency above 0 Hz")
    f1 = np.array([1.0, 3.0, 2.0, 4.0])
    _raises(_pyuff_file(tmp_path / "d.uff", [_set58(receptance(f1), x=f1, even=False)]), "abscissa", 1,
            "strictly increasing")


@pytest.mark.parametrize("kw, field", [
    ({"ord_lab": "furlong/N"}, "ordinate_axis_units_lab"),
    ({"den_lab": "dyn"}, "orddenom_axis_units_lab"),
    ({"abs_lab": "RPM"}, "abscissa_axis_units_lab"),
    ({"ord_type": 0}, "ordinate_spec_data_type"),
])
def test_unknown_unit(tmp_path, kw, field):
    p = _pyuff_file(tmp_path / "u.uff", [_set58(receptance(F_EVEN), **kw)])
    _raises(p, field, 1, "unknown")


@pytest.mark.parametrize("kw, field, match", [
    ({"rsp_dir": 3}, "rsp_dir", r"direction 3 \(Z translation\)"),
    ({"ref_dir": -5}, "ref_dir", r"direction -5 \(Y rotation\)"),
    ({"ref_dir": 0}, "ref_dir", r"direction 0 \(scalar\)"),
])
def test_direction_not_x_or_y(tmp_path, kw, field, match):
    p = _pyuff_file(tmp_path / "dir.uff", [_set58(receptance(F_EVEN), **kw)])
    _raises(p, field, 1, match)


def test_error_names_the_data_set(tmp_path):
    H = receptance(F_EVEN)
    p = _pyuff_file(tmp_path / "two.uff", [_set58(H), _set58(H, rsp_dir=6)])
    with pytest.raises(FRFFileError) as e:
        read_frfs(p)
    assert (e.value.dataset, e.value.field) == (2, "rsp_dir")


# ---------------------------------------------------------------------------- diagnosis from UFF files

def test_diagnose_accepts_uff_files(tmp_path):
    from mutext.diagnose import diagnose
    from mutext.hide import hidden_effect_data
    case = hidden_effect_data("three_mass", seed=5, kind="stiffness")
    uffs = [write_uff58(tmp_path / f"m{k}.uff", h, ordinate="acceleration") for k, h in enumerate(case.measured)]
    for u, h in zip(uffs, case.measured):
        assert "m/s^2" in u.read_text()
        np.testing.assert_allclose(read_frf(u).response, h.response, rtol=1e-11)
    # the verdict is the answer key's, as for the same data given as FRF objects
    # (tests/test_diagnose.py::test_screen_response_equals_the_extended_model_file)
    d_uff = diagnose(case.model, uffs)
    assert case.key["kind"] == "stiffness"
    assert (d_uff.verdict.kind, d_uff.verdict.station) == (case.key["kind"], case.key["station"])


def test_command_line_diagnose_reads_every_frf_of_a_uff_file(tmp_path, capsys):
    """`mutext diagnose MODEL all.uff`: one Universal File with all measured channels (velocity ordinates)."""
    import json

    from mutext.cli import main
    from mutext.hide import hidden_effect_data
    case = hidden_effect_data("three_mass", seed=5, kind="stiffness")
    p = write_uff58(tmp_path / "all.uff", case.measured, ordinate="velocity")
    assert len(read_frfs(p)) == len(case.measured) > 1
    capsys.readouterr()
    assert main(["diagnose", case.model, str(p), "--json", "--quiet"]) == 0
    top = json.loads(capsys.readouterr().out)["findings"][0]
    assert (top["kind"], top["station"]) == (case.key["kind"], case.key["station"])
