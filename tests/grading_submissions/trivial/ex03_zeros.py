"""ex03 submission that returns zero for everything."""
import numpy as np


def natural_frequency(t, y, cycles):
    return 0.0


def damping_ratio(t, y, cycles):
    return 0.0


def cart_mass(omega_bare, omega_weighted, m_w):
    return 0.0


def stiffness(omega_bare, m_c):
    return 0.0


def damping_coefficient(zeta, m_c, omega):
    return 0.0


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    return np.zeros(3)
