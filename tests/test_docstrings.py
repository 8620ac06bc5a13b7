"""Every public function, class and method documents every parameter (numpydoc).

Modelled on python-control's ``control/tests/docstrings_test.py``.  The public
namespace is walked the way a user meets it: every module and package of
``mutext`` whose dotted name has no component starting with ``_``, and in each
its ``__all__`` when it has one, otherwise its attributes without a leading
underscore whose ``__module__`` is in ``mutext`` (a function defined in a
private module and re-exported by a package's ``__init__`` is public).  Objects
are deduplicated by identity; public methods of public classes are checked too.

For each object the ``Parameters`` (and ``Other Parameters``) section of its
docstring is parsed -- entries are the lines ``name : type`` or
``name1, name2 : type`` at the section's indentation -- and

* every argument of the signature (positional and keyword-only, without
  ``self``/``cls`` and private ``_name`` fields; ``*args``/``**kwargs`` written as ``*args``/``**kwargs`` or
  by their bare names) must be documented, and
* every documented parameter must exist in the signature.

A class is checked against the signature of its constructor: its own
docstring's Parameters and those of ``__init__`` count, and for a dataclass or
a NamedTuple (generated constructor) the class docstring's Attributes too.

The failure lists ``module.function: missing a, b; unknown c`` per object.
"""
from __future__ import annotations

import dataclasses
import enum
import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import matplotlib

import mutext

matplotlib.use("Agg")      # a module that draws on import must not need a display

ROOT = Path(mutext.__file__).resolve().parent.parent

# Files whose objects are not checked while they are being reworked (none now).  An entry ``x.py``
# also covers the package ``x/`` it is split into; an entry whose objects are all documented must be
# removed (``test_pending_files_still_pending``).
_PENDING_FILES: set = set()

_PARAMETER_SECTIONS = ("Parameters", "Other Parameters")
_ENTRY = re.compile(r"^(\*{0,2}[A-Za-z_]\w*(?:\s*,\s*\*{0,2}[A-Za-z_]\w*)*)\s*(?::.*)?$")


# ----------------------------------------------------------------------------
# the public namespace
# ----------------------------------------------------------------------------

def public_modules() -> list:
    """The modules and packages of ``mutext`` without a ``_``-prefixed name component."""
    modules = [mutext]
    for info in pkgutil.walk_packages(mutext.__path__, prefix="mutext."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        modules.append(importlib.import_module(info.name))
    return modules


def _is_ours(obj) -> bool:
    return str(getattr(obj, "__module__", "") or "").startswith("mutext")


def _exported(module) -> list:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in vars(module) if not n.startswith("_")]
    out = []
    for name in names:
        obj = getattr(module, name, None)
        if (inspect.isfunction(obj) or inspect.isclass(obj)) and _is_ours(obj):
            out.append(obj)
    return out


def _public_methods(cls) -> list:
    out = []
    for name, attr in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(attr, (staticmethod, classmethod)):
            attr = attr.__func__
        if inspect.isfunction(attr) and _is_ours(attr):
            out.append(attr)
    return out


def public_objects() -> list:
    """Public functions, classes and methods of ``mutext``, each once (by identity)."""
    seen: set[int] = set()
    out = []
    for module in public_modules():
        for obj in _exported(module):
            candidates = [obj] + (_public_methods(obj) if inspect.isclass(obj) else [])
            for item in candidates:
                if id(item) not in seen:
                    seen.add(id(item))
                    out.append(item)
    return out


def qualified_name(obj) -> str:
    return f"{obj.__module__}.{obj.__qualname__}"


def source_file(obj) -> str | None:
    """The defining file relative to the repository root (``mutext/lti.py``), or None."""
    try:
        path = inspect.getsourcefile(inspect.unwrap(obj))
    except TypeError:
        return None
    if path is None:
        return None
    try:
        return Path(path).resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return None


def is_pending(obj) -> bool:
    path = source_file(obj)
    if path is None:
        return False
    for entry in _PENDING_FILES:
        if path == entry or (entry.endswith(".py") and path.startswith(entry[:-3] + "/")):
            return True
    return False


# ----------------------------------------------------------------------------
# docstrings
# ----------------------------------------------------------------------------

def sections(doc: str | None) -> dict[str, list[str]]:
    """The numpydoc sections of a docstring: title -> its lines (the title and underline removed)."""
    lines = inspect.cleandoc(doc or "").splitlines()
    out: dict[str, list[str]] = {}
    current = None
    i = 0
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        title = line.strip()
        if title and re.fullmatch(r"-{3,}", nxt.strip()) and len(nxt.strip()) >= len(title) - 1:
            current = title
            out.setdefault(current, [])
            i += 2
            continue
        if current is not None:
            out[current].append(line)
        i += 1
    return out


def _entries(lines: list[str]) -> list[str]:
    body = [ln for ln in lines if ln.strip()]
    if not body:
        return []
    indent = min(len(ln) - len(ln.lstrip()) for ln in body)
    names = []
    for ln in body:
        if len(ln) - len(ln.lstrip()) != indent:
            continue
        m = _ENTRY.match(ln.strip())
        if m:
            names.extend(n.strip() for n in m.group(1).split(","))
    return names


def documented(doc: str | None, titles=_PARAMETER_SECTIONS) -> list[str]:
    """Parameter names listed in the given sections of ``doc`` (``*args`` kept with its stars)."""
    secs = sections(doc)
    names = []
    for title in titles:
        names.extend(_entries(secs.get(title, [])))
    return names


def has_examples(obj) -> bool:
    secs = sections(inspect.getdoc(obj))
    return any(t in secs for t in ("Examples", "Example"))


def _signature_names(sig: inspect.Signature) -> list[str]:
    names = []
    for p in sig.parameters.values():
        if p.name in ("self", "cls") or p.name.startswith("_"):     # private fields are not documented
            continue
        if p.kind is p.VAR_POSITIONAL:
            names.append("*" + p.name)
        elif p.kind is p.VAR_KEYWORD:
            names.append("**" + p.name)
        else:
            names.append(p.name)
    return names


def _has_own_constructor(cls) -> bool:
    """The constructor is written (or generated) in mutext, not inherited from object or Exception."""
    if dataclasses.is_dataclass(cls) or _is_namedtuple(cls):
        return True
    for klass in cls.__mro__:
        if "__init__" in vars(klass) or "__new__" in vars(klass):
            return _is_ours(klass) and klass.__module__ != "typing"
    return False


def _is_namedtuple(cls) -> bool:
    return issubclass(cls, tuple) and hasattr(cls, "_fields")


def check(obj) -> tuple[list[str], list[str]] | None:
    """``(missing, unknown)`` parameter names of a public object, or None when it has nothing to check."""
    if inspect.isclass(obj):
        if issubclass(obj, enum.Enum) or not _has_own_constructor(obj):
            return None
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            return None
        doc = inspect.getdoc(obj)
        listed = documented(doc)
        init = vars(obj).get("__init__")
        if init is not None and inspect.isfunction(init) and init.__doc__:
            listed += documented(init.__doc__)
        accepted = list(listed)
        if dataclasses.is_dataclass(obj) or _is_namedtuple(obj):
            accepted += documented(doc, ("Attributes",))
    else:
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            return None
        listed = documented(inspect.getdoc(obj))
        accepted = list(listed)
    params = _signature_names(sig)
    bare = {p.lstrip("*") for p in params}
    accepted_bare = {a.lstrip("*") for a in accepted}
    missing = [p for p in params if p.lstrip("*") not in accepted_bare]
    unknown = [d for d in listed if d.lstrip("*") not in bare]
    return missing, unknown


def problems(objects=None, *, include_pending=False) -> dict[str, str]:
    """``{qualified name: "missing a, b; unknown c"}`` for the objects that fail."""
    out = {}
    for obj in (public_objects() if objects is None else objects):
        if not include_pending and is_pending(obj):
            continue
        result = check(obj)
        if result is None:
            continue
        missing, unknown = result
        if missing or unknown:
            parts = []
            if missing:
                parts.append("missing " + ", ".join(missing))
            if unknown:
                parts.append("unknown " + ", ".join(unknown))
            out[qualified_name(obj)] = "; ".join(parts)
    return out


# ----------------------------------------------------------------------------
# the tests
# ----------------------------------------------------------------------------

def test_the_parser_reads_numpydoc_parameters():
    def f(a, b, *args, c=1, **kwargs):
        """Summary.

        Parameters
        ----------
        a, b : float
            Two numbers.

            A second paragraph.
        *args
            More.
        c : int, optional
            A keyword.
        kwargs : dict
            Passed on.
        d : str
            Not in the signature.

        Returns
        -------
        e : float
            Not a parameter.
        """
    assert check(f) == ([], ["d"])

    def g(x, y):
        """One line, no sections."""
    assert check(g) == (["x", "y"], [])


def test_every_public_parameter_is_documented():
    found = problems()
    listing = "\n".join(f"  {name}: {what}" for name, what in sorted(found.items()))
    assert not found, (f"{len(found)} public functions/classes/methods leave parameters undocumented or "
                       f"document parameters they do not have (numpydoc 'Parameters' section):\n{listing}")


def test_pending_files_still_pending():
    """Every entry of ``_PENDING_FILES`` still has an undocumented parameter (else remove it)."""
    failing = set()
    for obj in public_objects():
        if is_pending(obj):
            result = check(obj)
            if result and (result[0] or result[1]):
                path = source_file(obj)
                failing.update(e for e in _PENDING_FILES
                               if path == e or (e.endswith(".py") and path.startswith(e[:-3] + "/")))
    done = sorted(_PENDING_FILES - failing)
    assert not done, f"these files document every parameter now; remove them from _PENDING_FILES: {done}"


if __name__ == "__main__":       # a summary: counts and the full listing
    objs = public_objects()
    checked = [o for o in objs if check(o) is not None]
    every = problems(objs, include_pending=True)
    rest = problems(objs)
    print(f"{len(objs)} public objects, {len(checked)} with parameters to check, "
          f"{len(every)} incomplete ({len(rest)} outside the pending files), "
          f"{sum(has_examples(o) for o in objs)} with Examples")
    for name, what in sorted(rest.items()):
        print(f"  {name}: {what}")
