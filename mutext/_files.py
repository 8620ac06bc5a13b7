"""Output directories named on the command line, checked before any work is done."""
from __future__ import annotations

import os

from .errors import ModelError


def output_directory(path, option: str = "--out") -> str:
    """Create the directory ``path`` (and its parents) for output, or raise :class:`ModelError` saying why not.

    An empty name (which would write into the current directory), a path that exists and is not a
    directory, and a place the operating system refuses (``/proc``, under a file, no permission) are
    named with the option they came from, instead of a traceback from ``os.makedirs`` after the work.
    """
    p = os.fspath(path) if path is not None else ""
    if not str(p).strip():
        raise ModelError(f"{option} needs a directory name (an empty name would write into the current "
                         "directory)")
    if os.path.exists(p) and not os.path.isdir(p):
        raise ModelError(f"{option} {p}: exists and is not a directory")
    try:
        os.makedirs(p, exist_ok=True)
    except OSError as exc:
        raise ModelError(f"{option} {p}: cannot create the directory ({exc.strerror or exc})") from None
    if not os.access(p, os.W_OK | os.X_OK):
        raise ModelError(f"{option} {p}: the directory is not writable")
    return p
