"""mu submission with crude numerics: Frobenius norm, a coarse search over D, Delta = I / lambda(M)
(valid, not the smallest), the size rel missing from the LFT, the bound at the last frequency only."""
import numpy as np


def _c(M_re, M_im):
    return np.asarray(M_re, float) + 1j * np.asarray(M_im, float)


def mu_full(M_re, M_im):
    return float(np.linalg.norm(_c(M_re, M_im), "fro"))


def mu_scalar_blocks_upper(M_re, M_im):
    M = _c(M_re, M_im)
    n = M.shape[0]
    best = np.linalg.norm(M, 2)
    grid = np.logspace(-1, 1, 5)                           # too coarse
    for d in np.array(np.meshgrid(*[grid] * (n - 1))).reshape(n - 1, -1).T:
        D = np.r_[d, 1.0]
        best = min(best, np.linalg.norm(D[:, None] * M / D[None, :], 2))
    return float(best)


def destabilizing_delta(M_re, M_im):
    M = _c(M_re, M_im)
    lam = np.linalg.eigvals(M)
    lam = lam[np.argmax(abs(lam))]
    Delta = np.eye(M.shape[0]) / lam
    return Delta.real, Delta.imag


def uncertain_spring_lft(m, k, rel):
    A = np.array([[0.0, 1.0], [-k / m, 0.0]])
    B = np.array([[0.0, 0.0], [-1.0 / m, 1.0 / m]])
    C = np.array([[k, 0.0], [1.0, 0.0]])                  # rel forgotten
    return A, B, C, np.zeros((2, 2))


def mu_peak(M_re, M_im):
    Ms = np.asarray(M_re, float) + 1j * np.asarray(M_im, float)
    return mu_scalar_blocks_upper(Ms[-1].real, Ms[-1].imag)
