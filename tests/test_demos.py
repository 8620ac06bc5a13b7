"""What a new user meets in the demos: help, honest output with their own data, complete JSON."""
import json

import pytest

from mutext.cli import main
from mutext.rig import FRF, write_frf


def test_demo_help_is_the_demos_own(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["demo", "diagnose", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "--example" in out and "--seed" in out


def test_three_mass_frf_must_be_the_f1_x1_channel(tmp_path, capsys):
    path = write_frf(tmp_path / "x3.csv", FRF([0.5, 1.0, 2.0, 3.0], [1e-3, 2e-3, 1e-3, 5e-4], input_station=1,
                                              output_station=3))
    assert main(["demo", "three-mass", "--frf", str(path), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "f1 -> x1" in err and "station 3" in err


def test_two_mass_hinf_json_reports_the_checks(capsys):
    assert main(["demo", "two-mass-hinf", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["closed_loop_stable"] is True
    assert len(d["controller_rhp_poles"]) == 2
    assert d["closed_loop_hinf_slycot"] == pytest.approx(d["closed_loop_hinf"], rel=1e-4)


class _Terminal:
    """A stream that says it is a terminal, recording what is written."""

    def __init__(self):
        self.text = ""

    def isatty(self):
        return True

    def write(self, s):
        self.text += s

    def flush(self):
        pass


def test_progress_line_is_also_the_log_stream_below_the_bar():
    from mutext.progress import ProgressLine
    term = _Terminal()
    line = ProgressLine(term)
    line("W_z try 1/2", 0.25)
    print("[mbi] try 1: Wz = 0.01", file=line)      # a log line clears the unfinished bar first
    assert term.text.endswith("\r" + " " * 110 + "\r[mbi] try 1: Wz = 0.01\n")
    line("done", 1.0)
    term.text = ""
    print("after the end", file=line)               # a finished bar stays
    assert term.text == "after the end\n"


def test_progress_piped_into_a_log_shows_every_tenth():
    import io

    from mutext.progress import ProgressLine
    log = io.StringIO()                    # not a terminal: one line per step worth saying
    line = ProgressLine(log)
    for k in range(1, 31):
        line(f"data set {k}/30: case_{k} ok", k / 30)
    pct = [int(x.split("]")[1].split("%")[0]) for x in log.getvalue().splitlines()]
    assert pct[0] == 3 and pct[-1] == 100 and len(pct) == 11
    assert all(b - a <= 10 for a, b in zip(pct, pct[1:]))      # no jump from the first case to the end
