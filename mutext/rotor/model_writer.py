r"""Structural edits of a model file's TOML text that keep the user's comments and layout.

A model file (:mod:`mutext.rotor.model`) is a user's document: the diagnosis
writes what it found *into* it (a changed bearing stiffness, an added spring,
a mass with its own spring and damper) and hands it back.  The edits are made
on the parsed document (``tomlkit``, a round-trip TOML parser), never by
pattern matching on the text, so a value is changed exactly in the table the
caller selects, in any layout TOML allows (inline comments, keys in any order,
tables of one kind not contiguous), and everything the edit does not touch --
comments, blank lines, number formats, key order -- is written back as it
was.  (One exception, a property of the round-trip parser: entries of one
``[[table]]`` that stand apart in the file, another table between them, are
written together, in their order, with their comments; the file means the
same.)

Three edits cover what :mod:`mutext.diagnose` writes:

* :meth:`ModelFile.set` -- ``key = value`` in the *k*-th ``[[table]]`` a
  predicate selects (the old value kept in a comment);
* :meth:`ModelFile.append` -- a new ``[[table]]`` entry, with a comment line (a list of
  numbers, e.g. the coefficients of an ``[[impedance]]``, written number by number);
* :meth:`ModelFile.scale` -- every listed key of every listed table multiplied
  by a factor (e.g. all damping values).

Every written value is a finite real number written in full precision
(``repr`` of the float), so the model read back holds the value the caller
gave, bit for bit.  With ``si=True`` the value is given in SI and written in
the file's own units (``units = "inch-pound"`` files get lbf/in, lb, ...;
:data:`QUANTITIES` says what each key of each table measures, as the reader
converts it), so an SI result never lands unconverted in an inch-pound file.
Bad input is a :class:`~mutext.errors.ModelError` naming the file, the table
and the key.
"""
from __future__ import annotations

import math
from typing import Callable

import tomlkit
from tomlkit.exceptions import TOMLKitError
from tomlkit.items import AoT, Table

from ..errors import ModelError
from .units import from_si

__all__ = ["ModelFile", "QUANTITIES"]

#: What each numeric key of a model file's tables measures (:mod:`mutext.rotor.units`), as the reader
#: converts it: the unit in which ``si=True`` values are written.  An ``[[impedance]]``'s numerator
#: carries its unit (a stiffness); its denominator is dimensionless.
QUANTITIES = {
    "bearing": {"stiffness": "stiffness", "damping": "damping", "stiffness_y": "stiffness",
                "damping_y": "damping", "kxy": "stiffness", "kyx": "stiffness"},
    "disk": {"mass": "mass", "polar_inertia": "inertia", "transverse_inertia": "inertia", "width": "length",
             "outer_diameter": "length", "inner_diameter": "length", "density": "density"},
    "mass": {"mass": "mass"},
    "spring": {"stiffness": "stiffness"},
    "damper": {"damping": "damping"},
    "exciter": {"force_per_ampere": "force_per_current", "negative_stiffness": "stiffness"},
    "crack": {"depth_ratio": "dimensionless"},
    "impedance": {"numerator": "stiffness", "denominator": "dimensionless"},
}


def _number(x, where: str):
    """A finite real number as a TOML item (bool and strings are refused)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(float(x)):
        raise ModelError(f"{where}: a finite real number is needed, got {x!r}")
    return tomlkit.item(float(x))


class ModelFile:
    """A model file's TOML document, edited in place; :meth:`text` gives the file back.

    Parameters
    ----------
    text : str
        The model file's text.
    source : str
        Its name in error messages.

    Examples
    --------
    >>> mf = ModelFile('# my rig\\n[[spring]]\\nname = "k1"\\nstiffness = 800.0   # N/m\\n')
    >>> mf.set("spring", lambda t: t["name"] == "k1", "stiffness", 820.0, "stiffened")
    800.0
    >>> print(mf.text())
    # my rig
    [[spring]]
    name = "k1"
    stiffness = 820.0 # N/m -- stiffened (was 800.0)
    <BLANKLINE>
    """

    def __init__(self, text: str, source: str = "model file"):
        self.source = source
        try:
            self.doc = tomlkit.parse(text)
        except TOMLKitError as exc:
            raise ModelError(f"{source}: not valid TOML: {exc}") from None

    def entries(self, table: str) -> list:
        """The entries of ``[[table]]`` (or the one ``[table]``) in file order; [] when absent.

        Parameters
        ----------
        table : str
            The table's name (``"spring"``, ``"mass"``, ``"shaft"``, ...).

        Returns
        -------
        list of tomlkit.items.Table
            The entries themselves (dict-like; changing one changes the document).

        Raises
        ------
        ModelError
            ``table`` names a value, not a table.
        """
        if table not in self.doc:
            return []
        t = self.doc[table]
        if isinstance(t, (AoT, list)):
            return list(t)
        if isinstance(t, (Table, dict)):
            return [t]
        raise ModelError(f"{self.source}: '{table}' is a value, not a table")

    def set(self, table: str, select: Callable[[dict], bool], key: str, value: float, note: str = "",
            k: int = 0, *, si: bool = False) -> float | None:
        """Set ``key = value`` in the ``k``-th entry of ``[[table]]`` that ``select`` accepts.

        The line gets the comment ``note (was OLD)`` after the comment it had; a key the entry does not
        hold yet is added to it.

        Parameters
        ----------
        table : str
            The table's name (``"spring"``, ``"bearing"``, ...).
        select : callable
            ``select(entry) -> bool`` on each entry (a dict of its keys), e.g.
            ``lambda t: t["name"] == "k1"``.
        key : str
            The key to set.
        value : float
            The new value, in the file's units (finite; written in full precision).
        note : str
            Comment on the change (may be empty).
        k : int
            Which of the selected entries (0-based, in file order).
        si : bool
            ``value`` is in SI: written in the file's units (see :data:`QUANTITIES`).

        Returns
        -------
        float or None
            The old value (in the file's units); None when the key was added.

        Raises
        ------
        ModelError
            Fewer than ``k + 1`` entries selected, an old value that is not a number, a value that is
            not a finite real number.
        """
        hits = [t for t in self.entries(table) if select(t)]
        if len(hits) <= k:
            raise ModelError(f"{self.source}: no [[{table}]] entry to change '{key}' in "
                             f"({len(hits)} match the selection, entry {k + 1} asked for)")
        t = hits[k]
        where = f"{self.source}: [[{table}]] #{self.entries(table).index(t) + 1}, '{key}'"
        old = t.get(key)
        if old is not None and (isinstance(old, bool) or not isinstance(old, (int, float))):
            raise ModelError(f"{where}: holds {old!r}, not a number that can be changed")
        item = _number(self._in_file_units(value, table, key, where) if si else value, where)
        text = (note + (f" (was {old})" if old is not None else "")).strip()
        kept = old.trivia.comment.lstrip("#").strip() if old is not None else ""
        text = f"{kept} -- {text}" if kept and text else (kept or text)     # the user's comment first
        if text:
            item.comment(text)
        t[key] = item
        return None if old is None else float(old)

    def append(self, table: str, entries: dict, note: str = "", *, si: bool = False) -> None:
        """Append a ``[[table]]`` entry holding ``entries`` (a comment line ``note`` opens it).

        Parameters
        ----------
        table : str
            The table's name; the array of tables is created when the file has none.
        entries : dict
            Key -> value of the new entry: strings, booleans, integers and lists that hold a string
            (e.g. ``between = ["m1", "ground"]``) as given; floats and lists of numbers (the
            coefficients of an ``[[impedance]]``) as finite floats in full precision.
        note : str
            The comment line that opens the entry (none when empty).
        si : bool
            The floats and number lists of ``entries`` are in SI: written in the file's units (see
            :data:`QUANTITIES`).

        Raises
        ------
        ModelError
            ``table`` exists but is not an array of tables, or a number that is not finite.
        """
        new = tomlkit.table()
        if note:
            new.add(tomlkit.comment(note))
        for key, v in entries.items():
            where = f"{self.source}: new [[{table}]] entry, '{key}'"
            if isinstance(v, (list, tuple)) and v and not any(isinstance(x, str) for x in v):
                # coefficients (an [[impedance]]'s numerator): each a finite number in full precision
                arr = tomlkit.array()
                for j, x in enumerate(v):
                    x = x.item() if hasattr(x, "item") else x
                    arr.append(_number(self._in_file_units(x, table, key, where) if si else x, f"{where}[{j}]"))
                new[key] = arr
            elif isinstance(v, (str, bool, list, int)):
                new[key] = v                # names, flags, stations and counts as given
            else:
                new[key] = _number(self._in_file_units(v, table, key, where) if si else v, where)
        new.add(tomlkit.nl())
        new.trivia.indent = "\n"
        if table not in self.doc:
            self.doc.append(table, tomlkit.aot())
        t = self.doc[table]
        if not isinstance(t, AoT):
            raise ModelError(f"{self.source}: '{table}' is not an array of tables ([[{table}]]): cannot add one")
        t.append(new)

    def scale(self, tables: dict, factor: float, note: str = "") -> int:
        """Multiply every key of ``tables`` (table name -> keys) present in the file by ``factor``.

        Parameters
        ----------
        tables : dict
            Table name -> list of keys, e.g. ``{"damper": ["damping"]}``; keys an entry does not hold are
            skipped.
        factor : float
            The multiplier (finite).
        note : str
            Comment on each changed line (the old value is added to it, as by :meth:`set`).

        Returns
        -------
        int
            How many values were scaled.

        Raises
        ------
        ModelError
            A listed key holding something other than a number, a factor that is not finite.
        """
        _number(factor, f"{self.source}: scale factor")
        count = 0
        for table, keys in tables.items():
            for n, t in enumerate(self.entries(table), start=1):
                for key in keys:
                    if key not in t:
                        continue
                    v = t[key]
                    if isinstance(v, bool) or not isinstance(v, (int, float)):
                        raise ModelError(f"{self.source}: [[{table}]] #{n}, '{key}' = {v!r} is not a plain "
                                         "number: cannot scale it")
                    self.set(table, lambda x, t=t: x is t, key, float(v) * factor, note)
                    count += 1
        return count

    def _in_file_units(self, value, table: str, key: str, where: str):
        """An SI ``value`` of ``[[table]]``'s ``key`` in the file's units."""
        system = str(self.doc.get("units", "SI"))
        quantity = QUANTITIES.get(table, {}).get(key)
        if quantity is None:
            raise ModelError(f"{where}: no unit is known for this key, so an SI value cannot be written "
                             f"into a file in {system} units")
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return value                    # refused with its own message by _number
        try:
            return from_si(float(value), quantity, system)
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}") from None

    def text(self) -> str:
        """The edited file's text."""
        return tomlkit.dumps(self.doc)
