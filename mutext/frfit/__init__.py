r"""Rational models of measured frequency responses (vector fitting).

A measured FRF :math:`G_k = G(j\omega_k)` is approximated by a stable, strictly
proper rational function in pole-residue form,

.. math::
    H(s) = \sum_{i=1}^{n} \frac{r_i}{s - p_i},

with complex poles in conjugate pairs.  The poles are found by the vector
fitting iteration [GS]_: with the current poles :math:`p_i`, a scaling function
:math:`\sigma(s) = 1 + \sum_i \tilde r_i/(s - p_i)` and the numerator are fitted
by linear least squares from :math:`\sigma(s) G(s) \approx \sum_i r_i/(s-p_i)`;
the zeros of :math:`\sigma` are the new poles (unstable ones are reflected into
the left half plane).  With the poles fixed, the residues are a final linear
least-squares fit.  Each frequency is weighted by :math:`1/|G_k|`, so a response
spanning decades is fitted in relative terms, resonances and antiresonances
alike.

The residual reported is the RMS relative error
:math:`\sqrt{\operatorname{mean}_k |H(j\omega_k) - G_k|^2/|G_k|^2}`: with noisy
data it cannot go below the noise level, and a fit well above it means the
order is too low.

:func:`fit_magnitude` fits a magnitude alone (the D scalings of mu-synthesis,
:mod:`mutext.dk`): the same vector-fitting step (:func:`_relocate`) on
:math:`|D|^2` as a rational function of :math:`\omega^2`, a least-squares fit
of the residues kept positive, and a spectral factorisation to a stable,
minimum-phase :math:`\hat D(s)`.

:func:`resonances` reads the lightly damped pole pairs of such a fit as measured
resonances (natural frequency, damping ratio, peak) with standard
uncertainties from a parametric bootstrap; :func:`noise_level` estimates the
relative noise of the data it needs.

The package keeps one idea per module: ``_vf`` (the checked data and the
vector-fitting core: basis, realisation, stable poles, :func:`_relocate`),
``_rational`` (:func:`fit_frf`, :func:`fit_frf_auto`, :class:`RationalFit`),
``_noise`` (:func:`noise_level`), ``_resonances`` (:func:`resonances`, the
bootstrap), ``_magnitude`` (:func:`fit_magnitude`, :class:`MagnitudeFit`, the
spectral factorisation) and ``_envelope`` (:func:`fit_envelope`).

References
----------
.. [GS] B. Gustavsen and A. Semlyen, "Rational approximation of frequency domain
   responses by vector fitting", IEEE Trans. Power Delivery 14(3), 1999.
"""
from __future__ import annotations

from ._envelope import fit_envelope
from ._magnitude import MagnitudeFit, fit_magnitude
from ._noise import noise_level
from ._rational import RationalFit, fit_frf, fit_frf_auto
from ._resonances import Resonance, resonances

# private names other modules reach for (the diagnosis's fit-quality check, the D scalings)
from ._magnitude import _constant  # noqa: F401
from ._vf import _basis, _lstsq, _realisation, _split_poles  # noqa: F401

__all__ = ["RationalFit", "Resonance", "MagnitudeFit", "fit_envelope", "fit_frf", "fit_frf_auto", "fit_magnitude",
           "noise_level", "resonances"]
