"""The documented course setup (docs/gradescope/, docs/grading.md), run end to end.

Gradescope builds an image by running ``setup.sh`` as root, then runs
``run_autograder`` as root once per submission and reads
``results/results.json``.  The slow test rebuilds that layout in a scratch
directory (``AUTOGRADER`` and ``MUTEXT_VENV`` point there instead of
``/autograder`` and ``/opt/mutext``): the zip from ``make_autograder.py``,
a fresh virtual environment with ``mutext`` and the instructor's
``mutext_grader`` installed from the zip's source, the course secret stored
for root only; then the reference solution (full marks, ``isolation: uid``),
the same file graded twice (the same inputs and score) and once edited (new
inputs), a submission that tries to read the secret (it cannot), every hostile
submission and one that only borrows the reference (all 0), and wrong uploads
(no file, two files).  The default run checks course mode
(``--require-isolation``) on its own, and what the zip holds: only files git
tracks (no ``diagnosis/`` of the quick start), a fresh or a given secret.
"""
import copy
import dataclasses
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from grading_harness import ROOT
from mutext_grader import core
from mutext_grader.cli import NOT_ISOLATED, main as grade_main

GRADESCOPE = ROOT / "docs" / "gradescope"
sys.path.insert(0, str(GRADESCOPE))
import make_autograder  # noqa: E402
HOSTILE = ROOT / "tests" / "grading_submissions" / "hostile"
SOLUTION = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
SEED = 20250611


def _not_isolated(monkeypatch):
    """Make every run report isolation "none", as on a laptop without Landlock.  The confined run of a
    file on the same inputs is made once: the runs of the course-mode test differ only in what the
    grader does with the report."""
    real = core.run_submission
    runs = {}

    def run(submission, jobs, **kwargs):
        key = (str(submission), json.dumps([dataclasses.asdict(j) for j in jobs]), repr(sorted(kwargs.items())))
        if key not in runs:
            runs[key] = real(submission, jobs, **kwargs)
        res = copy.deepcopy(runs[key])
        res.isolation = "none"
        return res
    monkeypatch.setattr(core, "run_submission", run)
    return runs


def test_course_mode_scores_an_unisolated_run_zero(monkeypatch, tmp_path, capsys):
    runs = _not_isolated(monkeypatch)
    relaxed = core.grade("ex03_free_decay", SOLUTION, seed=SEED)
    assert relaxed.score == relaxed.max_score == 10      # the same run, not required: full marks
    strict = core.grade("ex03_free_decay", SOLUTION, require_isolation=True, seed=SEED)
    assert strict.score == 0 and strict.max_score == 10
    assert all("not isolated" in q.output for q in strict.questions)
    out = tmp_path / "results.json"
    assert grade_main(["ex03", str(SOLUTION), "--require-isolation", "--output", str(out),
                       "--seed", str(SEED)]) == NOT_ISOLATED
    assert len(runs) == 1                                # one confined run behind the three reports
    data = json.loads(out.read_text())
    assert data["score"] == 0 and data["isolation"] == "none"
    assert "isolation was required" in data["output"]


def _git(repo, *args):
    subprocess.run(["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@example.org", *args],
                   check=True, capture_output=True)


def test_zip_packs_tracked_files_only_and_a_secret(tmp_path):
    repo = tmp_path / "checkout"
    tracked = ["pyproject.toml", "README.md", "LICENSE", "mutext/__init__.py", "mutext/data/rig.toml",
               "instructor/pyproject.toml", "instructor/mutext_grader/__init__.py",
               "instructor/mutext_grader/solutions/ex03_free_decay.py", "book/intro.md", "tests/test_x.py"]
    for f in tracked:
        (repo / f).parent.mkdir(parents=True, exist_ok=True)
        (repo / f).write_text(f"# {f}\n")
    _git(tmp_path, "init", "-q", str(repo))
    _git(repo, "add", "--", *tracked)
    _git(repo, "commit", "-q", "-m", "course")
    # what the quick start and a careless instructor leave behind, none of it tracked
    outputs = ["diagnosis/answer_key.json", "diagnosis/report/report.html", "mutext/answer_key.json",
               "instructor/mutext_grader/solutions/scratch.py", "mutext/__pycache__/lti.cpython-311.pyc",
               "autograder-ex02.zip", "instructor/build/lib/mutext_grader/__init__.py"]
    for f in outputs:
        (repo / f).parent.mkdir(parents=True, exist_ok=True)
        (repo / f).write_text("{}\n")
    out = make_autograder.build("ex03", tmp_path / "ag.zip", repo=repo)
    with zipfile.ZipFile(out) as z:
        names = set(z.namelist())
        secret = z.read("secret")
        modes = {i.filename: (i.external_attr >> 16) & 0o777 for i in z.infolist()}
        assert z.read("exercise") == b"ex03_free_decay\n"
    packed = {f"mutext-src/{f}" for f in tracked if not f.startswith(("book/", "tests/"))}
    assert names == packed | {"setup.sh", "run_autograder", "exercise", "secret"}
    assert not any("diagnosis" in n or "answer_key" in n or "scratch" in n for n in names)
    assert re.fullmatch(rb"[0-9a-f]{64}\n", secret) and modes["secret"] == 0o600
    assert modes["setup.sh"] == modes["run_autograder"] == 0o755 and (out.stat().st_mode & 0o077) == 0
    # a fresh secret every time, unless the course's own is given
    again = make_autograder.build("ex03", tmp_path / "ag2.zip", repo=repo)
    with zipfile.ZipFile(again) as z:
        assert z.read("secret") != secret
    course = tmp_path / "course.secret"
    course.write_bytes(b"0123456789abcdef0123456789abcdef\n")
    assert make_autograder.main(["ex03", str(tmp_path / "ag3.zip"), "--secret-file", str(course)]) == 0
    with zipfile.ZipFile(tmp_path / "ag3.zip") as z:
        assert z.read("secret") == course.read_bytes()
    course.write_bytes(b"short\n")
    with pytest.raises(SystemExit, match="at least"):
        make_autograder.main(["ex03", str(tmp_path / "ag4.zip"), "--secret-file", str(course)])
    with pytest.raises(SystemExit, match="unknown exercise"):
        make_autograder.build("ex99", tmp_path / "ag5.zip", repo=repo)


def test_the_checkout_packs_both_packages():
    files = make_autograder.packed_files()
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files"], check=True, capture_output=True,
                            text=True).stdout.split()
    assert set(files) <= set(listed)
    assert "instructor/mutext_grader/solutions/ex03_free_decay.py" in files
    assert "instructor/mutext_grader/core.py" in files and "instructor/pyproject.toml" in files
    assert "mutext/grading/sandbox.py" in files and "pyproject.toml" in files and "README.md" in files
    assert not any(f.startswith(("tests/", "book/", "benchmarks/", ".venv/", "diagnosis/")) for f in files)


def test_demo_outputs_are_ignored_by_git():
    for f in ("diagnosis/answer_key.json", "case/report/report.html", "autograder-ex03.zip", "course.secret"):
        assert subprocess.run(["git", "-C", str(ROOT), "check-ignore", "-q", f]).returncode == 0, f


#: a submission of ex03 that quotes its inputs back (through an error message) and tries to read the secret
PROBE = """
SECRET = {secret!r}


def natural_frequency(t, y, cycles):
    raise ValueError(f"inputs {{cycles!r}} {{float(t[1]):.17g}} {{float(y[3]):.17g}}")


def damping_ratio(t, y, cycles):
    try:
        with open(SECRET) as fh:
            data = fh.read()
    except OSError as exc:
        raise ValueError(f"secret unreadable: {{type(exc).__name__}}") from None
    raise ValueError(f"secret read: {{data}}")
"""


@pytest.mark.slow
@pytest.mark.skipif(not (IS_ROOT and sys.platform.startswith("linux")),
                    reason="the Gradescope container runs the grader as root on Linux")
def test_gradescope_layout_end_to_end():
    # under /var/tmp with mode 755: the child's user must be able to run the venv's Python
    base = Path(tempfile.mkdtemp(prefix="mutext-gradescope-", dir="/var/tmp"))
    try:
        base.chmod(0o755)
        ag, venv = base / "autograder", base / "opt" / "mutext"
        (ag / "source").mkdir(parents=True)
        venv.parent.mkdir()
        zpath = base / "autograder.zip"
        subprocess.run([sys.executable, str(GRADESCOPE / "make_autograder.py"), "ex03", str(zpath)], check=True,
                       capture_output=True)
        with zipfile.ZipFile(zpath) as z:
            names = z.namelist()
            assert {"setup.sh", "run_autograder", "exercise", "secret"} <= set(names)
            assert "mutext-src/mutext/grading/sandbox.py" in names
            assert "mutext-src/instructor/mutext_grader/solutions/ex03_free_decay.py" in names
            assert not any(".venv/" in n or "diagnosis/" in n for n in names)
            secret_text = z.read("secret").decode().strip()
            z.extractall(ag / "source")
        env = dict(os.environ, AUTOGRADER=str(ag), MUTEXT_VENV=str(venv), MUTEXT_TIME_LIMIT="15")
        env.pop("PYTHONPATH", None)
        setup = subprocess.run(["bash", str(ag / "source" / "setup.sh")], env=env, capture_output=True,
                               text=True, timeout=900)
        assert setup.returncode == 0, setup.stderr[-3000:]
        shutil.copy(ag / "source" / "run_autograder", ag / "run_autograder")
        # the unprivileged user cannot read the installed packages, the source tree nor the secret
        site = next(venv.glob("lib/python3*/site-packages"))
        for d in (site / "mutext", site / "mutext_grader", ag / "source"):
            assert (d.stat().st_mode & 0o077) == 0, d
        assert (site / "mutext_grader" / "solutions" / "ex03_free_decay.py").is_file()
        secret = ag / "secret"
        st = secret.stat()
        assert st.st_uid == 0 and stat.S_IMODE(st.st_mode) == 0o600
        assert secret.read_text().strip() == secret_text and not (ag / "source" / "secret").exists()
        denied = subprocess.run(["cat", str(secret)], user=65534, group=65534, capture_output=True)
        assert denied.returncode != 0 and secret_text.encode() not in denied.stdout

        def run(*files):
            sub = ag / "submission"
            shutil.rmtree(sub, ignore_errors=True)
            sub.mkdir()
            for f in files:
                shutil.copy(f, sub / Path(f).name)
            subprocess.run(["bash", str(ag / "run_autograder")], env=env, capture_output=True, timeout=300)
            return json.loads((ag / "results" / "results.json").read_text())

        ref = run(SOLUTION)
        assert ref["score"] == 10 and ref["isolation"] == "uid", ref["output"]
        assert "course secret" in ref["extra_data"]["inputs"]
        # course mode: the same file, the same inputs and score; an edited file, new inputs
        probe = base / "probe.py"
        probe.write_text(PROBE.format(secret=str(secret)))
        first, second = run(probe), run(probe)
        inputs = [t["output"] for t in first["tests"] if "inputs " in t["output"]]
        assert inputs and inputs == [t["output"] for t in second["tests"] if "inputs " in t["output"]]
        assert first["score"] == second["score"] == 0 and first["isolation"] == "uid"
        probe.write_text(probe.read_text() + "# edited\n")
        edited = run(probe)
        assert [t["output"] for t in edited["tests"] if "inputs " in t["output"]] != inputs
        # the child could not read the secret, and nothing of it reached the results
        for res in (first, second, edited):
            assert "secret unreadable" in json.dumps(res) and secret_text not in json.dumps(res)
        borrow = base / "borrow.py"
        borrow.write_text("from mutext_grader.solutions.ex03_free_decay import *\n")
        for f in sorted(HOSTILE.glob("ex03_*.py")) + [borrow]:
            res = run(f)
            assert res["score"] == 0, (f.name, res["output"])
            assert res.get("isolation") == "uid", (f.name, res["output"])
        assert run()["score"] == 0 and "exactly one" in run()["output"]
        assert "exactly one" in run(SOLUTION, borrow)["output"]
        # a lost secret stops the grading with a reason instead of drawing inputs anyhow
        secret.rename(base / "secret.moved")
        lost = run(SOLUTION)
        assert lost["score"] == 0 and "no course secret" in lost["output"]
    finally:
        shutil.rmtree(base, ignore_errors=True)
