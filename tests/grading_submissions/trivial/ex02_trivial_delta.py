"""ex02 submission that solves nothing: library one-liners (the Frobenius norm, sigma_max without
D-scaling, its peak over frequency), the trivial Delta = diag(1/M_11, 0, ...), a zero LFT."""
import numpy as np


def _c(M_re, M_im):
    return np.asarray(M_re, float) + 1j * np.asarray(M_im, float)


def mu_full(M_re, M_im):
    return float(np.linalg.norm(_c(M_re, M_im)))


def mu_scalar_blocks_upper(M_re, M_im):
    return float(np.linalg.norm(_c(M_re, M_im), 2))


def destabilizing_delta(M_re, M_im):
    M = _c(M_re, M_im)
    Delta = np.zeros(M.shape, complex)
    Delta[0, 0] = 1.0 / M[0, 0]          # the first row of I - M Delta is zero
    return Delta.real, Delta.imag


def uncertain_spring_lft(m, k, rel):
    return np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), np.zeros((2, 2))


def mu_peak(M_re, M_im):
    return float(max(np.linalg.norm(M, 2) for M in _c(M_re, M_im)))
