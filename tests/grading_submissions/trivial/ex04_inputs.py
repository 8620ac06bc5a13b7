"""ex04 submission that returns its arguments (identity matrices scaled by them, constants) of the
asked shapes instead of computing anything."""
import numpy as np


def element_matrices(E, I, rho, A, L):
    return E * I * np.eye(4), rho * A * L * np.eye(4)


def assemble(n_elements, length, E, I, rho, A, support):
    n = 2 * n_elements
    return E * I * np.eye(n), rho * A * length * np.eye(n)


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    return np.arange(1.0, n_modes + 1) * length


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    return np.array([1e-2, 6e-4, 4e-5]) * mode
