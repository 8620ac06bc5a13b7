r"""A rotor with a breathing crack at speed: a linear time-periodic system.

A transverse crack turns with the shaft.  Under weight dominance it opens
when its mouth faces down and closes half a turn later, so the shaft
stiffness changes with the rotation angle :math:`\theta = \Omega t + \theta_0`:

.. math::
    M\ddot q + (C + \Omega G)\dot q + \Big(K_h + \sum_{\text{cracks}} \big[
    g_{xx}(\theta) A_{xx} + g_{yy}(\theta) A_{yy} + g_{xy}(\theta) A_{xy}\big]\Big) q = B u,

with :math:`K_h` the rotor without the crack, :math:`A` the changes of the
fully open crack (:meth:`mutext.rotor.crack.Crack.directional_deltas`) and
:math:`g` the breathing law (:func:`mutext.rotor.crack.breathing_weights`).
The stiffness is periodic with one revolution, :math:`K(t) = \sum_m K_m
e^{jm\Omega t}` (orders up to 3 for the Mayes law, 2 for the gaping
notch, all orders for the Gasch switch).

**Harmonic transfer functions.**  Forced at :math:`e^{j\omega t}`, the
steady response is :math:`q(t) = \sum_k Q_k e^{j(\omega + k\Omega)t}` and
harmonic balance gives, for :math:`k = -N..N` (truncated),

.. math::
    Z(\omega + k\Omega)\,Q_k + \sum_{m \ne 0} K_m Q_{k-m} = B\,\delta_{k0},\qquad
    Z(\nu) = K_0 - \nu^2 M + j\nu(C + \Omega G),

a block system of size :math:`(2N+1)\,n` per frequency
(:func:`harmonic_response`).  For the smooth laws the truncation converges
fast (Mayes: :math:`2.5\cdot10^{-6}` at the default N = 6 on the thesis
rotor); the Gasch switch has harmonics decaying like :math:`1/m` and
converges like :math:`1/N` (0.4 % at N = 24, 0.1 % at N = 64 near the second
mode; the analyzer's FRF over a sweep: 7 % of its peak at N = 6).
:func:`analyzer_truncation` estimates the truncation error from the changes
between N = 2, 4, 8, ... and chooses N for a tolerance, with a Richardson
extrapolation in :math:`1/N` where that is better (``harmonics="auto"`` of
:func:`analyzer_frf` and :func:`analyzer_combination`; the default of
:func:`mutext.rig.measure_rotor`).  :math:`H_k = C_y Q_k` are the harmonic
transfer functions ([Wer91]_): :math:`H_0` is what reaches the excitation
frequency, :math:`H_{k \ne 0}` the sidebands at :math:`\omega + k\Omega`.

**What the analyzer measures.**  A stepped-sine analyzer drives
:math:`u = a\cos(\omega t + \varphi)`, waits a settling time
:math:`t_s`, and correlates the response with the excitation over a whole
number of revolutions :math:`T`:
:math:`\hat H = \frac{2}{aT}\int_{t_s}^{t_s+T} y\,e^{-j(\omega t+\varphi)}dt`.
With the harmonic transfer functions this is exactly

.. math::
    \hat H(\omega) = H_0(\omega) + e^{-2j\varphi}\sum_k \overline{H_{-k}(\omega)}\;
    \frac{1}{T}\int_{t_s}^{t_s+T} e^{j(k\Omega - 2\omega)t}dt,

(:func:`analyzer_frf`): the second term, from the negative-frequency half of
the real excitation, matters only where :math:`2\omega` is near a multiple
of :math:`\Omega`.  The sidebands make the measured FRF resonate where
:math:`\omega \pm k\Omega` meets a natural frequency, which no
time-invariant model can reproduce.

**Combination frequencies.**  The first-order signature of the
time-periodic rotor is not in :math:`\hat H` (where it enters only through
the resonances of the small :math:`H_{k\ne0}` terms folded back) but at the
combination frequencies :math:`\omega + k\Omega` themselves: an analyzer
that also correlates the response with :math:`e^{-j((\omega + k\Omega)t +
\varphi)}` (the rotor's angle known from a once-per-revolution mark)
measures

.. math::
    \hat H_k(\omega) = H_k(\omega) + e^{-2j\varphi}\sum_{k'} \overline{H_{k'}(\omega)}\;
    \frac{1}{T}\int_{t_s}^{t_s+T} e^{-j(2\omega + (k + k')\Omega)t}dt

(:func:`analyzer_combination`; :math:`k = 0` is :math:`\hat H`).  Over whole
revolutions the excitation line itself averages out exactly, so
:math:`\hat H_k` is the off-diagonal harmonic transfer function, of the
order of the crack's stiffness change, where :math:`\hat H` holds it only
squared (a sideband is :math:`H_{-k}` turned back by a second pass through the
crack) or near the resonances :math:`\omega + k\Omega = \omega_n`.

**Brute force.**  :func:`stepped_sine` integrates the same equations in time
(fourth-order Runge-Kutta on a modal basis, the breathing law evaluated
directly, not through its Fourier series), with the analyzer's settling time
and correlation, as an independent check of the harmonic balance.

The package holds one module per idea: ``_model`` (:class:`PeriodicRotor`,
its reduction, :func:`periodic_rotor`), ``_balance`` (the harmonic-balance
solve, :class:`HarmonicResponse`), ``_analyzer`` (:func:`harmonic_response`,
the analyzer's steady-state responses, the truncation's convergence),
``_truncation`` (the estimated truncation error and the automatic choice of N) and
``_stepped_sine`` (the time integration); every name is imported from
``mutext.rotor.periodic``.

Units: SI (m, N, A, s); frequencies in Hz at the interface, rad/s inside.

References
----------
.. [Wer91] N. M. Wereley, *Analysis and control of linear periodically time
   varying systems*, PhD thesis, MIT, 1991 (harmonic transfer functions).
.. [Ga93] R. Gasch, "A survey of the dynamic behaviour of a simple rotating
   shaft with a transverse crack", *J. Sound Vib.* 160(2) (1993) 313-332.
.. [Mad] R. J. Madden, M.S. thesis, Cleveland State University, ch. 4 (the
   sweeps: 0.1 A, 40 revolutions per correlation, 700 ms settling, 10 Hz).
"""
from __future__ import annotations

from ._analyzer import ANALYZER, analyzer_combination, analyzer_frf, harmonic_convergence, harmonic_response
from ._balance import HarmonicResponse
from ._model import PeriodicRotor, periodic_rotor
from ._stepped_sine import stepped_sine
from ._truncation import AUTO, Truncation, analyzer_truncation

__all__ = ["PeriodicRotor", "HarmonicResponse", "periodic_rotor", "harmonic_response", "analyzer_frf",
           "analyzer_combination", "stepped_sine", "harmonic_convergence", "ANALYZER", "analyzer_truncation",
           "Truncation", "AUTO"]
