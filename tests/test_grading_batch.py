"""``mutext grade EXERCISE DIR --jobs N``: a class of submissions, each in its own confined child.

A directory holds the reference solution of ex03, a wrong submission (Hz
instead of rad/s), a hostile one (reads the solution by path), one that
imports the grader (an integrity violation), one with a syntax error, and a
file that is not a submission.  The batch is graded once with two jobs.
"""
import contextlib
import csv
import io
import json
import os
import shutil
import sys
from pathlib import Path

import pytest
from grading_harness import ROOT, SUBS

from mutext.cli import main
from mutext_grader import GradingError
from mutext_grader import batch as gbatch
from mutext.grading._jail import landlock_abi

IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
ABI = landlock_abi() if sys.platform.startswith("linux") else 0

FILES = {
    "reference.py": ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py",
    "ex03_hz.py": SUBS / "ex03_hz.py",
    "hostile_read_path.py": SUBS / "hostile" / "ex03_read_path.py",
    "cheat_at_import.py": SUBS / "cheat_at_import.py",
    "syntax_error.py": SUBS / "syntax_error.py",
}
QUESTIONS = ["a1", "a2", "b1", "b2", "c", "d"]


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    """The class graded once through the command line with 2 jobs: (exit code, stdout, stderr, directory)."""
    d = tmp_path_factory.mktemp("class")
    for name, src in FILES.items():
        shutil.copyfile(src, d / name)
    (d / "notes.txt").write_text("not a submission\n")
    # capsys is function-scoped: capture by hand for the module's one run
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(["grade", "ex03", str(d), "--jobs", "2", "--time-limit", "30"])
    return rc, out.getvalue(), err.getvalue(), d


def _rows(d):
    with open(d / "results" / "summary.csv", newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_summary_has_one_row_per_submission_with_scores_per_question(graded):
    rc, _out, err, d = graded
    assert rc == 0, err
    with open(d / "results" / "summary.csv", newline="", encoding="utf-8") as fh:
        header = next(csv.reader(fh))
    assert header == ["submission", "status", "score", "max_score", *QUESTIONS,
                      "integrity", "problems", "isolation", "seconds", "results", "error"]
    rows = {r["submission"]: r for r in _rows(d)}
    assert sorted(rows) == sorted(FILES)                 # notes.txt and results/ are not submissions
    assert all(r["status"] == "graded" and float(r["max_score"]) == 10 for r in rows.values())
    ref = rows["reference.py"]
    assert float(ref["score"]) == 10 and [float(ref[q]) for q in QUESTIONS] == [1.5, 1.5, 1.5, 1.5, 2, 2]
    assert ref["integrity"] == "" and ref["problems"] == ""
    hz = rows["ex03_hz.py"]
    assert float(hz["score"]) == pytest.approx(7.17) and float(hz["a1"]) == 0 and float(hz["d"]) == pytest.approx(0.67)
    for name, r in rows.items():
        assert float(r["score"]) == pytest.approx(sum(float(r[q]) for q in QUESTIONS), abs=0.011), name


def test_hostile_and_cheating_submissions_score_zero_and_are_recorded(graded):
    d = graded[3]
    rows = {r["submission"]: r for r in _rows(d)}
    hostile = rows["hostile_read_path.py"]
    assert float(hostile["score"]) == 0 and all(float(hostile[q]) == 0 for q in QUESTIONS)
    assert "could not be imported" in hostile["problems"]
    cheat = rows["cheat_at_import.py"]
    assert float(cheat["score"]) == 0
    assert "integrity violation" in cheat["integrity"] and "mutext_grader" in cheat["integrity"]
    syntax = rows["syntax_error.py"]
    assert float(syntax["score"]) == 0 and "SyntaxError" in syntax["problems"]
    # the batch went on past them: the files after them in the order were graded too
    assert [r["submission"] for r in _rows(d)] == sorted(FILES)


def test_results_file_per_submission_progress_and_table(graded):
    _rc, out, err, d = graded
    for name in FILES:
        res = json.loads((d / "results" / (Path(name).stem + ".json")).read_text())
        row = next(r for r in _rows(d) if r["submission"] == name)
        assert res["score"] == float(row["score"])
        assert [t["name"].split(")")[0].strip("(") for t in res["tests"]] == QUESTIONS
        assert res["extra_data"]["submission"] == name and res["isolation"] == row["isolation"]
    for k, name in enumerate(sorted(FILES), start=1):
        assert f"{k}/{len(FILES)} {name}" in err                # progress on stderr
    assert "5 of 5 graded" in out and "summary.csv" in out
    assert "reference.py" in out and "10.00" in out


def test_isolation_and_parallelism(graded):
    _rc, out, err, d = graded
    isolation = {r["isolation"] for r in _rows(d)}
    if IS_ROOT:
        assert isolation == {"uid"}
    if isolation <= {"uid", "landlock"} and ABI >= gbatch.SIGNAL_SCOPE_ABI:
        assert "2 at a time" in out and "one at a time" not in err
    else:
        assert "one at a time" in out and "graded one submission at a time" in err


def test_concurrency_needs_children_kept_apart():
    ok = ["mount-namespace", "uid 65534", "landlock (ABI 7)", "seccomp (no new processes)"]
    assert gbatch.concurrency_problem("uid", ok) is None
    assert gbatch.concurrency_problem("landlock", ["landlock (ABI 6)"]) is None
    assert "signal" in gbatch.concurrency_problem("uid", ["mount-namespace", "uid 65534", "landlock (ABI 5)"])
    assert "no Landlock" in gbatch.concurrency_problem("uid", ["mount-namespace", "uid 65534", "no Landlock"])
    assert "not isolated" in gbatch.concurrency_problem("none", ok)


def test_a_submission_that_cannot_be_graded_is_recorded_and_the_rest_graded(tmp_path, monkeypatch):
    shutil.copyfile(FILES["syntax_error.py"], tmp_path / "a_ok.py")
    shutil.copyfile(FILES["syntax_error.py"], tmp_path / "b_broken.py")
    real = gbatch.grade

    def grade(exercise, path, time_limit=60.0, **kwargs):
        if Path(path).name == "b_broken.py":
            raise GradingError("the submission could not be run in a confined process: test")
        return real(exercise, path, time_limit=time_limit, **kwargs)
    monkeypatch.setattr(gbatch, "grade", grade)
    res = gbatch.grade_batch("ex03_free_decay", tmp_path, jobs=1, out_dir=tmp_path / "out")
    assert [r["status"] for r in res.rows] == ["graded", "error"]
    assert [r["submission"] for r in res.failed] == ["b_broken.py"]
    with open(tmp_path / "out" / "summary.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert rows[1]["status"] == "error" and "confined process: test" in rows[1]["error"]
    assert rows[1]["score"] == "" and rows[0]["score"] == "0.0"
    broken = json.loads((tmp_path / "out" / "b_broken.json").read_text())
    assert "could not be graded" in broken["output"] and broken["extra_data"]["status"] == "error"


def test_misuse_is_named(tmp_path, capsys):
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "empty").mkdir()
    assert main(["grade", "ex03", str(tmp_path / "empty")]) == 2
    assert "no submission (*.py file)" in capsys.readouterr().err
    assert main(["grade", "nope", str(tmp_path)]) == 2
    assert "unknown exercise" in capsys.readouterr().err
    assert main(["grade", "ex03", str(tmp_path), "--jobs", "0"]) == 2
    assert "jobs" in capsys.readouterr().err
    assert main(["grade", "ex03", str(tmp_path), "--output", str(tmp_path / "r.json")]) == 2
    assert "--out DIR" in capsys.readouterr().err
    assert main(["grade", "ex03", str(tmp_path / "a.py"), "--jobs", "2"]) == 2
    assert "for a directory" in capsys.readouterr().err
    with pytest.raises(GradingError, match="not a directory"):
        gbatch.find_submissions(tmp_path / "a.py")


def test_a_link_out_of_the_directory_is_not_graded(tmp_path):
    d = tmp_path / "class"
    d.mkdir()
    (tmp_path / "elsewhere.py").write_text("x = 1\n")
    (d / "link.py").symlink_to(tmp_path / "elsewhere.py")
    res = gbatch.grade_batch("ex03", d)
    assert [r["status"] for r in res.rows] == ["error"]
    assert "symbolic link to a file outside the directory" in res.rows[0]["error"]
