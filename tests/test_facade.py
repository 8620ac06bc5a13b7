"""The top-level entry points: ``from mutext import hinfsyn`` is the same object as its module's, loaded
on first use, and ``import mutext`` alone imports none of the heavy solvers."""
import subprocess
import sys

import pytest

import mutext


@pytest.mark.parametrize("name", sorted(mutext._ENTRY_POINTS))
def test_entry_point_is_the_modules_object(name):
    import importlib
    module = importlib.import_module(mutext._ENTRY_POINTS[name], "mutext")
    assert getattr(mutext, name) is getattr(module, name)
    assert name in mutext.__all__ and name in dir(mutext)


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        mutext.nope  # noqa: B018


def test_import_mutext_loads_no_solver():
    code = ("import sys, mutext; heavy = [m for m in ('cvxpy', 'casadi', 'slycot', 'control', 'scipy') "
            "if m in sys.modules]; print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""


def test_no_entry_point_shadows_a_subpackage():
    # a name that is also a module of the package would be the module or the function depending on what
    # was imported first
    import pkgutil
    modules = {m.name for m in pkgutil.iter_modules(mutext.__path__)}
    assert not set(mutext._ENTRY_POINTS) & modules
