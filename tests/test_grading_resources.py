"""The autograder against submissions that go for the grading machine rather than the answers.

``tests/grading_submissions/hostile/ex03_resources.py`` tries, one question each, to hold memory the
child's address-space limit does not count (memfds, System V shared memory and message queues,
socket pairs), to fill the disk (a deep tree of unreadable directories, 1 GiB of files, half of them
deleted but held open, 30,000 empty files) and to forge a result far larger than any honest one.  As
root the child's scratch directory is a tmpfs of 256 MiB and 10,000 files in its own mount namespace;
as a plain user the parent measures the directory every second and at the end of each question, and
stops the child beyond that (naming the question that left the files).
Either way every question scores 0, the grader's memory and time stay bounded and nothing is left in
/tmp, /var/tmp or /dev/shm afterwards.  The rest checks the parts one by one: the size caps on the
values the child returns, over-long lines on its channel, one wall-clock budget per submission,
removal of trees no recursive cleanup survives, Landlock rules decided on real paths (a virtual
environment's ``lib64 -> lib``), and a batch-mate's file, which a child without mount namespace and
Landlock must not read without the report saying so.
"""
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import pytest

from grading_harness import ROOT, q
from mutext.grading import sandbox
from mutext.grading._jail import landlock_abi
from mutext.grading.sandbox import Job, run_submission
from mutext_grader import grade

HOSTILE = Path(__file__).resolve().parent / "grading_submissions" / "hostile"
RESOURCES = HOSTILE / "ex03_resources.py"
READER = HOSTILE / "reader.py"
REFERENCE = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
LANDLOCK = sys.platform.startswith("linux") and landlock_abi() > 0
SHARED = ("/tmp", "/var/tmp", "/dev/shm")
LITTER = "zz_mutext_hostile"

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux confinement")


def _shmem_kib():
    with open("/proc/meminfo") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith("Shmem:"))


@pytest.fixture
def machine_left_as_it_was(monkeypatch):
    """Records the private directories of the gradings in a test; afterwards none of them, nothing of
    the unprivileged user's and no hostile marker is left in the shared temporary directories, and
    the shared memory is back where it was."""
    made = []
    prepare = sandbox._prepare

    def recording(workdir, *args):
        made.append(Path(workdir))
        return prepare(workdir, *args)
    monkeypatch.setattr(sandbox, "_prepare", recording)
    nobody = sandbox._nobody()[0]
    before = {d: set(os.listdir(d)) for d in SHARED if os.path.isdir(d)}
    shmem = _shmem_kib()
    yield made
    assert made
    assert [str(w) for w in made if os.path.lexists(w)] == []
    strays = []
    for d, names in before.items():
        for n in set(os.listdir(d)) - names:
            try:
                owner = os.lstat(os.path.join(d, n)).st_uid
            except FileNotFoundError:
                continue
            if LITTER in n or (IS_ROOT and owner == nobody):
                strays.append(os.path.join(d, n))
    assert strays == []
    assert _shmem_kib() - shmem < 128 * 1024, "shared memory not released"


# ----------------------------------------------------------------------------
# the grouped attack, as root and as a plain user
# ----------------------------------------------------------------------------

def _check_common(rep, seconds):
    assert rep.score == 0, rep.text()
    assert "0 of 56 memfds" in q(rep, "a1").output and "Operation not permitted" in q(rep, "a1").output
    assert "shmget EPERM, msgget EPERM, socketpair EPERM" in q(rep, "a2").output
    assert "malformed value" in q(rep, "d").output
    assert seconds < 120, seconds


@pytest.mark.skipif(not IS_ROOT, reason="the tmpfs needs a grader running as root")
def test_resource_attacks_as_root(machine_left_as_it_was):
    t0 = time.monotonic()
    rep = grade("ex03", RESOURCES, 20.0, seed=1)
    _check_common(rep, time.monotonic() - t0)
    assert rep.isolation == "uid", rep.isolation_details
    assert any(d.startswith("scratch directory: tmpfs of 256 MiB, 10000 files") for d in rep.isolation_details)
    for qid in ("b2", "c"):
        assert "No space left on device" in q(rep, qid).output, q(rep, qid).output
    written = int(q(rep, "b2").output.split("big files: ")[1].split(" MiB")[0])
    assert written <= 256
    assert "deep tree" in q(rep, "b1").output


@pytest.mark.slow
@pytest.mark.skipif(not LANDLOCK, reason="the kernel offers no Landlock")
def test_resource_attacks_as_plain_user(monkeypatch, machine_left_as_it_was):
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    t0 = time.monotonic()
    rep = grade("ex03", RESOURCES, 20.0, seed=1)
    _check_common(rep, time.monotonic() - t0)
    assert rep.isolation == "landlock", rep.isolation_details
    assert any("no tmpfs of its own" in d for d in rep.isolation_details)
    assert "stopped: it wrote more than 256 MiB" in q(rep, "b2").output, q(rep, "b2").output
    assert "stopped: it created more than 10000 files" in q(rep, "c").output, q(rep, "c").output


# ----------------------------------------------------------------------------
# values and lines from the child: sizes checked before anything is computed
# ----------------------------------------------------------------------------

def _ss(n, m=1, p=1):
    return {"A": [[0.0] * n for _ in range(n)], "B": [[0.0] * m for _ in range(n)],
            "C": [[0.0] * n for _ in range(p)], "D": [[0.0] * m for _ in range(p)], "dt": None,
            "inputs": ["u"] * m, "outputs": ["y"] * p}


def test_returned_values_are_capped_in_size():
    ok = sandbox._valid_value
    assert ok("ss", _ss(sandbox.MAX_STATES)) and ok("ss", _ss(0)) and ok("ss", _ss(3, 2, 4))
    assert not ok("ss", _ss(sandbox.MAX_STATES + 1))
    assert not ok("ss", _ss(2, m=sandbox.MAX_STATES + 1))
    bad = _ss(3)
    bad["B"] = [[0.0], [0.0]]                 # rows of B do not match A
    assert not ok("ss", bad)
    bad = _ss(3)
    bad["A"][1] = [0.0]                       # ragged
    assert not ok("ss", bad)
    n = sandbox.MAX_ELEMENTS
    assert ok("array", {"shape": [n], "data": [0.0] * n})
    assert not ok("array", {"shape": [n + 1], "data": [0.0] * (n + 1)})
    assert not ok("array", {"shape": [1] * 33, "data": [0.0]})
    assert not ok("float", 10 ** 400) and not ok("float", True)
    # the forged 1500-state controller is turned down at once, without a look at its numbers
    huge = _ss(1500)
    t0 = time.process_time()            # CPU time: the same on a busy machine
    assert sandbox._clean_calls("ss", [{"ok": True, "value": huge}], 1)[0]["ok"] is False
    assert time.process_time() - t0 < 0.5


FLOOD = """\
import os


def flood():
    os.makedirs("many", exist_ok=True)
    for n in range(10_050):
        os.close(os.open(f"many/f{n}", os.O_WRONLY | os.O_CREAT, 0o600))
    return 1.0


def quiet():
    return 2.0
"""


def test_files_left_by_a_question_are_its_own(tmp_path, monkeypatch, machine_left_as_it_was):
    """A question that floods the scratch directory between two measurements and returns is stopped at its
    end, not the question that runs after it in the same child (which runs again in a clean child)."""
    from mutext.grading import _child
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")          # no tmpfs: the parent measures
    monkeypatch.setattr(_child, "SCRATCH_CHECK_INTERVAL", 1e6)  # no periodic measurement in between
    sub = tmp_path / "flood.py"
    sub.write_text(FLOOD)
    jobs = [Job("c", "flood", "float", [{"args": []}]), Job("d", "quiet", "float", [{"args": []}])]
    res = run_submission(sub, jobs, time_limit=60)
    c, d = res.questions["c"], res.questions["d"]
    assert c.status == "crashed" and "it created more than 10000 files" in c.error, c
    assert c.last_call is None
    assert d.status == "ok" and d.calls == [{"ok": True, "value": 2.0}], d
    assert res.children == 2


def test_overlong_lines_on_the_channel_are_skipped_unread(tmp_path):
    f = tmp_path / "results.jsonl"
    ev = json.dumps({"event": "boot", "nonce": "n"}) + "\n"
    big = b"x" * (sandbox._Events.MAX_LINE + 10)
    f.write_bytes(ev.encode() + big)
    events = sandbox._Events(f, "n")
    assert [e["event"] for e in events.read()] == ["boot"]
    assert events.read() == [] and events.skipping
    with open(f, "ab") as fh:
        fh.write(b"more of the long line\n" + ev.encode())
    assert [e["event"] for e in events.read()] == ["boot"]


def test_one_time_budget_for_the_whole_submission(machine_left_as_it_was):
    """Every question stalls: each times out and restarts the child, until the budget is spent."""
    jobs = [Job(f"q{i}", "stall", "float", [{"args": []}]) for i in range(4)]
    t0 = time.monotonic()
    res = run_submission(READER, jobs, time_limit=1.5, total_limit=3.0)
    elapsed = time.monotonic() - t0
    outs = [res.questions[f"q{i}"] for i in range(4)]
    assert all(o.status == "timeout" for o in outs)
    assert "grading time budget spent (3 s" in outs[-1].error
    assert outs[0].error.startswith("time limit of 1.5 s exceeded")
    assert elapsed < 3.0 + sandbox.STARTUP_LIMIT, elapsed
    with pytest.raises(ValueError, match="total_limit"):
        run_submission(READER, jobs, time_limit=2.0, total_limit=float("nan"))


# ----------------------------------------------------------------------------
# the parent's own cleanup and measurement
# ----------------------------------------------------------------------------

def _deep_tree(top, depth):
    fd = os.open(top, os.O_RDONLY | os.O_DIRECTORY)
    for _ in range(depth):
        os.mkdir("d", dir_fd=fd)
        sub = os.open("d", os.O_RDONLY | os.O_DIRECTORY, dir_fd=fd)
        os.close(fd)
        fd = sub
    os.close(os.open("f", os.O_WRONLY | os.O_CREAT, 0o600, dir_fd=fd))
    os.close(fd)


def test_trees_no_recursive_cleanup_survives_are_removed(tmp_path, monkeypatch):
    # /dev/shm (a tmpfs) where there is one: metadata on some disks costs milliseconds per directory
    base = Path(tempfile.mkdtemp(prefix="mutext-test-", dir="/dev/shm" if os.path.isdir("/dev/shm") else tmp_path))
    try:
        outside = tmp_path / "keep.txt"
        outside.write_text("stays")
        top = base / "box"
        top.mkdir()
        _deep_tree(str(top), 20_000)
        with pytest.raises(RecursionError):
            shutil.rmtree(top)
        (top / "link").symlink_to(outside)
        (top / "dirlink").symlink_to(tmp_path)
        (top / "closed").mkdir()
        (top / "closed" / "x").write_text("x")
        (top / "submission.py").write_text("pass\n")
        os.chmod(top / "closed", 0)
        used, files = sandbox._tree_use(str(top), 2 ** 30, 100)
        assert files == 101                   # counting stopped at the first excess
        monkeypatch.setattr(sandbox, "_fix_perms", lambda: True)     # as the child's own user would
        assert sandbox._remove_tree(top, keep=("submission.py",))
        assert sorted(os.listdir(top)) == ["submission.py"]
        assert sandbox._remove_tree(top) and not top.exists()
        assert outside.read_text() == "stays" and tmp_path.is_dir()
    finally:
        sandbox._remove_tree(base)
    assert not base.exists()


# ----------------------------------------------------------------------------
# Landlock rules on real paths
# ----------------------------------------------------------------------------

def _venv_like(tmp_path):
    """A virtual environment with the grader installed beside the libraries, and ``lib64 -> lib``."""
    venv = tmp_path / "venv"
    site = venv / "lib" / "python3.11" / "site-packages"
    (site / "numpy").mkdir(parents=True)
    (site / "numpy" / "__init__.py").write_text("")
    grader = site / "mutext_grader"
    (grader / "solutions").mkdir(parents=True)
    (grader / "core.py").write_text("# grader\n")
    (grader / "solutions" / "ex03_free_decay.py").write_text("ANSWER = 42\n")
    (venv / "pyvenv.cfg").write_text("home = /usr/bin\n")
    (venv / "lib64").symlink_to("lib")
    (site / "grader_link").symlink_to(grader)
    return venv, site, grader


def test_read_rules_never_follow_a_link_into_a_secret_root(tmp_path):
    venv, site, grader = _venv_like(tmp_path)
    full, listing = sandbox._read_rules(str(venv), [str(grader)])
    secret = os.path.realpath(grader)
    for p in full:
        r = os.path.realpath(p)
        assert not sandbox._under(r, secret) and not sandbox._under(secret, r), p
    assert not any("lib64" in p or "grader_link" in p for p in full + listing)
    assert str(site / "numpy") in full and str(site) in listing
    # a rule given by mistake to a link is dropped by what it leads to
    assert sandbox._safe_rules([str(venv / "lib64"), str(site / "numpy")], [secret]) == [str(site / "numpy")]
    assert sandbox._safe_rules([str(site / "grader_link")], [secret], listing=True) == []


@pytest.mark.skipif(not LANDLOCK, reason="the kernel offers no Landlock")
def test_plain_user_cannot_read_the_solutions_through_a_link(tmp_path, monkeypatch, machine_left_as_it_was):
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    ref = grade("ex03", REFERENCE, seed=1)         # a correct submission still works as a plain user
    assert ref.score == 10 and ref.isolation == "landlock", ref.text()
    venv, site, grader = _venv_like(tmp_path)
    python_dirs = sandbox._python_dirs
    monkeypatch.setattr(sandbox, "GRADER_DIR", grader)
    monkeypatch.setattr(sandbox, "_python_dirs", lambda: python_dirs() + [str(venv)])
    via_link = venv / "lib64" / "python3.11" / "site-packages" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
    paths = [str(via_link), str(grader / "solutions" / "ex03_free_decay.py"), str(site / "numpy" / "__init__.py")]
    res = run_submission(READER, [Job("p", "read_paths", "array", [{"args": [paths]}])], time_limit=60)
    call = res.questions["p"].calls[0]
    assert call["ok"], (res.questions["p"], res.stderr_tail)
    assert call["value"]["data"] == [0.0, 0.0, 1.0]      # the libraries beside the grader stay readable
    assert res.isolation == "landlock", res.isolation_details


# ----------------------------------------------------------------------------
# batch-mates and litter without mount namespace or Landlock
# ----------------------------------------------------------------------------

def _batch(tmp):
    batch = Path(tempfile.mkdtemp(prefix="mutext-test-batch-", dir=tmp))
    os.chmod(batch, 0o755)
    mine, mate = batch / "alice.py", batch / "bob.py"
    shutil.copyfile(READER, mine)
    mate.write_text("def natural_frequency(t, y, cycles):\n    return 1.0\n")
    for f in (mine, mate):
        os.chmod(f, 0o644)
    return batch, mine, mate


def test_a_readable_batch_mate_is_reported(monkeypatch):
    """Without mount namespace and Landlock (here: a plain user's run with Landlock left out), the probe
    reads the other submissions of the directory and the report names them."""
    monkeypatch.setattr(sandbox, "FORCE_MODE", "user")
    monkeypatch.setattr(sandbox, "SKIP", ("landlock",))
    batch, mine, mate = _batch(None)
    try:
        res = run_submission(mine, [Job("p", "read_paths", "array", [{"args": [[str(mate)]]}])], time_limit=60)
    finally:
        sandbox._remove_tree(batch)
    assert res.questions["p"].calls[0]["value"]["data"] == [1.0]
    assert res.isolation == "none"
    assert any("other submissions" in d and str(mate) in d and str(mine) in d for d in res.isolation_details), \
        res.isolation_details

@pytest.mark.skipif(not IS_ROOT, reason="root only")
def test_root_without_namespace_or_landlock_reports_a_readable_batch_mate(monkeypatch, machine_left_as_it_was):
    batch, mine, mate = _batch(None)
    try:
        jobs = [Job("p", "read_paths", "array", [{"args": [[str(mate)]]}]),
                Job("l", "litter", "array", [{"args": ["batch"]}])]
        res = run_submission(mine, jobs, time_limit=60)        # with its mount namespace: hidden
        assert res.questions["p"].calls[0]["value"]["data"] == [0.0] and res.isolation == "uid"
        assert res.questions["l"].calls[0]["value"]["data"] == [0.0]
        monkeypatch.setattr(sandbox, "SKIP", ("namespaces", "landlock"))
        try:
            res = run_submission(mine, jobs, time_limit=60)
        except sandbox.SandboxError as exc:      # Python itself unreadable for the unprivileged user
            assert "cannot be read by the unprivileged user" in str(exc)
            return
        assert res.questions["p"].calls[0]["value"]["data"] == [1.0]
        assert res.isolation == "none"
        assert any("other submissions" in d and str(mate) in d for d in res.isolation_details), \
            res.isolation_details
        # what it left in /tmp, /var/tmp and /dev/shm as the unprivileged user is gone (the fixture checks)
        assert res.questions["l"].calls[0]["value"]["data"][0] > 0
        mate.chmod(0o600)
        mine.chmod(0o600)
        res = run_submission(mine, jobs[:1], time_limit=60)
        assert res.questions["p"].calls[0]["value"]["data"] == [0.0]
        assert not any("other submissions" in d for d in res.isolation_details), res.isolation_details
    finally:
        sandbox._remove_tree(batch)


def test_the_submission_directory_is_hidden_from_the_root_child(tmp_path):
    d = next((p for p in ("/var/lib", "/var/cache", "/etc") if os.path.isdir(p)), None)
    if d is None:
        pytest.skip("no directory to try")
    plan = sandbox._hide_plan([], str(tmp_path / "mutext-grade-x"), os.path.join(d, "student.py"))
    assert any(h == os.path.realpath(d) for h, _ in plan)
