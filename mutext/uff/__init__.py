r"""Universal File Format data set 58 (FRFs of modal-test and analyzer software) in and out.

Modal-test systems export measured frequency response functions as
Universal File Format (UFF, ``.uff`` / ``.unv``) data set 58, "function at
nodal DOF", ASCII or binary (58b).  :func:`read_uff58` turns every FRF data set
of such a file into a :class:`mutext.response.FRF` (displacement per force or
per current, SI); :func:`write_uff58` writes FRFs back.  Files are read and
written through the `pyuff <https://github.com/ladisk/pyuff>`_ package.
:func:`mutext.rig.read_frf` and :func:`mutext.rig.read_frfs` dispatch to this
module for a UFF file, so everything that accepts an FRF file accepts UFF 58.

What is read (record and field numbers of data set 58)
------------------------------------------------------
* **Function type** (record 6 field 1, ``func_type``) must be 4, a frequency
  response function.
* **Ordinate** (record 7 field 1, ``ord_data_type``) must be complex (5 or 6);
  a real-only ordinate is refused (the phase is missing).
* **Abscissa** in Hz (record 8: specific data type 18 = frequency, or 0/1;
  units label ``Hz``, ``rad/s`` or ``cpm`` if given), strictly increasing;
  even (record 7: minimum + increment) or uneven spacing.  Lines at or below
  0 Hz at the start (analyzers export the 0 Hz line) are dropped with a note;
  a file with no line above 0 Hz is an error.
* **Response** (record 9, ordinate numerator): specific data type 8
  displacement, 11 velocity, 12 acceleration (or 0/1 with a units label).
* **Reference** (record 10, ordinate denominator): specific data type 13
  (excitation force) or 9 (reaction force) -- a force.

  *A current reference* (an exciter or magnetic-bearing coil current; UFF has no
  data type for it) is flagged by the **units label** ``A`` (or ``mA``) of the
  denominator (record 10 field 6, ``orddenom_axis_units_lab``) -- or by an
  ordinate units label ending in ``/A`` -- with the denominator's specific data
  type 0 (unknown) or 1 (general).  :func:`write_uff58` writes a current
  reference that way (type 1, label ``A``).
* **Units** come from the units labels (record 9 and 10 field 6) when given,
  otherwise SI (m, m/s, m/s^2 per N), or the length and force factors of a
  units data set 164 in the same file.  The ordinate label may hold the whole
  ratio (``m/s^2/N``, ``(1/N)*(m/s²)``, ``g/N``, ``(m/s2)/N``, ``mm/N``,
  ``in/lbf``, ``in/s/lbf``, ``m/A``) or only the response unit with the
  reference unit in the denominator label.  A label is read as a product of
  powers of known units (:func:`parse_units`; case-insensitive, ``µ`` = ``u``,
  exponents as ``^2``, ``**2``, ``²``, ``s2``): length ``m mm um cm in mil
  ft``, time ``s``, ``g`` (9.80665 m/s^2), force ``N kN lbf lb`` (1 lbf =
  4.4482216152605 N), current ``A mA``; it must come out as a displacement,
  velocity or acceleration per force or current.  An unknown label is an error
  naming the data set, the field and the label; ``units={label: label to
  read}`` says how to read it (``mutext frf ... --units LABEL=UNIT``).
* **Text that is not UTF-8** in the header (ID lines, entity names, units
  labels: analyzers write Latin-1, e.g. the byte 0xB2 for ``²``) is read as
  Latin-1, with a note.
* **Nodes and directions** (record 6 fields 6, 7, 9, 10: ``rsp_node``,
  ``rsp_dir``, ``ref_node``, ``ref_dir``).  The node is mapped to a model
  station by ``mapping={node: station}`` (default: station = node).  The
  direction +1/-1 (X translation) is ``x``, +2/-2 (Y) is ``y``; a negative
  direction flips the sign of the response (so that it is the response in +x/+y
  to a force in +x/+y).  A Z translation, a rotation or a scalar (0) direction
  is refused.

Conversion to displacement per force (or current) in SI
-------------------------------------------------------
With :math:`\omega = 2\pi f` [rad/s] and the file's values first scaled to SI
(m, m/s or m/s^2 per N or A),

.. math::

    H_d = H_d^{\text{file}}, \qquad
    H_d = \frac{H_v}{j\omega}, \qquad
    H_d = \frac{H_a}{-\omega^2},

times :math:`-1` if exactly one of the two directions is negative.  The
conversion made is stated in ``FRF.metadata["uff_conversion"]`` (what the file
holds, in what units, and each step: the scale factor with the definitions of
the units it comes from, e.g. ``g = 9.80665 m/s^2``, ``lbf = 4.4482216152605
N``, the division by :math:`j\omega` or :math:`-\omega^2`, a sign flip), and
also in ``metadata["conversion"]`` when the values were changed (the key
every reader uses, :mod:`mutext.rig`).  What the reader did that the user
should know (a 0 Hz line dropped, Latin-1 text) is in
``metadata["notes"]``, a list of str.  The file's nodes, directions, ID lines
and entity names are kept in ``metadata`` (``uff_*`` keys).

Errors
------
Every problem raises :class:`mutext.rig.FRFFileError` naming the file, the
data set (1-based position in the file) and the field: not a UFF file, no data
set 58, a function type that is not an FRF, a real-only ordinate, no frequency
above 0 Hz or a non-increasing frequency, an unknown unit (with what to
change), a direction that is not X or Y, a node not in the mapping.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from mutext.response import FRF
>>> from mutext.uff import write_uff58, read_uff58
>>> f = np.arange(1.0, 6.0)
>>> h = FRF(f, 1 / ((2 * np.pi * 3)**2 - (2 * np.pi * f)**2 + 1j * f), input_station=1, output_station=2)
>>> path = os.path.join(tempfile.mkdtemp(), "h.uff")
>>> _ = write_uff58(path, [h], ordinate="acceleration")
>>> g, = read_uff58(path)
>>> (g.input_station, g.output_station), bool(np.allclose(g.response, h.response, rtol=1e-10))
((1, 2), True)
"""
from __future__ import annotations

# One idea per private module: ``_units`` the units labels (shared with the FRF files of mutext.rig),
# ``_sets`` the file read into data sets (pyuff, Latin-1 headers, data set 164), ``_fields`` the codes and
# fields of a data set 58, ``_read`` a data set 58 as an FRF, ``_ordinate`` its units and conversion to
# displacement per force, ``_write`` FRFs written as data sets 58.

from ._read import drop_non_positive, dropped_note, read_uff58
from ._sets import is_uff_file
from ._units import (G0, KNOWN_UNITS, LBF, Units, motion_units, parse_units, reference_units, relabel,
                     units_hint)
from ._write import write_uff58

__all__ = ["G0", "LBF", "KNOWN_UNITS", "Units", "is_uff_file", "parse_units", "read_uff58", "write_uff58"]
