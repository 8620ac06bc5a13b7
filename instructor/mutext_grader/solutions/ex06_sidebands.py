r"""Reference solution of exercise ``ex06_sidebands``: sidebands of a cracked rotor at speed.

(a) is the formula :math:`f = f_n - kF`; (b) fits a complex quadratic to the
inverse of the response (the dynamic stiffness, nearly quadratic in f near a
mode) around a candidate, leaving the centre out, and measures how far the
centre departs from it; (c) refines the modes on the data, tests every
candidate far enough from a resonance, and counts an order as present when a
candidate's size exceeds five times the noise.  numpy only; Hz throughout.
"""
from __future__ import annotations

import numpy as np

VERDICTS = ("none", "once per revolution", "twice per revolution")
CENTRE_HZ = 1.0
HALF_WIDTH_HZ = 3.0
MODE_SEARCH = 0.05        # a mode is looked for within 5 % of each given natural frequency
CLEARANCE_HZ = 6.0        # candidates closer than this to a resonance are not tested
THRESHOLD = 5.0           # in units of the noise


def sideband_frequencies(natural_frequencies_hz, speed_hz, orders, f_min, f_max):
    fn = np.asarray(natural_frequencies_hz, float).ravel()
    ks = [s * abs(int(k)) for k in orders for s in (1, -1)]
    c = np.sort(np.array([x - k * float(speed_hz) for x in fn for k in ks], float))
    c = c[(c >= f_min) & (c <= f_max)]
    out = []
    for x in c:
        if not out or x - out[-1] > 1e-9:
            out.append(float(x))
    return np.array(out)


def sideband_size(freq_hz, re, im, f_candidate, half_width_hz):
    f = np.asarray(freq_hz, float)
    y = 1.0 / (np.asarray(re, float) + 1j * np.asarray(im, float))
    x = f - float(f_candidate)
    window = np.abs(x) <= half_width_hz
    centre = np.abs(x) <= CENTRE_HZ
    fit = window & ~centre
    coef = np.linalg.lstsq(np.vander(x[fit], 3), y[fit], rcond=None)[0]
    base = np.vander(x[centre], 3) @ coef
    return float(np.max(np.abs(y[centre] - base) / np.abs(base)))


def _data_modes(f, h, natural_frequencies_hz):
    """The frequency of the largest |H| within 5 % of each given natural frequency in the band."""
    out = set()
    for fn in natural_frequencies_hz:
        near = np.abs(f - fn) <= MODE_SEARCH * fn
        if f.min() < fn < f.max() and near.any():
            out.add(float(f[np.flatnonzero(near)[np.argmax(np.abs(h[near]))]]))
    return sorted(out)


def classify(freq_hz, re, im, natural_frequencies_hz, speed_hz, noise):
    f = np.asarray(freq_hz, float)
    h = np.asarray(re, float) + 1j * np.asarray(im, float)
    given = [float(x) for x in natural_frequencies_hz]
    modes = _data_modes(f, h, given)
    found = set()
    for fm in modes:
        for k in (1, -1, 2, -2, 3, -3):
            fc = fm - k * speed_hz
            if fc - HALF_WIDTH_HZ < f.min() or fc + HALF_WIDTH_HZ > f.max():
                continue
            if min(abs(fc - x) for x in modes + given) < CLEARANCE_HZ:
                continue
            if sideband_size(f, h.real, h.imag, fc, HALF_WIDTH_HZ) > THRESHOLD * noise:
                found.add(abs(k))
    if found & {1, 3}:
        return VERDICTS.index("once per revolution")
    if 2 in found:
        return VERDICTS.index("twice per revolution")
    return VERDICTS.index("none")
