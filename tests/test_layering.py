"""The package's layering, read from its source: no module imports one above it.

Bottom-up (a module may import its own layer and those below; within a layer
the imports between units must not form a cycle)::

    errors, jsonio, _files, _validation, _solver (the one seam to the conic solver)
    lti, response, _mpl
    hinf, mu, frfit
    dk, uncertain, rotor/
    mbi, rig, sysid, diagnose/, hide, uff, batch, report
    examples/
    demos/, plots, diagrams, grading/, commands/, progress
    cli, the package's facade (``mutext/__init__.py``: every entry point, loaded on first use)

A *unit* is the first name below ``mutext`` (``mutext.rotor.crack`` is unit
``rotor``).  Both module-level and function-local imports count: a local
import hides an edge of the graph, it does not remove it.  So do the
registries that name modules as strings for ``importlib.import_module`` (the
CLI's demos and commands, the facade's entry points, the grading package's
lazy names): in a module that calls ``import_module``, every module path
written as a string in a module-level dict (``"mutext.demos.rotor"``, or
``".lti"`` relative to the package) is an import at its line.  No two modules
import each other, directly or around a loop.  The check is a plain AST walk
(no import-linter), so it runs without importing the package.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "mutext"

LAYERS = [
    {"errors", "jsonio", "_files", "_validation", "_solver"},
    {"lti", "response", "_mpl"},
    {"hinf", "mu", "frfit"},
    {"dk", "uncertain", "rotor"},
    {"mbi", "rig", "sysid", "diagnose", "hide", "uff", "batch", "report"},
    {"examples"},
    {"demos", "plots", "diagrams", "grading", "commands", "progress"},
    {"cli", ""},
]
# ``""`` is the package itself: its facade names entry points of every layer (no module imports it)
LAYER = {unit: k for k, units in enumerate(LAYERS) for unit in units}

#: Known violations in modules being reworked elsewhere, as (file, imported unit).
#: Empty today; an entry here names its follow-up issue and is removed with it.
ALLOWED: set[tuple[str, str]] = set()


def module_name(path: Path, root: Path = PACKAGE) -> str:
    """Dotted name of a source file below ``root`` (``rotor/crack.py`` -> ``mutext.rotor.crack``)."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join([root.name] + parts)


def imports(source: str, module: str, is_package: bool = False, modules=frozenset()):
    """``(line, target)`` for every import in ``source``, module-level and local.

    ``target`` is the dotted module imported: ``from .rotor import units``
    yields ``mutext.rotor.units`` when that is one of ``modules`` (or, for the
    package itself, ``from mutext import plots`` yields ``mutext.plots``), else
    ``mutext.rotor``.
    """
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                yield node.lineno, sub if sub in modules or target == PACKAGE.name else target
    yield from registry_imports(source, package)


_MODULE_PATH = re.compile(r"^(mutext(\.\w+)+|\.+\w+(\.\w+)*)$")


def registry_imports(source: str, package: str):
    """``(line, target)`` for every module named as a string in a module-level dict of a module that
    calls ``import_module`` (a registry: ``{"rotor": ("mutext.demos.rotor", "...")}`` or
    ``{"hinfsyn": ".hinf"}``, relative names resolved against ``package``)."""
    tree = ast.parse(source)
    calls = any(isinstance(n, ast.Call) and getattr(n.func, "attr", getattr(n.func, "id", None)) == "import_module"
                for n in ast.walk(tree))
    if not calls:
        return
    for stmt in tree.body:
        value = stmt.value if isinstance(stmt, (ast.Assign, ast.AnnAssign)) else None
        if not isinstance(value, ast.Dict):
            continue
        for v in value.values:
            for c in ([v] if isinstance(v, ast.Constant) else getattr(v, "elts", [])):
                if isinstance(c, ast.Constant) and isinstance(c.value, str) and _MODULE_PATH.match(c.value):
                    name = c.value
                    if name.startswith("."):
                        level = len(name) - len(name.lstrip("."))
                        base = package.split(".")[: len(package.split(".")) - level + 1]
                        name = ".".join(base + [name.lstrip(".")])
                    yield c.lineno, name


def unit(dotted: str) -> str | None:
    """The layer unit of a ``mutext`` module (``""`` for the package itself), None outside it."""
    parts = dotted.split(".")
    if parts[0] != PACKAGE.name:
        return None
    return parts[1] if len(parts) > 1 else ""


def module_edges(root: Path = PACKAGE):
    """``(file, line, from_module, to_module)`` for every import of the package by its own modules."""
    paths = {module_name(p, root): p for p in sorted(root.rglob("*.py"))}
    for name, path in paths.items():
        for line, target in imports(path.read_text(encoding="utf-8"), name, path.name == "__init__.py", paths):
            if unit(target) is not None and target != name:
                yield path.relative_to(root.parent).as_posix(), line, name, target


def edges(root: Path = PACKAGE):
    """``(file, line, from_unit, to_unit)`` for every import between units of the package."""
    for file, line, src, dst in module_edges(root):
        if unit(src) != unit(dst):
            yield file, line, unit(src), unit(dst)


def upward(edge_list, layer=LAYER, allowed=ALLOWED):
    """The edges that import a higher layer (or a unit missing from the layer map), as messages."""
    bad = []
    for file, line, src, dst in edge_list:
        if (file, dst) in allowed:
            continue
        if src not in layer or dst not in layer:
            missing = src if src not in layer else dst
            bad.append(f"{file}:{line}: unit {missing!r} has no layer (add it to LAYERS)")
        elif layer[dst] > layer[src]:
            bad.append(f"{file}:{line}: {src} (layer {layer[src]}) imports {dst} (layer {layer[dst]})")
    return bad


def cycles(edge_list) -> list[str]:
    """Import cycles of a graph given as ``(file, line, src, dst)`` edges, each as
    ``a -> b -> ... -> a (file:line of each edge)``; empty when the graph is acyclic."""
    graph: dict[str, dict[str, str]] = {}
    for file, line, src, dst in edge_list:
        graph.setdefault(src, {}).setdefault(dst, f"{file}:{line}")
    found, done = [], set()

    def visit(node, path, seen):
        for nxt in sorted(graph.get(node, {})):
            if nxt in path:
                ring = path[path.index(nxt):] + [nxt]
                if frozenset(ring) not in done:
                    done.add(frozenset(ring))
                    where = ", ".join(graph[a][b] for a, b in zip(ring, ring[1:]))
                    found.append(" -> ".join(ring) + f" ({where})")
            elif nxt not in seen:
                seen.add(nxt)
                visit(nxt, path + [nxt], seen)

    for start in sorted(graph):
        visit(start, [start], {start})
    return found


def same_layer_cycles(edge_list, layer=LAYER) -> list[str]:
    """Cycles between units of one layer (see :func:`cycles`)."""
    return cycles(e for e in edge_list if layer.get(e[2]) is not None and layer.get(e[2]) == layer.get(e[3]))


# ----------------------------------------------------------------------------- the package

def test_no_module_imports_a_higher_layer():
    bad = upward(edges())
    assert not bad, "imports of a higher layer:\n" + "\n".join(bad)


def test_no_import_cycle_within_a_layer():
    found = same_layer_cycles(list(edges()))
    assert not found, "import cycles between units of one layer:\n" + "\n".join(found)


def test_no_import_cycle_between_modules():
    # inside a unit too (a function-local import that closes a loop only hides it)
    found = cycles(module_edges())
    assert not found, "import cycles between modules:\n" + "\n".join(found)


def test_registries_are_seen_and_name_real_modules():
    # the CLI's registries and the facade are edges of the graph, and each string names a module that exists
    found = [(f, dst) for f, _, src, dst in module_edges()
             if f in ("mutext/cli.py", "mutext/__init__.py", "mutext/grading/__init__.py")]
    targets = {dst for _, dst in found}
    assert {"mutext.demos.rotor", "mutext.commands.diagnose", "mutext.hinf", "mutext.grading.spec"} <= targets
    root = PACKAGE.parent
    missing = sorted(t for t in targets if not (root / (t.replace(".", "/") + ".py")).is_file()
                     and not (root / t.replace(".", "/") / "__init__.py").is_file())
    assert not missing, f"registries name modules that do not exist: {missing}"


def test_every_unit_has_a_layer():
    units = {unit(module_name(p)) for p in PACKAGE.rglob("*.py")}
    assert units <= set(LAYER), f"units missing from LAYERS: {sorted(units - set(LAYER))}"


# ----------------------------------------------------------------------------- the check itself

def _tree(tmp_path, files: dict[str, str]) -> Path:
    root = tmp_path / "mutext"
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return root


def test_check_reports_a_deliberate_back_reference(tmp_path):
    # a library module reaching up into the CLI from inside a function, as the demos once did
    root = _tree(tmp_path, {
        "__init__.py": "",
        "rotor/__init__.py": "",
        "rotor/demo.py": "import numpy\n\ndef run():\n    from ..cli import print_json\n    return print_json\n",
        "cli.py": "from .rotor import demo\n",
    })
    bad = upward(edges(root))
    assert bad == ["mutext/rotor/demo.py:4: rotor (layer 3) imports cli (layer 7)"]


def test_check_reports_a_back_reference_through_a_registry(tmp_path):
    # a library module that loads a demo by name: no import statement, still an upward edge
    root = _tree(tmp_path, {
        "__init__.py": "",
        "mu/__init__.py": ("import importlib\n\nSHOWS = {\"peak\": (\"mutext.demos.peak\", \"a demo\")}\n\n"
                           "def show(name):\n    return importlib.import_module(SHOWS[name][0])\n"),
        "demos/__init__.py": "",
        "demos/peak.py": "",
    })
    assert upward(edges(root)) == ["mutext/mu/__init__.py:3: mu (layer 2) imports demos (layer 6)"]
    # the same dict without import_module is data, not an import
    (root / "mu/__init__.py").write_text("SHOWS = {\"peak\": (\"mutext.demos.peak\", \"a demo\")}\n")
    assert upward(edges(root)) == []


@pytest.mark.parametrize("source, target", [
    ("from mutext.examples.three_mass import TABLE_3_1", "mutext.examples.three_mass"),
    ("from mutext import plots", "mutext.plots"),
    ("import mutext.cli", "mutext.cli"),
    ("from .. import examples", "mutext.examples"),
    ("from ..examples import two_mass", "mutext.examples"),
])
def test_imports_resolve_absolute_relative_and_submodule_forms(source, target):
    (line, got), = imports(source, "mutext.rotor.tuning")
    assert line == 1 and got.startswith(target)


def test_check_reports_a_same_layer_cycle_and_an_unknown_unit():
    edge_list = [("mutext/rig.py", 5, "rig", "uff"), ("mutext/uff.py", 9, "uff", "rig"),
                 ("mutext/new.py", 1, "new", "lti")]
    assert same_layer_cycles(edge_list) == ["rig -> uff -> rig (mutext/rig.py:5, mutext/uff.py:9)"]
    assert upward(edge_list) == ["mutext/new.py:1: unit 'new' has no layer (add it to LAYERS)"]


def test_allow_list_silences_only_its_edge():
    edge_list = [("mutext/mu.py", 3, "mu", "dk"), ("mutext/mu.py", 4, "mu", "mbi")]
    assert upward(edge_list, allowed={("mutext/mu.py", "dk")}) == [
        "mutext/mu.py:4: mu (layer 2) imports mbi (layer 4)"]


def test_check_reports_a_cycle_inside_a_unit(tmp_path):
    # the screen builds on the hypotheses, which reach back into the screen from a function
    root = _tree(tmp_path, {
        "__init__.py": "",
        "diagnose/__init__.py": "from ._screen import screen\n",
        "diagnose/_hypotheses.py": "def hypotheses():\n    from ._screen import resolve\n",
        "diagnose/_screen.py": "from ._hypotheses import hypotheses\n",
    })
    assert upward(edges(root)) == []
    assert cycles(module_edges(root)) == [
        "mutext.diagnose._screen -> mutext.diagnose._hypotheses -> mutext.diagnose._screen "
        "(mutext/diagnose/_screen.py:1, mutext/diagnose/_hypotheses.py:2)"]


def test_from_package_import_submodule_is_the_submodule():
    (line, got), = imports("from . import units", "mutext.rotor.model", modules={"mutext.rotor.units"})
    assert got == "mutext.rotor.units"
    (line, got), = imports("from . import Rotor", "mutext.rotor.model", modules={"mutext.rotor.units"})
    assert got == "mutext.rotor"
