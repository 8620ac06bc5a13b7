r"""Frequency-response files and a virtual test rig.

Measured frequency response functions (FRFs) of the rotor rig are exchanged
as small text files, one input-output channel per file.

File format
-----------
::

    # input_station: 12
    # input_quantity: current
    # input_unit: A
    # output_station: 13
    # output_quantity: displacement
    # output_unit: um
    # speed_hz: 10
    # rig: cracked rotor, ball bearings
    freq_hz,re,im
    20.0,1.25e+01,-3.1e-01
    20.5,1.27e+01,-3.3e-01
    ...

* Header lines ``# key: value`` come first.  Required keys:
  ``input_station`` (int), ``input_quantity`` (``force`` or ``current``),
  ``input_unit`` (``N``, ``kN``, ``lbf``, ``lb`` for a force, ``A``, ``mA``
  for a current), ``output_station`` (int), ``output_quantity``
  (``displacement``, ``velocity`` or ``acceleration``), ``output_unit``
  (``m``, ``mm``, ``um``, ``in`` ...; ``m/s``, ``mm/s``, ``in/s`` ...;
  ``m/s^2``, ``m/s²``, ``g`` ... -- any label of
  :func:`mutext.uff.parse_units` of that quantity, which may also hold the
  whole ratio, e.g. ``(1/N)*(m/s²)``, if it agrees with ``input_unit``).
  Optional: ``speed_hz`` (float, running speed), ``input_direction`` and
  ``output_direction`` (``x`` or ``y``, the plane of a rotor; default ``x``),
  ``input_name`` and ``output_name`` (the model's port names).  Any other ``# key: value`` is kept
  as metadata (strings); ``excitation`` (the sweep's force or current amplitude, e.g. ``2 N``) is
  reported by ``mutext diagnose --repeat`` (sweeps at two levels compared).  A combination-frequency response (a time-periodic
  rotor's response at :math:`f + kF` to excitation at :math:`f`, written by
  :func:`measure_rotor` with ``combination=``) says so with ``order: k``
  (integer, not 0) and ``response_frequency: f_exc + k * speed_hz``; its rows
  are on the excitation frequency and it needs ``speed_hz``.  Keys are case-sensitive and may appear once.
* Then the CSV header line ``freq_hz,re,im`` and one row per frequency:
  frequency in Hz (strictly increasing) and the real and imaginary parts of
  the response in ``output_unit`` per ``input_unit`` (e.g. um/A).  Blank
  lines are ignored.  Rows at or below 0 Hz at the start (an analyzer's 0 Hz
  line) are dropped with a note; a file with no row above 0 Hz is an error.
* UTF-8 text; a file that is not UTF-8 (``µm`` or ``m/s²`` written in
  Latin-1) is read as Latin-1, with a note.

:func:`read_frf` converts the response to displacement per force or current
in SI (m/N or m/A): units scaled, velocity divided by :math:`j\omega`,
acceleration by :math:`-\omega^2` (:math:`\omega = 2\pi f`).  Every format
error raises :class:`FRFFileError` naming the file, the line and the field; an
unknown unit also says what to change (edit the label, or pass
``units={label: label to read}``).

What the readers tell about a file read, in :attr:`FRF.metadata`:

* ``metadata["notes"]``: a list of str, present only when there is
  something to note (lines at or below 0 Hz dropped, text read as Latin-1).
  ``mutext frf convert`` and ``mutext frf resonances`` print them.
* ``metadata["conversion"]``: a str, present when the values were changed:
  what the file held and in what units, what it became, and each step (the
  scale factor with the definitions of the units it comes from, e.g.
  ``g = 9.80665 m/s^2``, ``in = 0.0254 m``, ``lbf = 4.4482216152605 N``;
  the division by :math:`j\omega` or :math:`-\omega^2`).  A Universal File
  also states it, changed or not, in ``metadata["uff_conversion"]``.
* ``metadata["file_output_unit"]``, ``metadata["file_input_unit"]``: the
  units labels as written.

:func:`write_frf` writes none of these back (the file it writes holds SI
values read as they stand).

Universal File Format data set 58 (``.uff``/``.unv``, the export of modal-test
software) is read too: :func:`read_frf` and :func:`read_frfs` hand such a file
to :func:`mutext.uff.read_uff58`, which converts velocity or acceleration per
force to displacement per force in SI; :func:`mutext.uff.write_uff58` writes it.

The virtual rig :func:`measure` produces the same :class:`FRF` objects from
a model, with optional measurement noise, so that identification code can be
exercised on data with a known truth.  The thesis sweeps ([Mad]_ sec. 4.3)
were linear sine sweeps from 20 to 1000 Hz in 0.5 Hz steps with a 0.1 A
exciter current at 10 Hz running speed, truncated to 20-225 Hz because the
response above is dominated by noise; :func:`sweep_frequencies` reproduces
that grid.

References
----------
.. [Mad] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University,
   ch. 4.
.. [Pin] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012, sec. 2.4 (circular
   complex normal noise on FRF measurements).
"""
from __future__ import annotations

# One idea per private module.  The FRF file format: ``_format`` its keys, quantities and units, ``_csv`` the
# text of a file read, ``_read`` files read (UTF-8 or Latin-1; a Universal File handed to mutext.uff),
# ``_write`` a file written.  The virtual rig: ``_noise`` the measurement noise, ``_measure`` a model's channel
# measured, ``_rotor`` a finite-element rotor measured (the analyzer on a breathing crack).
from ..response import FRF, INPUT_UNITS, OUTPUT_UNITS, FRFFileError, sweep_frequencies
from ._format import CSV_HEADER
from ._measure import (THESIS_ANALYSIS_BAND_HZ, THESIS_EXCITATION_A, THESIS_SPEED_HZ, THESIS_SWEEP_HZ, measure,
                       with_noise)
from ._noise import Noise
from ._read import read_frf, read_frfs
from ._rotor import measure_rotor
from ._write import write_frf

__all__ = [
    "FRF", "FRFFileError", "Noise", "read_frf", "write_frf", "read_frfs", "measure",
    "sweep_frequencies", "INPUT_UNITS", "OUTPUT_UNITS", "CSV_HEADER", "measure_rotor", "with_noise",
    "THESIS_SWEEP_HZ", "THESIS_ANALYSIS_BAND_HZ", "THESIS_EXCITATION_A", "THESIS_SPEED_HZ",
]

