"""The autograder against hostile submissions.

Every file in ``tests/grading_submissions/hostile/`` tries to score without
solving the exercise, or to damage the grader: walking frames or the garbage
collector to the child's audit hook and switching it off, reading or
importing the reference solutions by path (at import time or lazily inside a
call), starting a process by every route (``subprocess``,
``_posixsubprocess.fork_exec``, ``os.fork``, ``os.posix_spawn``,
``os.system``), writing outside its directory (a ``.pth`` into
site-packages, the grader's home, ``/tmp``), exhausting memory, forging
events on the results channel, forging a result too large to check
(a 1500-state controller).  Each must score 0.  Attacks on the machine's
memory, disk and time are in ``tests/test_grading_resources.py``.  As root (how the tests
run in CI and in a grading container) the child runs as ``nobody`` in its own
mount namespace, and the report says ``isolation: uid``; a plain user gets
Landlock and seccomp where the kernel has them.  ``probe.py`` tries every
escape from inside the child and reports which worked (none may).
"""
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from grading_harness import ROOT, grade_without_warm_up, q
from mutext.grading import sandbox
from mutext_grader import GradingError, cli_grade, grade
from mutext.grading._jail import landlock_abi
from mutext.grading.sandbox import Job, run_submission

HOSTILE = Path(__file__).resolve().parent / "grading_submissions" / "hostile"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
LANDLOCK = sys.platform.startswith("linux") and landlock_abi() > 0
FORGE_LIMIT = 6.0
MARK = "zz_mutext_hostile_marker"

#: graded in tests/test_grading_resources.py, as root and as a plain user, with the machine checked after
RESOURCE_ATTACKS = {"ex03_resources"}
SUBMISSIONS = {p.stem: p for p in sorted(HOSTILE.glob("ex0*.py")) if p.stem not in RESOURCE_ATTACKS}
EXERCISES = {"ex01": "ex01_two_mass_hinf", "ex03": "ex03_free_decay", "ex04": "ex04_beam_element", "ex08": "ex08_mbi"}

_pool = ThreadPoolExecutor(max_workers=2)
_futures = {}
_lock = threading.Lock()


def graded(name):
    """Report of a hostile submission (or ``"reference"``); all are graded once, two at a time.  The
    hostile files are graded without the warm-up of the grader's reference computations (most fail at
    import; the checks of the others compute what they need; see ``grade_without_warm_up``)."""
    with _lock:
        if not _futures:
            _futures["reference"] = _pool.submit(grade, "ex03_free_decay",
                                                 ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py")
            for n in sorted(SUBMISSIONS, key=lambda n: n != "ex03_forge_events"):
                limit = FORGE_LIMIT if n == "ex03_forge_events" else 60.0
                _futures[n] = _pool.submit(grade_without_warm_up, EXERCISES[n[:4]], SUBMISSIONS[n], limit)
    return _futures[name].result()


def _marker_paths():
    dirs = {sysconfig.get_paths()["purelib"], *__import__("site").getsitepackages(), os.path.expanduser("~root"),
            os.path.expanduser("~"), "/tmp", "/var/tmp", "/dev/shm"}
    return [Path(d) / (MARK + ".pth") for d in dirs] + [Path(d) / MARK for d in dirs] + [
        ROOT / "mutext" / "grading" / (MARK + ".py"), ROOT / "instructor" / "mutext_grader" / (MARK + ".py")]


# ----------------------------------------------------------------------------
# every hostile submission scores 0; the reference still scores full marks
# ----------------------------------------------------------------------------

def test_reference_scores_full_marks_in_the_confined_child():
    rep = graded("reference")
    assert rep.score == 10, rep.text()
    if IS_ROOT:
        assert rep.isolation == "uid", rep.isolation_details
        assert "Isolation: uid" in rep.text()
        assert rep.to_gradescope()["isolation"] == "uid"
    elif LANDLOCK:
        assert rep.isolation == "landlock", rep.isolation_details


@pytest.mark.parametrize("name", sorted(SUBMISSIONS))
def test_hostile_submission_scores_zero(name):
    rep = graded(name)
    assert rep.score == 0, rep.text()
    if IS_ROOT:
        assert rep.isolation == "uid", rep.isolation_details


@pytest.mark.parametrize("name", ["ex01_frames", "ex03_frames", "ex04_frames", "ex08_frames", "ex03_gc"])
def test_switching_off_the_audit_hook_does_not_reach_the_solutions(name):
    rep = graded(name)
    assert all("No module named 'mutext_grader'" in x.output for x in rep.questions), rep.text()


@pytest.mark.parametrize("name", ["ex03_read_path", "ex03_importlib_path"])
def test_solution_file_cannot_be_opened(name):
    out = q(graded(name), "a1").output
    assert "solutions/ex03_free_decay.py" in out
    assert "No such file or directory" in out or "Permission denied" in out


def test_lazy_reading_inside_calls_fails_in_every_question():
    rep = graded("ex03_lazy")
    for x in rep.questions:
        assert "No such file or directory" in x.output or "Permission denied" in x.output, x.output


@pytest.mark.parametrize("name", ["ex03_subprocess", "ex03_posixsubprocess", "ex03_fork", "ex03_posix_spawn"])
def test_no_process_can_be_started(name):
    out = q(graded(name), "a1").output
    assert "Operation not permitted" in out, out


def test_os_system_starts_nothing():
    # os.system cannot fork: it returns an error status, and the copy it should have made does not exist
    assert "No such file or directory: 'stolen.py'" in q(graded("ex03_system"), "a1").output


def test_writes_outside_the_child_directory_fail_and_leave_nothing():
    rep = graded("ex03_write_outside")
    out = q(rep, "a1").output                 # the submission counted its successful writes: none
    assert q(rep, "a1").score == 0 and ("got" not in out or "got 0" in out), out
    left = [p for p in _marker_paths() if p.exists()]
    for p in left:
        p.unlink()
    assert not left


def test_exhausting_memory_fails_the_question_only():
    rep = graded("ex03_memory")
    assert "MemoryError" in q(rep, "a1").output and "MemoryError" in q(rep, "a2").output
    assert "MemoryError" in q(rep, "b1").output
    assert "defines no function stiffness()" in q(rep, "b2").output      # the rest is still graded


def test_forged_events_neither_extend_the_time_limit_nor_pass_values():
    rep = graded("ex03_forge_events")
    a1, a2 = q(rep, "a1"), q(rep, "a2")
    assert a1.status == "timeout" and f"time limit of {FORGE_LIMIT:g} s exceeded" in a1.output
    assert "malformed value" in a2.output and a2.score == 0
    if IS_ROOT:
        assert rep.isolation == "uid"     # the forged "confined" event was ignored


def test_a_forged_oversize_controller_is_rejected_before_any_computation():
    rep = graded("ex01_forged_controller")
    assert "malformed value" in q(rep, "d").output, rep.text()
    assert rep.seconds < 60, rep.seconds      # the closed loop of 1500 states took the grader 11 minutes


# ----------------------------------------------------------------------------
# probing the confinement from inside the child
# ----------------------------------------------------------------------------

def _probe():
    sys.path.insert(0, str(HOSTILE))
    try:
        import probe
    finally:
        sys.path.remove(str(HOSTILE))
    args = [str(ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"),
            str(ROOT / "instructor" / "mutext_grader"),
            str(ROOT), sysconfig.get_paths()["purelib"], os.path.expanduser("~"), str(ROOT / "mutext")]
    res = run_submission(HOSTILE / "probe.py", [Job("p", "probe", "array", [{"args": args}])], time_limit=60)
    call = res.questions["p"].calls[0]
    assert call["ok"], (res.questions["p"], res.stderr_tail)
    return res, dict(zip(probe.ATTEMPTS, call["value"]["data"]))


def _assert_confined(worked):
    assert worked.pop("write the working directory") == 1
    assert worked.pop("import mutext.lti") == 1
    assert {k: v for k, v in worked.items() if v} == {}


@pytest.mark.skipif(not IS_ROOT, reason="the unprivileged user needs a grader running as root")
def test_probe_as_root_finds_no_way_out():
    res, worked = _probe()
    assert res.isolation == "uid"
    assert any(d.startswith("uid ") for d in res.isolation_details)
    _assert_confined(worked)


@pytest.mark.skipif(not LANDLOCK, reason="the kernel offers no Landlock")
def test_probe_as_plain_user_with_landlock_finds_no_way_out(monkeypatch):
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    res, worked = _probe()
    assert res.isolation == "landlock", res.isolation_details
    if IS_ROOT:
        worked.pop("become root again")      # the test runs as root: setuid(0) is no escape here
    _assert_confined(worked)


def test_a_run_that_is_not_isolated_says_so(monkeypatch, capsys):
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    monkeypatch.setattr(sandbox, "SKIP", ("landlock", "seccomp"))
    res, worked = _probe()
    assert worked["read the solution"] == 1
    assert res.isolation == "none"
    assert any("could read" in d and "ex03_free_decay.py" in d for d in res.isolation_details)
    ref = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
    assert cli_grade(["ex03", str(ref), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["isolation"] == "none" and "NOT isolated" in data["output"] and data["score"] == 10


@pytest.mark.skipif(not IS_ROOT, reason="root only")
def test_root_without_namespace_or_landlock_never_claims_isolation(monkeypatch):
    """Fails closed: either the child cannot even start as nobody, or the report says "none"."""
    monkeypatch.setattr(sandbox, "SKIP", ("namespaces", "landlock"))
    ref = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
    try:
        rep = grade("ex03", ref)
    except GradingError as exc:
        assert "cannot be read by the unprivileged user" in str(exc)
        return
    readable = any("could read" in d for d in rep.isolation_details)
    assert rep.isolation == ("none" if readable else "uid"), rep.isolation_details


# ----------------------------------------------------------------------------
# time limit, results channel, a package on PYTHONPATH only
# ----------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["nan", "-1", "0", "inf"])
def test_time_limit_must_be_a_positive_number(value, capsys):
    ref = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
    assert cli_grade(["ex03", str(ref), "--time-limit", value]) == 2
    assert "--time-limit must be a positive number of seconds" in capsys.readouterr().err
    with pytest.raises(GradingError, match="positive number of seconds"):
        grade("ex03", ref, time_limit=float(value))


def test_values_from_the_child_are_validated():
    clean = sandbox._clean_calls
    assert clean("float", [{"ok": True, "value": 1.5}], 1) == [{"ok": True, "value": 1.5}]
    for bad in ({"ok": True, "value": "1.5"}, {"ok": True, "value": True}, {"ok": True, "value": [1.0]},
                {"ok": "yes"}, 3, None, {"ok": False, "error": 7}):
        assert clean("float", [bad], 1)[0]["ok"] is False
    arr = {"shape": [2], "data": [1.0, 2.0]}
    assert clean("array", [{"ok": True, "value": arr}], 1)[0]["ok"] is True
    assert clean("array", [{"ok": True, "value": {"shape": [3], "data": [1.0, 2.0]}}], 1)[0]["ok"] is False
    ss = {"A": [[1.0]], "B": [[1.0]], "C": [[1.0]], "D": [[0.0]], "dt": 0, "inputs": ["u"], "outputs": ["y"]}
    assert clean("ss", [{"ok": True, "value": ss}], 1)[0]["ok"] is True
    assert clean("ss", [{"ok": True, "value": dict(ss, A="os.system")}], 1)[0]["ok"] is False
    assert len(clean("float", [{"ok": True, "value": 1.0}] * 5, 2)) == 2
    assert clean("float", "junk", 1) == []


def test_results_channel_survives_absurd_lines(tmp_path):
    f = tmp_path / "results.jsonl"
    f.write_text("[" * 100000 + "\n" + json.dumps({"event": "boot", "nonce": "n"}) + "\n")
    assert [e["event"] for e in sandbox._Events(f, "n").read()] == ["boot"]


def test_package_only_on_pythonpath(tmp_path):
    """A copy of the package on PYTHONPATH (not installed) grades, and its solutions stay out of reach."""
    src = tmp_path / "src"
    shutil.copytree(ROOT / "mutext", src / "mutext", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "instructor" / "mutext_grader", src / "mutext_grader",
                    ignore=shutil.ignore_patterns("__pycache__"))
    # one interpreter grades both files (each in its own confined child), the outputs split by a line
    code = ("import sys, mutext, mutext.cli; print(mutext.__file__); "
            "sys.exit(max(print('=' * 20, flush=True) or mutext.cli.main(['grade', 'ex03', f]) for f in sys.argv[1:]))")
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env["PYTHONPATH"] = str(src)
    runs = ((src / "mutext_grader" / "solutions" / "ex03_free_decay.py", "Total: 10.00 / 10"),
            (HOSTILE / "ex03_read_path.py", "Total: 0.00 / 10"))
    out = subprocess.run([sys.executable, "-c", code, *[str(sub) for sub, _ in runs]], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith(str(src / "mutext" / "__init__.py")), out.stdout
    parts = out.stdout.split("=" * 20 + "\n")[1:]
    assert len(parts) == len(runs), out.stdout
    for (sub, total), text in zip(runs, parts):
        assert total in text and text.count("Total: ") == 1, text


LIBRARY_CALLS = '''
import ctypes


def dk_peak():
    import control as ct
    from mutext.dk import dk_iteration
    from mutext.mu import Block, BlockStructure
    G = ct.tf([-6, 3], [50, 15, 1])
    WI, WP = ct.tf([1, 0.2], [0.5, 1]), ct.tf([0.5, 0.05], [1, 0.01])
    zero, one = ct.tf([0], [1]), ct.tf([1], [1])
    rows = [[zero, zero, WI], [WP * G, WP, WP * G], [-G, -one, -G]]
    P = ct.ss(ct.tf([[r.num[0][0] for r in row] for row in rows], [[r.den[0][0] for r in row] for row in rows]))
    S = BlockStructure([Block.full(1, 1, "input"), Block.full(1, 1, "performance")])
    return float(dk_iteration(ct.minreal(P, verbose=False), S, 1, 1, max_iter=1, out=None).mu_upper)


def own_ctypes():
    return float(ctypes.CDLL(None).getpid())
'''


def test_the_library_runs_in_the_child_where_the_submission_may_not_load_native_code(tmp_path):
    """D-K limits BLAS to one thread through threadpoolctl, which finds the BLAS libraries with ctypes:
    the child does that before its guard, so the library's D-K runs inside a question, while the
    submission's own ctypes call is still refused."""
    sub = tmp_path / "library_calls.py"
    sub.write_text(LIBRARY_CALLS)
    res = run_submission(sub, [Job("dk", "dk_peak", "float", [{"args": []}]),
                               Job("native", "own_ctypes", "float", [{"args": []}])], time_limit=120)
    dk, native = res.questions["dk"], res.questions["native"]
    assert dk.status == "ok" and not dk.violations and 0.5 < dk.calls[0]["value"] < 5, (dk, res.stderr_tail)
    assert native.violations == ["loading native code through ctypes (ctypes.dlopen)"], native
    assert not native.calls[0]["ok"] and "blocked by the grader" in native.calls[0]["error"], native
