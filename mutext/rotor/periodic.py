r"""A rotor with a breathing crack at speed: a linear time-periodic system.

A transverse crack turns with the shaft.  Under weight dominance it opens
when its mouth faces down and closes half a turn later, so the shaft
stiffness changes with the rotation angle :math:`\theta = \Omega t + \theta_0`:

.. math::
    M\ddot q + (C + \Omega G)\dot q + \Big(K_h + \sum_{\text{cracks}} \big[
    g_{xx}(\theta) A_{xx} + g_{yy}(\theta) A_{yy} + g_{xy}(\theta) A_{xy}\big]\Big) q = B u,

with :math:`K_h` the rotor without the crack, :math:`A` the changes of the
fully open crack (:meth:`mutext.rotor.crack.Crack.directional_deltas`) and
:math:`g` the breathing law (:func:`mutext.rotor.crack.breathing_weights`).
The stiffness is periodic with one revolution, :math:`K(t) = \sum_m K_m
e^{jm\Omega t}` (orders up to 3 for the Mayes law, 2 for the gaping
notch, all orders for the Gasch switch).

**Harmonic transfer functions.**  Forced at :math:`e^{j\omega t}`, the
steady response is :math:`q(t) = \sum_k Q_k e^{j(\omega + k\Omega)t}` and
harmonic balance gives, for :math:`k = -N..N` (truncated),

.. math::
    Z(\omega + k\Omega)\,Q_k + \sum_{m \ne 0} K_m Q_{k-m} = B\,\delta_{k0},\qquad
    Z(\nu) = K_0 - \nu^2 M + j\nu(C + \Omega G),

a block system of size :math:`(2N+1)\,n` per frequency
(:func:`harmonic_response`).  For the smooth laws the truncation converges
fast (Mayes: :math:`2.5\cdot10^{-6}` at the default N = 6 on the thesis
rotor); the Gasch switch has harmonics decaying like :math:`1/m` and
converges like :math:`1/N` (0.4 % at N = 24, 0.1 % at N = 64 near the second
mode).  :math:`H_k = C_y Q_k` are the harmonic
transfer functions ([Wer91]_): :math:`H_0` is what reaches the excitation
frequency, :math:`H_{k \ne 0}` the sidebands at :math:`\omega + k\Omega`.

**What the analyzer measures.**  A stepped-sine analyzer drives
:math:`u = a\cos(\omega t + \varphi)`, waits a settling time
:math:`t_s`, and correlates the response with the excitation over a whole
number of revolutions :math:`T`:
:math:`\hat H = \frac{2}{aT}\int_{t_s}^{t_s+T} y\,e^{-j(\omega t+\varphi)}dt`.
With the harmonic transfer functions this is exactly

.. math::
    \hat H(\omega) = H_0(\omega) + e^{-2j\varphi}\sum_k \overline{H_{-k}(\omega)}\;
    \frac{1}{T}\int_{t_s}^{t_s+T} e^{j(k\Omega - 2\omega)t}dt,

(:func:`analyzer_frf`): the second term, from the negative-frequency half of
the real excitation, matters only where :math:`2\omega` is near a multiple
of :math:`\Omega`.  The sidebands make the measured FRF resonate where
:math:`\omega \pm k\Omega` meets a natural frequency, which no
time-invariant model can reproduce.

**Combination frequencies.**  The first-order signature of the
time-periodic rotor is not in :math:`\hat H` (where it enters only through
the resonances of the small :math:`H_{k\ne0}` terms folded back) but at the
combination frequencies :math:`\omega + k\Omega` themselves: an analyzer
that also correlates the response with :math:`e^{-j((\omega + k\Omega)t +
\varphi)}` (the rotor's angle known from a once-per-revolution mark)
measures

.. math::
    \hat H_k(\omega) = H_k(\omega) + e^{-2j\varphi}\sum_{k'} \overline{H_{k'}(\omega)}\;
    \frac{1}{T}\int_{t_s}^{t_s+T} e^{-j(2\omega + (k + k')\Omega)t}dt

(:func:`analyzer_combination`; :math:`k = 0` is :math:`\hat H`).  Over whole
revolutions the excitation line itself averages out exactly, so
:math:`\hat H_k` is the off-diagonal harmonic transfer function, of the
order of the crack's stiffness change, where :math:`\hat H` holds it only
squared (a sideband is :math:`H_{-k}` turned back by a second pass through the
crack) or near the resonances :math:`\omega + k\Omega = \omega_n`.

**Brute force.**  :func:`stepped_sine` integrates the same equations in time
(fourth-order Runge-Kutta on a modal basis, the breathing law evaluated
directly, not through its Fourier series), with the analyzer's settling time
and correlation, as an independent check of the harmonic balance.

Units: SI (m, N, A, s); frequencies in Hz at the interface, rad/s inside.

References
----------
.. [Wer91] N. M. Wereley, *Analysis and control of linear periodically time
   varying systems*, PhD thesis, MIT, 1991 (harmonic transfer functions).
.. [Ga93] R. Gasch, "A survey of the dynamic behaviour of a simple rotating
   shaft with a transverse crack", *J. Sound Vib.* 160(2) (1993) 313-332.
.. [Mad] R. J. Madden, M.S. thesis, Cleveland State University, ch. 4 (the
   sweeps: 0.1 A, 40 revolutions per correlation, 700 ms settling, 10 Hz).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Sequence

import casadi as ca
import numpy as np
import scipy.linalg as sla

from ..errors import ModelError
from ..lti import blas_single_thread
from ..response import FRFMatrix
from .analysis import _port_info, _ports, _speed
from .crack import breathing_fourier, breathing_weights

__all__ = ["PeriodicRotor", "HarmonicResponse", "periodic_rotor", "harmonic_response", "analyzer_frf",
           "analyzer_combination", "stepped_sine", "harmonic_convergence", "ANALYZER"]

#: The thesis's sweep settings (sec. 4.3): 0.1 A, 40 revolutions per correlation, 700 ms settling.
ANALYZER = {"amplitude": 0.1, "revolutions": 40, "settle_s": 0.7}


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
        err = [_rel_err(harmonic_response(red, f, harmonics=0)(0), harmonic_response(self, f, harmonics=0)(0))]
        if not self.time_invariant():
            fr, rr = harmonic_response(self, f[::10], harmonics=2), harmonic_response(red, f[::10], harmonics=2)
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
    from .assembly import Rotor
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


def harmonic_response(model, freqs_hz, *, harmonics: int = 6, inputs=None, outputs=None) -> HarmonicResponse:
    r"""Harmonic transfer functions by truncated harmonic balance (module docstring).

    ``model`` is a :class:`PeriodicRotor` (full or reduced) or a Rotor (then
    ``inputs``/``outputs`` select the ports).  Cost: one dense complex solve
    of size :math:`(2N+1)n` per frequency, so reduce the full finite-element
    model first for sweeps (:meth:`PeriodicRotor.reduce`).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).
    harmonics : int, optional
        Truncation N of the harmonic balance (orders -N..N).
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.
    """
    t0 = time.perf_counter()
    pr = _as_periodic(model, inputs, outputs)
    f = _freqs(freqs_hz)
    N = _harmonics(harmonics)
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


def _window_average(nu, t_start, T):
    """(1/T) * integral of exp(j nu t) over [t_start, t_start + T]."""
    nu = np.asarray(nu, float)
    small = np.abs(nu * T) < 1e-9
    safe = np.where(small, 1.0, nu)
    val = np.exp(1j * safe * t_start) * (np.exp(1j * safe * T) - 1.0) / (1j * safe * T)
    return np.where(small, np.exp(1j * nu * t_start), val)


def _settle(pr: PeriodicRotor, settle_s: float, revolutions: int):
    if not (np.isfinite(settle_s) and settle_s >= 0):
        raise ModelError(f"settle_s must be a non-negative time [s], got {settle_s!r}")
    if isinstance(revolutions, bool) or not isinstance(revolutions, (int, np.integer)) or revolutions < 1:
        raise ModelError(f"revolutions must be a positive integer, got {revolutions!r}")
    if not pr.speed > 0:
        raise ModelError(f"{pr.name}: the analyzer correlates over whole revolutions; the rotor does not "
                         "turn (speed 0)")
    return float(settle_s), revolutions * pr.period


def analyzer_frf(model, freqs_hz, *, harmonics: int = 6, revolutions: int = ANALYZER["revolutions"],
                 settle_s: float = ANALYZER["settle_s"], excitation_phase: float = 0.0,
                 inputs=None, outputs=None) -> FRFMatrix:
    r"""The FRF a stepped-sine analyzer reports for a time-periodic rotor (steady state).

    :math:`\hat H = H_0 + e^{-2j\varphi}\sum_k \overline{H_{-k}}\,\langle e^{j(k\Omega-2\omega)t}\rangle`
    (module docstring), with the window :math:`[t_s, t_s + T]`, :math:`T` =
    ``revolutions`` turns, and the excitation :math:`a\cos(\omega t +
    \varphi)` starting with the rotor at its angle zero.  Transients are not
    included (see :func:`stepped_sine` for those).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).
    harmonics : int, optional
        Truncation N of the harmonic balance (orders -N..N).
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.

    Examples
    --------
    >>> from mutext.rotor import loads_model, data_path
    >>> from mutext.rotor.periodic import periodic_rotor, analyzer_frf
    >>> rotor = loads_model(open(data_path("rotor.toml")).read() +
    ...     "[[crack]]\nstation = 15\ndepth_ratio = 0.4\nbreathing = 'mayes'\n", base_dir=data_path(""))
    >>> pr = periodic_rotor(rotor, inputs=["i12"], outputs=["x13"]).reduce(1500.0)
    >>> H = analyzer_frf(pr, [40.0, 80.0])
    >>> H.H.shape
    (1, 1, 2)
    """
    pr = _as_periodic(model, inputs, outputs)
    hr = harmonic_response(pr, freqs_hz, harmonics=harmonics)
    t_s, T = _settle(pr, settle_s, revolutions)
    w = 2 * np.pi * hr.freqs_hz
    H = hr(0).copy()
    N = hr.harmonics
    for k in range(-N, N + 1):
        avg = _window_average(k * pr.speed - 2 * w, t_s, T)
        H += np.exp(-2j * excitation_phase) * np.conj(hr(-k)) * avg
    return FRFMatrix(hr.freqs_hz, H, list(pr.inputs), list(pr.outputs), pr.speed, dict(pr.ports))


def analyzer_combination(model, freqs_hz, orders=(-2, -1, 1, 2), *, harmonics: int = 6,
                         revolutions: int = ANALYZER["revolutions"], settle_s: float = ANALYZER["settle_s"],
                         excitation_phase: float = 0.0, inputs=None, outputs=None) -> dict:
    r"""Combination-frequency responses :math:`\hat H_k` a stepped-sine analyzer records (steady state).

    For each excitation frequency :math:`\omega` and each order ``k`` in
    ``orders``, the response correlated at :math:`\omega + k\Omega` over
    ``revolutions`` turns after ``settle_s`` (module docstring):
    :math:`\hat H_k = H_k + e^{-2j\varphi}\sum_{k'}\overline{H_{k'}}\,
    \langle e^{-j(2\omega + (k+k')\Omega)t}\rangle`.  ``k = 0`` gives
    :func:`analyzer_frf`.  The phase is referred to the rotor at its angle
    zero at :math:`t = 0` (a keyphasor).  The harmonic balance is solved
    with ``harmonics + max|k|`` terms either side, so that the window terms
    of order ``k`` reach as far as those of :func:`analyzer_frf` (where
    :math:`2f` is a multiple of the speed, order ``k`` draws on
    :math:`H_{-k-2f/F}`).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).

    orders : sequence of int, optional
        Orders k of the combination frequencies :math:`\omega + k\Omega`.
    harmonics : int, optional
        Truncation N of the harmonic balance (orders -N..N).
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.

    Returns
    -------
    dict
        ``{k: FRFMatrix}``, each on the excitation frequencies ``freqs_hz``
        (the response is at ``freqs_hz + k * speed / 2 pi``).
    """
    pr = _as_periodic(model, inputs, outputs)
    ks = []
    for k in orders:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise ModelError(f"orders must be integers (the k of f_exc + k F), got {k!r}")
        ks.append(int(k))
    if not ks:
        raise ModelError("orders must name at least one order k")
    N = _harmonics(harmonics)
    N = N + max(abs(k) for k in ks)
    hr = harmonic_response(pr, freqs_hz, harmonics=N)
    t_s, T = _settle(pr, settle_s, revolutions)
    w = 2 * np.pi * hr.freqs_hz
    out = {}
    for k in ks:
        H = hr(k).copy()
        for kp in range(-N, N + 1):
            avg = _window_average(-(2 * w + (k + kp) * pr.speed), t_s, T)
            H += np.exp(-2j * excitation_phase) * np.conj(hr(kp)) * avg
        out[k] = FRFMatrix(hr.freqs_hz, H, list(pr.inputs), list(pr.outputs), pr.speed, dict(pr.ports))
    return out


def harmonic_convergence(model, freqs_hz, *, harmonics: Sequence[int] = (0, 1, 2, 3, 4, 6, 8),
                         inputs=None, outputs=None) -> list[dict]:
    """How :math:`H_0` settles as the truncation grows: for each N, the largest change
    relative to the largest N (over the frequencies and channels, relative to the
    largest response) and the time taken.

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).

    harmonics : sequence of int, optional
        Truncations N to compare (the largest is the reference).
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.
    """
    pr = _as_periodic(model, inputs, outputs)
    Ns = sorted({_harmonics(n) for n in harmonics})
    res = [harmonic_response(pr, freqs_hz, harmonics=n) for n in Ns]
    ref = res[-1](0)
    scale = np.max(np.abs(ref))
    return [{"harmonics": n, "max_change": float(np.max(np.abs(r(0) - ref)) / scale), "seconds": r.seconds}
            for n, r in zip(Ns, res)]


def _rk4_propagators(pr: PeriodicRotor, P: int, h: float, input_index: int):
    """Per phase step j: z+ = F_j z + g_j @ [u(t), u(t+h/2), u(t+h)] for RK4 on the modal model."""
    r = pr.n
    eps = 1e-9 * h        # the Gasch switch falls on step boundaries: evaluate inside the step
    t = np.arange(P) * h
    stages = np.stack([t + eps, t + 0.5 * h, t + h - eps], axis=1)      # (P, 3)
    K = pr.stiffness_at(pr.speed * stages.ravel()).reshape(P, 3, r, r)
    Mi = np.linalg.inv(pr.M)          # the identity on a mass-orthonormal basis
    A = np.zeros((P, 3, 2 * r, 2 * r))
    A[:, :, :r, r:] = np.eye(r)
    A[:, :, r:, :r] = -Mi @ K
    A[:, :, r:, r:] = -Mi @ pr.D
    b = np.zeros(2 * r)
    b[r:] = Mi @ pr.B[:, input_index]
    I = np.eye(2 * r)

    def step(z, b0, bh, b1):
        A0, Ah, A1 = A[:, 0], A[:, 1], A[:, 2]
        k1 = A0 @ z + b0
        k2 = Ah @ (z + 0.5 * h * k1) + bh
        k3 = Ah @ (z + 0.5 * h * k2) + bh
        k4 = A1 @ (z + h * k3) + b1
        return z + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)

    zero_b = np.zeros((P, 2 * r, 1))
    F = step(np.broadcast_to(I, (P, 2 * r, 2 * r)), 0.0, 0.0, 0.0)
    zz = np.zeros((P, 2 * r, 1))
    bb = np.broadcast_to(b[:, None], (P, 2 * r, 1))
    g = np.concatenate([step(zz, bb, zero_b, zero_b), step(zz, zero_b, bb, zero_b),
                        step(zz, zero_b, zero_b, bb)], axis=2)         # (P, 2r, 3)
    return F, g


def _port_index(names, name, kind: str) -> int:
    """Position of port ``name`` among ``names`` (the first when ``None``), or a named error."""
    if name is None:
        return 0
    if name not in names:
        raise ModelError(f"no {kind} port '{name}' in this rotor; its {kind}s are {', '.join(names)}")
    return list(names).index(name)


def stepped_sine(model, freqs_hz, *, in_port: str | None = None, out_port: str | None = None,
                 amplitude: float = ANALYZER["amplitude"], revolutions: int = ANALYZER["revolutions"],
                 settle_s: float = ANALYZER["settle_s"], excitation_phase: float = 0.0,
                 steps_per_rev: int | None = None, cutoff_hz: float = 1500.0, progress=None,
                 orders: Sequence[int] = ()) -> dict:
    r"""Brute-force stepped-sine measurement by time integration (the analyzer, in software).

    Each frequency starts from rest with the rotor at angle zero, is driven
    by :math:`a\cos(\omega t + \varphi)` for ``settle_s`` (rounded to whole
    integration steps) and then correlated with the excitation over
    ``revolutions`` turns, exactly as :func:`analyzer_frf` assumes, except
    that nothing is assumed about the steady state: the residual transient
    of a lightly damped mode after the settling time is part of the result.
    The equations are integrated on the modal basis of
    :meth:`PeriodicRotor.reduce` (``cutoff_hz`` if ``model`` is not reduced)
    by the classical Runge-Kutta method with ``steps_per_rev`` steps per turn
    (default: the stability limit of the stiffest basis vector with a margin,
    and at least 40 steps per period of the response); the breathing laws are evaluated at every stage, so the check does
    not rely on their Fourier series.  ``orders`` adds the correlations at
    the combination frequencies :math:`\omega + k\Omega` (the independent
    check of :func:`analyzer_combination`).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).

    in_port, out_port : str, optional
        The excited input and the measured output (default: the first of each).
    amplitude : float, optional
        Excitation amplitude (input unit, e.g. A).
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.

    steps_per_rev : int, optional
        Runge-Kutta steps per revolution (default: from the stability limit).
    cutoff_hz : float, optional
        Cutoff [Hz] of the reduction when ``model`` is not reduced.
    progress : callable, optional
        Called with the fraction of the work done (0..1).
    orders : sequence of int, optional
        Orders k of the combination frequencies also correlated.

    Returns
    -------
    dict
        ``freqs_hz``, ``H`` (complex, output unit per input unit), ``steps_per_rev``,
        ``settle_s`` (as used), ``seconds``, ``n_modes``; with ``orders``,
        ``H_orders`` = ``{k: response at f + k F per input unit}``.
    """
    t0 = time.perf_counter()
    pr = model if isinstance(model, PeriodicRotor) else periodic_rotor(model)
    ii = _port_index(pr.inputs, in_port, "input")
    oi = _port_index(pr.outputs, out_port, "output")
    f = _freqs(freqs_hz)
    if pr.basis is None:
        pr = pr.reduce(cutoff_hz)
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise ModelError(f"amplitude must be positive, got {amplitude!r}")
    t_s, _ = _settle(pr, settle_s, revolutions)
    # the stiffest state, not the revolution average: an open crack only removes stiffness (the
    # breathing weights lie in [0, 1]), so the closed crack, K_healthy, bounds K(t) from above; with
    # the mean, a switching (Gasch) crack with both compliances drives RK4 unstable while it is closed
    w_max = float(np.sqrt(np.max(np.linalg.eigvalsh(pr.K_healthy))))
    if steps_per_rev is None:
        # RK4 is stable for h w < 2.8 on the imaginary axis: the stiffest Ritz shape sets the step;
        # the swept response itself gets at least 40 steps per period
        steps_per_rev = max(200, int(np.ceil(w_max * pr.period / 2.5)),
                            int(np.ceil(40 * (f.max() + 3 * pr.speed / (2 * np.pi)) * pr.period)))
    P = int(steps_per_rev)
    if P < 8:
        raise ModelError(f"steps_per_rev must be at least 8, got {steps_per_rev!r}")
    h = pr.period / P
    n_settle = int(round(t_s / h))
    n_rec = revolutions * P
    F, g = _rk4_propagators(pr, P, h, ii)
    r = pr.n
    w = 2 * np.pi * f
    Z = np.zeros((2 * r, f.size))
    c_out = np.zeros(2 * r)
    c_out[:r] = pr.Cy[oi]
    acc = np.zeros(f.size, complex)
    korders = [int(k) for k in orders]
    acc_k = {k: np.zeros(f.size, complex) for k in korders}
    ph = excitation_phase
    total = n_settle + n_rec
    report = max(1, total // 20)
    with blas_single_thread():
        for step in range(total):
            j = step % P
            tn = step * h
            U = amplitude * np.cos(np.outer([tn, tn + 0.5 * h, tn + h], w) + ph)
            Z = F[j] @ Z + g[j] @ U
            if step + 1 > n_settle:
                y = c_out @ Z
                tt = (step + 1) * h
                acc += y * np.exp(-1j * (w * tt + ph))
                for k in korders:
                    acc_k[k] += y * np.exp(-1j * ((w + k * pr.speed) * tt + ph))
            if progress is not None and step % report == 0:
                progress(step / total)
    # rectangle rule over whole periods: samples at t_s + h, ..., t_s + T (periodic integrand)
    H = 2.0 * acc / (amplitude * n_rec)
    extra = {"H_orders": {k: 2.0 * a / (amplitude * n_rec) for k, a in acc_k.items()}} if korders else {}
    return {**extra, "freqs_hz": f, "H": H, "steps_per_rev": P, "settle_s": n_settle * h, "seconds":
            time.perf_counter() - t0, "n_modes": r, "input": pr.inputs[ii], "output": pr.outputs[oi],
            "reduction_error": pr.reduction_error}
