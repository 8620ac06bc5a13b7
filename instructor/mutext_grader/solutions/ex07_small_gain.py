r"""Reference solution of exercise ``ex07_small_gain``: the M-Delta loop and the small-gain theorem.

(a) builds the plant ``P`` (inputs ``[w1, w2, u]``, outputs ``[z1, z2, y]``)
from the mass and stiffness matrices and closes ``u = K y`` with
python-control's ``StateSpace.lft``; (b) takes the norm from
python-control's ``linfnorm`` (SLICOT AB13DD); (c) is the rank-one
perturbation from the SVD, :math:`\Delta = v_1 u_1^H/\sigma_1`; (d) searches
the one free phase (lower bound) and the one free scaling (upper bound) of
two complex ``1 x 1`` blocks by a scan and a bounded one-dimensional
minimisation.
"""
from __future__ import annotations

import control as ct
import numpy as np
from scipy.optimize import minimize_scalar


def m_delta(m1, m2, k1, k2, r1, r2, K):
    Mm = np.diag([m1, m2])
    K0 = np.array([[k1, -k1], [-k1, k1 + k2]])
    b = np.array([[1.0, 0.0], [-1.0, 1.0]])            # columns b_1, b_2
    Mi = np.linalg.inv(Mm)
    Z, I = np.zeros((2, 2)), np.eye(2)
    A = np.block([[Z, I], [-Mi @ K0, Z]])
    B = np.vstack([np.zeros((2, 3)), Mi @ np.column_stack([-b, [0.0, 1.0]])])
    C = np.vstack([np.hstack([np.diag([r1 * k1, r2 * k2]) @ b.T, Z]), [[0.0, 1.0, 0.0, 0.0]]])
    P = ct.ss(A, B, C, np.zeros((3, 3)))
    # the lower LFT of python-control closes the last output (y) to the last input (u) with u = K y
    return P.lft(ct.ss(K), nu=1, ny=1)


def small_gain(M):
    gpeak, fpeak = ct.linfnorm(ct.ss(M))
    return np.array([float(gpeak), float(fpeak), 1.0 / float(gpeak)])


def destabilizing_delta(M, omega):
    Mj = np.asarray(ct.ss(M)(1j * float(omega)), complex).reshape(2, 2)
    U, s, Vh = np.linalg.svd(Mj)
    Delta = np.outer(Vh[0].conj(), U[:, 0].conj()) / s[0]
    return Delta.real, Delta.imag


def _lower(Mj):
    def rho(t):
        return -np.max(np.abs(np.linalg.eigvals(Mj @ np.diag([np.exp(1j * t), 1.0]))))
    grid = np.linspace(-np.pi, np.pi, 73)
    vals = [rho(t) for t in grid]
    k = int(np.argmin(vals))
    res = minimize_scalar(rho, bounds=(grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]), method="bounded",
                          options={"xatol": 1e-10})
    return -min(res.fun, vals[k])


def _upper(Mj):
    def sig(x):
        d = np.exp(x)
        return np.linalg.norm(np.diag([d, 1.0]) @ Mj @ np.diag([1.0 / d, 1.0]), 2)
    grid = np.linspace(-15, 15, 121)
    vals = [sig(x) for x in grid]
    k = int(np.argmin(vals))
    res = minimize_scalar(sig, bounds=(grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]), method="bounded",
                          options={"xatol": 1e-10})
    return min(res.fun, vals[k])


def structured_mu(M_re, M_im):
    Ms = np.asarray(M_re, float) + 1j * np.asarray(M_im, float)
    return np.array([max(_lower(Mj) for Mj in Ms), max(_upper(Mj) for Mj in Ms)])
