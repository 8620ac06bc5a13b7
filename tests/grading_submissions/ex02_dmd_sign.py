"""mu submission with sign and scaling slips: D M D instead of D M D^-1, I + M Delta singular,
the LFT closes with the wrong sign; mu_full and mu_peak are right."""
import numpy as np
from scipy.optimize import minimize


def _c(M_re, M_im):
    return np.asarray(M_re, float) + 1j * np.asarray(M_im, float)


def mu_full(M_re, M_im):
    return float(np.linalg.norm(_c(M_re, M_im), 2))


def _best(M, similarity):
    n = M.shape[0]

    def f(x):
        d = np.exp(np.clip(np.r_[x, 0.0], -30, 30))
        right = 1 / d if similarity else d
        return np.log(np.linalg.norm(d[:, None] * M * right[None, :], 2))

    r = minimize(f, np.zeros(n - 1), method="Nelder-Mead",
                 options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20000, "maxfev": 20000})
    r = minimize(f, r.x, method="Nelder-Mead",
                 options={"xatol": 1e-11, "fatol": 1e-14, "maxiter": 20000, "maxfev": 20000})
    return float(np.exp(r.fun))


def mu_scalar_blocks_upper(M_re, M_im):
    return _best(_c(M_re, M_im), similarity=False)       # D M D


def destabilizing_delta(M_re, M_im):
    M = _c(M_re, M_im)
    n = M.shape[0]
    best = None
    for th0 in np.linspace(0, 2 * np.pi, 6, endpoint=False):
        x0 = np.full(n - 1, th0)

        def f(th):
            return -max(abs(np.linalg.eigvals(M * np.exp(1j * np.r_[th, 0.0])[None, :])))

        r = minimize(f, x0, method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-14})
        if best is None or r.fun < best.fun:
            best = r
    u = np.exp(1j * np.r_[best.x, 0.0])
    lam = np.linalg.eigvals(M * u[None, :])
    lam = lam[np.argmax(abs(lam))]
    Delta = -np.diag(u / lam)                              # wrong sign
    return Delta.real, Delta.imag


def uncertain_spring_lft(m, k, rel):
    A = np.array([[0.0, 1.0], [-k / m, 0.0]])
    B = np.array([[0.0, 0.0], [1.0 / m, 1.0 / m]])       # +w: closes to k (1 - rel delta)
    C = np.array([[rel * k, 0.0], [1.0, 0.0]])
    return A, B, C, np.zeros((2, 2))


def mu_peak(M_re, M_im):
    Ms = np.asarray(M_re, float) + 1j * np.asarray(M_im, float)
    return max(_best(M, similarity=True) for M in Ms)
