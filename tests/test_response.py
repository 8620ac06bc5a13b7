"""One frequency-response type: a model's channel, a measured file and a virtual measurement are the same FRF."""
import numpy as np
import pytest

from mutext.errors import ModelError
from mutext.response import FRF, FRFMatrix
from mutext.rig import FRFFileError, measure, read_frf, write_frf
from mutext.rotor import data_path, load_model
from mutext.rotor.tuning import model_response


@pytest.fixture(scope="module")
def rotor():
    return load_model(data_path("rotor.toml"))


def test_model_channel_knows_where_it_was_taken(rotor):
    f = np.linspace(20, 225, 83)
    M = rotor.frf(f, inputs=["i12", "F15"], outputs=["x13", "y13"])
    assert isinstance(M, FRFMatrix)
    ch = M.channel("y13", "i12")
    assert (ch.input_station, ch.output_station, ch.input_direction, ch.output_direction) == (12, 13, "x", "y")
    assert (ch.input_quantity, ch.input_name, ch.output_name, ch.unit) == ("current", "i12", "y13", "m/A")
    assert ch.speed_hz == pytest.approx(10.0)
    # the channel, given back to the model by its stations, is the same response by another solver path
    np.testing.assert_allclose(model_response(rotor, ch), ch.response, rtol=1e-9)
    force = M.channel("x13", "F15")
    assert force.input_quantity == "force" and force.label == "F15->x13"
    np.testing.assert_allclose(model_response(rotor, force), force.response, rtol=1e-9)
    assert len(M.channels()) == 4


def test_directions_and_names_survive_a_file(tmp_path, rotor):
    ch = rotor.frf([30.0, 31.0, 32.0], inputs=["i12"], outputs=["y13"]).channel("y13", "i12")
    back = read_frf(write_frf(tmp_path / "y13.csv", ch, output_unit="um"))
    assert (back.output_direction, back.input_name, back.output_name) == ("y", "i12", "y13")
    np.testing.assert_allclose(back.response, ch.response, rtol=1e-15)
    text = (tmp_path / "y13.csv").read_text().replace("output_direction: y", "output_direction: z")
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(FRFFileError, match=r"bad.csv, line \d+ \[output_direction\]: unknown direction 'z'"):
        read_frf(tmp_path / "bad.csv")


def test_metadata_directions_are_read_as_fields():
    """Older callers passed the direction as metadata; it becomes the field."""
    h = FRF([1.0, 2.0], [1.0, 2.0], metadata={"output_direction": "y", "rig": "a"})
    assert h.output_direction == "y" and h.metadata == {"rig": "a"}
    with pytest.raises(ModelError, match="output_direction"):
        FRF([1.0, 2.0], [1.0, 2.0], output_direction="up")


def test_measure_names_the_ports_of_a_state_space_model(rotor):
    ss = rotor.state_space(inputs=["i12"], outputs=["x13"])
    h = measure(ss, "i12", "x13", [25.0, 35.0], input_station=12, output_station=13, input_quantity="current")
    assert h.label == "i12->x13"
    np.testing.assert_allclose(h.response, rotor.frf([25.0, 35.0])("x13", "i12"), rtol=1e-8)


def test_sweep_grid_is_written_as_decimals(tmp_path):
    """A decimal sweep (0.2 Hz in 0.02 Hz steps) gives decimals in the file, not 0.30000000000000004."""
    from mutext.response import sweep_frequencies
    f = sweep_frequencies(0.2, 9.98, 0.02)
    assert f.size == 490 and f[5] == 0.3 and f[-1] == 9.98
    p = write_frf(tmp_path / "g.csv", FRF(f, np.ones(f.size), input_station=1, output_station=1))
    rows = [ln.split(",")[0] for ln in p.read_text().splitlines() if ln[:1].isdigit()]
    assert max(len(r) for r in rows) <= 4
