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
"""
from __future__ import annotations

import json
import math
import os
import secrets
import shutil
import signal
import subprocess
import sys
import sysconfig
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Job", "PhaseOutcome", "SandboxResult", "SandboxError", "run_submission", "PROTECTED_MODULES",
           "isolation_mode"]

RUNNER = Path(__file__).with_name("_runner.py")
JAIL = Path(__file__).with_name("_jail.py")
PACKAGE_ROOT = Path(__file__).resolve().parents[1]          # .../mutext
#: a source checkout (its git history and tests hold answers too), or None for an installed package
CHECKOUT = PACKAGE_ROOT.parent if (PACKAGE_ROOT.parent / "pyproject.toml").is_file() else None


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
#: parts of the package never copied into the child's ``lib`` (``data`` holds the rig's parameters)
UNSTAGED = ("grading", "examples", "demos", "data")
#: time allowed for the child to start Python and import numpy/scipy/control
STARTUP_LIMIT = 120.0
#: bytes a child may write to any file (guards the disk against print loops)
FILE_SIZE_LIMIT = 64 * 2 ** 20
#: address space of a child (guards the machine against runaway allocations)
MEMORY_LIMIT = 3 * 2 ** 30
#: processes and threads of the unprivileged user (a fork bomb stops here even without seccomp)
PROCESS_LIMIT = 64
#: bytes and files (inodes) of the child's scratch directory in all (a tmpfs of this size in the root
#: child's mount namespace; elsewhere the parent measures the directory and stops a child beyond it)
SCRATCH_BYTES = 256 * 2 ** 20
SCRATCH_FILES = 10_000
#: seconds between two measurements of the scratch directory by the parent (where no tmpfs limits it)
SCRATCH_CHECK_INTERVAL = 1.0
#: states (and inputs, outputs) of a returned model, and numbers in a returned array or model: the
#: parent rejects larger values before any computation (the child enforces the same limits)
MAX_STATES = 200
MAX_ELEMENTS = 100_000
#: other ``*.py`` files of the submission's own directory the child's probe tries to read
BATCH_PROBES = 20
#: directories a root child never sees (covered by empty file systems), besides the package and checkout
HIDDEN_DIRS = ("/root", "/home", "/autograder", "/srv", "/mnt", "/media", "/opt", "/var/tmp", "/dev/shm", "/run")
#: system directories a Landlock-confined child may read
SYSTEM_DIRS = ("/usr", "/lib", "/lib32", "/lib64", "/libx32", "/bin", "/sbin", "/etc", "/proc", "/sys")
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

def _real(p) -> str:
    return os.path.realpath(os.fspath(p))


def _under(p: str, d: str) -> bool:
    """``p`` is ``d`` or inside it (both real, absolute paths)."""
    return p == d or p.startswith(d.rstrip("/") + "/")


def _secret_roots() -> list:
    """Directories the child must not read at all: the real package and the source checkout."""
    roots = [_real(PACKAGE_ROOT)] + ([_real(GRADER_DIR)] if GRADER_DIR else [])
    if CHECKOUT is not None:
        roots.append(_real(CHECKOUT))
    return roots


def _prefixes() -> list:
    return sorted({_real(p) for p in (sys.prefix, sys.exec_prefix, sys.base_prefix, sys.base_exec_prefix)
                   if p and os.path.isdir(p) and _real(p) != "/"})


def _in_venv(r: str) -> bool:
    """``r`` is inside a virtual environment (a directory with ``pyvenv.cfg``)."""
    d = r
    while d not in ("/", ""):
        if os.path.isfile(os.path.join(d, "pyvenv.cfg")):
            return True
        d = os.path.dirname(d)
    return False


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


def _read_rules(tree: str, excluded: list) -> tuple:
    """Landlock read rules for ``tree`` minus ``excluded``: ``(full, list_only)`` lists of real paths.

    A directory on the way to an excluded path may be listed but only its
    other entries may be read (a ``pip install`` into site-packages puts the
    package beside the libraries the child needs).  Everything is decided on
    real paths: a Landlock rule holds for the file or directory a path leads
    to, so a symbolic link (a virtual environment's ``lib64 -> lib``) is
    never given a rule of its own: inside ``tree`` its target has its own
    rules, a target outside gets none from here (the Python installation
    and the system directories have rules of their own)."""
    tree = _real(tree)
    excluded = [_real(e) for e in excluded]
    inner = [e for e in excluded if _under(e, tree)]
    if tree in inner:
        return [], []
    if not inner:
        return [tree], []
    if not os.path.isdir(tree):
        return [], []
    full, listing = [], [tree]
    try:
        names = sorted(os.listdir(tree))
    except OSError:
        return [], []
    for name in names:
        p = os.path.join(tree, name)
        if _real(p) != p:
            continue
        f, ls = _read_rules(p, excluded)
        full += f
        listing += ls
    return full, listing


def _safe_rules(paths: list, secret: list, listing: bool = False) -> list:
    """``paths`` without those whose real path leads into a secret root (the checkout's own Python
    installation, a virtual environment in it, excepted) or, for a read rule, holds one (a listing rule
    reads names only)."""
    checkout = _real(CHECKOUT) if CHECKOUT is not None else None
    secret = [_real(s) for s in secret]
    out = []
    for p in paths:
        r = _real(p)
        inside = [s for s in secret if _under(r, s)]
        if any(s != checkout for s in inside):
            continue
        if inside and not (any(_under(r, pre) for pre in _prefixes()) or _in_venv(r)):
            continue
        if not listing and (r == "/" or any(_under(s, r) for s in secret)):
            continue
        out.append(p)
    return out


def _batch_files(submission) -> list:
    """The submission's original file and, in its directory, the other ``*.py`` files (a class's
    submissions side by side): the child works on a copy and must not read any of them."""
    out = []
    for p in dict.fromkeys([os.path.abspath(os.fspath(submission)), _real(submission)]):
        out.append(p)
        try:
            names = sorted(n for n in os.listdir(os.path.dirname(p)) if n.endswith(".py"))
        except OSError:
            continue
        out += [os.path.join(os.path.dirname(p), n) for n in names[:BATCH_PROBES + 1]]
    return [p for p in dict.fromkeys(out) if os.path.isfile(p)]


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


def _stage_library(lib: Path, extra_modules) -> None:
    """Copy the modules a student may import into ``lib/mutext`` (read-only for the child)."""
    skip = {PACKAGE_ROOT / u for u in UNSTAGED} | {_module_dir(m) for m in extra_modules}

    def ignore(directory, names):
        d = Path(directory)
        return [n for n in names if n == "__pycache__" or d / n in skip or (d / n).with_suffix("") in skip
                or not (n.endswith(".py") or (d / n).is_dir())]
    shutil.copytree(PACKAGE_ROOT, lib / PACKAGE_ROOT.name, ignore=ignore)
    for dirpath, dirnames, filenames in os.walk(lib):
        os.chmod(dirpath, 0o755)
        for f in filenames:
            os.chmod(os.path.join(dirpath, f), 0o644)


def _nobody():
    try:
        import pwd
        pw = pwd.getpwnam("nobody")
        uid, gid = pw.pw_uid, pw.pw_gid
    except (ImportError, KeyError):
        uid, gid = 65534, 65534
    try:
        import grp
        gid = grp.getgrnam("nogroup").gr_gid
    except (ImportError, KeyError):
        pass
    return uid, gid


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
# the child's files: measured and removed whatever their depth, names or permissions
# ----------------------------------------------------------------------------------------------------------

_DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


class _TreeChanged(OSError):
    """A directory was moved while the tree was walked."""


def _fix_perms() -> bool:
    # as root nothing needs it (and a chmod must never follow a link the child swapped in); as the
    # child's own user, restoring the owner's rights is how the grader gets back into a chmod 000 directory
    return not (hasattr(os, "geteuid") and os.geteuid() == 0)


def _open_dir(name, dir_fd, fix):
    try:
        return os.open(name, _DIR_FLAGS, dir_fd=dir_fd)
    except PermissionError:
        if not fix or not hasattr(os, "O_PATH"):
            raise
        # through a descriptor of what is there now: a link swapped in is not followed
        pfd = os.open(name, os.O_PATH | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=dir_fd)
        try:
            os.chmod(f"/proc/self/fd/{pfd}", 0o700)
        finally:
            os.close(pfd)
        return os.open(name, _DIR_FLAGS, dir_fd=dir_fd)


def _list_fd(fd, fix):
    if fix and (os.fstat(fd).st_mode & 0o700) != 0o700:
        os.fchmod(fd, 0o700)
    return os.listdir(fd)


def _walk_tree(top, fix=None):
    """Every entry below the directory ``top``, children before their directory, as
    ``(dir_fd, name, stat, depth)`` (``dir_fd`` is the open directory that holds ``name``, valid until the
    next step; ``depth`` 0 for entries of ``top`` itself).

    Iterative and descriptor-based: one directory is open at a time (going up through ``..``, checked to be
    the directory it came from), names are relative to it, so neither the depth of the tree (recursion,
    path length) nor links (never followed) stop or mislead it; a directory without rights for its owner
    gets them back first (see :func:`_fix_perms`).  Entries on another file system are reported, not entered.
    """
    import stat as st_
    fix = _fix_perms() if fix is None else fix
    fd = os.open(top, _DIR_FLAGS)
    try:
        here = os.fstat(fd)
        dev = here.st_dev
        ident = (here.st_dev, here.st_ino)
        names = _list_fd(fd, fix)
        stack = []          # (name, sibling names still to visit, identity) of the directories above
        while True:
            if names:
                name = names.pop()
                try:
                    est = os.stat(name, dir_fd=fd, follow_symlinks=False)
                except FileNotFoundError:
                    continue
                if st_.S_ISDIR(est.st_mode) and est.st_dev == dev:
                    try:
                        child = _open_dir(name, fd, fix)
                    except FileNotFoundError:
                        continue
                    cst = os.fstat(child)
                    if (cst.st_dev, cst.st_ino) != (est.st_dev, est.st_ino):
                        os.close(child)
                        raise _TreeChanged(f"{name} changed while the tree was walked")
                    try:
                        sub = _list_fd(child, fix)
                    except OSError:
                        os.close(child)
                        raise
                    stack.append((name, names, ident))
                    os.close(fd)
                    fd, ident, names = child, (cst.st_dev, cst.st_ino), sub
                    continue
                yield fd, name, est, len(stack)
                continue
            if not stack:
                return
            name, names, up = stack.pop()
            parent = os.open("..", _DIR_FLAGS, dir_fd=fd)
            pst = os.fstat(parent)
            if (pst.st_dev, pst.st_ino) != up:
                os.close(parent)
                raise _TreeChanged("a directory was moved while the tree was walked")
            done = os.fstat(fd)
            os.close(fd)
            fd, ident = parent, up
            yield fd, name, done, len(stack)
    finally:
        os.close(fd)


def _remove_tree(top, keep=()) -> bool:
    """Remove ``top`` and everything in it (or, with ``keep``, everything in it but the names ``keep`` of
    its own entries); True if that was done.  Unlike :func:`shutil.rmtree`, no depth, path length or
    permissions left by the child stop it (:func:`_walk_tree`)."""
    import stat as st_
    top = os.fspath(top)
    if not os.path.lexists(top):
        return True
    try:
        if os.path.islink(top) or not os.path.isdir(top):
            os.unlink(top)
            return True
        for _ in range(3):      # a tree that changed under the walk (it cannot once the child is gone)
            try:
                for dir_fd, name, est, depth in _walk_tree(top):
                    if depth == 0 and name in keep:
                        continue
                    try:
                        if st_.S_ISDIR(est.st_mode):
                            os.rmdir(name, dir_fd=dir_fd)
                        else:
                            os.unlink(name, dir_fd=dir_fd)
                    except FileNotFoundError:
                        pass
                break
            except _TreeChanged:
                continue
        if not keep:
            os.rmdir(top)
        return True
    except OSError:
        return False


def _tree_use(top, max_bytes, max_files, seen=None) -> tuple:
    """``(bytes, files)`` below ``top`` (disk blocks, entries), counting stops as soon as either exceeds its
    maximum (a child's flood of files costs the grader no more than that)."""
    import stat as st_
    seen = set() if seen is None else seen
    used = files = 0
    for _fd, _name, est, _depth in _walk_tree(top):
        files += 1
        if st_.S_ISREG(est.st_mode):
            if est.st_nlink > 1:
                if (est.st_dev, est.st_ino) in seen:
                    continue
                seen.add((est.st_dev, est.st_ino))
            used += max(getattr(est, "st_blocks", 0) * 512, 0) or est.st_size
        if used > max_bytes or files > max_files:
            break
    return used, files


def _held_deleted(pid) -> int:
    """Bytes of deleted files the process ``pid`` still holds open or mapped (they take disk space that
    no listing of the directory shows)."""
    import stat as st_
    total, seen = 0, set()
    try:
        for n in os.listdir(f"/proc/{pid}/fd"):
            try:
                est = os.stat(f"/proc/{pid}/fd/{n}")
            except OSError:
                continue
            if st_.S_ISREG(est.st_mode) and est.st_nlink == 0 and (est.st_dev, est.st_ino) not in seen:
                seen.add((est.st_dev, est.st_ino))
                total += est.st_blocks * 512
        with open(f"/proc/{pid}/maps") as fh:
            for line in fh:
                if line.endswith(" (deleted)\n") and "/memfd:" not in line and "/SYSV" not in line:
                    lo, hi = line.split(None, 1)[0].split("-")
                    total += int(hi, 16) - int(lo, 16)
    except OSError:
        pass
    return total


class _Scratch:
    """The parent's watch over the disk a child uses: its scratch directory, deleted files it holds, and
    (as root, when neither a mount namespace nor Landlock kept it out of them) what the unprivileged user
    created in the shared temporary directories during the run."""

    SHARED = ("/tmp", "/var/tmp", "/dev/shm")

    def __init__(self, box, uid):
        self.box, self.uid = str(box), uid
        self.shared = uid is not None and os.name == "posix"
        self.before = {d: self._names(d) for d in self.SHARED} if self.shared else {}
        self.failures = 0
        self.others = self._others(None) if self.shared else False   # processes of the user besides ours
        self.left = []

    def _others(self, pid):
        """Does any process of the child's user run besides ``pid``?  (Then what that user created in the
        shared directories may not be the child's, and is not removed.)"""
        try:
            names = os.listdir("/proc")
        except OSError:
            return True
        for n in names:
            if n.isdigit() and int(n) != pid:
                try:
                    if os.stat(f"/proc/{n}").st_uid == self.uid:
                        return True
                except OSError:
                    pass
        return False

    @staticmethod
    def _names(d):
        try:
            return set(os.listdir(d))
        except OSError:
            return set()

    def strays(self):
        """Entries of the shared temporary directories that the child's user created during the run."""
        out = []
        for d, before in self.before.items():
            for n in self._names(d) - before:
                p = os.path.join(d, n)
                try:
                    if os.lstat(p).st_uid == self.uid:
                        out.append(p)
                except OSError:
                    pass
        return out

    def over(self, pid):
        """Why the child uses too much disk, or None."""
        try:
            seen = set()
            used, files = _tree_use(self.box, SCRATCH_BYTES, SCRATCH_FILES, seen)
            if self.shared and not self.others:
                self.others = self._others(pid)
            for p in (self.strays() if self.shared else []):
                if os.path.isdir(p) and not os.path.islink(p):
                    b, f = _tree_use(p, SCRATCH_BYTES - used, SCRATCH_FILES - files, seen)
                else:
                    est = os.lstat(p)
                    b, f = est.st_blocks * 512, 0
                used, files = used + b, files + f + 1
            used += _held_deleted(pid)
            self.failures = 0
        except OSError:
            self.failures += 1       # a tree changing all the time cannot hide from the measurement
            return (None if self.failures < 3 else
                    "its files could not be measured (they kept changing)")
        if used > SCRATCH_BYTES:
            return f"it wrote more than {SCRATCH_BYTES // 2 ** 20} MiB of files"
        if files > SCRATCH_FILES:
            return f"it created more than {SCRATCH_FILES} files and directories"
        return None

    def clean(self, keep=("submission.py",)):
        """Empty the scratch directory (but ``keep``) and remove what the child left in shared places
        (only when no other process of its user ran meanwhile; otherwise :attr:`left` lists it)."""
        ok = _remove_tree(self.box, keep=keep)
        strays = self.strays() if self.shared else []
        if strays and (self.others or self._others(None)):
            self.others = True
            self.left = sorted(set(self.left + strays))
            return False
        for p in strays:
            ok = _remove_tree(p) and ok
        return ok


# ----------------------------------------------------------------------------------------------------------
# running a child
# ----------------------------------------------------------------------------------------------------------

def _child_env(box):
    # nothing of the grader's environment: it may hold tokens, and PYTHON* would redirect imports
    return {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": box, "TMPDIR": box, "MPLCONFIGDIR": box,
            "LANG": "C.UTF-8", "LC_ALL": "C.UTF-8", "MPLBACKEND": "Agg",
            # one BLAS thread: graders often run several submissions on a few cores
            "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
            # Windows needs these to start Python at all
            **{k: v for k, v in os.environ.items() if os.name == "nt" and k.upper() in ("SYSTEMROOT", "WINDIR")}}


def _kill(proc):
    try:
        if os.name == "posix":
            os.killpg(proc.pid, signal.SIGKILL)
        else:   # pragma: no cover
            proc.kill()
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.kill()
    except (ProcessLookupError, PermissionError, OSError):
        pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:   # pragma: no cover
        pass


class _Events:
    """Reads complete lines appended to the results file, keeping those with our nonce.

    Lines are decoded defensively: only JSON objects (plain data) are kept,
    malformed or absurdly nested lines are dropped, and so is a line longer
    than :attr:`MAX_LINE` bytes, unread (the parent reads at most that much
    of it at a time, not the whole line)."""

    MAX_LINE = 16 * 2 ** 20

    def __init__(self, path, nonce):
        self.path, self.nonce, self.pos = path, nonce, 0
        self.skipping = False     # inside a line that is too long: drop everything up to its end

    def read(self):
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.pos)
                data = fh.read(self.MAX_LINE + 1)
        except FileNotFoundError:
            return []
        out = []
        while data:
            end = data.find(b"\n") if self.skipping else data.rfind(b"\n")
            if self.skipping:
                if end < 0:
                    self.pos += len(data)
                    return out
                self.pos += end + 1
                data = data[end + 1:]
                self.skipping = False
                continue
            if end < 0:
                if len(data) > self.MAX_LINE:
                    self.pos += len(data)
                    self.skipping = True
                return out
            self.pos += end + 1
            for line in data[:end].splitlines():
                if len(line) > self.MAX_LINE:
                    continue
                try:
                    ev = json.loads(line)
                except Exception:   # noqa: BLE001 - ValueError, RecursionError: not ours
                    continue
                if isinstance(ev, dict) and ev.get("nonce") == self.nonce:
                    out.append(ev)
            return out
        return out


def _module_dir(name):
    """File or directory of a ``mutext`` module or package (``"mutext.rotor"`` -> ``.../mutext/rotor``)."""
    parts = name.split(".")
    if parts[0] != PACKAGE_ROOT.name:
        raise ValueError(f"only modules of {PACKAGE_ROOT.name} can be protected, got {name!r}")
    path = PACKAGE_ROOT.joinpath(*parts[1:])
    return path if path.is_dir() else path.with_suffix(".py")


def _number(x):
    return (isinstance(x, float) or (isinstance(x, int) and not isinstance(x, bool) and abs(x) <= 2 ** 63))


def _size(n, cap=MAX_STATES):
    return isinstance(n, int) and not isinstance(n, bool) and 0 <= n <= cap


def _matrix(m, rows, cols):
    """``m`` is a list of ``rows`` lists of ``cols`` numbers (``cols`` None: any one length)."""
    if not (isinstance(m, list) and len(m) == rows and all(isinstance(r, list) for r in m)):
        return False
    if rows and cols is None:
        cols = len(m[0])
    return all(len(r) == cols for r in m) and all(_number(v) for r in m for v in r)


def _valid_value(kind, v):
    """A value sent by the child has the plain shape its kind promises, within the size limits
    (:data:`MAX_STATES`, :data:`MAX_ELEMENTS`): sizes are checked before any number is looked at."""
    if kind == "float":
        return _number(v)
    if kind == "array":
        if not (isinstance(v, dict) and isinstance(v.get("shape"), list) and isinstance(v.get("data"), list)):
            return False
        shape = v["shape"]
        return (len(shape) <= 32 and all(_size(n, MAX_ELEMENTS) for n in shape)
                and math.prod(shape) == len(v["data"]) <= MAX_ELEMENTS and all(_number(x) for x in v["data"]))
    if kind == "ss":
        if not (isinstance(v, dict) and all(isinstance(v.get(k), list) for k in "ABCD")):
            return False
        A, B, C, D = (v[k] for k in "ABCD")
        n, p = len(A), len(D)
        m = len(D[0]) if p and isinstance(D[0], list) else (len(B[0]) if n and isinstance(B[0], list) else 0)
        if not (_size(n) and _size(p) and _size(m) and len(C) == p and (n or not B)
                and n * n + n * m + p * n + p * m <= MAX_ELEMENTS):
            return False
        if not (_matrix(A, n, n) and _matrix(B, n, m) and _matrix(C, p, n) and _matrix(D, p, m)):
            return False
        return ((v.get("dt") is None or _number(v.get("dt")))
                and all(isinstance(v.get(k, []), list) and len(v.get(k, [])) <= MAX_STATES
                        and all(isinstance(x, str) and len(x) <= 200 for x in v.get(k, []))
                        for k in ("inputs", "outputs")))
    return False


def _clean_calls(kind, calls, n):
    """The child's list of call outcomes, checked: ``{"ok": True, "value": ...}`` or ``{"ok": False, "error": str}``."""
    out = []
    for c in (calls if isinstance(calls, list) else [])[:n]:
        if isinstance(c, dict) and c.get("ok") is True and _valid_value(kind, c.get("value")):
            out.append({"ok": True, "value": c["value"]})
        elif isinstance(c, dict) and c.get("ok") is False and isinstance(c.get("error"), str):
            out.append({"ok": False, "error": c["error"][:2000]})
        else:
            out.append({"ok": False, "error": "the grading process sent back a malformed value"})
    return out


def _confinement(ev, mode, batch=()):
    """``(isolation, details)`` from the child's ``confined`` event (``batch``: the submission's original
    file and its batch-mates, which the child's probe tried to read too)."""
    applied = [str(a) for a in ev.get("applied") or []][:20]
    problems = [str(a)[:300] for a in ev.get("problems") or []][:20]
    found = [str(a) for a in ev.get("readable") or []][:200]
    readable = [a for a in found if a not in batch][:10]
    mates = [a for a in found if a in batch][:5]
    writable = [str(a) for a in ev.get("writable") or []][:10]
    details = applied + problems
    tmp = _real(tempfile.gettempdir())
    critical = [w for w in writable if w != tmp]
    if readable:
        details.append("the submission could read " + ", ".join(readable))
    if mates:
        details.append("the submission could read the files of its directory (its own original, other "
                       "submissions): " + ", ".join(mates))
        readable += mates
    if writable:
        details.append("the submission could write into " + ", ".join(writable))
    if readable or critical:
        return "none", details
    if mode == "root" and any(a.startswith("uid ") for a in applied):
        return "uid", details
    if any(a.startswith("landlock") for a in applied):
        return "landlock", details
    return "none", details


def _run_once(workdir, plan, jobs, time_limit, outcomes, imp, log, state, scratch=None, total_limit=None):
    """Start one child for ``jobs``; fill ``outcomes``/``imp``; return the phase that was cut short as
    ``(phase, status, exit code or reason)``.

    ``total_limit``: seconds for the whole submission, counted from the first child's boot (``state``
    keeps that time across children); beyond it the child is stopped with status ``"budget"``.
    ``scratch`` (a :class:`_Scratch`) is measured every :data:`SCRATCH_CHECK_INTERVAL` seconds; a child
    over the disk budget is stopped with status ``"disk"``."""
    nonce = secrets.token_hex(16)
    results = workdir / f"results-{nonce}.jsonl"
    request = workdir / f"request-{nonce}.json"
    errpath = workdir / f"stderr-{nonce}.txt"
    n_phases = len(jobs) + 1
    budget = STARTUP_LIMIT + time_limit * n_phases + 10.0     # a child never lives longer than this
    cpu = int(min(budget, 2.0 ** 40)) + 1
    rfd = os.open(results, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_EXCL, 0o600)
    posix = os.name == "posix"
    try:
        req = dict(plan, nonce=nonce, results_fd=rfd if posix else None, results_path=str(results),
                   parent_pid=os.getpid(),
                   jobs=[{"id": t.id, "function": t.function, "kind": t.kind, "calls": t.calls} for t in jobs])
        req["rlimits"] = dict(plan["rlimits"], cpu=[cpu, cpu + 5])
        fd = os.open(request, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as fh:
            json.dump(req, fh)
        with open(errpath, "wb") as err:
            proc = subprocess.Popen(
                [sys.executable, "-I", "-S", "-B", str(JAIL), str(request)], cwd=plan["box"],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, env=_child_env(plan["box"]),
                pass_fds=(rfd,) if posix else (), start_new_session=posix)
    finally:
        os.close(rfd)
    events = _Events(results, nonce)
    order = ["import"] + [t.id for t in jobs] if imp.status == "not_run" else [t.id for t in jobs]
    kinds = {t.id: (t.kind, len(t.calls)) for t in jobs}
    phase, t0, cut, started = "startup", time.monotonic(), None, time.monotonic()
    next_check = started + SCRATCH_CHECK_INTERVAL
    stage = "startup"        # startup -> confined -> booted: each event is accepted once, in order
    nxt = 0                  # index in ``order`` of the next phase allowed to start
    delay = 0.01
    while True:
        rc = proc.poll()
        for ev in events.read():
            kind, p = ev.get("event"), ev.get("phase")
            now = time.monotonic()
            if kind == "confined" and stage == "startup":
                stage = "confined"
                state["isolation"], state["details"] = _confinement(ev, plan["mode"], plan["probe_batch"])
                applied = [str(a) for a in ev.get("applied") or []]
                if scratch is not None and any(a == "mount-namespace" or a.startswith("landlock") for a in applied):
                    scratch.shared = False      # the child could not write into the shared directories
                if not any(a.startswith("scratch directory") for a in applied):
                    state["details"].append(
                        f"scratch directory: no tmpfs of its own; {FILE_SIZE_LIMIT // 2 ** 20} MiB per file, "
                        f"the grader stops the child beyond {SCRATCH_BYTES // 2 ** 20} MiB or {SCRATCH_FILES} "
                        f"files (measured every {SCRATCH_CHECK_INTERVAL:g} s)")
                if ev.get("fatal"):
                    state["fatal"] = str(ev["fatal"])[:500]
            elif kind == "boot" and stage == "confined":
                stage, phase, t0 = "booted", None, now
                state.setdefault("booted_at", now)
            elif stage != "booted":
                continue
            elif kind == "start" and phase is None and nxt < len(order) and p == order[nxt]:
                phase, t0 = p, now
                nxt += 1
            elif kind == "call" and p == phase and p in outcomes and isinstance(ev.get("index"), int):
                outcomes[p].last_call = ev["index"]
            elif kind == "violation" and p in (["import"] + list(outcomes)):
                o = imp if p == "import" else outcomes[p]
                if len(o.violations) < 20:
                    o.violations.append(str(ev.get("what"))[:300])
            elif kind == "result" and p == phase and p == "import":
                imp.status = "ok" if ev.get("ok") is True else "error"
                imp.error = str(ev.get("error", ""))[:2000]
                imp.seconds = now - t0
                phase, t0 = None, now
            elif kind == "result" and p == phase and p in outcomes:
                o = outcomes[p]
                kind_, n = kinds[p]
                o.status, o.calls, o.seconds = "ok", _clean_calls(kind_, ev.get("calls"), n), now - t0
                phase, t0 = None, now
        if rc is not None:
            if phase is not None:
                cut = (phase, "crashed", rc)
            break
        if "fatal" in state:
            _kill(proc)
            break
        # phase None: the runner between phases; a stuck runner (e.g. a thread the
        # submission started holding the interpreter) must not stall grading either
        limit = STARTUP_LIMIT if phase == "startup" else time_limit
        now = time.monotonic()
        if total_limit is not None and "booted_at" in state and now - state["booted_at"] > total_limit:
            _kill(proc)
            cut = (phase, "budget", None)
            break
        if now - t0 > limit or now - started > budget:
            _kill(proc)
            cut = (phase, "timeout", None)
            break
        if scratch is not None and now >= next_check:
            why = scratch.over(proc.pid)
            next_check = time.monotonic() + SCRATCH_CHECK_INTERVAL
            if why:
                _kill(proc)
                cut = (phase, "disk", why)
                break
        time.sleep(delay)
        delay = min(0.05, delay * 1.5)
    with open(errpath, "rb") as fh:
        fh.seek(max(0, os.path.getsize(errpath) - 4000))
        log.append(fh.read().decode("utf-8", "replace"))
    return cut


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
    if not (isinstance(time_limit, (int, float)) and math.isfinite(time_limit) and time_limit > 0):
        raise ValueError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if total_limit is None:
        total_limit = (len(jobs) + 2) * float(time_limit)
    if not (isinstance(total_limit, (int, float)) and math.isfinite(total_limit) and total_limit > 0):
        raise ValueError(f"total_limit must be a positive number of seconds, got {total_limit!r}")
    workdir = Path(tempfile.mkdtemp(prefix="mutext-grade-"))
    scratch = None
    try:
        plan = _prepare(workdir, submission, tuple(blocked_modules))
        scratch = _Scratch(plan["box"], plan["uid"])
        sub = Path(plan["submission"])
        outcomes = {t.id: PhaseOutcome("not_run") for t in jobs}
        imp = PhaseOutcome("not_run")
        log: list = []
        state: dict = {}
        children = 0
        pending = list(jobs)
        spent = (f"grading time budget spent ({total_limit:g} s for the whole submission, restarts of the "
                 "grading process included)")
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
            if cut is not None:
                phase, status, why = cut
                text = ""
                if status == "budget":
                    if imp.status == "not_run":
                        imp.status, imp.error = "timeout", spent
                    for o in outcomes.values():
                        if o.status == "not_run":
                            o.status, o.error = "timeout", spent
                    break
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
        details = state.get("details", ["the child did not report its confinement"])
        if scratch.shared:
            scratch.clean()
            scratch.shared = False
            if scratch.left:
                details.append("not removed (other processes of the unprivileged user ran): what it created "
                               "in the shared temporary directories: " + ", ".join(scratch.left[:10]))
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
