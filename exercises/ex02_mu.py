r"""Exercise ex02: the structured singular value.

Fill in the five functions below, then check that your file runs with::

    mutext check ex02_mu exercises/ex02_mu.py

(it says whether each function runs and returns the right kind of value; your instructor's
grader scores it, on inputs drawn for your file)

For a complex matrix ``M`` (it maps the inputs ``w`` of the uncertainty
channels to their outputs ``z``) and a set of structured perturbations
``Delta`` (which map ``z`` back to ``w``),

.. math::
    \mu(M) = 1 / \min\{\bar\sigma(\Delta) : \det(I - M\Delta) = 0\} .

Book chapter: "Structured singular value".  Two structures are used here:

* one *full* complex block: ``Delta`` is any complex ``n x n`` matrix;
* ``n`` complex *scalar* ``1 x 1`` blocks: ``Delta = diag(delta_1, ..., delta_n)``
  with complex ``delta_i``.

For the scalar blocks, every positive diagonal ``D`` commutes with
``Delta``, so ``mu(M) <= sigma_max(D M D^-1)``: the *D-scaling upper bound*
is the smallest such value.  ``log sigma_max(e^X M e^-X)`` is convex in the
diagonal ``X``, so a simple optimiser finds it; with cvxpy it is the
smallest ``beta`` for which the LMI ``M^H X M - beta^2 X <= 0`` has a
positive diagonal solution ``X = D^2`` (bisection on ``beta``; build the
problem once with a ``cp.Parameter`` for ``beta^2``, normalise
``sum(diag(X)) = n``, and count a ``cvxpy.error.SolverError`` as
infeasible).

Complex matrices are passed to your functions as their real and imaginary
parts (lists of lists); build them with ``M = np.asarray(M_re) + 1j *
np.asarray(M_im)``.

Units are SI: masses in kg, stiffnesses in N/m, forces in N,
displacements in m.

Rules
-----
* You may import numpy, scipy, cvxpy, control, ``mutext.lti`` and
  ``mutext.hinf``.  Importing ``mutext.mu``, ``mutext.uncertain`` or
  ``mutext.dk`` (which compute these answers), ``mutext.examples`` or
  ``mutext.grading``, or reading their files, is blocked and scores 0 (for
  the whole file if it happens at module level).
* Each function has a time limit (60 s by default); code at module level
  runs once, when the file is imported.
* Return the types stated below.  Values of ``mu`` are compared to a
  relative tolerance of 1e-3.
"""
import numpy as np
import scipy.linalg
import scipy.optimize


def mu_full(M_re, M_im):
    """(a) mu of ``M`` for one full complex block.

    Parameters
    ----------
    M_re, M_im : (n, n) array_like
        Real and imaginary parts of ``M``.

    Returns
    -------
    float
        ``mu(M)`` for one full ``n x n`` complex block, which equals the
        largest singular value of ``M`` (not the spectral radius).
    """
    raise NotImplementedError


def mu_scalar_blocks_upper(M_re, M_im):
    """(a) D-scaling upper bound on mu for ``n`` complex ``1 x 1`` blocks.

    Parameters
    ----------
    M_re, M_im : (n, n) array_like
        Real and imaginary parts of ``M``.

    Returns
    -------
    float
        ``min_D sigma_max(D M D^-1)`` over positive diagonal ``D`` (a
        similarity: ``D`` on the left, its inverse on the right).  One entry
        of ``D`` can be fixed to 1.  For ``M = [[2, 2], [-1, -1]]`` this is
        3.0 (and ``mu_full`` gives 3.162).
    """
    raise NotImplementedError


def destabilizing_delta(M_re, M_im):
    """(b) The smallest destabilising perturbation with ``n`` complex scalar blocks.

    Parameters
    ----------
    M_re, M_im : (n, n) array_like
        Real and imaginary parts of ``M``.

    Returns
    -------
    (Delta_re, Delta_im) : tuple of two (n, n) numpy arrays
        Real and imaginary parts of a *diagonal* complex ``Delta`` with
        ``det(I - M Delta) = 0`` (to 1e-6, relative) and ``sigma_max(Delta)``
        as small as you can make it (full points when ``1/sigma_max(Delta)``
        is within 2 % of ``mu``; half of them for any diagonal ``Delta``
        that makes ``I - M Delta`` singular).  Hint: with complex scalar
        blocks ``mu(M) = max rho(M U)`` over diagonal unitary ``U``; if
        ``lambda`` is the eigenvalue of ``M U`` of largest modulus, then
        ``Delta = U / lambda`` makes ``I - M Delta`` singular.
    """
    raise NotImplementedError


def uncertain_spring_lft(m, k, rel):
    """(c) A mass-spring with an uncertain stiffness as an upper LFT.

    The mass ``m`` (kg) is tied to the ground by a spring of stiffness
    ``k (1 + rel * delta)`` (N/m) with ``-1 <= delta <= 1``; a force ``f``
    (N) acts on it and ``x`` (m) is its displacement:

    ``m x'' + k (1 + rel delta) x = f``.

    Parameters
    ----------
    m : float
        Mass [kg].
    k : float
        Nominal stiffness [N/m].
    rel : float
        Relative size of the stiffness uncertainty (e.g. 0.2 for +-20 %).

    Returns
    -------
    (A, B, C, D) : tuple of numpy arrays (or a control.StateSpace)
        The generalized plant ``P``, continuous time, inputs ``[w, f]``
        and outputs ``[z, x]`` in this order, such that closing the
        uncertainty loop ``w = delta * z`` (the upper LFT
        ``F_u(P, delta) = P22 + P21 delta (1 - P11 delta)^-1 P12``) gives
        the model ``f -> x`` above for every ``delta``.  Any scaling of
        ``w`` and ``z`` is accepted.
    """
    raise NotImplementedError


def mu_peak(M_re, M_im):
    """(d) Peak over frequency of the D-scaling upper bound.

    Parameters
    ----------
    M_re, M_im : (N, n, n) array_like
        Real and imaginary parts of a frequency response ``M(j w_i)``,
        ``i = 1..N``, with ``n`` complex ``1 x 1`` blocks.

    Returns
    -------
    float
        ``max_i min_D sigma_max(D M(j w_i) D^-1)``: the upper bound of (a)
        at every frequency, and the largest of them (a single number).
    """
    raise NotImplementedError
