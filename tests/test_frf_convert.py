"""``mutext frf convert``: mutext's CSV <-> Universal File data set 58, round trips and named errors."""
import numpy as np
import pytest

from mutext.cli import main
from mutext.response import FRF
from mutext.rig import read_frf, read_frfs, write_frf
from mutext.uff import read_uff58


def _frf(**kw):
    f = 20.0 + 0.5 * np.arange(61)                       # the thesis grid: exact in ASCII UFF too
    rng = np.random.default_rng(7)
    w = 2 * np.pi * f
    h = 1e-6 / (1e5 - 0.5 * w ** 2 + 20j * w) * (1 + 0.01 * rng.standard_normal(f.size))
    args = {"input_station": 12, "output_station": 13, "input_quantity": "current", "speed_hz": 10.0,
            "input_direction": "y", "output_direction": "y", "input_name": "i12", "output_name": "x13",
            "metadata": {"rig": "cracked rotor"}}
    args.update(kw)
    return FRF(f, h, **args)


@pytest.fixture()
def csv_file(tmp_path):
    return write_frf(tmp_path / "h.csv", _frf(), output_unit="um")


def _rel(a, b):
    return float(np.max(np.abs(a - b) / np.abs(a)))


def _same_channel(a, b):
    assert (b.input_station, b.output_station) == (a.input_station, a.output_station)
    assert (b.input_direction, b.output_direction) == (a.input_direction, a.output_direction)
    assert (b.input_quantity, b.output_quantity) == (a.input_quantity, a.output_quantity)
    assert (b.input_name, b.output_name, b.speed_hz) == (a.input_name, a.output_name, a.speed_hz)
    np.testing.assert_array_equal(b.freq_hz, a.freq_hz)


@pytest.mark.parametrize("uff, opts, rtol", [
    ("h.uff", ["--binary"], 1e-12),      # data set 58b: double precision
    ("h.unv", [], 1e-11),                # ASCII: 12 significant digits (E20.12), a bound of 5e-12
])
def test_round_trip_csv_uff_csv(tmp_path, csv_file, capsys, uff, opts, rtol):
    a = read_frf(csv_file)
    assert main(["frf", "convert", str(csv_file), str(tmp_path / uff), *opts]) == 0
    out = capsys.readouterr()
    assert str(tmp_path / uff) in out.out
    assert "not written: rig" in out.err                  # a header entry UFF 58 has no place for is named
    assert main(["frf", "convert", str(tmp_path / uff), str(tmp_path / "back.csv")]) == 0
    b = read_frf(tmp_path / "back.csv")
    _same_channel(a, b)
    assert _rel(a.response, b.response) <= rtol
    assert b.metadata["file_output_unit"] == "m"          # from a UFF: SI unless --unit
    assert "uff_conversion" in b.metadata


def test_uff_ordinates_and_unit_kept(tmp_path, csv_file):
    a = read_frf(csv_file)
    assert main(["frf", "convert", str(csv_file), str(tmp_path / "acc.uff"), "--ordinate", "acceleration",
                 "--binary"]) == 0
    raw, = read_uff58(tmp_path / "acc.uff")
    assert "acceleration" in raw.metadata["uff_ordinate"] and "divided by -omega^2" in raw.metadata["uff_conversion"]
    assert _rel(a.response, raw.response) <= 1e-12
    # CSV -> CSV keeps the file's unit unless told
    assert main(["frf", "convert", str(csv_file), str(tmp_path / "same.csv")]) == 0
    assert "# output_unit: um" in (tmp_path / "same.csv").read_text()
    assert main(["frf", "convert", str(csv_file), str(tmp_path / "mm.csv"), "--unit", "mm"]) == 0
    c = read_frf(tmp_path / "mm.csv")
    assert c.metadata["file_output_unit"] == "mm" and _rel(a.response, c.response) <= 1e-12


def test_several_frfs_one_uff_and_back_to_one_csv_each(tmp_path, capsys):
    files = [write_frf(tmp_path / f"in{k}.csv", _frf(output_station=k, output_name=f"x{k}")) for k in (1, 2, 3)]
    assert main(["frf", "convert", *map(str, files), str(tmp_path / "all.uff"), "--binary"]) == 0
    assert [h.output_station for h in read_frfs(tmp_path / "all.uff")] == [1, 2, 3]
    capsys.readouterr()
    assert main(["frf", "convert", str(tmp_path / "all.uff"), str(tmp_path / "ch.csv")]) == 0
    assert capsys.readouterr().out.split() == [str(tmp_path / f"ch_{k}.csv") for k in (1, 2, 3)]
    for k, f in zip((1, 2, 3), files):
        b = read_frf(tmp_path / f"ch_{k}.csv")
        _same_channel(read_frf(f), b)


def test_node_mapping(tmp_path, csv_file):
    assert main(["frf", "convert", str(csv_file), str(tmp_path / "n.uff"), "--map", "101=12", "--map",
                 "102=13"]) == 0
    h, = read_uff58(tmp_path / "n.uff")
    assert (h.input_station, h.output_station) == (101, 102)
    assert main(["frf", "convert", str(tmp_path / "n.uff"), str(tmp_path / "n.csv"), "--map", "101=12",
                 "--map", "102=13"]) == 0
    assert (read_frf(tmp_path / "n.csv").input_station, read_frf(tmp_path / "n.csv").output_station) == (12, 13)


def _fails(capsys, *argv):
    capsys.readouterr()
    rc = main(["frf", "convert", *map(str, argv)])
    err = capsys.readouterr().err
    assert rc != 0
    return err


def test_bad_input_is_named(tmp_path, csv_file, capsys):
    missing = tmp_path / "missing.csv"
    err = _fails(capsys, missing, tmp_path / "x.uff")
    assert str(missing) in err and "no such file" in err
    err = _fails(capsys, tmp_path / "missing.uff", tmp_path / "x.csv")
    assert "missing.uff" in err and "no such file" in err
    # unknown extensions, of the input and of the output
    (tmp_path / "h.txt").write_text(csv_file.read_text())
    err = _fails(capsys, tmp_path / "h.txt", tmp_path / "x.uff")
    assert "h.txt" in err and "unknown extension (.txt)" in err
    err = _fails(capsys, csv_file, tmp_path / "x.mat")
    assert "x.mat" in err and "unknown extension (.mat)" in err
    assert not (tmp_path / "x.mat").exists()
    # malformed files
    bad = tmp_path / "bad.csv"
    bad.write_text(csv_file.read_text() + "40.5,1.0\n")
    err = _fails(capsys, bad, tmp_path / "x.uff")
    assert str(bad) in err and "expected 3 comma-separated values" in err
    assert not (tmp_path / "x.uff").exists()
    bad_uff = tmp_path / "bad.uff"
    bad_uff.write_text("this is not a universal file\n")
    err = _fails(capsys, bad_uff, tmp_path / "x.csv")
    assert str(bad_uff) in err and "Universal File" in err
    # options that do not apply, an output that cannot be written
    err = _fails(capsys, csv_file, tmp_path / "x.csv", "--binary")
    assert "x.csv" in err and "--binary" in err
    err = _fails(capsys, csv_file, tmp_path / "no" / "dir" / "x.csv")
    assert "x.csv" in err
    err = _fails(capsys, csv_file, tmp_path / "x.uff", "--map", "1=a")
    assert "--map" in err
