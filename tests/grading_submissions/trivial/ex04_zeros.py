"""ex04 submission that returns zeros of the asked shapes."""
import numpy as np


def element_matrices(E, I, rho, A, L):
    return np.zeros((4, 4)), np.zeros((4, 4))


def assemble(n_elements, length, E, I, rho, A, support):
    return np.zeros((2 * n_elements, 2 * n_elements)), np.zeros((2 * n_elements, 2 * n_elements))


def natural_frequencies(n_elements, length, E, I, rho, A, support, n_modes):
    return np.zeros(n_modes)


def relative_errors(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
    return np.zeros(3)
