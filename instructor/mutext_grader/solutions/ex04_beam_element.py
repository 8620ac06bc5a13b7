r"""Reference solution of exercise ``ex04_beam_element``.

Euler-Bernoulli beam in one plane, cubic (Hermite) elements with the DOFs
``[w1, theta1, w2, theta2]`` of each element: deflection ``w`` (m) and slope
``theta = dw/dz`` (rad, counterclockwise positive).  Uniform beam, SI units
(Pa, m^4, kg/m^3, m^2, m); frequencies in rad/s.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

#: beta_n L of the first modes: pinned-pinned n pi; clamped-free roots of cos(x) cosh(x) = -1
BETA_L = {
    "pinned": [np.pi, 2 * np.pi, 3 * np.pi, 4 * np.pi],
    "cantilever": [1.8751040687119611, 4.6940911329741745, 7.8547574382376126, 10.995540734875467],
}


def element_matrices(E, I, rho, A, L):
    """Stiffness and consistent mass matrix (4x4 each) of one element of length ``L``."""
    K = E * I / L**3 * np.array([[12.0, 6 * L, -12.0, 6 * L],
                                 [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                 [-12.0, -6 * L, 12.0, -6 * L],
                                 [6 * L, 2 * L**2, -6 * L, 4 * L**2]])
    M = rho * A * L / 420.0 * np.array([[156.0, 22 * L, 54.0, -13 * L],
                                        [22 * L, 4 * L**2, 13 * L, -3 * L**2],
                                        [54.0, 13 * L, 156.0, -22 * L],
                                        [-13 * L, -3 * L**2, -22 * L, 4 * L**2]])
    return K, M


def constrained_dofs(n_elements, support):
    """Global DOFs (0-based, order ``w1, theta1, w2, theta2, ...``) that the supports fix."""
    if support == "pinned":
        return [0, 2 * n_elements]                 # w at both ends
    if support == "cantilever":
        return [0, 1]                              # w and theta at z = 0
    raise ValueError(f"support must be 'pinned' or 'cantilever', got {support!r}")


def assemble(n_elements, length, E, I, rho, A, support):
    """Global ``(K, M)`` of a uniform beam of ``n_elements`` equal elements, supports applied."""
    n = int(n_elements)
    ndof = 2 * (n + 1)
    K = np.zeros((ndof, ndof))
    M = np.zeros((ndof, ndof))
    Ke, Me = element_matrices(E, I, rho, A, length / n)
    for e in range(n):
        idx = np.arange(2 * e, 2 * e + 4)           # element e shares node e+1 with element e+1
        K[np.ix_(idx, idx)] += Ke
        M[np.ix_(idx, idx)] += Me
    free = np.setdiff1d(np.arange(ndof), constrained_dofs(n, support))
    return K[np.ix_(free, free)], M[np.ix_(free, free)]


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    """The ``n_modes`` lowest natural frequencies in rad/s, ascending."""
    K, M = assemble(n_elements, length, E, I, rho, A, support)
    lam = sla.eigh(K, M, eigvals_only=True)
    return np.sqrt(lam[:n_modes])


def analytic_frequency(length, E, I, rho, A, support, mode):
    """Exact Euler-Bernoulli frequency (rad/s): ``(beta L)^2 sqrt(E I / (rho A L^4))``."""
    bl = BETA_L[support][mode - 1]
    return bl**2 * np.sqrt(E * I / (rho * A * length**4))


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    """``(omega_N - omega_exact) / omega_exact`` of mode ``mode`` for each N of ``element_counts``."""
    exact = analytic_frequency(length, E, I, rho, A, support, mode)
    return np.array([natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] / exact - 1.0
                     for n in element_counts])
