"""Static checks of the package's source: no name is used that is not defined (pyflakes), and no module
or function grows past the sizes one reader can hold.

A name left behind when code moves between modules is found only when that line runs; this finds it
before (a method of a result class that no default test calls was such a case).
"""
from __future__ import annotations

import ast
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


#: Largest module (lines) and function (lines of code, its docstring not counted).
MODULE_LINES, FUNCTION_LINES = 800, 120


def code_lines(node) -> int:
    """Lines of a function without its docstring."""
    n = node.end_lineno - node.lineno + 1
    first = node.body[0] if node.body else None
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
        n -= first.end_lineno - first.lineno + 1
    return n


def oversized(paths, root=PACKAGE):
    """``path: what`` for each module over :data:`MODULE_LINES` lines and function over :data:`FUNCTION_LINES`
    lines of code."""
    out = []
    for p in paths:
        text = p.read_text(encoding="utf-8")
        rel = p.relative_to(root.parent).as_posix()
        if len(text.splitlines()) > MODULE_LINES:
            out.append(f"{rel}: {len(text.splitlines())} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and code_lines(node) > FUNCTION_LINES:
                out.append(f"{rel}:{node.lineno}: {node.name} has {code_lines(node)} lines of code")
    return out


def test_no_module_or_function_too_long():
    bad = oversized(sorted(PACKAGE.rglob("*.py")))
    assert not bad, (f"split these (modules up to {MODULE_LINES} lines, functions up to {FUNCTION_LINES} lines of "
                     "code):\n" + "\n".join(bad))


def test_size_check_counts_code_not_docstrings(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(FUNCTION_LINES))
    doc = '    """' + "\n".join(["doc"] * 30) + '"""\n'
    (tmp_path / "mutext").mkdir()
    ok = tmp_path / "mutext" / "ok.py"
    ok.write_text("def f():\n" + doc + body[:body.rindex("\n")] + "\n")
    long = tmp_path / "mutext" / "long.py"
    long.write_text("def g():\n" + body + "\n    return x0\n")
    assert oversized([ok, long], tmp_path / "mutext") == [
        f"mutext/long.py:1: g has {FUNCTION_LINES + 2} lines of code"]


def _escape_warnings(paths):
    """Files whose source compiles with a warning (an invalid escape such as ``\\p`` in a docstring
    that should be raw: a DeprecationWarning now, a SyntaxWarning from Python 3.12, an error later)."""
    import warnings
    out = []
    for p in paths:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                compile(p.read_text(encoding="utf-8"), str(p), "exec")
            except (SyntaxError, DeprecationWarning, SyntaxWarning) as exc:
                out.append(f"{p}: {exc}")
    return out


def test_no_source_compiles_with_a_warning(tmp_path):
    assert not _escape_warnings(sorted(PACKAGE.rglob("*.py")))
    bad = tmp_path / "bad.py"
    bad.write_text('def f():\n    """a :math:`\\partial` term"""\n')
    assert _escape_warnings([bad])
