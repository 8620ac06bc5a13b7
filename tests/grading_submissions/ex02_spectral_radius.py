"""mu submission that confuses mu with unscaled norms: spectral radius for one full block, no D-scaling,
a full-block destabilising Delta; the LFT is right."""
import numpy as np


def _c(M_re, M_im):
    return np.asarray(M_re, float) + 1j * np.asarray(M_im, float)


def mu_full(M_re, M_im):
    return float(max(abs(np.linalg.eigvals(_c(M_re, M_im)))))


def mu_scalar_blocks_upper(M_re, M_im):
    return float(np.linalg.norm(_c(M_re, M_im), 2))


def destabilizing_delta(M_re, M_im):
    U, s, Vh = np.linalg.svd(_c(M_re, M_im))
    Delta = np.outer(Vh[0].conj(), U[:, 0].conj()) / s[0]
    return Delta.real, Delta.imag


def uncertain_spring_lft(m, k, rel):
    A = np.array([[0.0, 1.0], [-k / m, 0.0]])
    B = np.array([[0.0, 0.0], [-1.0 / m, 1.0 / m]])
    C = np.array([[rel * k, 0.0], [1.0, 0.0]])
    return A, B, C, np.zeros((2, 2))


def mu_peak(M_re, M_im):
    Ms = np.asarray(M_re, float) + 1j * np.asarray(M_im, float)
    return max(np.linalg.norm(M, 2) for M in Ms)
