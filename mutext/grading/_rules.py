"""What the child may see: real paths, Landlock rules, the copy of the package it may import, the
unprivileged user (the parts that read no setting a test changes; :mod:`mutext.grading.sandbox` puts
them together)."""
from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from ._settings import BATCH_PROBES, CHECKOUT, PACKAGE_ROOT, UNSTAGED


def _real(p) -> str:
    return os.path.realpath(os.fspath(p))


def _under(p: str, d: str) -> bool:
    """``p`` is ``d`` or inside it (both real, absolute paths)."""
    return p == d or p.startswith(d.rstrip("/") + "/")


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


def _module_dir(name):
    """File or directory of a ``mutext`` module or package (``"mutext.rotor"`` -> ``.../mutext/rotor``)."""
    parts = name.split(".")
    if parts[0] != PACKAGE_ROOT.name:
        raise ValueError(f"only modules of {PACKAGE_ROOT.name} can be protected, got {name!r}")
    path = PACKAGE_ROOT.joinpath(*parts[1:])
    return path if path.is_dir() else path.with_suffix(".py")


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

