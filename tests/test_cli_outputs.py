"""Output directories and counts on the command line are checked before any work, with the option named."""
import os

import pytest

from mutext.cli import main


@pytest.fixture
def existing_file(tmp_path):
    f = tmp_path / "existing.txt"
    f.write_text("x\n")
    return f


def _err(capsys):
    return capsys.readouterr().err


@pytest.mark.parametrize("out, words", [("", "needs a directory name"), ("/proc/mutext-x", "cannot create"),
                                        ("/dev/null/x", "cannot create")])
def test_rig_hide_refuses_bad_output_dirs(out, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["rig", "hide", "--seed", "1", "--out", out]) == 1
    err = _err(capsys)
    assert "--out" in err and words in err and "Traceback" not in err
    assert not list(tmp_path.iterdir())        # nothing written into the current directory


def test_rig_hide_refuses_an_existing_file_and_an_absurd_count(existing_file, capsys, tmp_path):
    assert main(["rig", "hide", "--seed", "1", "--out", str(existing_file)]) == 1
    assert "exists and is not a directory" in _err(capsys)
    assert main(["rig", "hide", "--seed", "1", "--count", "1000000000", "--out", str(tmp_path / "big")]) == 2
    assert "--count must be between 1 and" in _err(capsys)
    assert not (tmp_path / "big").exists()


def test_rig_hide_names_a_malformed_model(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[[mass]]\nname = "m1"\n')
    assert main(["rig", "hide", "--seed", "1", "--example", str(bad), "--out", str(tmp_path / "o")]) == 1
    err = _err(capsys)
    assert "bad.toml" in err and "[[mass]] #1" in err and "missing 'mass'" in err
    broken = tmp_path / "broken.toml"
    broken.write_text("[[mass]\n")
    assert main(["rig", "hide", "--seed", "1", "--example", str(broken), "--out", str(tmp_path / "o")]) == 1
    assert "not a valid TOML file" in _err(capsys)


def test_diagnose_checks_out_before_the_work(existing_file, tmp_path, capsys):
    from mutext.rotor import data_path
    model = data_path("three_mass.toml")
    assert main(["rig", "hide", "--seed", "2", "--out", str(tmp_path / "case")]) == 0
    capsys.readouterr()
    data = sorted((tmp_path / "case" / "measured").iterdir())[0]
    for out, words in ((existing_file, "exists and is not a directory"), ("/proc/mutext-zz", "cannot create")):
        assert main(["diagnose", model, str(data), "--out", str(out), "--quiet"]) == 1
        err = _err(capsys)
        assert words in err and "Traceback" not in err


def test_demo_plots_dir_is_checked(capsys):
    assert main(["demo", "two-mass-hinf", "--plots", "/dev/null/x"]) == 1
    assert "--plots /dev/null/x: cannot create the directory" in _err(capsys)


def test_batch_where_every_data_set_fails_exits_nonzero(tmp_path, capsys):
    case = tmp_path / "batch" / "case_1"
    (case / "measured").mkdir(parents=True)
    (case / "model.toml").write_text('[[mass]]\nname = "m1"\n')      # malformed: every data set fails
    (case / "measured" / "a.csv").write_text("freq_hz,re,im\n1,1,0\n")
    code = main(["diagnose", "--batch", str(tmp_path / "batch"), "--quiet"])
    out = capsys.readouterr()
    assert code == 1, out
    assert os.path.exists(tmp_path / "batch" / "summary.csv")


def test_version_help_and_usage_errors(capsys):
    from importlib.metadata import version
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"mutext {version('mutext')}"
    assert main(["help"]) == 0 and "usage: mutext" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:          # argparse's own --help
        main(["help", "diagnose"])
    assert exc.value.code == 0 and "--validate" in capsys.readouterr().out
    # usage mistakes exit 2 (as argparse and 'mutext grade' do), errors in the data exit 1
    assert main(["diagnose"]) == 2 and "give a model file" in _err(capsys)
    assert main(["diagnose", "m.toml", "d.csv", "--jobs", "2"]) == 2 and "--jobs and --scheduler are for --batch" in _err(capsys)
    assert main(["diagnose", "--batch", "x", "m.toml"]) == 2 and "--batch takes a directory" in _err(capsys)
    assert main(["nonsense"]) == 2


def test_a_usage_error_is_said_before_the_heavy_imports():
    import subprocess
    import sys
    code = ("import sys; from mutext.cli import main; rc = main(['diagnose']); "
            "print(rc, 'numpy' in sys.modules, 'casadi' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.split() == ["2", "False", "False"], out


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["help"]])
def test_output_piped_into_a_reader_that_stops_is_no_traceback(args):
    # `mutext --help | head -1`: the reader closes the pipe before mutext writes
    import subprocess
    import sys
    p = subprocess.Popen([sys.executable, "-c", "import sys; from mutext.cli import main; sys.exit(main())", *args],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait() == 0
    assert "Traceback" not in err and "BrokenPipe" not in err
