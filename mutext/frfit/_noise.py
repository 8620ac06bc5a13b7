r"""The relative noise level of a measured FRF, from the data alone (fourth differences of
:math:`\ln G` away from its sharp features)."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._vf import _check_hz

_D4 = np.array([1.0, -4.0, 6.0, -4.0, 1.0])   # fourth difference


def noise_level(freq_hz, response) -> float:
    r"""Relative noise level of a measured FRF, estimated from the data alone.

    With circular complex Gaussian noise of standard deviation :math:`\sigma`
    relative to :math:`|G|` (as :class:`mutext.rig.Noise`),
    :math:`G_k = G^0_k(1 + \sigma e_k)` and, to first order,
    :math:`L_k = \ln G_k = \ln G^0_k + \sigma e_k`.  The fourth difference
    along the frequency index,

    .. math::
        d_k = L_k - 4L_{k+1} + 6L_{k+2} - 4L_{k+3} + L_{k+4},
        \qquad L = \ln|G| + j\,\arg G \ \text{(phase unwrapped)},

    cancels any cubic trend of :math:`L` (mass and stiffness lines, the flanks
    of the resonances) and leaves, for white noise, circular Gaussian samples
    with :math:`E|d_k|^2 = (1+16+36+16+1)\sigma^2 = 70\sigma^2`, so
    :math:`|d_k|` is Rayleigh distributed with median
    :math:`\sqrt{35}\,\sqrt{2\ln 2}\,\sigma`.  The estimate is

    .. math::
        \hat\sigma = \frac{\operatorname{median}_k |d_k|}{\sqrt{35}\,\sqrt{2\ln 2}}

    (the median absolute deviation about zero, the noise having zero mean),
    taken over the samples away from sharp features: a first estimate from all
    samples flags those with :math:`|d_k|` above 4 times its Rayleigh scale
    (3e-4 probability for noise alone), and each run of flagged samples is
    excluded together with as many samples again plus 2 on each side, where a
    resonance or antiresonance still curves :math:`L` faster than a cubic but
    no longer stands out (fewer than 10 samples left: the first estimate).

    Why not simply a median of second differences (variance :math:`6\sigma^2`):
    near a resonance they keep the curvature of :math:`\ln G` over about
    :math:`1/\sqrt\sigma` frequency steps on each side, and on 0.5 Hz grids
    with 1-2 % damping that biased the median 15-30 % high; the fourth
    difference with the exclusion stays within a few percent (scatter 5-10 %
    with 200-500 frequencies).

    Parameters
    ----------
    freq_hz : array_like
        Frequencies [Hz], positive; uniformly or smoothly (e.g. logarithmically)
        spaced, at least 8.
    response : array_like
        Complex response at ``freq_hz``.

    Returns
    -------
    float
        :math:`\hat\sigma`, e.g. 0.01 for 1 % noise.  Noise independent from
        one frequency to the next is assumed; with an absolute noise floor the
        value is a typical (median) relative level.

    Raises
    ------
    mutext.errors.ModelError
        Malformed data (see :func:`fit_frf`) or fewer than 8 frequencies.
    """
    w, G = _check_hz(freq_hz, response, "noise level")
    if w.size < 8:
        raise ModelError(f"noise level: need at least 8 frequencies, got {w.size}")
    L = np.log(np.abs(G)) + 1j * np.unwrap(np.angle(G))
    a = np.abs(np.convolve(L, _D4, mode="valid"))
    rayleigh = np.sqrt(2 * np.log(2))                  # median of a Rayleigh variable of unit scale
    scale = np.median(a) / rayleigh
    flagged = a > 4.0 * scale
    excluded = flagged.copy()
    edges = np.flatnonzero(np.diff(np.r_[0, flagged.astype(int), 0]))
    for i, j in zip(edges[::2], edges[1::2]):          # runs flagged[i:j]
        g = (j - i) + 2
        excluded[max(0, i - g):j + g] = True
    if np.count_nonzero(~excluded) >= 10:
        scale = np.median(a[~excluded]) / rayleigh
    return float(scale / np.sqrt(0.5 * np.sum(_D4 ** 2)))
