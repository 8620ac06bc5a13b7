"""FRF files (format, units, errors) and the virtual test rig."""
import control as ct
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.lti import freqresp, mck_to_ss
from mutext.rig import (FRF, FRFFileError, Noise, THESIS_SWEEP_HZ, measure, read_frf, read_frfs,
                        sweep_frequencies, write_frf)

GOOD_HEADER = """# input_station: 12
# input_quantity: current
# input_unit: A
# output_station: 13
# output_quantity: displacement
# output_unit: {unit}
# speed_hz: 10
# rig: cracked rotor
freq_hz,re,im
"""


def _write(tmp_path, text, name="ch.frf"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _two_mass():
    # chain ground - k2 - m2 - k1 - m1 (thesis two-mass example) with light damping
    m1, m2, k1, k2 = 1.0, 2.0, 450.0, 175.0
    M = np.diag([m1, m2])
    K = np.array([[k1, -k1], [-k1, k1 + k2]])
    C = 0.002 * K + 0.01 * M
    return mck_to_ss(M, C, K, inputs={"f1": 0, "f2": 1}, outputs={"x1": 0, "x2": 1})


# ----------------------------------------------------------------------------
# reading and units
# ----------------------------------------------------------------------------

@pytest.mark.parametrize("unit, factor", [("m", 1.0), ("mm", 1e-3), ("um", 1e-6), ("in", 0.0254)])
def test_read_converts_units_to_si(tmp_path, unit, factor):
    p = _write(tmp_path, GOOD_HEADER.format(unit=unit) + "20,1.5,-2\n20.5,3,0.25\n")
    frf = read_frf(p)
    assert frf.freq_hz.tolist() == [20.0, 20.5]
    assert np.allclose(frf.omega, 2 * np.pi * np.array([20.0, 20.5]), rtol=1e-15)
    # by value: 1.5 mm/A is 1.5e-3 m/A, 1.5 in/A is 0.0381 m/A
    assert frf.response[0] == pytest.approx((1.5 - 2j) * factor, rel=1e-15)
    assert frf.response[1] == pytest.approx((3 + 0.25j) * factor, rel=1e-15)
    assert frf.unit == "m/A"
    assert (frf.input_station, frf.output_station) == (12, 13)
    assert (frf.input_quantity, frf.output_quantity) == ("current", "displacement")
    assert frf.speed_hz == 10.0
    assert frf.metadata["rig"] == "cracked rotor"
    assert frf.metadata["file_output_unit"] == unit
    assert frf.source == p


def test_inch_value_explicit(tmp_path):
    p = _write(tmp_path, GOOD_HEADER.format(unit="in") + "100,1,0\n")
    assert read_frf(p).response[0] == pytest.approx(0.0254)


def test_force_input_and_optional_keys(tmp_path):
    text = ("# input_station: 3\n# input_quantity: force\n# input_unit: N\n# output_station: 3\n"
            "# output_quantity: displacement\n# output_unit: m\nfreq_hz,re,im\n1e1,1e-6,0\n")
    frf = read_frf(_write(tmp_path, text))
    assert frf.unit == "m/N" and frf.speed_hz is None and frf.metadata == {
        "file_output_unit": "m", "file_input_unit": "N"}


@pytest.mark.parametrize("unit", ["m", "mm", "um", "in"])
def test_round_trip(tmp_path, unit):
    rng = np.random.default_rng(0)
    f = np.sort(rng.uniform(20, 1000, 50))
    G = (rng.standard_normal(50) + 1j * rng.standard_normal(50)) * 10.0 ** rng.uniform(-9, -3, 50)
    frf = FRF(f, G, input_station=12, output_station=13, input_quantity="current",
              speed_hz=10.0, metadata={"operator": "virtual", "note": "x = 1, y = 2"})
    p = write_frf(tmp_path / f"rt_{unit}.frf", frf, output_unit=unit)
    back = read_frf(p)
    assert np.array_equal(back.freq_hz, f)
    assert np.allclose(back.response, G, rtol=1e-12, atol=0)
    if unit == "m":
        assert np.array_equal(back.response, G)
    assert back.metadata["operator"] == "virtual" and back.metadata["note"] == "x = 1, y = 2"
    assert (back.input_station, back.output_station, back.speed_hz) == (12, 13, 10.0)
    assert back.input_quantity == "current" and back.unit == "m/A"
    # rewriting the read FRF gives the same file (the file units are not duplicated as metadata;
    # in other units the last digit may differ by the rounding of the unit conversion)
    p2 = write_frf(tmp_path / f"rt2_{unit}.frf", back, output_unit=unit)
    if unit == "m":
        assert p2.read_text() == p.read_text()
    else:
        assert p2.read_text().splitlines()[:10] == p.read_text().splitlines()[:10]
        assert np.allclose(read_frf(p2).response, G, rtol=1e-15 * 8, atol=0)


def test_response_in_other_units():
    frf = FRF([10.0, 20.0], [1e-6, 2e-6j], input_station=1, output_station=2)
    assert np.allclose(frf.response_in("um"), [1.0, 2.0j])
    with pytest.raises(ModelError, match="unknown displacement unit"):
        frf.response_in("ft")


def test_read_frfs_glob_and_list(tmp_path):
    for st in (13, 5, 9):
        text = GOOD_HEADER.format(unit="um").replace("output_station: 13", f"output_station: {st}")
        _write(tmp_path, text + "20,1,0\n", name=f"cracked_{st:02d}.frf")
    frfs = read_frfs(str(tmp_path / "cracked_*.frf"))
    assert [f.output_station for f in frfs] == [5, 9, 13]          # sorted by file name
    frfs = read_frfs([tmp_path / "cracked_13.frf", tmp_path / "cracked_05.frf"])
    assert [f.output_station for f in frfs] == [13, 5]
    assert read_frfs(tmp_path / "cracked_09.frf")[0].output_station == 9
    with pytest.raises(ModelError, match="no file matches"):
        read_frfs(str(tmp_path / "healthy_*.frf"))


# ----------------------------------------------------------------------------
# errors: each names the file, the line and the problem
# ----------------------------------------------------------------------------

def _header_without(key):
    return "".join(l + "\n" for l in GOOD_HEADER.format(unit="um").splitlines()
                   if not l.startswith(f"# {key}:"))


@pytest.mark.parametrize("text, line, field, match", [
    # missing required key (whole-file problem, no line)
    (_header_without("output_unit") + "20,1,0\n", None, "output_unit", "missing required header key 'output_unit'"),
    (_header_without("input_station") + "20,1,0\n", None, "input_station", "missing required"),
    # unknown quantity / unit
    (GOOD_HEADER.format(unit="um").replace("current", "voltage") + "20,1,0\n", 2,
     "input_quantity", "unknown quantity 'voltage'"),
    (GOOD_HEADER.format(unit="um").replace("input_unit: A", "input_unit: N") + "20,1,0\n", 3,
     "input_unit", "unknown unit 'N' for a current input"),
    (GOOD_HEADER.format(unit="furlong") + "20,1,0\n", 6, "output_unit", "unknown unit 'furlong'"),
    (GOOD_HEADER.format(unit="um").replace("displacement", "strain") + "20,1,0\n", 5,
     "output_quantity", "unknown quantity 'strain'"),
    (GOOD_HEADER.format(unit="um").replace("displacement", "velocity") + "20,1,0\n", 6,
     "output_unit", "unknown unit 'um' for a velocity output"),
    # bad header values and lines
    (GOOD_HEADER.format(unit="um").replace("station: 12", "station: twelve") + "20,1,0\n", 1,
     "input_station", "not an integer"),
    (GOOD_HEADER.format(unit="um").replace("speed_hz: 10", "speed_hz: fast") + "20,1,0\n", 7,
     "speed_hz", "not a number"),
    (GOOD_HEADER.format(unit="um").replace("# rig: cracked rotor", "# rig cracked rotor") + "20,1,0\n",
     8, None, "not of the form '# key: value'"),
    (GOOD_HEADER.format(unit="um").replace("# rig: cracked rotor", "# input_unit: A") + "20,1,0\n",
     8, "input_unit", "repeated"),
    # bad numbers, by column
    (GOOD_HEADER.format(unit="um") + "20,1,0\n20.5,abc,0\n", 11, "re", "'abc' is not a number"),
    (GOOD_HEADER.format(unit="um") + "20,1,0\n20.5,1,1..2\n", 11, "im", "not a number"),
    (GOOD_HEADER.format(unit="um") + "2O,1,0\n", 10, "freq_hz", "not a number"),
    (GOOD_HEADER.format(unit="um") + "20,1,0\n21,nan,0\n", 11, "re", "NaN"),
    (GOOD_HEADER.format(unit="um") + "20,1,0\n21,1,inf\n", 11, "im", "NaN or infinite"),
    (GOOD_HEADER.format(unit="um") + "20,1\n", 10, None, "expected 3 comma-separated values"),
    # frequencies
    (GOOD_HEADER.format(unit="um") + "20,1,0\n20.5,1,0\n20.5,1,0\n", 12, "freq_hz",
     "not greater than the previous one"),
    (GOOD_HEADER.format(unit="um") + "20,1,0\n19,1,0\n", 11, "freq_hz", "strictly increasing"),
    (GOOD_HEADER.format(unit="um") + "0,1,0\n", 10, "freq_hz", "not positive"),
    # CSV header and data
    (GOOD_HEADER.format(unit="um").replace("freq_hz,re,im\n", "") + "20,1,0\n", 9, None,
     "expected the CSV header line 'freq_hz,re,im'"),
    (GOOD_HEADER.format(unit="um").replace("freq_hz,re,im\n", ""), None, None, "missing CSV header"),
    (GOOD_HEADER.format(unit="um"), 9, None, "no data rows"),
    (GOOD_HEADER.format(unit="um") + "20,1,0\n# late: key\n", 11, None, "header line after the CSV header"),
])
def test_read_errors_name_file_line_and_field(tmp_path, text, line, field, match):
    p = _write(tmp_path, text, name="bad.frf")
    with pytest.raises(FRFFileError, match=match) as exc:
        read_frf(p)
    err = exc.value
    assert isinstance(err, ModelError)
    assert str(p) in str(err)
    assert err.line == line and err.field == field
    if line is not None:
        assert f"line {line}" in str(err)
    if field is not None:
        assert f"[{field}]" in str(err)


def test_missing_file(tmp_path):
    with pytest.raises(FRFFileError, match="cannot read"):
        read_frf(tmp_path / "nope.frf")


def test_frf_and_writer_validation(tmp_path):
    with pytest.raises(ModelError, match="strictly increasing"):
        FRF([10.0, 10.0], [1, 2])
    with pytest.raises(ModelError, match="positive"):
        FRF([-1.0, 10.0], [1, 2])
    with pytest.raises(ModelError, match="non-finite"):
        FRF([1.0, 2.0], [1, np.nan])
    with pytest.raises(ModelError, match="2 frequencies but 3"):
        FRF([1.0, 2.0], [1, 2, 3])
    with pytest.raises(ModelError, match="input_quantity"):
        FRF([1.0], [1], input_quantity="voltage")
    with pytest.raises(ModelError, match="stations? must be set|must be set"):
        write_frf(tmp_path / "x.frf", FRF([1.0], [1.0]))
    with pytest.raises(ModelError, match="cannot be written"):
        write_frf(tmp_path / "x.frf", FRF([1.0], [1.0], input_station=1, output_station=2,
                                          metadata={"a:b": "c"}))


# ----------------------------------------------------------------------------
# virtual rig
# ----------------------------------------------------------------------------

def test_sweep_frequencies():
    f = sweep_frequencies()
    assert f.size == 411 and f[0] == 20.0 and f[-1] == 225.0
    assert np.allclose(np.diff(f), 0.5, rtol=0, atol=1e-12)
    full = sweep_frequencies(*THESIS_SWEEP_HZ)
    assert full.size == 1961 and full[-1] == 1000.0
    assert sweep_frequencies(1.0, 2.2, 0.5).tolist() == [1.0, 1.5, 2.0]
    with pytest.raises(ModelError, match="step"):
        sweep_frequencies(20, 225, 0)
    with pytest.raises(ModelError, match="start <= stop"):
        sweep_frequencies(30, 20, 0.5)


@pytest.mark.filterwarnings("ignore:Badly conditioned filter coefficients")
def test_measure_without_noise_equals_freqresp():
    sys = _two_mass()
    f = sweep_frequencies(0.5, 10.0, 0.25)        # covers both modes (1.19 and 4.23 Hz)
    frf = measure(sys, "f1", "x2", f, input_station=1, output_station=2)
    Gall = freqresp(sys, 2 * np.pi * f)
    G = Gall[1, 0, :]
    assert np.array_equal(frf.freq_hz, f)
    assert np.allclose(frf.response, G, rtol=1e-13, atol=0)
    # indices, a transfer function and a callable give the same data
    assert np.allclose(measure(sys, 0, 1, f).response, G, rtol=1e-13)
    tf = ct.ss2tf(ct.ss(sys.A, sys.B[:, :1], sys.C[1:, :], 0))
    assert np.allclose(measure(tf, 0, 0, f).response, G, rtol=1e-8)
    assert np.array_equal(measure(lambda w: Gall, 0, 1, f).response, G)
    assert np.array_equal(measure(lambda w: Gall[1, 0], 0, 0, f).response, G)
    # the callable receives rad/s
    assert np.allclose(measure(lambda w: w, 0, 0, f).response, 2 * np.pi * f, rtol=1e-15)
    # default grid is the truncated thesis sweep
    assert measure(lambda w: 1 / (1j * w + 1), 0, 0).freq_hz.size == 411


def test_measure_port_errors():
    sys = _two_mass()
    with pytest.raises(ModelError, match="no input named 'u'"):
        measure(sys, "u", 0, [1.0])
    with pytest.raises(ModelError, match="output index 5"):
        measure(sys, 0, 5, [1.0])
    with pytest.raises(ModelError, match="cannot compute a frequency response"):
        measure(object(), 0, 0, [1.0])


def _one_mass(w):
    m, c, k = 1.0, 0.5, 400.0
    return 1.0 / (k - m * w**2 + 1j * c * w)


def test_measure_noise_statistics_and_reproducibility():
    sys = _one_mass
    f = sweep_frequencies(0.5, 10.0, 0.01)
    G = _one_mass(2 * np.pi * f)
    rel, floor = 0.02, 1e-4
    a = measure(sys, 0, 0, f, noise=Noise(rel, floor), rng=7)
    b = measure(sys, 0, 0, f, noise=(rel, floor), rng=np.random.default_rng(7))
    assert np.array_equal(a.response, b.response)
    e = (a.response - G) / (rel * np.abs(G) + floor)
    # circular complex normal with unit variance: E|e|^2 = 1, real and imaginary parts 1/2 each
    n = e.size
    assert np.mean(np.abs(e)**2) == pytest.approx(1.0, abs=5 / np.sqrt(n))
    assert np.mean(e.real**2) == pytest.approx(0.5, abs=4 / np.sqrt(n))
    assert abs(np.mean(e.real * e.imag)) < 4 / np.sqrt(n)
    assert a.metadata["noise_relative"] == "0.02"
    # relative-only noise scales with |G|
    c = measure(sys, 0, 0, f, noise=0.05, rng=1)
    r = np.abs(c.response - G) / np.abs(G)
    assert 0.03 < np.sqrt(np.mean(r**2)) < 0.07
    assert np.array_equal(measure(sys, 0, 0, f, noise=0.0).response, measure(sys, 0, 0, f).response)
    with pytest.raises(ModelError, match="floor"):
        Noise(0.1, -1.0)


def test_measure_then_file_round_trip(tmp_path):
    frf = measure(_one_mass, 0, 0, noise=(0.01, 1e-6), rng=3, input_station=12, output_station=13,
                  input_quantity="current", speed_hz=10.0)
    back = read_frf(write_frf(tmp_path / "virtual.frf", frf, output_unit="um"))
    assert np.allclose(back.response, frf.response, rtol=1e-12, atol=0)
    assert back.metadata["noise_floor"] == "1e-06"
    assert back.band(20, 100).freq_hz[-1] == 100.0
