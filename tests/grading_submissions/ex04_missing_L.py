"""Beam-element submission whose element stiffness lacks the factor L in the rotational terms."""
import numpy as np
import scipy.linalg

BETA_L = {"pinned": [np.pi, 2 * np.pi, 3 * np.pi],
          "cantilever": [1.8751040687119611, 4.6940911329741745, 7.8547574382376126]}


def element_matrices(E, I, rho, A, L):
    K = E * I / L**3 * np.array([[12, 6, -12, 6],
                                 [6, 4, -6, 2],
                                 [-12, -6, 12, -6],
                                 [6, 2, -6, 4]], dtype=float)
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
    lam = scipy.linalg.eigvals(K, M).real
    return np.sqrt(np.sort(np.abs(lam)))[:n_modes]


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    exact = BETA_L[support][mode - 1] ** 2 * np.sqrt(E * I / (rho * A * length**4))
    return np.array([natural_frequencies(n, length, E, I, rho, A, support, mode)[-1] / exact - 1
                     for n in element_counts])
