r"""Mu-synthesis by D-K iteration.

For a generalized plant ``P`` whose first inputs/outputs are the channels of
a block structure :math:`\boldsymbol\Delta` (uncertainty and performance
blocks) and whose last are the measurements ``y`` and controls ``u``, D-K
iteration alternates two steps on the upper bound

.. math::
    \min_K \sup_\omega \inf_{D\in\mathcal D}
    \bar\sigma\big(D(j\omega)\,\mathcal F_\ell(P, K)(j\omega)\,D(j\omega)^{-1}\big)

([ZDG]_ sec. 11.5; [SP]_ sec. 8.12; Doyle's original scheme):

* **K step**: with rational, stable, minimum-phase scalings :math:`\hat D(s)`
  fixed, an H-infinity controller for :math:`\hat D P \hat D^{-1}` by
  :func:`mutext.hinf.hinfsyn` (0.1 % above the optimal level; slycot's
  Riccati synthesis, verified, if the LMI controller fails; then once more
  with lower-order scalings);
* **D step**: the optimal diagonal scalings :math:`D(\omega)` of the new
  closed loop on a frequency grid, each block's fitted by a stable,
  minimum-phase, biproper transfer function of order 0-5.

The pointwise scalings minimise the convex :math:`\log\bar\sigma(e^XMe^{-X})`
(one log scaling per block, the last fixed to 0) by the same
Osborne-plus-ellipsoid method as ``mutext.mu.mu_upper(method="osborne")``,
run on all frequencies at once and warm-started from the previous iteration.

What the fit must achieve is not closeness to the pointwise optimum but a
scaled closed loop whose peak stays near the peak of :math:`\mu`: far from the
peak the bound has slack and many scalings are equally good.  For every block
and frequency the D step therefore computes the interval of
:math:`\log d_k` over which :math:`\bar\sigma(DMD^{-1})` stays below
:math:`(1 + \text{fit\_tol})\,\max_\omega\mu` (a convex function of
:math:`\log d_k`, so the interval is found by bisection), and fits the middle of
that interval, weighted by the inverse of its half width.  Orders are raised
one at a time for the worst-fitted block until every fit stays inside half its
interval or a budget of added states is spent (the LMI K step slows down
steeply with the plant order); frequencies where the fitted scalings together
still exceed the level get narrower intervals and the fit is repeated.

The fit (:func:`fit_dscale`) works on :math:`\Phi(x) = |D(j\omega)|^2`,
:math:`x = \omega^2`, a positive rational function of :math:`x`.  Its poles
(real, or complex pairs for resonant scalings) are located by vector fitting (a
sequence of linear least-squares problems, Gustavsen and Semlyen [GS]_) and its
residues by a convex quadratic program with :math:`\Phi \ge 0` imposed on a
dense grid; a spectral factorisation then gives :math:`\hat D(s)` with all
poles and zeros in the left half plane.

Real parameters are treated as complex scalars in the iteration (D scalings
only, as in the classical ``dksyn``).  :func:`dgk_iteration` keeps them real
where it counts: it runs this iteration with the real parameters' ranges
scaled by a factor :math:`c \le 1` in the K steps and picks :math:`c` by the
D-G bound of the loop of the plant as given (see its docstring for the
approximation).  On the two-mass problem at 0.041 m it lowers the D-G bound
from 1.0187 to 1.0148 with the same 16-state controller budget.  A full D-G-K
iteration (``musyn``; Young 1996) would fit a G scaling per parameter and
frequency: for ``1 x 1`` real blocks these are discs
(:func:`mutext.mu.dg_disc` turns the D-G bound into the equivalent complex
problem, the disc centres :math:`jb_k(\omega)/\beta` closed as a feedback
around the real channels), and a K step needs stable rational filters for
them.  :math:`b_k` is odd in :math:`\omega` (so :math:`jb_k` acts like a
differentiator, and a stable filter adds a real part that widens the disc)
and not unique away from the peak.  Prototypes of that kind on the two-mass
problem (fitted centre filters; the pointwise "mu-K" shrinkage of the real
channels; Young's affine form with para-skew G filters made causal by an
all-pass, exact on the axis) gave D-G bounds of 1.02-1.49 (the book's mu
chapter has the details).  :func:`refine_controller` avoids the filters: it
keeps the optimal D-G scalings of every frequency and moves the controller's
parameters instead (trust-region steps on the peak of the scaled bound, each
checked on the recomputed D-G bound); 300 steps take the D-G-K controller
with 20 states from 1.0131 to 0.9896 (AB13MD; the thesis: 0.989).

After the iteration the best closed loop is analysed
with the optimal, unfitted scalings on a fine grid whose peaks are refined
(every value is :math:`\bar\sigma(DMD^{-1})` for an explicit :math:`D`, a
certified bound at that frequency), with lower bounds at the peaks
(:func:`mutext.mu.mu_sweep`) and, when the structure has real blocks, the
D-G bound at the frequencies that decide its peak
(:func:`mutext.mu.mu_upper`, ``method="fast"``).

Weights with integrators or near-axis poles.  A performance weight that
approximates an integrator by a pole very close to the axis (Skogestad and
Postlethwaite's distillation column: :math:`W_P` with poles at -1e-6 rad/s)
puts into the generalized plant states that the measurements do not see: they
stay poles of every closed loop, so the loop is stable only if they are stable
(an exact integrator, a pole at 0, cannot be handled: move it to a small
negative value first), and :math:`\mu` at frequencies below them is set by the
controller's gain there.  The iteration treats them as follows, with nothing
shifted, so that every reported number is for the plant as given:

* the K step works on the plant as given (:func:`mutext.hinf.hinfsyn`: the
  Riccati central controller copes with the stiff Lyapunov and Riccati
  equations; an LMI-only K step could not, and its error names the poles);
* the D steps' default grid leaves out poles that lie three decades or more
  below the rest of the plant's poles (:func:`near_axis_poles`; the grid spans
  1.5 decades beyond the other poles): fitting scalings over eleven decades
  costs fit accuracy where the peak of :math:`\mu` is (on the distillation
  column, 1.064 against 1.052 after the same iterations);
* the final analysis grid does reach 1.5 decades below them, so a peak of
  :math:`\mu` at low frequency is not missed; ``DKResult.near_axis_poles``
  lists them, ``DKResult.max_pole_real`` is the largest real part of the
  closed-loop poles of the plant as given, and a note records both.

The scalings converge slowly on this problem (about 0.2 % per iteration), so
the defaults fit them finely (``fit_tol=5e-4``) and keep iterating while a
step gains 0.1 % (``rel_improvement=1e-3``, ``patience=2``, up to
``max_iter=20``): 1.0273 with an 18-state controller in about 3 s, where
coarser fits (``fit_tol=0.02, rel_improvement=0.01, patience=1``) stop at
1.050.  The K steps build the central controller 0.1 % above the scaled
plant's optimal level (a robust path); the best loop's K step is redone
0.01 % above it at the end and kept where its peak is lower
(``benchmarks/bench_dk.py`` compares the defaults with dkpy).

The package keeps one idea per module: ``_dscale`` (the fitted scalings and the
scaled plant), ``_dstep`` (the D step), ``_kstep`` (the K step), ``_sweep``
(grids, the peak-refined sweeps and the final analysis), ``_loop``
(:func:`dk_iteration` and :class:`DKResult`), ``_dgk`` (:func:`dgk_iteration`),
``_modal``, ``_dgstep`` and ``_refine`` (:func:`refine_controller`), ``_branch``
(:func:`branch_mu`) and ``_report`` (the printed tables and the heartbeat).

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 11.
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005, sec. 8.12.
.. [GS] B. Gustavsen and A. Semlyen, "Rational approximation of frequency
   domain responses by vector fitting", *IEEE Trans. Power Delivery* 14
   (1999) 1052-1061.
"""
from __future__ import annotations

from ._branch import branch_mu
from ._dgk import dgk_iteration, real_scaled_plant
from ._dscale import DScaleFit, fit_dscale, fit_dscale_auto, scaled_plant
from ._loop import DKResult, dk_iteration
from ._refine import refine_controller
from ._sweep import NEAR_AXIS_GAP, near_axis_poles  # noqa: F401  (the default gap)

# private names the tests and benchmarks reach for (the functions themselves live in the
# modules named; a test that replaces one patches it in the module that looks it up)
from ._kstep import _k_step  # noqa: F401
from ._modal import _augmented_loop, _Modal  # noqa: F401
from ._dgstep import _dg_point  # noqa: F401
from ._sweep import _default_dk_grid, _final_analysis  # noqa: F401

__all__ = ["DScaleFit", "fit_dscale", "fit_dscale_auto", "scaled_plant", "DKResult", "dk_iteration",
           "dgk_iteration", "real_scaled_plant", "refine_controller", "near_axis_poles", "branch_mu"]
