r"""Reference solution of exercise ``ex02_mu``.

Structured singular value of complex matrices with numpy and scipy only:
the largest singular value (one full block), the D-scaling upper bound for
``n`` complex ``1 x 1`` blocks (a convex function of ``log D``), a
destabilising diagonal perturbation (maximise the spectral radius of
``M U`` over diagonal unitary ``U``), a mass-spring model with an
uncertain stiffness as an upper LFT, and the peak of the upper bound over
frequency.  Complex matrices travel as their real and imaginary parts.
"""
from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import minimize


def _complex(M_re, M_im):
    return np.asarray(M_re, dtype=float) + 1j * np.asarray(M_im, dtype=float)


def mu_full(M_re, M_im):
    """mu for one full complex block: the largest singular value of ``M``."""
    return float(np.linalg.norm(_complex(M_re, M_im), 2))


def _scaled_sigma(M, x):
    d = np.exp(np.concatenate([x, [0.0]]))       # the last scaling fixed to 1 (D and cD scale alike)
    return np.linalg.norm((d[:, None] * M) / d[None, :], 2)


def _upper(M):
    n = M.shape[0]
    if n == 1:
        return float(abs(M[0, 0]))
    best = np.linalg.norm(M, 2)
    starts = [np.zeros(n - 1)]
    # Osborne-like start: balance the moduli of the off-diagonal entries
    A = np.abs(M) + 1e-300
    starts.append(0.25 * np.log(A[-1, :-1] / A[:-1, -1]))
    for x0 in starts:
        r = minimize(lambda x: np.log(_scaled_sigma(M, x)), x0, method="Nelder-Mead",
                     options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20000, "maxfev": 20000})
        r = minimize(lambda x: np.log(_scaled_sigma(M, x)), r.x, method="Nelder-Mead",
                     options={"xatol": 1e-11, "fatol": 1e-14, "maxiter": 20000, "maxfev": 20000})
        best = min(best, _scaled_sigma(M, r.x))
    return float(best)


def mu_scalar_blocks_upper(M_re, M_im):
    """``min_D sigma_max(D M D^-1)`` over positive diagonal ``D``."""
    return _upper(_complex(M_re, M_im))


def _rho(M, th):
    u = np.exp(1j * np.concatenate([th, [0.0]]))
    lam = np.linalg.eigvals(M * u[None, :])
    k = int(np.argmax(np.abs(lam)))
    return lam[k], u


def destabilizing_delta(M_re, M_im):
    """Diagonal ``Delta`` with ``det(I - M Delta) = 0`` and the smallest ``sigma_max`` found.

    For complex scalar blocks ``mu(M) = max_U rho(M U)`` over diagonal unitary
    ``U``; if ``lambda`` is the eigenvalue of ``M U`` of largest modulus,
    ``Delta = U / lambda`` makes ``I - M Delta`` singular and has
    ``sigma_max(Delta) = 1 / |lambda|``.
    """
    M = _complex(M_re, M_im)
    n = M.shape[0]
    best = None
    grid = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    for th0 in itertools.product(grid, repeat=n - 1):
        r = minimize(lambda th: -abs(_rho(M, th)[0]), np.array(th0), method="Nelder-Mead",
                     options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 5000})
        if best is None or r.fun < best.fun:
            best = r
    lam, u = _rho(M, best.x)
    Delta = np.diag(u / lam)
    return Delta.real, Delta.imag


def uncertain_spring_lft(m, k, rel):
    """Upper LFT of ``m x'' + k (1 + rel delta) x = f``: inputs ``[w, f]``, outputs ``[z, x]``.

    ``z = rel k x`` and ``w = delta z`` enter as the force ``-w``, so closing
    ``w = delta z`` adds ``rel k delta x`` to the spring force.
    """
    A = np.array([[0.0, 1.0], [-k / m, 0.0]])
    B = np.array([[0.0, 0.0], [-1.0 / m, 1.0 / m]])
    C = np.array([[rel * k, 0.0], [1.0, 0.0]])
    D = np.zeros((2, 2))
    return A, B, C, D


def mu_peak(M_re, M_im):
    """Peak over frequency of the D-scaling upper bound; ``M_re``, ``M_im`` of shape ``(N, n, n)``."""
    Ms = _complex(M_re, M_im)
    return max(_upper(M) for M in Ms)
