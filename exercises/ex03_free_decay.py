r"""Exercise ex03: free-decay identification of a cart of the three-mass rig.

Fill in the functions below, then check that your file runs with::

    mutext check ex03_free_decay exercises/ex03_free_decay.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

A cart is pulled aside and released from rest, its neighbours clamped, so it
moves as the single degree of freedom

.. math::
    m\ddot x + c\dot x + k x = 0 .

A record is sampled at times ``t`` (s, equally spaced, starting at 0) with
displacements ``y`` (m), e.g. 3 s at 1 kHz from 25 mm.  From the first
positive peak that ``scipy.signal.find_peaks`` finds (``t_0, y_0``) and the
peak ``N`` cycles later (``t_N, y_N``) the thesis (sec. 3.3.2) computes

.. math::
    \omega = \frac{2\pi N}{t_N - t_0}\quad(3.1),\qquad
    \zeta = \frac{1}{2\pi N}\ln\frac{y_0}{y_N}\quad(3.2).

Repeating the test with a known mass ``m_w`` bolted on the cart separates mass
and stiffness: with :math:`\omega_c^2 = k/m_c` (bare cart) and
:math:`\omega_w^2 = k/(m_c + m_w)` (weighted cart),

.. math::
    m_c = \frac{m_w\,\omega_w^2}{\omega_c^2 - \omega_w^2}\quad(3.3),\qquad
    k = \omega_c^2 m_c\quad(3.4),\qquad c = 2\zeta m_c\omega_c\quad(3.5).

(Careful: the thesis prints :math:`\omega_c^2` in the numerator of (3.3);
derive it yourself from the two frequencies.)  Book chapter: "Model-based
identification on the three-mass rig".

Units are SI: s, m, kg, N/m, N s/m; frequencies in rad/s (not Hz).

Rules
-----
* You may import numpy, scipy, control, ``mutext.lti`` and ``mutext.hinf``.
  Importing ``mutext.sysid`` (which computes these answers),
  ``mutext.examples`` or ``mutext.grading``, or reading their files, is
  blocked and scores 0 (for the whole file if it happens at module level).
* Each function has a time limit (60 s by default); code at module level
  runs once, when the file is imported.
* ``t`` and ``y`` arrive as Python lists of floats: convert them with
  ``np.asarray``.  Return floats (and a numpy array in (d)).
"""
import numpy as np
import scipy.signal


def natural_frequency(t, y, cycles):
    """(a) Eq. (3.1): the frequency of a free-decay record, from its peak times.

    Parameters
    ----------
    t, y : list of float
        Sample times [s] and displacements [m] of a noise-free decay.
    cycles : int
        ``N``: use the first positive peak and the peak ``N`` cycles later.

    Returns
    -------
    float
        ``omega = 2 pi N / (t_N - t_0)`` in rad/s (not Hz).  This is the
        damped frequency; the grader accepts 1 % error.
    """
    raise NotImplementedError


def damping_ratio(t, y, cycles):
    """(a) Eq. (3.2): the damping ratio from the logarithmic decrement.

    Parameters as in :func:`natural_frequency`.

    Returns
    -------
    float
        ``zeta = ln(y_0 / y_N) / (2 pi N)`` (dimensionless): the decrement
        over ``N`` cycles divided by ``N`` and by ``2 pi``.  5 % accepted.
    """
    raise NotImplementedError


def cart_mass(omega_bare, omega_weighted, m_w):
    """(b) Eq. (3.3): the mass of the cart from the two frequencies.

    Parameters
    ----------
    omega_bare : float
        Frequency of the bare cart, ``omega_c`` [rad/s].
    omega_weighted : float
        Frequency of the cart with the added mass, ``omega_w`` [rad/s].
    m_w : float
        Added mass [kg].

    Returns
    -------
    float
        Mass ``m_c`` [kg] of the bare cart (without ``m_w``).
    """
    raise NotImplementedError


def stiffness(omega_bare, m_c):
    """(b) Eq. (3.4): the equivalent stiffness ``k`` [N/m] from ``omega_c`` [rad/s] and ``m_c`` [kg]."""
    raise NotImplementedError


def damping_coefficient(zeta, m_c, omega):
    """(c) Eq. (3.5): the viscous damping coefficient ``c`` [N s/m].

    Parameters
    ----------
    zeta : float
        Damping ratio of the bare cart.
    m_c : float
        Mass of the bare cart [kg].
    omega : float
        Frequency of the bare cart [rad/s].
    """
    raise NotImplementedError


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    """(d) Mass, stiffness and damping of a cart from two free-decay records.

    Parameters
    ----------
    t_bare, y_bare : list of float
        Record [s, m] of the bare cart.
    t_w, y_w : list of float
        Record [s, m] of the cart with the added mass ``m_w``.
    m_w : float
        Added mass [kg].

    Both records carry white measurement noise (standard deviation 3
    micrometres): choose the number of cycles yourself (e.g. 5; the peaks
    used must stand clear of the noise), and keep ``find_peaks`` from taking
    noise wiggles for peaks (its ``distance`` argument).

    Returns
    -------
    numpy array of shape (3,)
        ``[m_c, k, c]`` in kg, N/m and N s/m, of the *bare* cart, from (3.1)
        to (3.5); the damping from the bare record.  Accepted: 5 % for
        ``m_c``, 2 % for ``k`` and 5 % for ``c``.
    """
    raise NotImplementedError
