r"""Exercise ex07: the M-Delta loop and the small-gain theorem.

Fill in the four functions below, then check that your file runs with::

    mutext check ex07_small_gain exercises/ex07_small_gain.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

The two-mass system of the thesis (sec. 2.3): ``m1`` hangs from ``m2``
through the spring ``k1``, the spring ``k2`` ties ``m2`` to the ground, the
control force ``u`` acts on ``m2`` and the sensor measures ``y = x2``.  No
damper: all damping comes from the controller ``u = K y``.  Both springs are
uncertain, ``k_i (1 + r_i delta_i)`` with ``|delta_i| <= 1``.  Pulled out of
the loop, the perturbation sees the system

.. math::
    z = M(s)\,w,\qquad w = \Delta z,\qquad \Delta = \operatorname{diag}(\delta_1, \delta_2),

with the conventions (fixed, so that ``M`` is unique):

* ``z_1 = r_1 k_1 (x_1 - x_2)`` and ``z_2 = r_2 k_2 x_2`` [N]: the spring
  forces' uncertain parts at ``delta = 1``;
* ``w_i`` pushes back along its spring: the forces on the masses are
  ``-b_i w_i`` with ``b_1 = [1, -1]`` and ``b_2 = [0, 1]``;

so that ``M = F_l(P, K) = P11 + P12 K (I - P22 K)^-1 P21`` for the plant
``P`` with inputs ``[w1, w2, u]`` and outputs ``[z1, z2, y]``.  The loop is
stable for every stable ``Delta`` with ``||Delta||_inf < 1/||M||_inf``
(small gain, Zhou, Doyle & Glover, *Robust and Optimal Control*, thm. 9.1);
for the diagonal (structured) ``Delta`` the margin is ``1/sup mu(M(jw))``,
never smaller.  Book chapters: "Robust stability and performance" and
"Structured singular value".

Rules
-----
* You may import numpy, scipy, control, ``mutext.lti`` and ``mutext.hinf``.
  Importing ``mutext.mu``, ``mutext.uncertain``, ``mutext.dk`` or
  ``mutext.mbi`` (which compute these answers), ``mutext.examples`` or
  ``mutext.grading`` is blocked and scores 0.
* State-space models arrive as ``control.StateSpace`` objects; complex
  matrices as their real and imaginary parts (lists).
* SI units: kg, N/m, N, m, rad/s (not Hz).  Each function has a time limit
  (60 s by default).
"""
import numpy as np
import scipy.linalg
import control as ct


def m_delta(m1, m2, k1, k2, r1, r2, K):
    """(a) The system ``M`` that the perturbation ``Delta = diag(delta_1, delta_2)`` sees.

    Parameters
    ----------
    m1, m2 : float
        Masses [kg].
    k1, k2 : float
        Nominal stiffnesses [N/m] (``k1`` between the masses, ``k2`` from ``m2`` to the ground).
    r1, r2 : float
        Relative sizes of the stiffness uncertainties (e.g. 0.2 for +-20 %).
    K : control.StateSpace
        The controller, input ``y = x2`` [m], output ``u`` [N], closed as ``u = +K y``.

    Returns
    -------
    control.StateSpace (or a tuple (A, B, C, D))
        ``M = F_l(P, K)``, continuous time, inputs ``[w1, w2]``, outputs
        ``[z1, z2]`` in this order, with the scaling of the module docstring.
        Check: closing ``w = diag(delta) z`` must give the closed loop rebuilt
        with the springs ``k_i (1 + r_i delta_i)``.
    """
    raise NotImplementedError


def small_gain(M):
    """(b) The H-infinity norm of ``M``, where it peaks, and the small-gain margin.

    Parameters
    ----------
    M : control.StateSpace
        A stable system (the grader's ``M`` of (a)).

    Returns
    -------
    numpy array of 3 numbers
        ``[||M||_inf, omega_peak, margin]``: the norm (relative tolerance
        1e-4; a frequency grid alone gives too low a value), the frequency
        where ``sigma_max(M(j omega))`` peaks in **rad/s** (1 %), and the
        robust stability margin ``1/||M||_inf`` (1e-4).
    """
    raise NotImplementedError


def destabilizing_delta(M, omega):
    """(c) The smallest full complex ``Delta`` that makes ``I - M(j omega) Delta`` singular.

    Parameters
    ----------
    M : control.StateSpace
        The system of (b) (2 inputs, 2 outputs).
    omega : float
        Frequency [rad/s] (the peak of ``sigma_max(M)``).

    Returns
    -------
    (Delta_re, Delta_im) : tuple of two 2 x 2 numpy arrays
        A full complex ``Delta`` with ``det(I - M(j omega) Delta) = 0`` (to
        1e-6, relative) and the least ``sigma_max(Delta)``, which is
        ``1/sigma_max(M(j omega))`` (to 1e-4).  Hint: the singular value
        decomposition ``M(j omega) = U S V^H``.
    """
    raise NotImplementedError


def structured_mu(M_re, M_im):
    """(d) mu of ``M`` for the diagonal structure, its lower and upper bounds over frequency.

    Parameters
    ----------
    M_re, M_im : (N, 2, 2) array_like
        Real and imaginary parts of ``M(j omega_i)`` on a grid of ``N`` frequencies.

    Returns
    -------
    numpy array of 2 numbers
        ``[lower, upper]``: the peak over the grid of a lower bound on
        ``mu`` for two complex ``1 x 1`` blocks (``max rho(M U)`` over
        diagonal unitary ``U``) and the peak of the D-scaling upper bound
        ``min_D sigma_max(D M D^-1)``.  With two blocks the bounds meet
        (``2S + F <= 3``); each is compared with mu to a relative tolerance of 1e-3.
    """
    raise NotImplementedError
