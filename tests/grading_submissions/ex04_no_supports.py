"""Beam-element submission that forgets the supports (a free-free beam) and reports Hz in (c)."""
import numpy as np
import scipy.linalg


def element_matrices(E, I, rho, A, L):
    K = E * I / L**3 * np.array([[12, 6 * L, -12, 6 * L],
                                 [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                 [-12, -6 * L, 12, -6 * L],
                                 [6 * L, 2 * L**2, -6 * L, 4 * L**2]], dtype=float)
    M = rho * A * L / 420 * np.array([[156, 22 * L, 54, -13 * L],
                                      [22 * L, 4 * L**2, 13 * L, -3 * L**2],
                                      [54, 13 * L, 156, -22 * L],
                                      [-13 * L, -3 * L**2, -22 * L, 4 * L**2]])
    return K, M


def assemble(n_elements, length, E, I, rho, A, support):
    n = n_elements
    K = np.zeros((2 * n + 2, 2 * n + 2))
    M = np.zeros_like(K)
    Ke, Me = element_matrices(E, I, rho, A, length / n)
    for e in range(n):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += Ke
        M[s, s] += Me
    return K, M          # the supports are never applied


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    K, M = assemble(n_elements, length, E, I, rho, A, support)
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.abs(lam[:n_modes])) / (2 * np.pi)      # in Hz


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    beta_l = {"pinned": np.pi * mode, "cantilever": [1.875104068712, 4.694091132974, 7.854757438238][mode - 1]}
    exact = beta_l[support] ** 2 * np.sqrt(E * I / (rho * A * length**4))
    return np.array([natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] / exact - 1
                     for n in element_counts])
