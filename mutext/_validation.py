"""Declarative checks of parameters: constraints, a decorator and a plain check.

A constraint says what a parameter may be (:class:`Integer`, :class:`Real`,
:class:`Options`, :class:`Boolean`, :class:`Callable`, :class:`NoneOr`,
:class:`AnyOf`).  Each answers :meth:`~Constraint.is_satisfied_by`, describes
itself (``"an integer >= 1"``, ``"a finite number in (0, 1]"``) and lists a
few values that violate it (:meth:`~Constraint.invalid_examples`, which the
property-based bad-input tests feed to every declared parameter).

:func:`validate_params` declares the constraints of a function's parameters;
the call's arguments are checked before the body runs and a violation raises
``ModelError("<function>: <name> must be <description>, got <value>")``.  The
declarations are kept on the function (``__mutext_params__``) and
``__mutext_validate__(**some_arguments)`` checks a subset of them without
calling the function.  :func:`check_param` is the same check for values met
inside a function (fields of a model file, elements of a list).

This module sits at the bottom of the package: it imports only the standard
library, NumPy and :mod:`mutext.errors`.
"""
from __future__ import annotations

import functools
import inspect
import math

import numpy as np

from .errors import ModelError

__all__ = ["Constraint", "Integer", "Real", "Options", "Boolean", "Callable", "NoneOr", "AnyOf", "InstanceOf",
           "validate_params", "check_param"]


def _is_bool(value) -> bool:
    return isinstance(value, (bool, np.bool_))


def _fmt(x) -> str:
    """A bound as text: ``1``, ``0.2``, ``1e-12``."""
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return f"{float(x):g}"


class Constraint:
    """What a parameter may be: the base of the constraint classes."""

    def is_satisfied_by(self, value) -> bool:
        """True if ``value`` satisfies the constraint.

        Parameters
        ----------
        value : object
            The value to check.
        """
        raise NotImplementedError

    def describe(self) -> str:
        """The constraint as the end of a sentence ``"<name> must be ..."``."""
        raise NotImplementedError

    def invalid_examples(self) -> list:
        """A few values that violate the constraint (for the bad-input tests)."""
        raise NotImplementedError

    def __repr__(self):
        return f"<{type(self).__name__}: {self.describe()}>"


class Integer(Constraint):
    """A Python or NumPy integer (never a bool) in ``lo..hi`` (either bound may be None).

    Parameters
    ----------
    lo, hi : int, optional
        Inclusive bounds.
    """

    def __init__(self, lo: int | None = None, hi: int | None = None):
        self.lo = lo
        self.hi = hi

    def is_satisfied_by(self, value) -> bool:
        if _is_bool(value) or not isinstance(value, (int, np.integer)):
            return False
        return (self.lo is None or value >= self.lo) and (self.hi is None or value <= self.hi)

    def describe(self) -> str:
        if self.lo is not None and self.hi is not None:
            return f"an integer in {_fmt(self.lo)}..{_fmt(self.hi)}"
        if self.lo is not None:
            return f"an integer >= {_fmt(self.lo)}"
        if self.hi is not None:
            return f"an integer <= {_fmt(self.hi)}"
        return "an integer"

    def invalid_examples(self) -> list:
        out = [True, 1.5, "1", None]
        if self.lo is not None:
            out.append(int(self.lo) - 1)
        if self.hi is not None:
            out.append(int(self.hi) + 1)
        return out


_CLOSED = {"both": ("[", "]"), "left": ("[", ")"), "right": ("(", "]"), "neither": ("(", ")")}


class Real(Constraint):
    """A real number (Python or NumPy, never a bool, never NaN) in an interval.

    Parameters
    ----------
    lo, hi : float, optional
        Bounds of the interval (None: unbounded on that side).
    closed : {"both", "left", "right", "neither"}
        Which bounds belong to the interval.
    finite : bool
        Refuse infinite values.
    """

    def __init__(self, lo: float | None = None, hi: float | None = None, closed: str = "both",
                 finite: bool = True):
        if closed not in _CLOSED:
            raise ValueError(f"closed must be one of {sorted(_CLOSED)}, got {closed!r}")
        self.lo = lo
        self.hi = hi
        self.closed = closed
        self.finite = finite

    def is_satisfied_by(self, value) -> bool:
        if _is_bool(value) or not isinstance(value, (int, float, np.integer, np.floating)):
            return False
        x = float(value)
        if math.isnan(x) or (self.finite and math.isinf(x)):
            return False
        if self.lo is not None:
            if x < self.lo or (x == self.lo and self.closed in ("right", "neither")):
                return False
        if self.hi is not None:
            if x > self.hi or (x == self.hi and self.closed in ("left", "neither")):
                return False
        return True

    def describe(self) -> str:
        what = "a finite number" if self.finite else "a number"
        left, right = _CLOSED[self.closed]
        if self.lo is not None and self.hi is not None:
            return f"{what} in {left}{_fmt(self.lo)}, {_fmt(self.hi)}{right}"
        if self.lo is not None:
            return f"{what} {'>=' if left == '[' else '>'} {_fmt(self.lo)}"
        if self.hi is not None:
            return f"{what} {'<=' if right == ']' else '<'} {_fmt(self.hi)}"
        return what

    def invalid_examples(self) -> list:
        out = [True, "1", None, float("nan"), 1j]
        if self.finite:
            out.append(float("inf"))
        if self.lo is not None:
            out.append(float(self.lo) - 1.0)
            if self.closed in ("right", "neither"):
                out.append(self.lo)
        if self.hi is not None:
            out.append(float(self.hi) + 1.0)
            if self.closed in ("left", "neither"):
                out.append(self.hi)
        return out


class Options(Constraint):
    """One of a set of values (compared with ``==``; a bool is never an option unless listed).

    Parameters
    ----------
    options : iterable
        The allowed values.
    """

    def __init__(self, options):
        self.options = tuple(options)

    def is_satisfied_by(self, value) -> bool:
        try:
            return any(value == o and _is_bool(value) == _is_bool(o) for o in self.options)
        except (TypeError, ValueError):
            return False

    def describe(self) -> str:
        shown = sorted(self.options, key=repr) if len(self.options) > 1 else self.options
        return "one of " + ", ".join(repr(o) for o in shown)

    def invalid_examples(self) -> list:
        return [v for v in ("__not_an_option__", -12345, None) if not self.is_satisfied_by(v)]


class Boolean(Constraint):
    """True or False (a Python or NumPy bool; not 0 or 1)."""

    def is_satisfied_by(self, value) -> bool:
        return _is_bool(value)

    def describe(self) -> str:
        return "a bool (True or False)"

    def invalid_examples(self) -> list:
        return [1, "yes", None]


class Callable(Constraint):
    """A callable object."""

    def is_satisfied_by(self, value) -> bool:
        return callable(value)

    def describe(self) -> str:
        return "a callable"

    def invalid_examples(self) -> list:
        return [1, "f"]


class InstanceOf(Constraint):
    """An instance of a class (e.g. a model's ``Param``).

    Parameters
    ----------
    cls : type or tuple of types
        The accepted class(es).
    name : str, optional
        How the description names it (default ``"a <class name>"``).
    """

    def __init__(self, cls, name: str | None = None):
        self.cls = cls
        classes = cls if isinstance(cls, tuple) else (cls,)
        self.name = name or " or ".join(f"a {c.__name__}" for c in classes)

    def is_satisfied_by(self, value) -> bool:
        return isinstance(value, self.cls)

    def describe(self) -> str:
        return self.name

    def invalid_examples(self) -> list:
        return [v for v in (None, "x", 1.5) if not isinstance(v, self.cls)]


class AnyOf(Constraint):
    """Any of the given constraints.

    Parameters
    ----------
    *constraints : Constraint
        The alternatives.
    """

    def __init__(self, *constraints: Constraint):
        self.constraints = constraints

    def is_satisfied_by(self, value) -> bool:
        return any(c.is_satisfied_by(value) for c in self.constraints)

    def describe(self) -> str:
        return " or ".join(c.describe() for c in self.constraints)

    def invalid_examples(self) -> list:
        out = []
        for c in self.constraints:
            for v in c.invalid_examples():
                if not self.is_satisfied_by(v) and not any(v is w for w in out):
                    out.append(v)
        return out


class NoneOr(AnyOf):
    """None, or a value satisfying ``constraint``.

    Parameters
    ----------
    constraint : Constraint
        What a value other than None must satisfy.
    """

    def __init__(self, constraint: Constraint):
        super().__init__(constraint)
        self.constraint = constraint

    def is_satisfied_by(self, value) -> bool:
        return value is None or self.constraint.is_satisfied_by(value)

    def describe(self) -> str:
        return f"{self.constraint.describe()} or None"


def _message(where: str, name: str, value, constraint: Constraint) -> str:
    return f"{where}: {name} must be {constraint.describe()}, got {value!r}"


def check_param(where: str, name: str, value, constraint: Constraint, error: type = ModelError):
    """``value`` if it satisfies ``constraint``, else ``error("<where>: <name> must be ..., got ...")``.

    Parameters
    ----------
    where : str
        The function, model or element the value belongs to (starts the message).
    name : str
        The parameter or field.
    value : object
        The value to check.
    constraint : Constraint
        What the value must be.
    error : type, optional
        The exception raised (a :class:`~mutext.errors.MutextError`; default ModelError).
    """
    if not constraint.is_satisfied_by(value):
        raise error(_message(where, name, value, constraint))
    return value


def validate_params(constraints: dict, *, error: type = ModelError):
    """Decorator: check the arguments of the listed parameters before the function runs.

    Only the arguments given by the caller are checked (a default is the
    function's own choice).  The declarations are kept as
    ``func.__mutext_params__``; ``func.__mutext_validate__(**arguments)``
    checks some arguments without calling the function.

    Parameters
    ----------
    constraints : dict
        Parameter name -> :class:`Constraint`.
    error : type, optional
        The exception raised for a violation (default ModelError).
    """
    constraints = dict(constraints)

    def decorate(func):
        sig = inspect.signature(func)
        missing = [n for n in constraints if n not in sig.parameters]
        if missing:
            raise TypeError(f"validate_params: {func.__qualname__} has no parameter(s) {missing}")
        where = func.__name__

        def validate(**arguments):
            for name, value in arguments.items():
                c = constraints.get(name)
                if c is not None and not c.is_satisfied_by(value):
                    raise error(_message(where, name, value, c))

        # keyword-only parameters can only arrive by name: then the call's keywords are all there is
        # to check (no signature binding on every call of a function called in inner loops)
        keyword_only = all(sig.parameters[n].kind is inspect.Parameter.KEYWORD_ONLY for n in constraints)

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if keyword_only:
                for name, value in kwargs.items():
                    c = constraints.get(name)
                    if c is not None and not c.is_satisfied_by(value):
                        raise error(_message(where, name, value, c))
                return func(*args, **kwargs)
            try:
                bound = sig.bind(*args, **kwargs)
            except TypeError:
                return func(*args, **kwargs)      # the call's own TypeError
            validate(**{n: v for n, v in bound.arguments.items() if n in constraints})
            return func(*args, **kwargs)

        wrapper.__mutext_params__ = constraints
        wrapper.__mutext_validate__ = validate
        return wrapper

    return decorate
