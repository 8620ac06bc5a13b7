"""Static checks of the package's source: no name is used that is not defined (pyflakes).

A name left behind when code moves between modules is found only when that line runs; this finds it
before (a method of a result class that no default test calls was such a case).
"""
from __future__ import annotations

from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "mutext"


def _messages(paths):
    from pyflakes import api, reporter

    class Collect(reporter.Reporter):
        def __init__(self):
            self.found = []

        def flake(self, message):
            self.found.append(message)

        def syntaxError(self, filename, msg, lineno, offset, text):
            self.found.append(f"{filename}:{lineno}: syntax error: {msg}")

        def unexpectedError(self, filename, msg):
            self.found.append(f"{filename}: {msg}")

    r = Collect()
    for p in paths:
        api.checkPath(str(p), r)
    return r.found


def test_no_undefined_names_in_the_package():
    pytest.importorskip("pyflakes")
    from pyflakes import messages as m
    bad = [str(x) for x in _messages(sorted(PACKAGE.rglob("*.py")))
           if isinstance(x, str) or isinstance(x, (m.UndefinedName, m.UndefinedLocal, m.UndefinedExport))]
    assert not bad, "names used but not defined:\n" + "\n".join(bad)


def test_the_check_finds_an_undefined_name(tmp_path):
    pytest.importorskip("pyflakes")
    from pyflakes import messages as m
    f = tmp_path / "moved.py"
    f.write_text("import numpy as np\n\n\ndef error(T):\n    return as_ss(T)\n")
    found = [x for x in _messages([f]) if isinstance(x, m.UndefinedName)]
    assert len(found) == 1 and "as_ss" in str(found[0])
