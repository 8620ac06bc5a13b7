r"""Truncated harmonic balance: the block solve for the harmonic transfer functions
:math:`H_k` of a time-periodic rotor, and :class:`HarmonicResponse` that holds them.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from ...errors import ModelError
from ...lti import blas_single_thread
from ...response import FRFMatrix


def _freqs(freqs_hz) -> np.ndarray:
    f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ModelError("frequencies must be a non-empty list of positive, finite values [Hz]")
    return f


def _harmonics(N) -> int:
    if isinstance(N, bool) or not isinstance(N, (int, np.integer)) or N < 0:
        raise ModelError(f"harmonics must be a non-negative integer (k = -N..N), got {N!r}")
    return int(N)


@dataclass
class HarmonicResponse:
    r"""Harmonic transfer functions :math:`H_k(\omega)`, ``k = -N..N``.

    ``H[k + N]`` has shape ``(noutputs, ninputs, nfreq)``: the response at
    :math:`\omega + k\Omega` to a unit input :math:`e^{j\omega t}`.

    Attributes
    ----------
    freqs_hz : (nfreq,) ndarray
        Excitation frequencies [Hz].
    H : (2N+1, noutputs, ninputs, nfreq) complex ndarray
        The harmonic transfer functions, output unit per input unit.
    harmonics : int
        The truncation N.
    speed : float
        Spin speed [rad/s].
    inputs, outputs : list of str
        Port names.
    ports : dict
        Port name -> ``(station, direction, quantity)``.
    seconds : float
        Wall time of the computation.
    """
    freqs_hz: np.ndarray
    H: np.ndarray
    harmonics: int
    speed: float
    inputs: list
    outputs: list
    ports: dict
    seconds: float

    def __call__(self, k: int) -> np.ndarray:
        if abs(k) > self.harmonics:
            raise ModelError(f"harmonic {k} was not computed (N = {self.harmonics})")
        return self.H[k + self.harmonics]

    def frf(self) -> FRFMatrix:
        """:math:`H_0` as an FRF (the response at the excitation frequency, without the analyzer's window)."""
        return FRFMatrix(self.freqs_hz, self(0), list(self.inputs), list(self.outputs), self.speed,
                         dict(self.ports))


def _harmonic_balance(pr, f, N: int, t0: float) -> HarmonicResponse:
    """The truncated harmonic balance of the :class:`PeriodicRotor` ``pr`` at the checked
    frequencies ``f`` [Hz] with ``N`` harmonics either side; ``t0`` is when the work started."""
    if pr.time_invariant():
        N_eff = 0
    else:
        N_eff = N
    n, nb = pr.n, 2 * N_eff + 1
    Km = pr.stiffness_harmonics(2 * N_eff)
    base = np.zeros((nb * n, nb * n), complex)
    for k in range(nb):
        for l in range(nb):
            if k != l and (k - l) in Km:
                base[k * n:(k + 1) * n, l * n:(l + 1) * n] = Km[k - l]
    K0 = Km[0]
    nin, nout = pr.B.shape[1], pr.Cy.shape[0]
    rhs = np.zeros((nb * n, nin), complex)
    rhs[N_eff * n:(N_eff + 1) * n] = pr.B
    H = np.zeros((2 * N + 1, nout, nin, f.size), complex)
    w = 2 * np.pi * f
    ks = np.arange(-N_eff, N_eff + 1)
    chunk = max(1, int(4_000_000 // base.size))
    with blas_single_thread():
        for i0 in range(0, f.size, chunk):
            wc = w[i0:i0 + chunk]
            Z = np.broadcast_to(base, (wc.size,) + base.shape).copy()
            for b, k in enumerate(ks):
                nu = (wc + k * pr.speed)[:, None, None]
                Z[:, b * n:(b + 1) * n, b * n:(b + 1) * n] += K0[None] - nu * nu * pr.M[None] + 1j * nu * pr.D[None]
            X = np.linalg.solve(Z, np.broadcast_to(rhs, (wc.size,) + rhs.shape))
            X = X.reshape(wc.size, nb, n, nin)
            Hc = np.einsum("on,fbni->bofi", pr.Cy, X)
            H[N - N_eff:N + N_eff + 1, :, :, i0:i0 + chunk] = np.moveaxis(Hc, 2, -1)
    return HarmonicResponse(f, H, N, pr.speed, list(pr.inputs), list(pr.outputs), dict(pr.ports),
                            time.perf_counter() - t0)


def _response(pr, freqs_hz, harmonics) -> HarmonicResponse:
    """:func:`harmonic_response` of a :class:`PeriodicRotor` (its own ports)."""
    t0 = time.perf_counter()
    return _harmonic_balance(pr, _freqs(freqs_hz), _harmonics(harmonics), t0)


def _crack_range(pr) -> np.ndarray | None:
    """An orthonormal basis ``U`` (``n x r``) of the range of the turning cracks' stiffness changes,
    or None when it is not smaller than the model (then the low-rank solve saves nothing)."""
    A = np.hstack([a for c in pr.cracks for a in c.A])
    U, sv, _ = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(sv > 1e-12 * sv[0])) if sv.size and sv[0] > 0 else 0
    return U[:, :r] if 0 < r < pr.n else None


#: Above this size of the reduced block system, (2N+1) r, it is solved by GMRES (an FFT for the
#: Toeplitz product) instead of a dense factorisation; frequencies where GMRES does not reach
#: ``_GMRES_TOL`` within ``_GMRES_MAXIT`` iterations are solved densely.
_DENSE_MAX, _GMRES_TOL, _GMRES_MAXIT = 400, 1e-12, 150


def _harmonic_balance_lowrank(pr, f, N: int, t0: float, U: np.ndarray) -> HarmonicResponse:
    r""":func:`_harmonic_balance` through the crack's range ``U`` (``n x r``, :func:`_crack_range`).

    Every :math:`K_{m \ne 0}` is :math:`U C_m U^T`, so with :math:`P_k = U^T Q_k` the block system
    becomes :math:`P_k + G_k \sum_{l \ne k} C_{k-l} P_l = \delta_{k0} U^T Z_0^{-1} B`,
    :math:`G_k = U^T Z(\omega + k\Omega)^{-1} U`: size :math:`(2N+1)\,r` instead of
    :math:`(2N+1)\,n`, then :math:`H_k = \delta_{k0} C_y Z_0^{-1} B - C_y Z_k^{-1} U
    \sum_{l \ne k} C_{k-l} P_l`.  The same equations, solved otherwise: equal to rounding (to the
    GMRES tolerance, relative to the solution's norm, above ``_DENSE_MAX``)."""
    n, r, nb = pr.n, U.shape[1], 2 * N + 1
    Km = pr.stiffness_harmonics(2 * N)
    K0 = Km[0]
    C = np.zeros((4 * N + 1, r, r), complex)           # C[m + 2N] = U^T K_m U, C_0 = 0
    for m in range(-2 * N, 2 * N + 1):
        if m != 0:
            C[m + 2 * N] = U.T @ Km[m] @ U
    dense = nb * r <= _DENSE_MAX
    if dense:
        T = np.zeros((nb, r, nb, r), complex)
        for k in range(nb):
            T[k, :, :, :] = np.moveaxis(C[k - np.arange(nb) + 2 * N], 0, 1)
        T = T.reshape(nb * r, nb * r)
    L = _fft_size(6 * N + 1)
    Chat = np.fft.fft(C, L, axis=0)                      # (L, r, r)
    nin, nout = pr.B.shape[1], pr.Cy.shape[0]
    H = np.zeros((nb, nout, nin, f.size), complex)
    w = 2 * np.pi * f
    ks = np.arange(-N, N + 1)
    RHS = np.hstack([U, pr.B])
    chunk = max(1, min(int(2_000_000 // (nb * n * n)), int(4_000_000 // (nb * r) ** 2) if dense else 32))

    def toeplitz(x):                                     # x (B, nb, r) -> sum_l C_{k-l} x_l
        X = sfft.fft(x, L, axis=1)
        Yh = sum(Chat[:, :, b] * X[:, :, b, None] for b in range(r))
        return sfft.ifft(Yh, axis=1)[:, 2 * N:2 * N + nb]

    with blas_single_thread():
        for i0 in range(0, f.size, chunk):
            wc = w[i0:i0 + chunk]
            F = wc.size
            nu = (wc[:, None] + ks[None, :] * pr.speed)[..., None, None]          # (F, nb, 1, 1)
            Z = K0 - nu * nu * pr.M + 1j * nu * pr.D                              # (F, nb, n, n)
            X = np.linalg.solve(Z, np.broadcast_to(RHS, Z.shape[:2] + RHS.shape))   # (F, nb, n, r + nin)
            G = np.einsum("nr,fbns->fbrs", U, X[..., :r])                         # (F, nb, r, r)
            Y = np.einsum("on,fbnr->fbor", pr.Cy, X[..., :r])                     # (F, nb, nout, r)
            XB = X[:, N, :, r:]                                                   # (F, n, nin)
            rhs = np.zeros((F, nb, r, nin), complex)
            rhs[:, N] = np.einsum("nr,fni->fri", U, XB)
            if dense:
                # I + blockdiag(G) T
                S = np.einsum("fbrs,bsc->fbrc", G, T.reshape(nb, r, nb * r)).reshape(F, nb * r, nb * r)
                S += np.eye(nb * r)
                P = np.linalg.solve(S, rhs.reshape(F, nb * r, nin))               # (F, nb r, nin)
                TP = (T @ P).reshape(F, nb, r, nin)
            else:
                Gi = np.repeat(G, nin, axis=0)                                    # (F nin, nb, r, r)
                b = np.moveaxis(rhs, 3, 1).reshape(F * nin, nb * r)

                def apply(x):
                    y = x.reshape(-1, nb, r)
                    t = toeplitz(y)
                    return (y + sum(Gi[..., b] * t[..., b, None] for b in range(r))).reshape(-1, nb * r)

                P = _gmres(apply, b)
                res = np.linalg.norm(b - apply(P), axis=1) / np.linalg.norm(b, axis=1)
                for j in np.flatnonzero(~(res <= 100 * _GMRES_TOL)):
                    fi = j // nin
                    Tj = np.zeros((nb * r, nb * r), complex)
                    E = np.eye(nb * r, dtype=complex).reshape(nb * r, nb, r)
                    Tj = (E + np.einsum("brs,xbs->xbr", G[fi], toeplitz(E))).reshape(nb * r, nb * r).T
                    P[j] = np.linalg.solve(Tj, b[j])
                TP = np.moveaxis(toeplitz(P.reshape(-1, nb, r)).reshape(F, nin, nb, r), 1, 3)
            Hc = -np.einsum("fbor,fbri->boif", Y, TP)
            Hc[N] += np.einsum("on,fni->oif", pr.Cy, XB)
            H[:, :, :, i0:i0 + chunk] = Hc
    return HarmonicResponse(f, H, N, pr.speed, list(pr.inputs), list(pr.outputs), dict(pr.ports),
                            time.perf_counter() - t0)


def _fft_size(n: int) -> int:
    """The smallest 2^a 3^b at least ``n``."""
    best = 1 << (n - 1).bit_length()
    p3 = 1
    while p3 < best:
        p2 = p3
        while p2 < n:
            p2 *= 2
        best = min(best, p2)
        p3 *= 3
    return best


def _gmres(apply, b: np.ndarray) -> np.ndarray:
    """GMRES without restart on a batch of systems ``apply(x) = b`` (rows of ``b``), from zero, to
    ``_GMRES_TOL`` relative residual or ``_GMRES_MAXIT`` iterations (classical Gram-Schmidt twice)."""
    B, n = b.shape
    m = min(_GMRES_MAXIT, n)
    beta = np.linalg.norm(b, axis=1)
    beta = np.where(beta > 0, beta, 1.0)
    V = np.zeros((B, m + 1, n), complex)
    Hh = np.zeros((B, m + 1, m), complex)
    V[:, 0] = b / beta[:, None]
    y = None
    for j in range(m):
        v = apply(V[:, j])
        for _ in range(2):
            h = np.conj(V[:, :j + 1] @ v.conj()[..., None])[..., 0]          # V^H v
            v = v - (h[:, None, :] @ V[:, :j + 1])[:, 0]
            Hh[:, :j + 1, j] += h
        hn = np.linalg.norm(v, axis=1)
        Hh[:, j + 1, j] = hn
        V[:, j + 1] = v / np.where(hn > 0, hn, 1.0)[:, None]
        if j % 5 == 4 or j == m - 1:
            Hj = Hh[:, :j + 2, :j + 1]
            Q, R = np.linalg.qr(Hj)
            g = Q[:, 0, :].conj() * beta[:, None]                 # Q^H (beta e1)
            y = np.linalg.solve(R, g[..., None])[..., 0]
            resid = np.linalg.norm(np.einsum("bij,bj->bi", Hj, y) - beta[:, None] * np.eye(j + 2)[0], axis=1)
            if np.all(resid <= _GMRES_TOL * beta):
                break
    return (y[:, None, :] @ V[:, :y.shape[1]])[:, 0]
