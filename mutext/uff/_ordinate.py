r"""The ordinate of a data set 58: what it holds (displacement, velocity or acceleration per force or current)
and in what units, from its units labels, its specific data types and a units data set 164; and its conversion
to displacement per force (or current) in SI, :math:`H_d = H_v / (j\omega)`, :math:`H_d = H_a / (-\omega^2)`."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._fields import _REFERENCE_TYPES, _RESPONSE_TYPES, _SI_LABEL, _err
from ._units import KNOWN_UNITS, _label_used, motion_units, reference_units, relabel, units_hint


@dataclass(frozen=True)
class _Ordinate:
    """What the ordinate of a data set holds: ``quantity`` (displacement, velocity or acceleration) per
    ``reference`` (force or current), ``factor`` from the file's units to SI with the ``definitions`` of the
    non-SI units used, and ``file_units``, the units as the conversion states them."""
    quantity: str
    reference: str
    factor: float
    definitions: tuple
    file_units: str


def _ordinate(path, n, d, units, u164) -> _Ordinate:
    """The ordinate of data set ``n``: its units labels (read as ``units`` says) when given, else its specific
    data types in SI or in the units of the data set 164 ``u164``; the labels and the types must agree."""
    rst, dst = _spec_types(path, n, d)
    raw_num = d.get("ordinate_axis_units_lab")
    raw_den = d.get("orddenom_axis_units_lab")
    num_lab, den_lab = relabel(raw_num, units), relabel(raw_den, units)
    example = _SI_LABEL.get(_RESPONSE_TYPES.get(rst), "m/s^2") + "/N"
    num, den = _label_units(path, n, raw_num, raw_den, num_lab, den_lab, example)
    quantity, in_q, factor, defs = _from_labels(path, n, num, den, raw_num, raw_den)
    sysname = "SI"
    length_f, force_f = 1.0, 1.0
    if u164 is not None:
        length_f, force_f = 1.0 / u164[0], 1.0 / u164[1]
        sysname = f"data set 164 units {u164[2] or '?'} (length x {length_f:g}, force x {force_f:g})"
    if quantity is None:
        if rst not in _RESPONSE_TYPES:
            raise _err(path, n, "ordinate_spec_data_type", f"unknown response quantity (specific data type {rst}) "
                                                           f"and no units label; cannot tell displacement, velocity "
                                                           f"or acceleration; {units_hint(raw_num, example)}")
        quantity, factor = _RESPONSE_TYPES[rst], factor * length_f
    elif rst in _RESPONSE_TYPES and _RESPONSE_TYPES[rst] != quantity:
        raise _err(path, n, "ordinate_spec_data_type", f"specific data type {rst} ({_RESPONSE_TYPES[rst]}) "
                                                       f"contradicts the units label {str(raw_num).strip()!r} "
                                                       f"({quantity})")
    if in_q is None:
        if dst not in _REFERENCE_TYPES:
            raise _err(path, n, "orddenom_spec_data_type", f"unknown reference quantity (specific data type {dst}) "
                                                           f"and no units label; label 'N' for a force, 'A' for a "
                                                           f"current")
        in_q, factor = "force", factor / force_f
    elif dst in _REFERENCE_TYPES and in_q != "force":
        raise _err(path, n, "orddenom_spec_data_type", f"specific data type {dst} (force) contradicts the "
                                                       f"reference units ({in_q})")
    file_units = (str(raw_num).strip() if num is not None else f"{_SI_LABEL[quantity]} [{sysname}]")
    if den is not None:
        file_units += f" / {str(raw_den).strip()}"
    if num_lab != raw_num or den_lab != raw_den:
        file_units += f", read as {(str(num_lab).strip() if num is not None else '')}" + \
            (f" / {str(den_lab).strip()}" if den is not None else "")
    return _Ordinate(quantity, in_q, factor, defs, file_units)


def _spec_types(path, n, d) -> tuple:
    """The specific data types of the ordinate and of its denominator (0 or 1, unknown or general, or a
    motion over a force)."""
    rst = d.get("ordinate_spec_data_type", 0)
    dst = d.get("orddenom_spec_data_type", 0)
    if rst not in (0, 1) and rst not in _RESPONSE_TYPES:
        raise _err(path, n, "ordinate_spec_data_type", f"ordinate specific data type {rst} is not displacement (8), "
                                                       f"velocity (11) or acceleration (12)")
    if dst not in (0, 1) and dst not in _REFERENCE_TYPES:
        raise _err(path, n, "orddenom_spec_data_type", f"ordinate denominator specific data type {dst} is not a "
                                                       f"force (13 excitation, 9 reaction) or a current (0/1 with "
                                                       f"units label 'A')")
    return rst, dst


def _label_units(path, n, raw_num, raw_den, num_lab, den_lab, example) -> tuple:
    """The ordinate's and the denominator's units labels read (:class:`Units`, None where not given)."""
    return (_label(path, n, "ordinate_axis_units_lab", raw_num, num_lab, motion_units, KNOWN_UNITS, example),
            _label(path, n, "orddenom_axis_units_lab", raw_den, den_lab, reference_units,
                   "N, kN, lbf, lb (force), A, mA (current)", "N"))


def _label(path, n, key: str, raw, label, read, known: str, example: str):
    """One units label (``raw`` as in the file, ``label`` as it is read) read by ``read``; None where it is
    not given, an error naming ``key``, the ``known`` units and a hint with ``example`` where it is unknown."""
    if not _label_used(label):
        return None
    try:
        return read(label)
    except ValueError as exc:
        raise _err(path, n, key, f"unknown unit {str(raw).strip()!r} ({exc}); known: {known}; "
                                 f"{units_hint(raw, example)}") from None


def _from_labels(path, n, num, den, raw_num, raw_den) -> tuple:
    """``(quantity, reference, factor, definitions)`` that the units labels say (None where they do not): the
    ordinate label may hold the whole ratio, or the response only with the reference in the denominator."""
    quantity = in_q = None
    factor, defs = 1.0, ()
    if num is not None:
        quantity, factor, defs = num.quantity, num.factor, num.definitions
        in_q = num.reference
    if den is not None:
        den_q = "force" if den.dims[2] else "current"
        if in_q is not None:
            # the ordinate label holds the whole ratio: a denominator label must say the same
            if den_q != in_q or not math.isclose(num.reference_factor * den.factor, 1.0, rel_tol=1e-9):
                raise _err(path, n, "orddenom_axis_units_lab", f"units {str(raw_den).strip()!r} contradict the "
                                                               f"ordinate label {str(raw_num).strip()!r}")
        else:
            in_q, factor = den_q, factor / den.factor
            defs = tuple(dict.fromkeys(defs + den.definitions))
    return quantity, in_q, factor, defs


def _to_displacement(f_hz, data, o: _Ordinate, sign: int) -> tuple:
    """``(G, conversion, changed)``: the values ``data`` at ``f_hz`` [Hz] as displacement per force (or
    current) in SI, times ``sign`` (-1 if exactly one direction is negative), the conversion stated, and
    whether the values were changed."""
    quantity, in_q, factor, defs = o.quantity, o.reference, o.factor, o.definitions
    w = 2 * np.pi * f_hz
    G = data * factor
    in_unit = "N" if in_q == "force" else "A"
    steps = []
    if factor != 1.0:
        steps.append(f"scaled by {factor:.12g} to {_SI_LABEL[quantity]}/{in_unit}"
                     + (f" ({', '.join(defs)})" if defs else ""))
    if quantity == "velocity":
        G = G / (1j * w)
        steps.append("divided by j*omega")
    elif quantity == "acceleration":
        G = G / (-(w ** 2))
        steps.append("divided by -omega^2")
    if sign < 0:
        G = -G
        steps.append("sign flipped (one negative direction)")
    conv = (f"{quantity} per {in_q} in the file ({o.file_units}) -> displacement per {in_q} m/{in_unit}: "
            + (", ".join(steps) if steps else "unchanged") + "; omega = 2*pi*f [rad/s]")
    return G, conv, bool(steps)
