r"""Diagnosis: what a model gets wrong against measured FRFs, its cause, the fix and the gain.

:func:`diagnose` takes an engineering model (a lumped chain or a rotor, see
:mod:`mutext.rotor.model`) and measured frequency responses
(:class:`mutext.rig.FRF`, e.g. read with :func:`mutext.rig.read_frf`) and

1. compares model and data channel by channel (the residual over frequency,
   the measured against modelled resonances, the measured resonances the model
   has no partner for);
2. tests hypotheses of the form *kind at location* -- a change of a spring,
   mass or damper, a grounded spring, mass or damper added at a mass or a
   station, a bearing's stiffness or damping, a crack in a shaft element
   (:mod:`~mutext.diagnose.faults.lumped`, :mod:`~mutext.diagnose.faults.rotor`,
   :mod:`~mutext.diagnose.faults.crack`), a bearing's skew cross-coupled
   stiffness (:mod:`~mutext.diagnose.faults.bearing_cross`), a tuned-mass absorber at a mass of
   a chain (three parameters, :mod:`~mutext.diagnose.faults.absorber`); on
   the measurement chain a sensor's or exciter's gain (either sign), one
   file's scale (unit slips, named as such), a sensor's delay, a mass that
   moves with the sensor (:mod:`~mutext.diagnose.faults.channel`); for the whole
   structure all damping scaled and the analyser's frequency axis scaled
   (:mod:`~mutext.diagnose.faults.structure`) -- and **none**, fits the size of
   each, and ranks them;
3. adds further effects by forward selection while the residual stays above
   the noise, each with the same false-alarm control and confirmed on held-out
   data (:mod:`mutext.diagnose._select`);
4. tests whether what is left is the noise (:mod:`mutext.diagnose._fit_quality`)
   and says so first: **explained**, **partly explained** or **not explained**;
   when it is not, finds the station where the misfit lives and what it asks
   for (:mod:`mutext.diagnose._localize`);
5. writes the extended model (the original plus the identified elements) and
   measures the gain on data that the fit did not use.  Only an explained
   result is written as ``model_extended.toml``; anything else is written as
   ``model_extended_NOT_CONFIRMED.toml``.

The verdict
-----------
*Explained*: the final model leaves the fitted and the held-out data at the
noise (a lack-of-fit test against a model-free noise reference with its own
degrees of freedom) and, with an effect, does better on the held-out data
than the engineering model.  *Partly explained*: the effects found do better on
held-out data, but a residual above the noise remains (where, in frequency and
by channel, is reported, and the uncertainties are inflated by the misfit).
*Not explained*: nothing found does better on held-out data, or no effect is
significant while the residual is above the noise.  A size at a bound of its
range is never significant.  Given the same channels measured again at another
excitation level (``repeat=``), a response that depends on the level (a
nonlinear structure, which no hypothesis here can hold) is tested without a
model (:mod:`mutext.diagnose._amplitude`); when it does, the verdict says so
first and the status is at most *partly explained*.

Residual and noise
------------------
The residual of channel :math:`c` at frequency :math:`\omega_i` is the complex
log ratio of model and measurement (as in :mod:`mutext.rotor.tuning`),

.. math::
    r_{ci}(\theta) = \ln\frac{H_c(j\omega_i;\theta)}{\hat H_c(j\omega_i)},\qquad
    \mathrm{RSS}(\theta) = \sum_{c,i} (\mathrm{Re}\,r_{ci})^2 + (\mathrm{Im}\,r_{ci})^2 .

For relative circular complex noise of standard deviation :math:`\sigma` (the
virtual rig's :class:`~mutext.rig.Noise`) each real component of :math:`r`
has variance :math:`\sigma^2/2`.  :math:`\sigma` is estimated from the data
alone, before any model is fitted (model-free rational fits of each channel,
with their degrees of freedom: :mod:`mutext.diagnose._fit_quality`), so the
tests below do not depend on the hypotheses being right.

Hypotheses and their fit
------------------------
Every structural hypothesis changes the dynamic stiffness
:math:`Z(\omega) = K - \omega^2 M + j\omega (C + \Omega G)` by a matrix
:math:`\theta D(\omega)` on a few degrees of freedom :math:`U` (a spring:
:math:`D = S`, a damper :math:`j\omega S`, a mass :math:`-\omega^2 S`, with
:math:`S` the element's pattern, e.g. :math:`e_ie_i^T` to ground or
:math:`(e_i-e_j)(e_i-e_j)^T` between two masses).  With the receptance of the
engineering model :math:`R = Z^{-1}` (shared by all hypotheses: a lumped
chain's one inverse per frequency; a rotor's from one eigen-decomposition of its
state space, :math:`R(\omega) = X\,\mathrm{diag}(1/(j\omega - \lambda))\,Y`, of which only
the pieces below are formed, so that time and memory grow with the number of
stations, not its square at every frequency) the response of the changed model
is exact for any size (Woodbury identity):

.. math::
    H_c(\theta) = H_c(0) - \theta\, R_{oU}\, D\,u,\qquad
    (I + \theta R_{UU} D)\,u = R_{U:}\,b_c ,

    \frac{\partial H_c}{\partial \theta} = -R_{oU}\,(I + \theta D R_{UU})^{-1} D\,u ,

with :math:`o` the output DOF and :math:`b_c` the input vector of the
channel.  A crack is the same with :math:`\theta D` replaced by the exact
cracked-minus-intact stiffness of its shaft element
(:class:`mutext.rotor.crack.Crack`), a function of the depth ratio; an
absorber the same with the impedance :math:`Z(\omega; m_a, k_a, c_a)` of its
condensed degree of freedom, its three parameters fitted together (bounded
least squares in their logarithms, the threshold that of
:math:`\chi^2_3` at the same false-alarm rate, :math:`3\ln N` in the score).  A sensor
or exciter gain :math:`g` multiplies the channels of that sensor or
exciter: :math:`\ln g` enters the residual linearly.  The damping matrix of
the engineering model (modal damping included) is held fixed in this screen.

Each size is fitted by weighted (log) least squares: a scan of the size over
several decades and both signs (where physical) picks the start, Gauss-Newton
steps with the exact derivative above refine it.  The best few hypotheses are
then refitted on the *extended model* itself -- the model file with the new
element, loaded and tuned with :func:`mutext.rotor.tuning.tune` (IPOPT, exact
sensitivities, modal damping recomputed) -- so the reported size is that of
the model file the user receives.

Ranking and the "none" verdict
------------------------------
With :math:`s^2 = \hat\sigma^2/2`, hypothesis :math:`h` (one parameter)
improves the fit by :math:`\Delta\chi^2_h = (\mathrm{RSS}_0 -
\mathrm{RSS}_h)/s^2`.  Under the null hypothesis (model right, residual
noise) :math:`\Delta\chi^2` of one fitted parameter is :math:`\chi^2_1`
distributed; with :math:`m` hypotheses tested, the best is accepted only if

.. math::
    \Delta\chi^2_h > \chi^2_{1}\!\left(1 - \alpha/m\right)

(Bonferroni), so the false-alarm rate is at most :math:`\alpha` (default
1 %) when the model and noise level are right.  Hypotheses are ranked by
:math:`\mathrm{RSS}_h/s^2 + k_h\ln N` (the Bayesian information criterion,
:math:`k_h` = 1 fitted size, 0 for *none*, :math:`N` real residuals).  Others
whose :math:`\mathrm{RSS}` lies within :math:`\chi^2_1(0.95)\,s^2 = 3.84\,s^2`
of the best cannot be told apart from it with the channels measured: they are
reported as ``ambiguous_with``, with the sensor station whose response would
separate them best.

Gain on held-out data
---------------------
Two metrics, before (engineering model) and after (extended model), on data
the fit did not use (``validate`` FRFs; or, when none are given, every
fifth frequency of each fitted channel, held out of the fit):

.. math::
    e_{\mathrm{rel}} = \sqrt{\operatorname{mean}\frac{|H - \hat H|^2}{|\hat H|^2}},\qquad
    e_{\mathrm{dB}} = \sqrt{\operatorname{mean}\left(20\log_{10}\frac{|H|}{|\hat H|}\right)^2},

and the gain :math:`e_{\mathrm{rel}}^{\mathrm{before}}/e_{\mathrm{rel}}^{\mathrm{after}}`.
A well-diagnosed model reaches the noise level after the fix.

A worked example is in the Examples of :func:`diagnose`.

References
----------
.. [FM95] M. I. Friswell and J. E. Mottershead, *Finite Element Model Updating
   in Structural Dynamics*, Kluwer, 1995 (sensitivity-based updating and error
   localisation).
.. [Sch78] G. Schwarz, "Estimating the dimension of a model", *Ann. Statist.*
   6 (1978) 461-464 (BIC).
.. [PS12] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012 (noise on FRFs).
"""
from ._core import HOLDOUT_EVERY, diagnose
from ._extend import extended_model_text, mbi_reading, write_model
from ._hypotheses import KINDS, Hypothesis, hypotheses
from ._result import UNIT_SLIPS, ChannelComparison, Diagnosis, Finding, ResonanceRow
from . import faults
from ._sidebands import SidebandCandidate, SidebandEvidence, sideband_evidence

__all__ = ["diagnose", "Diagnosis", "Finding", "Hypothesis", "ChannelComparison", "ResonanceRow",
           "hypotheses", "extended_model_text", "write_model", "mbi_reading", "KINDS", "HOLDOUT_EVERY",
           "sideband_evidence", "SidebandEvidence", "SidebandCandidate", "UNIT_SLIPS", "faults"]
