"""Run a submission's functions in a throwaway child process.

The parent (this module) never imports the submission.  It writes a request
(inputs only, no answers) to a private temporary directory, starts
``python -I -B _runner.py request.json`` there and follows the results file
the child appends to.  Each phase (importing the submission, then each
question) has its own wall-clock limit; when one is exceeded the whole
process group is killed, the phase is recorded as timed out, and a fresh
child is started for the questions that have not run yet.  A child that
dies (``os._exit``, a segfault, the file-size limit) is handled the same way.
"""
from __future__ import annotations

import json
import os
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Job", "PhaseOutcome", "SandboxResult", "run_submission", "PROTECTED_MODULES"]

RUNNER = Path(__file__).with_name("_runner.py")
PACKAGE_ROOT = Path(__file__).resolve().parents[1]          # .../mutext
#: directories whose files hold answers (the grader, its solutions, the example models)
PROTECTED_DIRS = [Path(__file__).resolve().parent, PACKAGE_ROOT / "examples", PACKAGE_ROOT / "demos"]
if (PACKAGE_ROOT.parent / "pyproject.toml").is_file():
    # a source checkout: the git history and the test submissions hold answers too
    PROTECTED_DIRS += [PACKAGE_ROOT.parent / ".git", PACKAGE_ROOT.parent / "tests"]
#: modules a submission may not import (they contain or compute the answers)
PROTECTED_MODULES = ["mutext.grading", "mutext.examples", "mutext.demos"]
#: time allowed for the child to start Python and import numpy/scipy/control
STARTUP_LIMIT = 120.0
#: bytes a child may write to any file (guards the disk against print loops)
FILE_SIZE_LIMIT = 64 * 2 ** 20
#: address space of a child (guards the machine against runaway allocations)
MEMORY_LIMIT = 4 * 2 ** 30


@dataclass
class Job:
    """One question as the child sees it: a function name and the calls to make.

    ``calls`` is a list of ``{"args": [...], "kwargs": {...}}`` with JSON
    values; a state-space argument is ``{"__ss__": [A, B, C, D]}``.
    ``kind`` is ``"ss"`` (return a state-space model), ``"float"`` or
    ``"array"`` (an array of real numbers, e.g. a matrix or a tuple ``(K, M)``).
    """
    id: str
    function: str
    kind: str
    calls: list


@dataclass
class PhaseOutcome:
    """What happened in one phase (``"import"`` or a question id).

    ``status`` is ``"ok"``, ``"error"`` (import failed), ``"timeout"``,
    ``"crashed"`` (the child died) or ``"not_run"``.
    """
    status: str
    calls: list = field(default_factory=list)
    error: str = ""
    violations: list = field(default_factory=list)
    seconds: float = 0.0
    last_call: int | None = None    # index of the call running when the phase was cut short


@dataclass
class SandboxResult:
    import_: PhaseOutcome
    questions: dict
    children: int = 0
    stderr_tail: str = ""


def _child_env():
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    # one BLAS thread: graders often run several submissions on a few cores
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", MPLBACKEND="Agg")
    return env


def _limit_resources():   # pragma: no cover - runs in the child between fork and exec
    try:
        import resource
        resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_SIZE_LIMIT, FILE_SIZE_LIMIT))
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    except (ImportError, ValueError, OSError):
        pass


def _kill(proc):
    try:
        if os.name == "posix":
            os.killpg(proc.pid, signal.SIGKILL)
        else:   # pragma: no cover
            proc.kill()
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:   # pragma: no cover
        pass


class _Events:
    """Reads complete lines appended to the results file, keeping those with our nonce."""

    def __init__(self, path, nonce):
        self.path, self.nonce, self.pos = path, nonce, 0

    def read(self):
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.pos)
                data = fh.read()
        except FileNotFoundError:
            return []
        end = data.rfind(b"\n")
        if end < 0:
            return []
        self.pos += end + 1
        out = []
        for line in data[:end].splitlines():
            try:
                ev = json.loads(line)
            except ValueError:
                continue
            if isinstance(ev, dict) and ev.get("nonce") == self.nonce:
                out.append(ev)
        return out


def _module_dir(name):
    """File or directory of a ``mutext`` module or package (``"mutext.rotor"`` -> ``.../mutext/rotor``)."""
    parts = name.split(".")
    if parts[0] != PACKAGE_ROOT.name:
        raise ValueError(f"only modules of {PACKAGE_ROOT.name} can be protected, got {name!r}")
    path = PACKAGE_ROOT.joinpath(*parts[1:])
    return path if path.is_dir() else path.with_suffix(".py")


def _run_once(workdir, submission, jobs, time_limit, outcomes, imp, log, extra_modules=()):
    """Start one child for ``jobs``; fill ``outcomes``/``imp``; return the phase that was cut short."""
    nonce = secrets.token_hex(16)
    results = workdir / f"results-{nonce}.jsonl"
    request = workdir / f"request-{nonce}.json"
    request.write_text(json.dumps({
        "nonce": nonce, "results": str(results), "submission": str(submission),
        "blocked_dirs": [str(d) for d in PROTECTED_DIRS + [_module_dir(m) for m in extra_modules]],
        "protected_root": str(PACKAGE_ROOT),
        "blocked_modules": PROTECTED_MODULES + list(extra_modules),
        "jobs": [{"id": t.id, "function": t.function, "kind": t.kind, "calls": t.calls} for t in jobs],
    }))
    errpath = workdir / f"stderr-{nonce}.txt"
    events = _Events(results, nonce)
    with open(errpath, "wb") as err:
        proc = subprocess.Popen(
            [sys.executable, "-I", "-B", str(RUNNER), str(request)], cwd=workdir,
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, env=_child_env(),
            start_new_session=(os.name == "posix"),
            preexec_fn=_limit_resources if os.name == "posix" else None)
    phase, t0, cut = "startup", time.monotonic(), None
    delay = 0.01
    while True:
        rc = proc.poll()
        for ev in events.read():
            kind, p = ev.get("event"), ev.get("phase")
            now = time.monotonic()
            if kind == "boot":
                phase, t0 = None, now
            elif kind == "start":
                phase, t0 = p, now
            elif kind == "call" and p in outcomes:
                outcomes[p].last_call = ev.get("index")
            elif kind == "violation":
                (imp if p == "import" else outcomes.setdefault(p, PhaseOutcome("crashed"))).violations.append(
                    str(ev.get("what")))
            elif kind == "result" and p == "import":
                imp.status = "ok" if ev.get("ok") else "error"
                imp.error = str(ev.get("error", ""))
                imp.seconds = now - t0
                phase, t0 = None, now
            elif kind == "result" and p in outcomes:
                o = outcomes[p]
                o.status, o.calls, o.seconds = "ok", list(ev.get("calls") or []), now - t0
                phase, t0 = None, now
        if rc is not None:
            if phase is not None:
                cut = (phase, "crashed", rc)
            break
        # phase None: the runner between phases; a stuck runner (e.g. a thread the
        # submission started holding the interpreter) must not stall grading either
        limit = STARTUP_LIMIT if phase == "startup" else time_limit
        if time.monotonic() - t0 > limit:
            _kill(proc)
            cut = (phase, "timeout", None)
            break
        time.sleep(delay)
        delay = min(0.05, delay * 1.5)
    log.append(errpath.read_bytes()[-4000:].decode("utf-8", "replace"))
    return cut


def run_submission(submission, jobs, time_limit: float = 60.0, blocked_modules=()) -> SandboxResult:
    """Import ``submission`` in a child process and run ``jobs``.

    Parameters
    ----------
    submission : path-like
        The student's ``.py`` file.  It is copied into a private temporary
        directory first, so the child never opens the original location.
    jobs : list of Job
    time_limit : float
        Seconds of wall-clock time allowed for importing the submission and,
        separately, for each question.
    blocked_modules : sequence of str
        Further ``mutext`` modules or packages (e.g. ``"mutext.rotor"``) the
        submission may neither import nor read, in addition to
        :data:`PROTECTED_MODULES` (an exercise whose answer the library computes).

    Returns
    -------
    SandboxResult
        Per-phase outcomes with the raw values the submission returned.
    """
    workdir = Path(tempfile.mkdtemp(prefix="mutext-grade-"))
    try:
        sub = workdir / "submission.py"
        shutil.copyfile(submission, sub)
        outcomes = {t.id: PhaseOutcome("not_run") for t in jobs}
        imp = PhaseOutcome("not_run")
        log: list = []
        children = 0
        pending = list(jobs)
        while pending:
            children += 1
            cut = _run_once(workdir, sub, pending, time_limit, outcomes, imp, log, tuple(blocked_modules))
            if cut is not None:
                phase, status, rc = cut
                if phase == "startup":
                    imp.status = status
                    imp.error = ("the grading process could not start" if status == "crashed"
                                 else f"the grading process did not start within {STARTUP_LIMIT:g} s")
                elif phase == "import":
                    imp.status = status
                    imp.error = (f"importing the submission took longer than {time_limit:g} s" if status == "timeout"
                                 else f"the submission ended the grading process while it was being imported "
                                      f"(exit code {rc})")
                elif phase in outcomes:
                    o = outcomes[phase]
                    o.status = status
                    o.error = (f"time limit of {time_limit:g} s exceeded (an endless loop, or a very slow "
                               "computation?)" if status == "timeout"
                               else f"the grading process ended while this question was running (exit code {rc})")
            if imp.status == "not_run":
                imp.status = "crashed"
                imp.error = "the grading process stopped before the submission was imported"
            if imp.status != "ok":
                break
            still = [t for t in pending if outcomes[t.id].status == "not_run"]
            if len(still) == len(pending):   # no progress: do not loop forever
                for t in still:
                    outcomes[t.id].status = "crashed"
                    outcomes[t.id].error = "the grading process ended before this question ran"
                break
            pending = still
        # messages should name the student's file, not the private copy
        name = Path(submission).name

        def rename(text):
            return str(text).replace(str(sub), name).replace("submission.py", name)
        imp.error = rename(imp.error)
        for o in outcomes.values():
            o.error = rename(o.error)
            for c in o.calls:
                if isinstance(c, dict) and "error" in c:
                    c["error"] = rename(c["error"])
        tail = rename("\n".join(s for s in log if s.strip())[-2000:])
        return SandboxResult(import_=imp, questions=outcomes, children=children, stderr_tail=tail)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
