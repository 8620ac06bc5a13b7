"""The documented course setup (docs/gradescope/, docs/grading.md), run end to end.

Gradescope builds an image by running ``setup.sh`` as root, then runs
``run_autograder`` as root once per submission and reads
``results/results.json``.  The slow test rebuilds that layout in a scratch
directory (``AUTOGRADER`` and ``MUTEXT_VENV`` point there instead of
``/autograder`` and ``/opt/mutext``): the zip from ``make_autograder.py``,
a fresh virtual environment with the package installed from the zip's source,
then the reference solution (full marks, ``isolation: uid``), every hostile
submission and one that only borrows the reference (all 0), and wrong uploads
(no file, two files).  The default run checks course mode
(``--require-isolation``) on its own: a run that was not isolated scores 0.
"""
import json
import os
import shutil
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
HOSTILE = ROOT / "tests" / "grading_submissions" / "hostile"
SOLUTION = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


def _not_isolated(monkeypatch):
    """Make every run report isolation "none", as on a laptop without Landlock."""
    real = core.run_submission

    def run(*args, **kwargs):
        res = real(*args, **kwargs)
        res.isolation = "none"
        return res
    monkeypatch.setattr(core, "run_submission", run)


def test_course_mode_scores_an_unisolated_run_zero(monkeypatch, tmp_path, capsys):
    _not_isolated(monkeypatch)
    relaxed = core.grade("ex03_free_decay", SOLUTION)
    assert relaxed.score == relaxed.max_score == 10      # the same run, not required: full marks
    strict = core.grade("ex03_free_decay", SOLUTION, require_isolation=True)
    assert strict.score == 0 and strict.max_score == 10
    assert all("not isolated" in q.output for q in strict.questions)
    out = tmp_path / "results.json"
    assert grade_main(["ex03", str(SOLUTION), "--require-isolation", "--output", str(out)]) == NOT_ISOLATED
    data = json.loads(out.read_text())
    assert data["score"] == 0 and data["isolation"] == "none"
    assert "isolation was required" in data["output"]


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
            assert {"setup.sh", "run_autograder", "exercise"} <= set(names)
            assert "mutext-src/mutext/grading/core.py" in names and not any(".venv/" in n for n in names)
            z.extractall(ag / "source")
        env = dict(os.environ, AUTOGRADER=str(ag), MUTEXT_VENV=str(venv), MUTEXT_TIME_LIMIT="15")
        env.pop("PYTHONPATH", None)
        subprocess.run(["bash", str(ag / "source" / "setup.sh")], env=env, check=True, capture_output=True,
                       timeout=900)
        shutil.copy(ag / "source" / "run_autograder", ag / "run_autograder")
        # the unprivileged user cannot read the installed solutions, nor the source tree
        pkg = next(venv.glob("lib/python3*/site-packages/mutext"))
        assert (pkg.stat().st_mode & 0o077) == 0 and ((ag / "source").stat().st_mode & 0o077) == 0

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
        borrow = base / "borrow.py"
        borrow.write_text("from mutext_grader.solutions.ex03_free_decay import *\n")
        for f in sorted(HOSTILE.glob("ex03_*.py")) + [borrow]:
            res = run(f)
            assert res["score"] == 0, (f.name, res["output"])
            assert res.get("isolation") == "uid", (f.name, res["output"])
        assert run()["score"] == 0 and "exactly one" in run()["output"]
        assert "exactly one" in run(SOLUTION, borrow)["output"]
    finally:
        shutil.rmtree(base, ignore_errors=True)
