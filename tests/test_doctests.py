"""The Examples sections of the package's docstrings, run as tests (``doctest``).

Every module of ``mutext`` whose source holds a ``>>>`` prompt is collected,
so a new Examples section is checked without being registered here.  The
examples are meant to be short: the whole run takes a few seconds.
"""
from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")      # an example that draws must not need a display

PACKAGE = Path(__file__).resolve().parents[1] / "mutext"


def _modules_with_examples() -> list[str]:
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if ">>> " in path.read_text(encoding="utf-8"):
            parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            names.append(".".join(parts))
    return names


@pytest.mark.parametrize("name", _modules_with_examples())
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
                             verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples of {name} failed (see above)"


def test_the_first_functions_a_student_calls_have_examples():
    from mutext.diagnose import diagnose
    from mutext.dk import dk_iteration
    from mutext.hinf import hinfsyn
    from mutext.mu import mu_bounds
    from mutext.mbi import identify
    from mutext.rig import read_frf
    from mutext.rotor.analysis import frf
    from mutext.rotor.model import load_model
    for fn in (hinfsyn, mu_bounds, dk_iteration, identify, load_model, frf, read_frf, diagnose):
        assert ">>> " in (fn.__doc__ or ""), f"{fn.__module__}.{fn.__qualname__} has no Examples"
