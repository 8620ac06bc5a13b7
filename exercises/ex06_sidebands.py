r"""Exercise ex06: predict and find the sidebands of a cracked rotor at speed.

Fill in the three functions below, then check that your file runs with::

    mutext check ex06_sidebands exercises/ex06_sidebands.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

A rotor spinning at ``F`` Hz whose stiffness changes as it turns is linear
time-periodic.  Forced at a frequency ``f`` it also responds at ``f + kF``,
and its measured frequency response shows small extra resonances, sidebands,
where ``f + kF`` meets a natural frequency ``f_n``:

.. math::
    f = f_n - kF, \qquad k = \pm 1, \pm 2, \pm 3 .

* A breathing crack (it opens and closes once per turn) gives the orders
  ``|k| = 1`` (and 2 and 3): "once per revolution".
* An always-open crack, or any asymmetric shaft, changes twice per turn and
  gives only ``|k| = 2``: "twice per revolution".
* A time-invariant change (a healthy rotor, softer bearings, a loss of
  stiffness that does not turn with the shaft) moves the resonances but gives
  no sidebands: "none".

The sweeps of (b) and (c) are those of the book's rig (chapter "The cracked
rotor at speed"): force at station 12, displacement at station 13, 20-225 Hz
in 0.5 Hz steps, shaft at 9 to 11 Hz (the speed is an argument), with relative noise: each
measured value is ``H (1 + noise * n)`` with ``n`` circular complex Gaussian,
``E|n|^2 = 1``.  Sidebands are small: from about a tenth of a percent of the
response (an always-open crack's) to a few percent (a deep breathing crack's).

Rules
-----
* You may import numpy and scipy.  Importing ``mutext.diagnose``,
  ``mutext.rotor``, ``mutext.rig``, ``mutext.report``, ``mutext.commands``,
  ``mutext.examples`` or ``mutext.grading`` (which make these sweeps or
  compute these answers) is blocked and scores 0.
* Arguments arrive as Python lists: convert them with ``np.asarray``.  All
  frequencies, including the speed ``F``, are in Hz (not rad/s).
* Each function has a time limit (60 s by default).
"""
import numpy as np

#: Verdicts, in the order used by :func:`classify`'s return value.
VERDICTS = ("none", "once per revolution", "twice per revolution")


def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    """(a) Where the sidebands of the given modes must appear.

    Parameters
    ----------
    natural_frequencies_hz : list of float
        The natural frequencies ``f_n`` [Hz].
    speed_hz : float
        The running speed ``F`` [Hz].
    orders : list of int
        Positive orders, e.g. ``[1, 2, 3]`` or ``[2]``; ``k`` runs over
        ``+order`` and ``-order`` of each.
    f_min, f_max : float
        The band [Hz]; both ends belong to it.

    Returns
    -------
    numpy array
        Every ``f_n - k * F`` (each ``f_n``, each ``k`` in +-orders) with
        ``f_min <= f <= f_max``, sorted in increasing order; values closer
        than 1e-9 Hz to the previous kept value are dropped (two modes can
        share a sideband).  Checked to 1e-9 Hz.
    """
    raise NotImplementedError


def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    """(b) How far the response departs from a smooth baseline at ``f_candidate``.

    Recipe (follow it exactly; the result is checked to 0.1 %):

    1. ``H = re + 1j * im`` and ``Y = 1 / H``.  The inverse (the dynamic
       stiffness) is nearly quadratic in ``f`` near a mode,
       ``Y ~ (f_n^2 - f^2 + 2j zeta f_n f) / A``, where ``H`` itself is not
       smooth enough: its curvature would hide a sideband of 0.3 %.
    2. ``x = f - f_candidate``.  The window is ``|x| <= half_width_hz``, the
       centre is ``|x| <= 1`` (Hz); both limits included.
    3. Fit ``Y ~ c2 x^2 + c1 x + c0`` (complex coefficients, linear least
       squares, e.g. ``np.linalg.lstsq(np.vander(x, 3), Y)``) to the points of
       the window that are NOT in the centre: a sideband in the centre must not
       pull the baseline.
    4. Evaluate the baseline ``B`` at the centre points and return the
       largest ``|Y - B| / |B|`` over them.

    Parameters
    ----------
    freq_hz, re, im : list of float
        A measured sweep: frequencies [Hz], real and imaginary parts [m/A].
    f_candidate : float
        Where a sideband could be [Hz].
    half_width_hz : float
        Half width of the window [Hz] (e.g. 3).

    Returns
    -------
    float
        The relative size of the departure (about the relative size of a
        sideband there; about 2-3 times ``noise`` where there is none).
    """
    raise NotImplementedError


def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    """(c) Once per revolution, twice per revolution, or no sidebands.

    Recipe (it classifies all the graded sweeps right):

    1. The modes in the data: for each given natural frequency inside the
       sweep, the frequency of the largest ``|H|`` within 5 % of it (a crack
       or a bearing moves the resonances a little; the model's ``f_n`` only
       says where to look).  Keep the distinct ones.
    2. The candidates: ``fc = f_m - k F`` for each data mode ``f_m`` and
       ``k = +-1, +-2, +-3``, keeping those whose window
       ``[fc - 3, fc + 3]`` lies inside the sweep and that are at least 6 Hz
       from every data mode and every given natural frequency (next to a
       resonance, even 1/H is not quadratic and the baseline fails).
    3. Order ``|k|`` is present if ``sideband_size(..., fc, 3.0)`` of one of
       its candidates exceeds ``5 * noise``.  (Without sidebands the size is
       the noise, scattered over the centre points and the fit: it stays below
       about 4 noise.  A fixed threshold fails when the noise changes.)
    4. "once per revolution" if order 1 or 3 is present, else "twice per
       revolution" if order 2 is, else "none".

    Parameters
    ----------
    freq_hz, re, im : list of float
        A measured sweep, as in (b).
    natural_frequencies_hz : list of float
        The healthy model's natural frequencies [Hz] (two per mode: the
        rotor bends in two planes).
    speed_hz : float
        The running speed ``F`` [Hz].
    noise : float
        The relative noise level of the sweep (e.g. 5e-4).

    Returns
    -------
    int
        ``VERDICTS.index(verdict)``: 0 "none", 1 "once per revolution",
        2 "twice per revolution".  The graded sweeps come from known models
        (breathing crack, open crack, time-invariant rotors); the verdict
        must be that of the model.
    """
    raise NotImplementedError
