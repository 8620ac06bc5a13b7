r"""The time-periodic rotor: :class:`PeriodicRotor` (its matrices and the turning cracks'
changes), the Rayleigh-Ritz reduction and :func:`periodic_rotor`, which builds it from a
:class:`~mutext.rotor.Rotor`.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Sequence

import casadi as ca
import numpy as np
import scipy.linalg as sla

from ...errors import ModelError
from ...lti import blas_single_thread
from ..analysis import _port_info, _ports, _speed
from ..crack import breathing_fourier, breathing_weights
from ._balance import _response


@dataclass
class _TurningCrack:
    name: str
    law: str
    theta0: float
    A: tuple          # (Axx, Ayy, Axy), global (n x n) in the rotor's coordinates


@dataclass
class PeriodicRotor:
    """The matrices of a rotor whose stiffness turns with the shaft.

    Build it with :func:`periodic_rotor`; :meth:`reduce` projects it on the
    modes below a cutoff (the modal coordinates the time integration needs).

    Attributes
    ----------
    M, D : ndarray
        Mass and velocity matrices (``D = C + speed * G``).
    K_healthy : ndarray
        Stiffness without the turning cracks.
    cracks : list
        The turning cracks: name, law, angle at t = 0, and their global
        :math:`A_{xx}, A_{yy}, A_{xy}`.
    B, Cy : ndarray
        Inputs (N or A per unit input) and output selection.
    speed : float
        Running speed [rad/s].
    basis : ndarray or None
        Mass-normalised modes (``ndof x r``) when reduced, else None.
    reduction_error : float or None
        Largest relative error of the reduced time-averaged FRF on the band
        it was checked on (see :meth:`reduce`).
    inputs, outputs : list of str
        Names of the input and output ports (the columns of ``B``, the rows of ``Cy``).
    ports : dict
        Port name -> ``(station, direction, quantity)``.
    name : str
        Name of the model.
    cutoff_hz : float or None
        Cutoff of the reduction [Hz], or None.
    reduction_band_hz : tuple or None
        Band [Hz] on which ``reduction_error`` was measured.
    """
    M: np.ndarray
    D: np.ndarray
    K_healthy: np.ndarray
    cracks: list
    B: np.ndarray
    Cy: np.ndarray
    speed: float
    inputs: list
    outputs: list
    ports: dict = field(default_factory=dict)
    name: str = "rotor"
    basis: np.ndarray | None = None
    cutoff_hz: float | None = None
    reduction_error: float | None = None
    reduction_band_hz: tuple | None = None

    @property
    def n(self) -> int:
        return self.M.shape[0]

    @property
    def period(self) -> float:
        """One revolution [s]."""
        return 2.0 * np.pi / self.speed

    def stiffness_harmonics(self, max_order: int) -> dict:
        r""":math:`K_m` for :math:`|m| \le` ``max_order`` (complex ``n x n``), with
        :math:`K(t) = \sum_m K_m e^{jm\Omega t}`; ``K_0`` includes :math:`K_h`.

        Parameters
        ----------
        max_order : int
            Highest order :math:`|m|` returned.
        """
        Km = {m: np.zeros((self.n, self.n), complex) for m in range(-max_order, max_order + 1)}
        Km[0] = Km[0] + self.K_healthy
        for c in self.cracks:
            coef = breathing_fourier(c.law, max_order)
            for m in range(-max_order, max_order + 1):
                cm = coef[m + max_order] * np.exp(1j * m * c.theta0)
                if np.any(np.abs(cm) > 1e-14):
                    Km[m] += cm[0] * c.A[0] + cm[1] * c.A[1] + cm[2] * c.A[2]
        return Km

    def stiffness_at(self, theta) -> np.ndarray:
        r"""Stiffness at shaft angles ``theta`` [rad] (the angle of the rotation, :math:`\Omega t`),
        from the breathing laws themselves; shape ``(len(theta), n, n)``.

        Parameters
        ----------
        theta : float or array_like
            Shaft angles [rad].
        """
        th = np.atleast_1d(np.asarray(theta, float))
        K = np.broadcast_to(self.K_healthy, (th.size, self.n, self.n)).copy()
        for c in self.cracks:
            g = breathing_weights(th + c.theta0, c.law)
            for gj, Aj in zip(g, c.A):
                K += gj[:, None, None] * Aj[None]
        return K

    def time_invariant(self) -> bool:
        return not self.cracks or self.speed == 0.0

    def ritz_basis(self, cutoff_hz: float) -> np.ndarray:
        """The mass-orthonormal Ritz basis of :meth:`reduce` (``ndof x r``), without the error check.

        Parameters
        ----------
        cutoff_hz : float
            Modes of the time-averaged stiffness below this frequency [Hz] are kept.
        """
        if self.basis is not None:
            raise ModelError(f"{self.name}: the model is already reduced")
        if not (isinstance(cutoff_hz, (int, float)) and np.isfinite(cutoff_hz) and cutoff_hz > 0):
            raise ModelError(f"cutoff_hz must be a positive frequency [Hz], got {cutoff_hz!r}")
        K0 = self.stiffness_harmonics(0)[0].real
        with blas_single_thread():
            lam, Phi = sla.eigh(K0, self.M)
            keep = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi) <= cutoff_hz
            F = [self.B, self.Cy.T]
            if self.cracks:
                U, sv, _ = np.linalg.svd(np.hstack([a for c in self.cracks for a in c.A]))
                F.append(U[:, :int(np.sum(sv > 1e-10 * sv[0]))])
            V = np.hstack([Phi[:, keep], np.linalg.solve(K0, np.hstack(F))])
            # drop directions already spanned, then re-diagonalise on the basis
            R = np.linalg.qr(V, mode="r")
            V = V[:, np.abs(np.diag(R)) > 1e-10 * np.max(np.abs(np.diag(R)))]
            _, W = sla.eigh(V.T @ K0 @ V, V.T @ self.M @ V)
        return V @ W

    def reduce(self, cutoff_hz: float, *, band_hz=(20.0, 225.0)) -> "PeriodicRotor":
        r"""Rayleigh-Ritz reduction: modes below ``cutoff_hz`` plus static shapes.

        The basis holds the undamped modes of the time-averaged stiffness
        :math:`K_0` below the cutoff and the static shapes
        :math:`K_0^{-1}F` of the crack's force patterns (the range of its
        :math:`A` matrices), the inputs and the outputs, made mass-orthonormal
        and re-diagonalised.  Modes alone are not enough: the turning crack
        bends the shaft locally, which low modes cannot represent, and a
        modal basis up to 20 kHz still misses the sidebands by a few percent.

        ``reduction_error`` is measured against the full model on ``band_hz``
        (every 0.5 Hz for the time-averaged response, and the harmonic
        transfer functions :math:`H_0` and :math:`H_{\pm 1}` with N = 2 on
        every 10th of those frequencies): the largest deviation over the
        largest response, over every channel.

        Parameters
        ----------
        cutoff_hz : float
            Modes of the time-averaged stiffness below this frequency [Hz] are kept.
        band_hz : (float, float), optional
            Band [Hz] on which the reduction error is measured.
        """
        red = self.project(self.ritz_basis(cutoff_hz))
        red.cutoff_hz = float(cutoff_hz)
        lo, hi = float(band_hz[0]), float(band_hz[1])
        if not (0 < lo < hi):
            raise ModelError(f"band_hz must be (low, high) with 0 < low < high, got {band_hz!r}")
        f = np.arange(lo, hi + 1e-9, 0.5) if hi - lo >= 1.0 else np.linspace(lo, hi, 3)
        err = [_rel_err(_response(red, f, 0)(0), _response(self, f, 0)(0))]
        if not self.time_invariant():
            fr, rr = _response(self, f[::10], 2), _response(red, f[::10], 2)
            err += [_rel_err(rr(k), fr(k)) for k in (-1, 0, 1)]
        red.reduction_error = float(max(err))
        red.reduction_band_hz = (float(f[0]), float(f[-1]))
        return red


def _project(self, P) -> "PeriodicRotor":
    """The model on the mass-orthonormal basis ``P`` (``ndof x r``, e.g. the ``basis`` of a
    reduction of a neighbouring model: the same rotor with another crack depth).

    Parameters
    ----------
    P : (ndof, r) array_like
        Mass-orthonormal basis.
    """
    if self.basis is not None:
        raise ModelError(f"{self.name}: the model is already reduced")
    P = np.asarray(P, float)
    if P.ndim != 2 or P.shape[0] != self.n:
        raise ModelError(f"{self.name}: a basis needs {self.n} rows, got shape {P.shape}")

    def proj(X):
        return P.T @ X @ P

    return replace(self, M=proj(self.M), D=proj(self.D), K_healthy=proj(self.K_healthy),
                   cracks=[replace(c, A=tuple(proj(a) for a in c.A)) for c in self.cracks],
                   B=P.T @ self.B, Cy=self.Cy @ P, basis=P, reduction_error=None, reduction_band_hz=None)


PeriodicRotor.project = _project


def _rel_err(H, ref) -> float:
    """Largest deviation over the largest reference response, per channel, then the worst channel."""
    scale = np.max(np.abs(ref), axis=-1, keepdims=True)
    return float(np.max(np.abs(H - ref) / np.where(scale > 0, scale, 1.0)))


def periodic_rotor(model, *, inputs: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
                   speed: float | None = None, values=None) -> PeriodicRotor:
    """The time-periodic matrices of a :class:`~mutext.rotor.Rotor` with breathing cracks.

    Cracks declared with ``breathing = "gaping" | "mayes" | "gasch"`` (in a model
    file, or ``Crack(..., breathing=...)``) turn with the shaft; everything
    else is time-invariant.  A rotor without a breathing crack gives a
    time-invariant model, for which every function here returns the ordinary
    FRF (a useful control).

    Parameters
    ----------
    model : Rotor
    inputs, outputs : sequence of str, optional
        Port names (default: all).
    speed : float, optional
        Running speed [rad/s] (default: the model's).
    values : mapping or array, optional
        Parameter values (default: nominal).
    """
    from ..assembly import Rotor
    if not isinstance(model, Rotor):
        raise ModelError(f"periodic_rotor needs a Rotor, got {type(model).__name__}")
    speed = _speed(model, speed)
    ins, outs = _ports(model, inputs, outputs)
    v = model.values(values)
    cracks = [el for el in model.elements if getattr(el, "breathing", None)]
    if cracks and not speed > 0:
        raise ModelError(f"{model.name}: the breathing crack '{cracks[0].name}' needs a running speed "
                         f"(speed or speed_rpm > 0), got {speed:g} rad/s")
    with blas_single_thread():
        M, C, K, G = model.matrices(v)
    B = model.input_matrix(v)[:, [model.input_names.index(q) for q in ins]]
    Cy = model.output_matrix()[[model.output_names.index(q) for q in outs]]
    turning, K_h = [], K.copy()
    psym = model._ps.symbols
    for el in cracks:
        loc = el.directional_deltas(psym, model.layout)
        fn = ca.Function("A", [model.p], list(loc))
        idx = np.asarray(el.dofs(model.layout))
        A = []
        for a in fn(v):
            g = np.zeros_like(K)
            g[np.ix_(idx, idx)] = np.asarray(a.full())
            A.append(g)
        c0 = breathing_fourier(el.breathing, 0)[0].real
        K_h -= c0[0] * A[0] + c0[1] * A[1] + c0[2] * A[2]
        theta0 = float(el.orientation)
        turning.append(_TurningCrack(el.name, el.breathing, theta0, tuple(A)))
    return PeriodicRotor(M=M, D=C + speed * G, K_healthy=K_h, cracks=turning, B=B, Cy=Cy, speed=float(speed),
                         inputs=ins, outputs=outs, ports=_port_info(model, ins, outs), name=model.name)


def _as_periodic(model, inputs=None, outputs=None) -> PeriodicRotor:
    if isinstance(model, PeriodicRotor):
        if inputs is not None or outputs is not None:
            raise ModelError("give the ports when building the PeriodicRotor (periodic_rotor(..., inputs=...))")
        return model
    return periodic_rotor(model, inputs=inputs, outputs=outputs)
