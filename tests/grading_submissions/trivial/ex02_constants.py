"""ex02 submission that solves nothing: the values of the fixed cases graded before inputs were drawn
(example 8.5: sigma_max sqrt(10), mu 3), Delta = I/3 and I, a static LFT, the old peak."""
import numpy as np


def mu_full(M_re, M_im):
    return 3.1622776601683795


def mu_scalar_blocks_upper(M_re, M_im):
    return 3.0


def destabilizing_delta(M_re, M_im):
    n = len(M_re)
    return np.eye(n) / 3.0, np.zeros((n, n))


def uncertain_spring_lft(m, k, rel):
    return np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), np.eye(2)


def mu_peak(M_re, M_im):
    return 3.723864518276034
