r"""Exercise ex01: H-infinity control of the two-mass system.

Fill in the four functions below, then check that your file runs with::

    mutext check ex01_two_mass_hinf exercises/ex01_two_mass_hinf.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

The system (book chapter "H-infinity control and LFTs"): mass ``m1`` hangs
from mass ``m2`` through the spring ``k1``; the spring ``k2`` ties ``m2`` to
the ground.  There is no damping.  A disturbance force ``f_e`` acts on
``m1``, the control force ``u`` on ``m2``, and a sensor measures the
displacement ``x2`` of ``m2`` with additive noise ``eta``:

.. math::
    m_1 \ddot x_1 + k_1 (x_1 - x_2) = f_e, \qquad
    m_2 \ddot x_2 + k_1 (x_2 - x_1) + k_2 x_2 = u, \qquad
    y = x_2 + \eta .

All quantities are SI: masses in kg, stiffnesses in N/m, forces in N,
displacements in m, frequencies in rad/s.  Positive ``x1``, ``x2``, ``f_e``
and ``u`` point the same way.

Rules
-----
* You may import numpy, scipy, control (python-control), ``mutext.lti`` and
  ``mutext.hinf``.  Importing ``mutext.examples`` or ``mutext.grading``, or
  reading their files, is blocked and scores 0 (for the whole file if it
  happens at module level).
* Each function has a time limit (60 s by default); code at module level
  runs once, when the file is imported.
* Return the types stated below.  State-space models may use any state
  coordinates: they are compared through their frequency responses.
"""
import numpy as np
import control as ct


def mechanical_model(m1, m2, k1, k2):
    """(a) State-space model of the two masses.

    Parameters
    ----------
    m1, m2 : float
        Masses in kg (``m1`` carries the disturbance, ``m2`` the actuator).
    k1, k2 : float
        Stiffnesses in N/m (``k1`` between the masses, ``k2`` from ``m2`` to ground).

    Returns
    -------
    control.StateSpace
        Continuous time, 2 inputs ``[f_e, u]`` (N; ``f_e`` on ``m1``, ``u``
        on ``m2``) and 2 outputs ``[x1, x2]`` (m), in this order.  A natural
        state is ``[x1, x2, dx1/dt, dx2/dt]``.
    """
    raise NotImplementedError


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4,
                      x_max=0.035, u_max=50.0):
    """(b) Generalized plant for H-infinity design.

    The exogenous inputs and the errors are normalised by their allowed sizes:
    ``f_e = f_max * f1`` (largest disturbance, N), ``eta = eta_max * f2``
    (largest sensor noise, m), ``z1 = x1 / x_max`` (allowed motion of m1, m)
    and ``z2 = u / u_max`` (allowed control force, N).  Use the exact
    reciprocals ``1/x_max`` and ``1/u_max`` as weights.  The grader calls this
    function with keyword arguments, and also with none (the defaults above
    are the thesis values).

    Returns
    -------
    control.StateSpace
        Continuous time, 3 inputs ``[f1, f2, u]`` and 3 outputs
        ``[z1, z2, y]``, in this order: ``f1``, ``f2``, ``z1``, ``z2`` are
        dimensionless, ``u`` is in N, ``y = x2 + eta`` in m.  Use it with
        ``nmeas=1, ncon=1``.
    """
    raise NotImplementedError


def hinf_norm(sys):
    """(c) H-infinity norm of a stable continuous-time system.

    Parameters
    ----------
    sys : control.StateSpace
        Stable, any number of inputs, outputs and states, ``D`` may be nonzero.

    Returns
    -------
    float
        ``sup over w of the largest singular value of G(jw)``, relative
        accuracy 1e-4 or better.  Test systems include a resonance with
        damping ratio 0.001 (a frequency grid will miss its peak: use the
        bisection on the Hamiltonian matrix from the book) and systems whose
        peak is at DC or at infinite frequency.
    """
    raise NotImplementedError


def controller():
    """(d) H-infinity controller for the thesis plant.

    The plant is ``generalized_plant()`` with the thesis's rounded weights
    ``28.6 1/m`` on ``x1`` and ``0.02 1/N`` on ``u`` (``x_max = 1/28.6``,
    ``u_max = 50``).  Full marks need a stabilizing controller whose
    closed-loop H-infinity norm is within 2 % of the optimal level (about
    1.007); within 10 % earns part of the points.

    Returns
    -------
    control.StateSpace
        Continuous time, 1 input ``y`` (m) and 1 output ``u`` (N), with the
        positive-feedback convention ``u = K y`` of ``control.hinfsyn`` and
        ``mutext.hinf.hinfsyn`` (the grader forms the lower LFT of the
        reference plant and ``K``).
    """
    raise NotImplementedError
