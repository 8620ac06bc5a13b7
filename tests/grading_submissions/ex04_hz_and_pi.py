"""Beam-element submission with correct matrices, frequencies in Hz, and n pi for the cantilever."""
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
    fixed = [0, 2 * n] if support == "pinned" else [0, 1]
    free = [k for k in range(2 * n + 2) if k not in fixed]
    return K[np.ix_(free, free)], M[np.ix_(free, free)]


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    K, M = assemble(n_elements, length, E, I, rho, A, support)
    return np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[:n_modes]) / (2 * np.pi)   # Hz


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    exact = (mode * np.pi) ** 2 * np.sqrt(E * I / (rho * A * length**4))   # pinned-pinned value for both
    return np.array([2 * np.pi * natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] / exact - 1
                     for n in element_counts])
