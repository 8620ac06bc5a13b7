"""The declarative parameter checks (``mutext._validation``) and the bad-input test they drive.

The constraints are tested one by one (descriptions, values that satisfy and
violate them: a bool is never an integer nor a real, NaN never a real, NumPy
scalars are accepted).  Then every public function of the package that declares
its parameters (``__mutext_params__``) is fed each declared parameter's
``invalid_examples()`` (and, with hypothesis installed, drawn values that
violate the constraint) through ``__mutext_validate__``: the declaration must
reject each one with the declared error, whose message names the function and
the parameter.  The declarations must name parameters of the signature that
the docstring documents.
"""
from __future__ import annotations

import importlib
import inspect
import math
import pkgutil

import numpy as np
import pytest

import mutext
from mutext._validation import (AnyOf, Boolean, Callable, InstanceOf, Integer, NoneOr, Options, Real,
                                check_param, validate_params)
from mutext.errors import ModelError, MutextError
from test_docstrings import documented  # noqa: E402  (tests/ is on sys.path under pytest)

# ----------------------------------------------------------------------------
# the constraints
# ----------------------------------------------------------------------------


@pytest.mark.parametrize("constraint, text", [
    (Integer(), "an integer"),
    (Integer(lo=1), "an integer >= 1"),
    (Integer(hi=-1), "an integer <= -1"),
    (Integer(1, 5), "an integer in 1..5"),
    (Real(), "a finite number"),
    (Real(finite=False), "a number"),
    (Real(lo=0), "a finite number >= 0"),
    (Real(lo=0, closed="neither"), "a finite number > 0"),
    (Real(hi=1, closed="neither"), "a finite number < 1"),
    (Real(0, 1, closed="right"), "a finite number in (0, 1]"),
    (Real(0, 0.2, closed="left"), "a finite number in [0, 0.2)"),
    (Real(1e-12, 1), "a finite number in [1e-12, 1]"),
    (Options({"x", "xy"}), "one of 'x', 'xy'"),
    (Boolean(), "a bool (True or False)"),
    (Callable(), "a callable"),
    (NoneOr(Integer(lo=0)), "an integer >= 0 or None"),
    (AnyOf(Integer(lo=1), Integer(hi=-1)), "an integer >= 1 or an integer <= -1"),
    (InstanceOf(dict), "a dict"),
])
def test_describe(constraint, text):
    assert constraint.describe() == text
    assert text in repr(constraint)


def test_integer():
    c = Integer(lo=1, hi=10)
    for v in (1, 10, np.int64(3), np.uint8(7), np.int32(1)):
        assert c.is_satisfied_by(v), v
    for v in (0, 11, True, False, np.bool_(True), 2.0, np.float64(2.0), "2", None, 2 + 0j):
        assert not c.is_satisfied_by(v), v
    assert not Integer().is_satisfied_by(True)           # a bool is never an integer


def test_real():
    c = Real()
    for v in (0, -3, 2.5, np.float32(1.5), np.float64(-1e300), np.int64(4)):
        assert c.is_satisfied_by(v), v
    for v in (float("nan"), np.nan, float("inf"), -np.inf, True, np.bool_(False), "1.0", None, 1j, [1.0]):
        assert not c.is_satisfied_by(v), v
    assert Real(finite=False).is_satisfied_by(math.inf)
    assert not Real(finite=False).is_satisfied_by(math.nan)      # NaN is never a real
    assert not Real(lo=0, finite=False).is_satisfied_by(-math.inf)


@pytest.mark.parametrize("closed, lo_in, hi_in", [("both", True, True), ("left", True, False),
                                                  ("right", False, True), ("neither", False, False)])
def test_real_bounds(closed, lo_in, hi_in):
    c = Real(0, 1, closed=closed)
    assert c.is_satisfied_by(0.5)
    assert c.is_satisfied_by(0) is lo_in and c.is_satisfied_by(1.0) is hi_in
    assert not c.is_satisfied_by(-1e-300) and not c.is_satisfied_by(1 + 1e-15)
    with pytest.raises(ValueError):
        Real(closed="open")


def test_options_boolean_callable_instance():
    c = Options(["x", "xy", 1])
    assert c.is_satisfied_by("x") and c.is_satisfied_by(1) and c.is_satisfied_by(np.int64(1))
    assert not c.is_satisfied_by("y") and not c.is_satisfied_by(True) and not c.is_satisfied_by([1])
    assert Boolean().is_satisfied_by(True) and Boolean().is_satisfied_by(np.bool_(False))
    assert not Boolean().is_satisfied_by(1) and not Boolean().is_satisfied_by("True")
    assert Callable().is_satisfied_by(len) and not Callable().is_satisfied_by(3)
    assert InstanceOf((list, tuple)).describe() == "a list or a tuple"
    assert InstanceOf(dict, "a mapping").is_satisfied_by({}) and not InstanceOf(dict).is_satisfied_by([])


def test_none_or_any_of():
    c = NoneOr(Real(lo=0))
    assert c.is_satisfied_by(None) and c.is_satisfied_by(2.0) and not c.is_satisfied_by(-1.0)
    assert None not in c.invalid_examples()
    c = AnyOf(Integer(lo=1), Integer(hi=-1))
    assert c.is_satisfied_by(-3) and c.is_satisfied_by(3) and not c.is_satisfied_by(0)
    assert 0 in c.invalid_examples()


@pytest.mark.parametrize("constraint", [
    Integer(), Integer(lo=8), Integer(1, 30), Real(), Real(finite=False), Real(lo=0, closed="neither"),
    Real(0, 1, closed="neither"), Options({"a", "b"}), Boolean(), Callable(), NoneOr(Integer(lo=0)),
    AnyOf(Integer(lo=1), Integer(hi=-1)), InstanceOf(dict)])
def test_invalid_examples_violate(constraint):
    bad = constraint.invalid_examples()
    assert bad
    for v in bad:
        assert not constraint.is_satisfied_by(v), (constraint, v)


def test_check_param_message():
    assert check_param("orbit", "points", 9, Integer(lo=8)) == 9
    with pytest.raises(ModelError, match=r"^orbit: points must be an integer >= 8, got 3$"):
        check_param("orbit", "points", 3, Integer(lo=8))

    class Mine(MutextError):
        pass
    with pytest.raises(Mine, match=r"x must be a finite number, got nan"):
        check_param("f", "x", float("nan"), Real(), error=Mine)


def test_decorator():
    calls = []

    @validate_params({"n": Integer(lo=1), "tol": Real(0, 1, closed="neither")})
    def f(a, n=3, *, tol=0.1, **kw):
        """Doc."""
        calls.append((a, n, tol))
        return n

    assert f("x", 2, tol=0.5) == 2 and f.__doc__ == "Doc." and f.__wrapped__.__name__ == "f"
    assert list(inspect.signature(f).parameters) == ["a", "n", "tol", "kw"]
    with pytest.raises(ModelError, match=r"^f: n must be an integer >= 1, got 0$"):
        f(None, 0)
    with pytest.raises(ModelError, match=r"^f: tol must be a finite number in \(0, 1\), got True$"):
        f(None, tol=True)
    assert len(calls) == 1                      # the body did not run for a bad argument
    with pytest.raises(TypeError):              # a call that does not bind is the function's own TypeError
        f()
    assert set(f.__mutext_params__) == {"n", "tol"}
    f.__mutext_validate__(n=5)
    with pytest.raises(ModelError, match="f: n must be"):
        f.__mutext_validate__(n=-1)
    with pytest.raises(TypeError, match="no parameter"):
        validate_params({"m": Integer()})(lambda n: n)


# ----------------------------------------------------------------------------
# the declarations of the package
# ----------------------------------------------------------------------------

def _public_modules():
    modules = [mutext]
    for info in pkgutil.walk_packages(mutext.__path__, prefix="mutext."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        modules.append(importlib.import_module(info.name))
    return modules


def declared_functions() -> list:
    """``(qualified name, function)`` for each public function or method of mutext with declarations."""
    seen, out = set(), []
    for module in _public_modules():
        names = getattr(module, "__all__", None)
        if names is None:
            names = [n for n in vars(module) if not n.startswith("_")]
        for name in names:
            obj = getattr(module, name, None)
            candidates = [obj]
            if inspect.isclass(obj):
                candidates += [getattr(a, "__func__", a) for n, a in vars(obj).items() if not n.startswith("_")]
            for fn in candidates:
                if callable(fn) and getattr(fn, "__mutext_params__", None) and id(fn) not in seen:
                    seen.add(id(fn))
                    out.append((f"{fn.__module__}.{fn.__qualname__}", fn))
    return sorted(out, key=lambda t: t[0])


DECLARED = declared_functions()


def _error(fn) -> type:
    """The error a declaration raises (the decorator's ``error``; ModelError by default)."""
    try:
        fn.__mutext_validate__(**{n: object() for n in fn.__mutext_params__})
    except MutextError as exc:
        return type(exc)
    raise AssertionError(f"{fn.__qualname__}: an object() passed every declared constraint")


def test_there_are_declarations():
    names = {n.rsplit(".", 1)[-1] for n, _ in DECLARED}
    assert len(DECLARED) >= 12, names
    assert {"hinf_norm", "mu_upper", "mu_sweep", "orbit", "hidden_effect_data", "check"} <= names


@pytest.mark.parametrize("qualname, fn", DECLARED, ids=[n for n, _ in DECLARED])
def test_declarations_match_signature_and_docstring(qualname, fn):
    params = inspect.signature(fn).parameters
    doc = documented(inspect.getdoc(fn))
    for name in fn.__mutext_params__:
        assert name in params, f"{qualname}: declares {name!r}, which is not a parameter"
        assert name in doc, f"{qualname}: the declared parameter {name!r} is not documented (numpydoc)"


def _expect_rejected(qualname, fn, name, bad, error):
    constraint = fn.__mutext_params__[name]
    assert not constraint.is_satisfied_by(bad)
    with pytest.raises(error) as exc:
        fn.__mutext_validate__(**{name: bad})
    assert isinstance(exc.value, MutextError)
    msg = str(exc.value)
    assert msg.startswith(f"{fn.__name__}: {name} must be {constraint.describe()}, got "), (qualname, msg)


@pytest.mark.parametrize("qualname, fn", DECLARED, ids=[n for n, _ in DECLARED])
def test_declarations_reject_their_invalid_examples(qualname, fn):
    error = _error(fn)
    for name, constraint in fn.__mutext_params__.items():
        for bad in constraint.invalid_examples():
            _expect_rejected(qualname, fn, name, bad, error)


try:
    import hypothesis
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
except ImportError:                                 # pragma: no cover - hypothesis is a test extra
    hypothesis = None

if hypothesis is not None:
    ANY = st.one_of(st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
                    st.booleans(), st.none(), st.text(max_size=4), st.complex_numbers(max_magnitude=10),
                    st.integers(-100, 100).map(np.int64), st.floats(-1e3, 1e3).map(np.float32),
                    st.lists(st.integers(), max_size=2))

    @pytest.mark.parametrize("qualname, fn", DECLARED, ids=[n for n, _ in DECLARED])
    def test_declarations_reject_drawn_violations(qualname, fn):
        error = _error(fn)
        params = sorted(fn.__mutext_params__)

        @settings(max_examples=40, deadline=None, derandomize=True, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(st.sampled_from(params), st.data())
        def prop(name, data):
            constraint = fn.__mutext_params__[name]
            bad = data.draw(ANY.filter(lambda v: not constraint.is_satisfied_by(v)))
            _expect_rejected(qualname, fn, name, bad, error)

        prop()
