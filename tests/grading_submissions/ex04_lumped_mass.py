"""Beam-element submission with a lumped mass matrix (half the element mass on each deflection)."""
import numpy as np
import scipy.linalg

BETA_L = {"pinned": [np.pi, 2 * np.pi, 3 * np.pi],
          "cantilever": [1.8751040687119611, 4.6940911329741745, 7.8547574382376126]}


def element_matrices(E, I, rho, A, L):
    K = E * I / L**3 * np.array([[12, 6 * L, -12, 6 * L],
                                 [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                                 [-12, -6 * L, 12, -6 * L],
                                 [6 * L, 2 * L**2, -6 * L, 4 * L**2]], dtype=float)
    # lumped: half the mass on each deflection, a little rotary inertia so that M is invertible
    m = rho * A * L
    M = np.diag([m / 2, m * L**2 / 420, m / 2, m * L**2 / 420])
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
    return np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[:n_modes])


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    exact = BETA_L[support][mode - 1] ** 2 * np.sqrt(E * I / (rho * A * length**4))
    return np.array([natural_frequencies(n, length, E, I, rho, A, support, mode)[-1] / exact - 1
                     for n in element_counts])
