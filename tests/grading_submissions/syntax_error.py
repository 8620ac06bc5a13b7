"""Submission with a syntax error: nothing can be graded."""
import numpy as np


def mechanical_model(m1, m2, k1, k2):
    M = np.diag([m1, m2]
    return M


def hinf_norm(sys):
    return 1.0
