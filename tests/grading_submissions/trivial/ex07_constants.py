"""ex07, a submission that does not solve: the open-loop plant for M, constants, the identity for
Delta, ones for the bounds."""
import numpy as np


def m_delta(m1, m2, k1, k2, r1, r2, K):
    return np.zeros((1, 1)), np.zeros((1, 2)), np.zeros((2, 1)), np.eye(2)


def small_gain(M):
    return np.array([1.0, 1.0, 1.0])


def destabilizing_delta(M, omega):
    return np.eye(2), np.zeros((2, 2))


def structured_mu(M_re, M_im):
    return np.array([1.0, 1.0])
