"""ex04 submission whose arrays are far larger than asked (the grader must not factorise them)."""
import numpy as np


def element_matrices(E, I, rho, A, L):
    return np.eye(40), np.eye(40)


def assemble(n_elements, length, E, I, rho, A, support):
    n = 120
    K = np.diag(np.arange(1.0, n + 1)) + np.diag(np.ones(n - 1), 1) + np.diag(np.ones(n - 1), -1)
    return K, np.eye(n)


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    return np.linspace(1.0, 1e4, 5000)


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    return np.full(2000, 1e-3)
