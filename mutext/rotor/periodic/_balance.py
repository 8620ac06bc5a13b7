r"""Truncated harmonic balance: the block solve for the harmonic transfer functions
:math:`H_k` of a time-periodic rotor, and :class:`HarmonicResponse` that holds them.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

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
