"""Run a submission's functions in a confined throwaway child process.

The parent (this module) never imports the submission.  For each child it
prepares a private temporary directory::

    mutext-grade-XXXX/          root only (0711): request, results and stderr files
        box/                    the child's home, working and temporary directory (its user owns it)
            submission.py       a copy of the student's file
        lib/mutext/             the parts of the package a student may import (no grader, solutions,
                                examples, demos, data, nor the exercise's blocked modules)

and starts ``python -I -S -B _jail.py request.json``.  :mod:`._jail` confines
the process (below), then runs :mod:`._runner`, which imports the submission
and calls its functions on the inputs of the request.  The child writes one
JSON line per event to a file descriptor the parent opened; the parent reads
the lines that carry its random nonce, accepts them only in the order of the
phases, validates every returned value (plain numbers, lists, strings) and
computes all scores itself.  Each phase (importing the submission, then each
question) has its own wall-clock limit; when one is exceeded the whole
process group is killed, the phase is recorded as timed out, and a fresh
child is started for the questions that have not run yet.  A child that
dies (``os._exit``, a segfault, a resource limit) is handled the same way.

Confinement (what the child can see)
------------------------------------
* As root (a Gradescope or CI container): a new mount namespace in which the
  real package, the source checkout, ``/root``, ``/home``, ``/tmp`` and the
  other scratch directories are covered by empty read-only file systems,
  except the Python installation and the child's ``box`` and ``lib``; a new
  network namespace; then the user ``nobody`` (no groups), which owns only
  ``box``.  ``isolation`` is ``"uid"``.
* For everyone, where the kernel offers it: Landlock (read only the Python
  installation, the system directories, ``lib`` and ``box``; write only
  ``box``; no TCP; no signals out of the sandbox) and a seccomp filter (no
  ``fork``, ``exec``, ``ptrace``, mounts, namespaces).  A plain user gets
  ``isolation`` ``"landlock"``.
* Resource limits: address space, CPU time, file size, processes, no core.
* The child then tries to read the reference solutions and the grader's
  files and to write into site-packages and the grader's home; if any of it
  succeeds, or nothing could be applied, the report says ``isolation``
  ``"none"``: the run was not isolated (the audit hook of :mod:`._runner`
  still reports honest mistakes, but it is no barrier).

Where the code is
-----------------
This module prepares the child's directories and rules (what reads the
settings tests change: :data:`FORCE_MODE`, :data:`SKIP`, :data:`GRADER_DIR`)
and runs the children one after another.  The fixed limits are in
:mod:`._settings`, the path rules in :mod:`._rules`, the start of a child and
the wait for its events in :mod:`._child`, the reading and checking of what
it sends back in :mod:`._channel`, and the measuring and removing of its
files in :mod:`._scratch`; their names can be imported from here too.
"""
from __future__ import annotations

import math
import os
import shutil
import signal
import sys
import sysconfig
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

# the private modules' names are imported here too: tests and the instructor's grader use them from here
from . import _scratch
from ._channel import _clean_calls, _confinement, _Events, _matrix, _number, _size, _valid_value
from ._child import _child_env, _kill, _run_once
from ._rules import (_batch_files, _in_venv, _module_dir, _nobody, _prefixes, _read_rules, _real, _safe_rules,
                     _stage_library, _under)
from ._scratch import (_DIR_FLAGS, _fix_perms, _held_deleted, _list_fd, _open_dir, _Scratch, _TreeChanged,
                       _tree_use, _walk_tree)
from ._settings import (BATCH_PROBES, CHECKOUT, FILE_SIZE_LIMIT, HIDDEN_DIRS, JAIL, MAX_ELEMENTS, MAX_STATES,
                        MEMORY_LIMIT, PACKAGE_ROOT, PROCESS_LIMIT, RUNNER, SCRATCH_BYTES, SCRATCH_CHECK_INTERVAL,
                        SCRATCH_FILES, STARTUP_LIMIT, SYSTEM_DIRS, UNSTAGED)

__all__ = ["Job", "PhaseOutcome", "SandboxResult", "SandboxError", "run_submission", "PROTECTED_MODULES",
           "isolation_mode"]


def _grader_dir():
    """Where the instructor's grader (``mutext_grader``: the reference solutions and answers) is, found
    without importing it, or None (a student's installation has no grader)."""
    import importlib.util
    try:
        spec = importlib.util.find_spec("mutext_grader")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(list(spec.submodule_search_locations)[0]).resolve()


#: the instructor's grader package (reference solutions, answer computation), or None
GRADER_DIR = _grader_dir()
#: directories whose files hold answers (the grader, its solutions, the example models)
PROTECTED_DIRS = [PACKAGE_ROOT / "examples", PACKAGE_ROOT / "demos"] + ([GRADER_DIR] if GRADER_DIR else [])
if CHECKOUT is not None:
    PROTECTED_DIRS += [CHECKOUT / ".git", CHECKOUT / "tests"]
#: modules a submission may not import (they contain or compute the answers)
PROTECTED_MODULES = ["mutext_grader", "mutext.grading", "mutext.examples", "mutext.demos"]
#: "root", "user" or None (decide from the effective user); tests set it to exercise the plain-user path
FORCE_MODE = None
#: confinement steps left out ("namespaces", "landlock", "seccomp"); only tests set it, to check that a
#: run which is not isolated says so
SKIP = ()


class SandboxError(RuntimeError):
    """The child could not be confined as required (e.g. Python not readable by the unprivileged user)."""


def isolation_mode() -> str:
    """``"root"`` (the child becomes another user) or ``"user"`` (Landlock and seccomp only)."""
    if FORCE_MODE is not None:
        return FORCE_MODE
    return "root" if hasattr(os, "geteuid") and os.geteuid() == 0 else "user"


@dataclass
class Job:
    """One question as the child sees it: a function name and the calls to make.

    ``calls`` is a list of ``{"args": [...], "kwargs": {...}}`` with JSON
    values; a state-space argument is ``{"__ss__": [A, B, C, D]}``.
    ``kind`` is ``"ss"`` (return a state-space model), ``"float"`` or
    ``"array"`` (an array of real numbers, e.g. a matrix or a tuple ``(K, M)``).

    Attributes
    ----------
    id : str
        Question id.
    function : str
        Name of the function to call.
    kind : str
        ``"ss"``, ``"float"`` or ``"array"``.
    calls : list of dict
        The calls, ``{"args": [...], "kwargs": {...}}``.
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

    Attributes
    ----------
    status : str
        ``"ok"``, ``"error"``, ``"timeout"``, ``"crashed"`` or ``"not_run"``.
    calls : list
        Result of each call made.
    error : str
        The error message (import failed, a crash).
    violations : list of str
        Forbidden operations the child attempted.
    seconds : float
        Wall time of the phase.
    last_call : int or None
        Index of the call running when the phase was cut short.
    """
    status: str
    calls: list = field(default_factory=list)
    error: str = ""
    violations: list = field(default_factory=list)
    seconds: float = 0.0
    last_call: int | None = None    # index of the call running when the phase was cut short


@dataclass
class SandboxResult:
    """What happened to a submission run by :func:`run_submission`.

    Attributes
    ----------
    import_ : PhaseOutcome
        The import of the submission.
    questions : dict
        Question id -> :class:`PhaseOutcome`.
    children : int
        Number of child processes started (one more per restart).
    stderr_tail : str
        The end of the children's standard error.
    isolation : str
        How the child was confined: ``"uid"``, ``"landlock"`` or ``"none"``.
    isolation_details : list of str
        What the confinement did and did not achieve.
    """
    import_: PhaseOutcome
    questions: dict
    children: int = 0
    stderr_tail: str = ""
    isolation: str = "none"          # "uid", "landlock" or "none" (see the module docstring)
    isolation_details: list = field(default_factory=list)


# ----------------------------------------------------------------------------------------------------------
# what the child may see
# ----------------------------------------------------------------------------------------------------------


def _secret_roots() -> list:
    """Directories the child must not read at all: the real package and the source checkout."""
    roots = [_real(PACKAGE_ROOT)] + ([_real(GRADER_DIR)] if GRADER_DIR else [])
    if CHECKOUT is not None:
        roots.append(_real(CHECKOUT))
    return roots


def _allowed_path(p: str) -> bool:
    """A ``sys.path`` entry the child may read: not in the package, not the checkout or above it (a venv
    inside the checkout is fine; a directory that holds the package beside libraries is read without it)."""
    r = _real(p)
    if r == "/" or _under(r, _real(PACKAGE_ROOT)) or (GRADER_DIR and _under(r, _real(GRADER_DIR))):
        return False
    if CHECKOUT is not None:
        checkout = _real(CHECKOUT)
        if _under(checkout, r):
            return False      # the checkout on sys.path (PYTHONPATH), or a directory above it
        if _under(r, checkout):
            return any(_under(r, pre) for pre in _prefixes()) or _in_venv(r)   # not e.g. its tests/
    return True


def _python_dirs() -> list:
    """The Python installation and the directories its imports come from (no package, no checkout)."""
    cands = _prefixes() + [os.path.dirname(os.path.realpath(sys.executable)), os.path.dirname(os.__file__),
                           sysconfig.get_paths().get("purelib", ""), sysconfig.get_paths().get("platlib", "")]
    cands += [p for p in sys.path if p and os.path.isabs(p)]
    out = [_real(c) for c in cands if c and os.path.isdir(c) and (c in _prefixes() or _allowed_path(c))]
    # drop directories inside others
    out = sorted(set(out), key=len)
    return [d for i, d in enumerate(out) if not any(_under(d, e) for e in out[:i])]


def _extra_paths() -> list:
    """Entries of the grader's ``sys.path`` the child should have too (dependencies on PYTHONPATH)."""
    return [p for p in sys.path if p and os.path.isabs(p) and os.path.isdir(p) and _allowed_path(p)]


def _probe_files(extra_modules, submission=None) -> list:
    """Files the child must not be able to read: the solutions, the grader, answer-holding modules, the
    submission's original file and its batch-mates."""
    out = []
    grading = Path(__file__).resolve().parent
    if GRADER_DIR is not None:
        out += sorted(str(p) for p in (GRADER_DIR / "solutions").glob("*.py"))
        out += [str(GRADER_DIR / "core.py")]
    out += [str(grading / "_runner.py"), str(PACKAGE_ROOT / "__init__.py")]
    out += sorted(str(p) for p in (PACKAGE_ROOT / "examples").glob("*.py"))[:3]
    out += sorted(str(p) for p in (PACKAGE_ROOT / "data").glob("*"))[:3]
    for m in extra_modules:
        d = _module_dir(m)
        out.append(str(d / "__init__.py" if d.is_dir() else d))
    if CHECKOUT is not None:
        out += [str(CHECKOUT / ".git" / "HEAD"), str(CHECKOUT / "tests" / "conftest.py"),
                str(CHECKOUT / "pyproject.toml")]
    out += _batch_files(submission) if submission is not None else []
    return [p for p in dict.fromkeys(out) if os.path.isfile(p)]


def _probe_dirs(workdir) -> list:
    """Directories the child must not be able to write: site-packages, the grader's home and files."""
    out = [sysconfig.get_paths().get("purelib", ""), sysconfig.get_paths().get("platlib", ""),
           sys.prefix, str(PACKAGE_ROOT), str(Path(__file__).resolve().parent), str(workdir),
           *([str(GRADER_DIR)] if GRADER_DIR else []),
           os.path.expanduser("~"), tempfile.gettempdir()]
    if CHECKOUT is not None:
        out.append(str(CHECKOUT))
    return [_real(p) for p in dict.fromkeys(out) if p and os.path.isdir(p)]


def _hide_plan(keep: list, workdir: str, submission=None) -> list:
    """``[[dir, [kept paths inside it]], ...]`` for the root child's mount namespace, outermost first
    (the submission's own directory too: its batch-mates)."""
    secret = _secret_roots()
    own = ([os.path.dirname(os.path.abspath(os.fspath(submission))), os.path.dirname(_real(submission))]
           if submission is not None else [])
    dirs = [*HIDDEN_DIRS, tempfile.gettempdir(), os.path.dirname(workdir), *secret, *own]
    dirs = sorted({_real(d) for d in dirs if os.path.isdir(d) and _real(d) != "/"}, key=len)
    plan = []
    for d in dirs:
        if d not in secret and any(k == d or _under(d, k) for k in keep):
            continue   # the Python installation, or a directory in it, stays visible
        covered_by = [ks for h, ks in plan if _under(d, h)]
        if covered_by and not any(_under(d, k) for ks in covered_by for k in ks):
            continue   # already invisible
        plan.append([d, [k for k in keep if _under(k, d) and k != d]])
    return plan



# ----------------------------------------------------------------------------------------------------------
# running a submission
# ----------------------------------------------------------------------------------------------------------

def _prepare(workdir: Path, submission, extra_modules) -> dict:
    """Lay out the child's directories and describe its confinement (the request minus the jobs)."""
    mode = isolation_mode()
    box, lib = workdir / "box", workdir / "lib"
    box.mkdir()
    _stage_library(lib, extra_modules)
    sub = box / "submission.py"
    shutil.copyfile(submission, sub)
    os.chmod(sub, 0o644)
    uid = gid = None
    if mode == "root":
        uid, gid = _nobody()
        os.chmod(workdir, 0o711)     # the child may pass through to box/ and lib/, nothing else
        os.chown(box, uid, gid)
        os.chmod(box, 0o700)
    python = _python_dirs()
    secret = _secret_roots()
    full, listing = [], []
    for d in list(SYSTEM_DIRS) + python:
        if os.path.exists(d):
            f, ls = _read_rules(_real(d), secret)
            full += f
            listing += ls
    full = _safe_rules(full, secret) + [str(lib), "/dev/urandom", "/dev/random", "/dev/zero"]
    listing = _safe_rules(listing, secret, listing=True)
    keep = python + [str(box), str(lib)]
    staged = lib / PACKAGE_ROOT.name
    blocked = [str(d) for d in PROTECTED_DIRS + [_module_dir(m) for m in extra_modules]]
    blocked += [str(staged / d.relative_to(PACKAGE_ROOT)) for d in
                [PACKAGE_ROOT / "grading", PACKAGE_ROOT / "examples", PACKAGE_ROOT / "demos"]
                + [_module_dir(m) for m in extra_modules]]
    return {
        "mode": mode, "uid": uid, "gid": gid, "skip": list(SKIP),
        "box": str(box), "lib": str(lib), "submission": str(sub), "runner": str(RUNNER),
        "hide": _hide_plan(keep, str(workdir), submission) if mode == "root" else [],
        "scratch": {"bytes": SCRATCH_BYTES, "files": SCRATCH_FILES},
        "max_states": MAX_STATES, "max_elements": MAX_ELEMENTS,
        "read": full, "list": listing, "write": [str(box), "/dev/null"],
        "python_dirs": python, "extra_paths": _extra_paths(),
        "probe_read": _probe_files(extra_modules, submission), "probe_write": _probe_dirs(workdir),
        "probe_batch": _batch_files(submission),
        "rlimits": {"as": MEMORY_LIMIT, "fsize": FILE_SIZE_LIMIT, "core": 0, "nofile": 1024,
                    **({"nproc": PROCESS_LIMIT} if mode == "root" else {})},
        # the audit hook's lists (reports attempts; the confinement is what blocks them)
        "blocked_dirs": blocked, "protected_root": str(staged),
        "blocked_modules": PROTECTED_MODULES + list(extra_modules),
    }



def _remove_tree(top, keep=()) -> bool:
    """:func:`._scratch._remove_tree` with this module's :func:`_fix_perms` (looked up here, so that a test
    may stand in for the child's own user)."""
    return _scratch._remove_tree(top, keep, fix=_fix_perms())


def _checked_limits(time_limit, total_limit, n_jobs) -> float:
    """``total_limit`` (its default for ``n_jobs`` questions filled in) once both limits are known to be
    positive, finite numbers of seconds."""
    if not (isinstance(time_limit, (int, float)) and math.isfinite(time_limit) and time_limit > 0):
        raise ValueError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if total_limit is None:
        total_limit = (n_jobs + 2) * float(time_limit)
    if not (isinstance(total_limit, (int, float)) and math.isfinite(total_limit) and total_limit > 0):
        raise ValueError(f"total_limit must be a positive number of seconds, got {total_limit!r}")
    return total_limit


def _record_cut(cut, imp, outcomes, time_limit, total_limit) -> bool:
    """Record in ``imp``/``outcomes`` the phase a child cut short (``cut`` from :func:`._child._run_once`);
    True when the grading time budget is spent (no further child is started)."""
    phase, status, why = cut
    text = ""
    if status == "budget":
        spent = (f"grading time budget spent ({total_limit:g} s for the whole submission, restarts of the "
                 "grading process included)")
        if imp.status == "not_run":
            imp.status, imp.error = "timeout", spent
        for o in outcomes.values():
            if o.status == "not_run":
                o.status, o.error = "timeout", spent
        return True
    if status == "disk":
        status, text = "crashed", f"the grading process was stopped: {why}"
    if phase == "startup":
        imp.status = status
        imp.error = ("the grading process could not start" if status == "crashed"
                     else f"the grading process did not start within {STARTUP_LIMIT:g} s")
    elif phase == "import":
        imp.status = status
        imp.error = (f"importing the submission took longer than {time_limit:g} s" if status == "timeout"
                     else text if cut[1] == "disk"
                     else f"the submission ended the grading process while it was being imported "
                          f"({_exit_text(why)})")
    elif phase in outcomes:
        o = outcomes[phase]
        o.status = status
        o.error = (f"time limit of {time_limit:g} s exceeded (an endless loop, or a very slow "
                   "computation?)" if status == "timeout"
                   else text if cut[1] == "disk"
                   else f"the grading process ended while this question was running ({_exit_text(why)})")
    return False


def _run_children(workdir, plan, jobs, time_limit, total_limit, outcomes, imp, log, state, scratch) -> int:
    """Start children until every question has run or cannot run (a fresh child after each one cut short);
    fill ``outcomes``/``imp``; return the number of children started."""
    children = 0
    pending = list(jobs)
    while pending:
        if children:
            scratch.clean()          # a restarted child starts with the scratch directory as it was
            if time.monotonic() - state.get("booted_at", math.inf) > total_limit:
                cut = (None, "budget", None)
            else:
                cut = None
        if not children or cut is None:
            children += 1
            cut = _run_once(workdir, plan, pending, time_limit, outcomes, imp, log, state, scratch,
                            total_limit)
        if "fatal" in state:
            raise SandboxError(state["fatal"])
        if cut is not None and _record_cut(cut, imp, outcomes, time_limit, total_limit):
            break
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
    return children


def _name_the_submission(sub, submission, imp, outcomes, log) -> str:
    """Messages name the student's file ``submission``, not the private copy ``sub``; returns the tail of
    the children's standard error so renamed."""
    name = Path(submission).name

    def rename(text):
        return str(text).replace(str(sub), name).replace("submission.py", name)
    imp.error = rename(imp.error)
    for o in outcomes.values():
        o.error = rename(o.error)
        for c in o.calls:
            if isinstance(c, dict) and "error" in c:
                c["error"] = rename(c["error"])
    return rename("\n".join(s for s in log if s.strip())[-2000:])


def _clean_shared(scratch, details) -> None:
    """Remove what the child left in the shared temporary directories, or say in ``details`` what was
    not removed."""
    if scratch.shared:
        scratch.clean()
        scratch.shared = False
        if scratch.left:
            details.append("not removed (other processes of the unprivileged user ran): what it created "
                           "in the shared temporary directories: " + ", ".join(scratch.left[:10]))


def run_submission(submission, jobs, time_limit: float = 60.0, blocked_modules=(),
                   total_limit: float | None = None) -> SandboxResult:
    """Import ``submission`` in a confined child process and run ``jobs``.

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
    total_limit : float, optional
        Seconds of wall-clock time for the whole submission, restarted children
        included (counted from the moment the first child has started Python);
        the questions not graded by then score 0 ("grading time budget
        spent").  Default: ``(number of questions + 2) * time_limit``.

    Returns
    -------
    SandboxResult
        Per-phase outcomes with the raw values the submission returned, and
        how the child was isolated.

    Raises
    ------
    SandboxError
        The child could not be confined as this user must confine it (as root:
        the unprivileged user cannot run this Python).
    """
    total_limit = _checked_limits(time_limit, total_limit, len(jobs))
    workdir = Path(tempfile.mkdtemp(prefix="mutext-grade-"))
    scratch = None
    try:
        plan = _prepare(workdir, submission, tuple(blocked_modules))
        scratch = _Scratch(plan["box"], plan["uid"])
        outcomes = {t.id: PhaseOutcome("not_run") for t in jobs}
        imp = PhaseOutcome("not_run")
        log: list = []
        state: dict = {}
        children = _run_children(workdir, plan, jobs, time_limit, total_limit, outcomes, imp, log, state,
                                 scratch)
        tail = _name_the_submission(Path(plan["submission"]), submission, imp, outcomes, log)
        details = state.get("details", ["the child did not report its confinement"])
        _clean_shared(scratch, details)
        return SandboxResult(import_=imp, questions=outcomes, children=children, stderr_tail=tail,
                             isolation=state.get("isolation", "none"), isolation_details=details)
    finally:
        if scratch is not None and scratch.shared:
            scratch.clean()
        _remove_tree(workdir)


def _exit_text(rc):
    """``exit code 3``, or the signal that ended the process and what it usually means."""
    if isinstance(rc, int) and rc < 0:
        sig = -rc
        why = {signal.SIGXCPU: "CPU time limit", signal.SIGXFSZ: "file size limit",
               signal.SIGKILL: "killed", signal.SIGSEGV: "segmentation fault",
               signal.SIGSYS: "forbidden system call"}.get(sig)
        name = signal.Signals(sig).name if sig in signal.Signals._value2member_map_ else f"signal {sig}"
        return f"{name}" + (f", {why}" if why else "")
    return f"exit code {rc}"

