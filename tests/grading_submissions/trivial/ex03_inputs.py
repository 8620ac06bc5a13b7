"""ex03 submission that returns one of its arguments (or the record's first sample) instead of an answer."""
import numpy as np


def natural_frequency(t, y, cycles):
    return float(cycles)


def damping_ratio(t, y, cycles):
    return float(y[0])


def cart_mass(omega_bare, omega_weighted, m_w):
    return m_w


def stiffness(omega_bare, m_c):
    return m_c


def damping_coefficient(zeta, m_c, omega):
    return m_c


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    return np.array([m_w, m_w, m_w])
