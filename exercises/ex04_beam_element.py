r"""Exercise ex04: Euler-Bernoulli beam elements.

Fill in the four functions below, then check that your file runs with::

    mutext check ex04_beam_element exercises/ex04_beam_element.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

A uniform beam bends in one plane: ``w(z)`` is its deflection (m) and
``theta(z) = dw/dz`` its slope (rad, counterclockwise positive), with ``z``
along the beam from 0 to ``length``.  The beam is cut into ``n_elements``
elements of equal length; within an element the deflection is the cubic
polynomial fixed by the four nodal values ``[w1, theta1, w2, theta2]``
(Hermite shape functions).  Free vibration obeys

.. math::
    M\ddot q + K q = 0 ,\qquad K\phi = \omega^2 M\phi ,

with the global DOFs ``q = [w1, theta1, w2, theta2, ..., w_{N+1}, theta_{N+1}]``
(node by node, node 1 at ``z = 0``).  No shear deformation and no rotary
inertia (the Euler-Bernoulli beam).  Book chapter: "Finite-element rotor and
crack models".

Units are SI: Young's modulus ``E`` in Pa, second moment of area ``I`` in
m^4, density ``rho`` in kg/m^3, cross-section area ``A`` in m^2, lengths in
m, frequencies in rad/s.

Supports (argument ``support``):

* ``"pinned"``: pinned-pinned, ``w = 0`` at both ends (the slopes are free);
* ``"cantilever"``: clamped at ``z = 0`` (``w1 = theta1 = 0``), free at ``z = length``.

Rules
-----
* You may import numpy, scipy, control, ``mutext.lti`` and ``mutext.hinf``.
  Importing ``mutext.rotor`` (which computes these matrices),
  ``mutext.examples`` or ``mutext.grading``, or reading their files, is
  blocked and scores 0 (for the whole file if it happens at module level).
* Each function has a time limit (60 s by default); code at module level
  runs once, when the file is imported.
* Return numpy arrays (or tuples of them) of the shapes stated below.
"""
import numpy as np
import scipy.linalg


def element_matrices(E, I, rho, A, L):
    """(a) Stiffness and consistent mass matrix of one beam element.

    Parameters
    ----------
    E, I, rho, A : float
        Young's modulus [Pa], second moment of area [m^4], density [kg/m^3]
        and cross-section area [m^2].
    L : float
        Element length [m].

    Returns
    -------
    (K, M) : tuple of two (4, 4) numpy arrays
        Stiffness [N/m, N, N m] and *consistent* mass matrix [kg, kg m,
        kg m^2] on the DOFs ``[w1, theta1, w2, theta2]``, with
        ``theta = dw/dz``.  Both follow from the cubic Hermite shape functions:
        ``K = int E I N'' N''^T dz`` and ``M = int rho A N N^T dz``.  (A
        *lumped* mass matrix, half the element mass on each deflection, is a
        different approximation and is not what is asked.)
    """
    raise NotImplementedError


def assemble(n_elements, length, E, I, rho, A, support):
    """(b) Global stiffness and mass matrices of a uniform beam, supports applied.

    Parameters
    ----------
    n_elements : int
        Number of equal elements ``N`` (each ``length / N`` long).
    length : float
        Length of the beam [m].
    E, I, rho, A : float
        As in (a).
    support : {"pinned", "cantilever"}
        See the module docstring.

    Returns
    -------
    (K, M) : tuple of two (2N, 2N) numpy arrays
        The ``2(N+1)`` global DOFs ``[w1, theta1, w2, theta2, ...]`` (node by
        node; element ``e`` joins nodes ``e`` and ``e+1``, which it shares with
        its neighbours) with the rows and columns of the two DOFs fixed by
        the supports removed, the others kept in that order: for
        ``"pinned"`` remove ``w1`` and ``w_{N+1}``, for ``"cantilever"``
        remove ``w1`` and ``theta1``.
    """
    raise NotImplementedError


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    """(c) The ``n_modes`` lowest natural frequencies of the supported beam.

    Parameters as in (b); ``n_modes`` (int) is at most ``2 * n_elements``.

    Returns
    -------
    numpy array of shape (n_modes,)
        Natural frequencies ``omega`` in rad/s (not Hz), ascending.  Solve the
        symmetric generalized eigenvalue problem ``K phi = omega^2 M phi``
        (``scipy.linalg.eigh(K, M)``).
    """
    raise NotImplementedError


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    """(d) Convergence of a natural frequency with the number of elements.

    The exact Euler-Bernoulli frequencies of the uniform beam are

    ``omega_n = (beta_n L)^2 * sqrt(E I / (rho A length^4))``

    with ``beta_n L = n pi`` for the pinned-pinned beam and, for the
    cantilever, the roots of ``cos(x) cosh(x) = -1``:
    ``beta_1 L = 1.875104068712``, ``beta_2 L = 4.694091132974``,
    ``beta_3 L = 7.854757438238`` (use at least this many digits: with 8
    elements the finite-element error is of the order of 1e-6).

    Parameters
    ----------
    length, E, I, rho, A, support : as in (b)
    mode : int
        Mode number ``n`` (1 = lowest).
    element_counts : sequence of 3 int
        The numbers of elements ``N`` to compare (the grader draws them,
        e.g. ``(3, 4, 7)``).

    Returns
    -------
    numpy array of shape (3,)
        ``(omega_N - omega_exact) / omega_exact`` of mode ``mode`` for each
        ``N`` of ``element_counts`` (in this order), where ``omega_N`` is the
        frequency of (c).  The consistent mass matrix makes these positive.
    """
    raise NotImplementedError
