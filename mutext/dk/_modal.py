r"""The controller in real modal form (the parameters that refinement moves) and the loop
augmented with the maps from the control input and to the measurement.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import cdf2rdf

from ..errors import ModelError
from ..lti import lft_lower, ss


class _Modal:
    r"""A controller in real modal form, each mode's input and output balanced.

    Parameters ``theta``: the real parts and imaginary parts of the modes (one
    per real mode, two per complex pair: the block
    :math:`\begin{bmatrix}\sigma & \omega\\ -\omega & \sigma\end{bmatrix}`),
    then ``B`` (row-major), ``C`` (row-major) and ``D``; ``scale`` the size of
    each, which sets the trust region.
    """

    def __init__(self, K):
        A, B, C, D = (np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))
        n = A.shape[0]
        self.n, self.ny, self.nu = n, B.shape[1], C.shape[0]
        cols, size = [], []
        if n:
            lam, V = np.linalg.eig(A)
            order = np.lexsort((-lam.imag, np.round(lam.real, 10)))
            lam, V = lam[order], V[:, order]
            _, T = cdf2rdf(lam, V)
            self.cond = float(np.linalg.cond(T))
            if not np.isfinite(self.cond) or self.cond > 1e10:
                raise ModelError(f"the controller has no usable modal form (eigenvector condition number "
                                 f"{self.cond:.3g}: repeated or defective poles)")
            Ti = np.linalg.inv(T)
            A, B, C = Ti @ A @ T, Ti @ B, C @ T
            i = 0
            g = np.ones(n)
            while i < n:
                m = 2 if (i + 1 < n and abs(A[i, i + 1]) > 1e-12 * (1.0 + abs(A[i, i]))) else 1
                e = np.zeros((n, n))
                e[i:i + m, i:i + m] = np.eye(m)
                cols.append(e.ravel())
                if m == 2:
                    e = np.zeros((n, n))
                    e[i, i + 1], e[i + 1, i] = 1.0, -1.0
                    cols.append(e.ravel())
                    size += [np.hypot(A[i, i], A[i, i + 1])] * 2
                else:
                    size.append(abs(A[i, i]))
                gb = np.linalg.norm(B[i:i + m]) + 1e-300
                gc = np.linalg.norm(C[:, i:i + m]) + 1e-300
                g[i:i + m] = np.sqrt(gc / gb)
                i += m
            B, C = B * g[:, None], C / g[None, :]
        else:
            self.cond = 1.0
        self.E = np.array(cols).T if cols else np.zeros((0, 0))
        thA = np.linalg.lstsq(self.E, A.ravel(), rcond=None)[0] if n else np.zeros(0)
        self.na = thA.size
        self.theta = np.concatenate([thA, B.ravel(), C.ravel(), D.ravel()])
        ref = max(np.abs(self.theta).max(), 1e-12)
        self.scale = np.concatenate([np.maximum(size, 1e-9 * ref), np.abs(B.ravel()), np.abs(C.ravel()),
                                     np.abs(D.ravel())])
        self.scale = np.maximum(self.scale, 1e-6 * ref)

    def matrices(self, theta):
        n, ny, nu, na = self.n, self.ny, self.nu, self.na
        A = (self.E @ theta[:na]).reshape(n, n) if n else np.zeros((0, 0))
        B = theta[na:na + n * ny].reshape(n, ny)
        C = theta[na + n * ny:na + n * ny + nu * n].reshape(nu, n)
        D = theta[na + n * ny + nu * n:].reshape(nu, ny)
        return A, B, C, D

    def ss(self, theta):
        return ss(*self.matrices(theta))

    def response(self, theta, s):
        """K(s) (nw, nu, ny) and the resolvent factors C(sI-A)^-1 (nw, nu, n), (sI-A)^-1 B (nw, n, ny)."""
        A, B, C, D = self.matrices(theta)
        n = self.n
        Z = s[:, None, None] * np.eye(n) - A
        Br = np.linalg.solve(Z, np.broadcast_to(B, (s.size, n, self.ny)))
        Cr = np.swapaxes(np.linalg.solve(np.swapaxes(Z, 1, 2), np.broadcast_to(C.T, (s.size, n, self.nu))), 1, 2)
        return Cr @ B + D, Cr, Br

    def d_response(self, Cr, Br):
        """dK/dtheta: (nw, nu*ny, ntheta), K flattened row-major."""
        nw, n, ny, nu = Cr.shape[0], self.n, self.ny, self.nu
        dA = np.einsum("wla,wbk->wlkab", Cr, Br).reshape(nw, nu * ny, n * n) @ self.E
        eye_y, eye_u = np.eye(ny), np.eye(nu)
        dB = np.einsum("wla,kc->wlkac", Cr, eye_y).reshape(nw, nu * ny, n * ny)
        dC = np.einsum("lm,wak->wlkma", eye_u, Br).reshape(nw, nu * ny, nu * n)
        dD = np.broadcast_to(np.eye(nu * ny), (nw, nu * ny, nu * ny))
        return np.concatenate([dA, dB, dC, dD], axis=2)

    def sensitivity_factors(self, Lft, Rgt, Cr, Br):
        r"""For the linear functional :math:`dK \mapsto L\,dK\,R` (``Lft`` (m, nu), ``Rgt`` (ny, m)):
        its value for each parameter, (ntheta, m, m)."""
        n = self.n
        X = Lft @ Cr                    # (m, n)
        Zr = Br @ Rgt                   # (n, m)
        FA = np.einsum("ia,bj->abij", X, Zr).reshape(n * n, X.shape[0], -1)
        FA = np.einsum("pij,pq->qij", FA, self.E) if n else FA[:0]
        FB = np.einsum("ia,kj->akij", X, Rgt).reshape(n * self.ny, X.shape[0], -1)
        FC = np.einsum("il,aj->laij", Lft, Zr).reshape(self.nu * n, X.shape[0], -1)
        FD = np.einsum("il,kj->lkij", Lft, Rgt).reshape(self.nu * self.ny, X.shape[0], -1)
        return np.concatenate([FA, FB, FC, FD], axis=0)


def _augmented_loop(P, K, nc, nr, nmeas, ncon):
    """The loop of ``P`` and ``K`` with an extra input ``v`` added to ``u`` and ``y`` as an extra
    output: inputs ``[w, v]``, outputs ``[z, y]``; its blocks are M, U (z from v), V (y from w)."""
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    Bw, Bu = B[:, :nr], B[:, nr:]
    Cz, Cy = C[:nc], C[nc:]
    Dz, Dy = D[:nc], D[nc:]
    Pa = ss(A, np.hstack([Bw, Bu, Bu]), np.vstack([Cz, Cy, Cy]),
            np.block([[Dz[:, :nr], Dz[:, nr:], Dz[:, nr:]], [Dy[:, :nr], Dy[:, nr:], Dy[:, nr:]],
                      [Dy[:, :nr], Dy[:, nr:], Dy[:, nr:]]]))
    return lft_lower(Pa, K, nmeas, ncon)
