r"""Exercise ex05: find the effect hidden in measured frequency responses.

Fill in the four functions below, then check that your file runs with::

    mutext check ex05_diagnose exercises/ex05_diagnose.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

A lumped chain (masses, springs and dampers; matrices ``M``, ``C``, ``K`` in
SI units) is the engineering model.  Its "measured" frequency responses come
from the real structure, which differs from the model by at most one effect
of the kinds

* ``"stiffness"``: a spring from one mass to the ground was added, size ``k`` [N/m];
* ``"mass"``: a mass was added to one mass, size ``m`` [kg];
* ``"damping"``: a damper from one mass to the ground was added, size ``c`` [N s/m];
* ``"none"``: no effect, the model is right;

plus relative measurement noise.  Book chapter: "What the model gets wrong".

The receptance of the model at angular frequency :math:`\omega = 2\pi f` is

.. math::
    H(j\omega) = (K - \omega^2 M + j\omega C)^{-1},

and a channel from a force at DOF ``i`` to the displacement of DOF ``o`` is
``H[o, i]``.  Compare model and data by the complex log ratio, summed over
the channels and frequencies,

.. math::
    \mathrm{RSS} = \sum |\ln(H_{\mathrm{model}} / H_{\mathrm{measured}})|^2
    = \sum (\ln|H_m/H_d|)^2 + (\angle H_m/H_d)^2 .

With relative noise of standard deviation :math:`\sigma` each of the two
parts has variance :math:`\sigma^2/2`, so on the right model
:math:`\mathrm{RSS} \approx N\sigma^2` for N complex points.  A hypothesis
(one size fitted) is real when it lowers the RSS by more than
:math:`20\,\sigma^2/2` (a chi-square test with a small false-alarm rate over
the dozen hypotheses of a chain).

Rules
-----
* You may import numpy and scipy.  Importing ``mutext.diagnose``,
  ``mutext.hide``, ``mutext.rotor`` or ``mutext.grading`` (which compute
  these answers) is blocked and scores 0.
* Arguments arrive as Python lists: convert them with ``np.asarray``.
  DOF indices are 0-based; stations (masses) in (d) are 1-based.
* Each function has a time limit (60 s by default).
"""
import numpy as np

#: Kinds of effect, in the order used by :func:`find_effect`'s return value.
KINDS = ("none", "stiffness", "mass", "damping")


def log_misfit(model_re, model_im, meas_re, meas_im):
    """(a) The RSS of the complex log ratio of two responses.

    Parameters
    ----------
    model_re, model_im, meas_re, meas_im : list of float
        Real and imaginary parts of the model's and the measured response
        (one channel, same frequencies).

    Returns
    -------
    float
        ``sum |ln(H_model / H_measured)|^2`` (use the log of the ratio, not the
        difference of the logs: the phase must stay within (-pi, pi]).
    """
    raise NotImplementedError


def response_with_grounded_spring(M, C, K, f_hz, i_in, i_out, dof, k):
    """(b) The channel ``i_in -> i_out`` of the chain with a spring ``k`` from ``dof`` to the ground.

    Parameters
    ----------
    M, C, K : list of lists
        The model's matrices (n x n, SI).
    f_hz : list of float
        Frequencies [Hz] (not rad/s).
    i_in, i_out, dof : int
        0-based DOF of the force, of the displacement and of the added spring.
    k : float
        Stiffness of the added spring [N/m].

    Returns
    -------
    numpy array, shape (2, len(f_hz))
        Real parts (row 0) and imaginary parts (row 1) of the response [m/N].
    """
    raise NotImplementedError


def fit_grounded_spring(M, C, K, f_hz, i_in, i_out, meas_re, meas_im, dof):
    """(c) The stiffness of a grounded spring at ``dof`` that best explains one measured channel.

    Parameters
    ----------
    M, C, K, f_hz, i_in, i_out, dof
        As in :func:`response_with_grounded_spring`.
    meas_re, meas_im : list of float
        The measured response (with about 1 % noise).

    Returns
    -------
    float
        The ``k`` [N/m] that minimises :func:`log_misfit` of the model with the
        spring against the data (within 2 % of the true value is accepted).
    """
    raise NotImplementedError


def find_effect(M, C, K, f_hz, channels, data_re, data_im, noise):
    """(d) Which effect is hidden in the data, where, and how large.

    Parameters
    ----------
    M, C, K, f_hz
        As above.
    channels : list of [int, int]
        ``[i_in, i_out]`` (0-based DOFs) of each measured channel.
    data_re, data_im : list of lists of float
        The measured responses, one list per channel.
    noise : float
        The relative noise level sigma (e.g. 0.01).

    Returns
    -------
    numpy array of 3 numbers
        ``[KINDS.index(kind), station, size]``: the kind, the 1-based mass
        (0 for "none") and the size in SI (kg, N/m or N s/m; 0 for "none").
        The kind and the station must be right; the size within 10 %.
    """
    raise NotImplementedError
