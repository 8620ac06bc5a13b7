r"""Reference solution of exercise ``ex01_two_mass_hinf``.

Two masses: ``m1`` hangs from ``m2`` through the spring ``k1``, ``m2`` is tied
to the ground by ``k2``.  The disturbance force ``f_e`` acts on ``m1``, the
control force ``u`` on ``m2``; the sensor measures ``x2`` with additive noise.
All quantities are SI (kg, N/m, N, m).
"""
from __future__ import annotations

import control as ct
import numpy as np


def mechanical_model(m1, m2, k1, k2):
    """State-space model from ``[f_e, u]`` (N) to ``[x1, x2]`` (m), state ``[x1, x2, dx1, dx2]``."""
    M = np.diag([m1, m2]).astype(float)
    K = np.array([[k1, -k1], [-k1, k1 + k2]], dtype=float)
    F = np.eye(2)                       # f_e pushes on m1, u on m2
    Z = np.zeros((2, 2))
    A = np.block([[Z, np.eye(2)], [-np.linalg.solve(M, K), Z]])
    B = np.vstack([Z, np.linalg.solve(M, F)])
    C = np.hstack([np.eye(2), Z])
    return ct.ss(A, B, C, np.zeros((2, 2)), inputs=["f_e", "u"], outputs=["x1", "x2"])


def generalized_plant(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4,
                      x_max=0.035, u_max=50.0):
    """Generalized plant, inputs ``[f1, f2, u]``, outputs ``[z1, z2, y]``.

    ``f_e = f_max f1`` and ``eta = eta_max f2`` (normalised exogenous inputs),
    ``z1 = x1 / x_max`` and ``z2 = u / u_max`` (normalised errors), and the
    measurement ``y = x2 + eta`` in metres.
    """
    G = mechanical_model(m1, m2, k1, k2)
    A, B, C = G.A, G.B, G.C
    n = A.shape[0]
    B_f = B[:, [0]] * f_max             # f1 -> force on m1
    B_eta = np.zeros((n, 1))            # noise does not move the masses
    B_u = B[:, [1]]
    C_z = np.vstack([C[[0]] / x_max, np.zeros((1, n))])
    C_y = C[[1]]
    D = np.array([[0.0, 0.0, 0.0],
                  [0.0, 0.0, 1.0 / u_max],
                  [0.0, eta_max, 0.0]])
    return ct.ss(A, np.hstack([B_f, B_eta, B_u]), np.vstack([C_z, C_y]), D,
                 inputs=["f1", "f2", "u"], outputs=["z1", "z2", "y"])


def _gain(A, B, C, D, w):
    """Largest singular value of ``C (jw I - A)^-1 B + D``."""
    G = C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B) + D
    return np.linalg.norm(G, 2)


def hinf_norm(sys, rtol=1e-9):
    r"""H-infinity norm of a stable continuous-time system.

    Bruinsma-Steinbuch iteration: for a level :math:`\gamma` above every
    singular value of ``D``, the Hamiltonian

    .. math::
        H(\gamma) = \begin{bmatrix} A + BR^{-1}D^TC & BR^{-1}B^T \\
        -C^T(I + DR^{-1}D^T)C & -(A + BR^{-1}D^TC)^T \end{bmatrix},\quad
        R = \gamma^2 I - D^TD

    has an eigenvalue :math:`j\omega` exactly when :math:`\gamma` is a singular
    value of :math:`G(j\omega)`.  Starting from a lower bound (gains at DC, at
    infinity and at the pole frequencies), the gain is evaluated at the
    midpoints of the intervals where it exceeds the bound, until the
    Hamiltonian at ``(1 + 2 rtol)`` times the bound has no imaginary
    eigenvalue.
    """
    A, B, C, D = (np.asarray(X, dtype=float) for X in (sys.A, sys.B, sys.C, sys.D))
    n, m, p = A.shape[0], D.shape[1], D.shape[0]
    sD = np.linalg.norm(D, 2) if D.size else 0.0
    if n == 0:
        return float(sD)
    poles = np.linalg.eigvals(A)
    if np.any(poles.real >= 0):
        return float("inf")
    # candidate peak frequencies: DC and the pole frequencies
    cands = [0.0] + [abs(q.imag) for q in poles] + [abs(q) for q in poles]
    lo = max([sD] + [_gain(A, B, C, D, w) for w in cands])
    if lo == 0.0:
        return 0.0
    for _ in range(100):
        g = (1.0 + 2.0 * rtol) * lo
        R = g * g * np.eye(m) - D.T @ D
        Ri = np.linalg.inv(R)
        Ah = A + B @ Ri @ D.T @ C
        H = np.block([[Ah, B @ Ri @ B.T], [-C.T @ (np.eye(p) + D @ Ri @ D.T) @ C, -Ah.T]])
        ev = np.linalg.eigvals(H)
        # imaginary-axis eigenvalues, with a tolerance scaled by their size
        w = np.sort(np.abs(ev[np.abs(ev.real) < 1e-8 * np.maximum(1.0, np.abs(ev))].imag))
        if w.size == 0:
            return float(lo)
        mids = 0.5 * (w[:-1] + w[1:]) if w.size > 1 else w
        new = max(_gain(A, B, C, D, x) for x in mids)
        if new <= lo:
            return float(lo)   # the bound no longer improves: converged to rounding
        lo = new
    return float(lo)


def controller():
    """H-infinity controller ``u = K y`` for the thesis plant (weights 28.6 1/m and 0.02 1/N).

    ``x_max = 1/28.6`` reproduces the thesis's rounded weight exactly.
    """
    from mutext.hinf import hinfsyn
    P = generalized_plant(x_max=1.0 / 28.6)
    return hinfsyn(P, 1, 1).K
