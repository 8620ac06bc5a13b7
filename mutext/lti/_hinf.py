"""The H-infinity norm by the Hamiltonian iteration of Bruinsma and Steinbuch ([BS]_, [BBK]_):
:func:`hinf_norm` and its result :class:`HinfNorm`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import Real, validate_params
from ._freqresp import sigma_max
from ._ss import as_ss, check_finite, ss
from ._stability import _axis_poles, balance_states


@dataclass
class HinfNorm:
    """Result of :func:`hinf_norm`.

    Attributes
    ----------
    value : float
        The norm (``inf`` for an unstable system or one with imaginary-axis poles,
        decided by the scale-aware rule of :func:`_axis_poles`).
    frequency : float
        A frequency (rad/s) where the peak is attained (``inf`` if at infinity).
    lower, upper : float
        Certified bracket: ``lower`` is a computed gain, ``upper`` a level at
        which the Hamiltonian has no imaginary-axis eigenvalue.
    iterations : int
    """
    value: float
    frequency: float
    lower: float
    upper: float
    iterations: int

    def __float__(self):
        return float(self.value)


def _hamiltonian(A, B, C, D, g):
    R = g * g * np.eye(D.shape[1]) - D.T @ D
    Ri = np.linalg.inv(R)
    Ah = A + B @ Ri @ D.T @ C
    return np.block([[Ah, B @ Ri @ B.T],
                     [-C.T @ (np.eye(D.shape[0]) + D @ Ri @ D.T) @ C, -Ah.T]])


@validate_params({"rtol": Real(0, 1, closed="neither")})
def hinf_norm(sys, rtol: float = 1e-10, *, require_stable: bool = True) -> HinfNorm:
    r"""H-infinity norm :math:`\sup_\omega \bar\sigma(G(j\omega))` of a continuous-time system.

    Two-step (Bruinsma-Steinbuch [BS]_) iteration on the Hamiltonian

    .. math::
        H(\gamma) = \begin{bmatrix} A + BR^{-1}D^TC & BR^{-1}B^T \\
        -C^T(I + DR^{-1}D^T)C & -(A + BR^{-1}D^TC)^T \end{bmatrix},
        \quad R = \gamma^2 I - D^TD,

    which has an eigenvalue :math:`j\omega` exactly when :math:`\gamma` is a
    singular value of :math:`G(j\omega)` [BBK]_.  Each step evaluates the gain at
    the midpoints of the intervals where the gain exceeds the current lower
    bound, which converges quadratically.

    Parameters
    ----------
    sys : StateSpace
    rtol : float
        Relative width of the final bracket ``[lower, upper]``.
    require_stable : bool
        If True (default), an unstable system has norm ``inf``.  If False the
        L-infinity norm (peak gain on the imaginary axis) is returned, which is
        finite when no pole lies on the imaginary axis.

    The gain is computed on ``G / s`` with ``s`` the size of ``B``, ``C`` and
    ``D`` (an exact rescaling), so systems scaled by 1e-160 or 1e300 give their
    norm, not an overflow; a norm beyond the largest double is ``inf``.

    Examples
    --------
    >>> from mutext.lti import ss, hinf_norm
    >>> G = ss([[0.0, 1.0], [-1.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])   # 1/(s^2 + 0.2 s + 1)
    >>> r = hinf_norm(G)
    >>> round(r.value, 3), round(r.frequency, 3)       # the resonance peak 1/(2 zeta sqrt(1 - zeta^2))
    (5.025, 0.99)
    """
    sys = as_ss(sys)
    check_finite(sys)
    B0, C0, D0 = (np.asarray(X, float) for X in (sys.B, sys.C, sys.D))
    sB = float(np.max(np.abs(B0))) if B0.size else 0.0
    sC = float(np.max(np.abs(C0))) if C0.size else 0.0
    sD0 = float(np.max(np.abs(D0))) if D0.size else 0.0
    logs = [x for x in ((np.log(sB) + np.log(sC)) if sB > 0 and sC > 0 else -np.inf,
                        np.log(sD0) if sD0 > 0 else -np.inf) if np.isfinite(x)]
    if logs and abs(max(logs)) > 30:
        # rescale to gains of order one: G = exp(ls) G', exactly, with |B'|, |C'|, |D'| <= 1
        ls = max(logs)
        Bs = B0 / sB if sB > 0 else B0
        Cs = C0 / sC * np.exp(np.log(sB) + np.log(sC) - ls) if sB > 0 and sC > 0 else C0 * 0.0
        Ds = D0 * np.exp(-ls)
        r = hinf_norm(ss(sys.A, Bs, Cs, Ds), rtol, require_stable=require_stable)
        with np.errstate(over="ignore"):
            f = np.exp(ls)
            return HinfNorm(float(r.value * f), r.frequency, float(r.lower * f), float(r.upper * f), r.iterations)
    D = np.asarray(sys.D, float)
    sD = np.linalg.norm(D, 2) if D.size else 0.0
    if sys.nstates == 0:
        return HinfNorm(sD, np.inf, sD, sD, 0)
    bal, _ = balance_states(sys)
    A, B, C = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
    poles, on_axis = _axis_poles(A)
    if np.any(on_axis):
        return HinfNorm(np.inf, float(np.min(np.abs(poles[on_axis].imag))), np.inf, np.inf, 0)
    if require_stable and np.any(poles.real > 0):
        return HinfNorm(np.inf, np.nan, np.inf, np.inf, 0)
    if np.linalg.norm(B) == 0 or np.linalg.norm(C) == 0:
        return HinfNorm(sD, np.inf, sD, sD, 0)

    # initial lower bound: gain at 0, infinity and near each pole's frequency
    cand = [0.0] + [abs(p) for p in poles] + [abs(p.imag) for p in poles if p.imag != 0]
    cand = np.unique(np.array(cand))
    s = sigma_max(bal, cand)
    k = int(np.argmax(s))
    lower, wpk = float(s[k]), float(cand[k])
    if sD > lower:
        lower, wpk = sD, np.inf
    if lower == 0.0:
        return HinfNorm(0.0, 0.0, 0.0, 0.0, 0)
    it = 0
    while True:
        it += 1
        g = (1.0 + 2.0 * rtol) * lower
        ev = np.linalg.eigvals(_hamiltonian(A, B, C, D, g))
        # generous: near a flat peak the crossing eigenvalues are nearly double and their
        # computed real parts are O(sqrt(eps)); spurious candidates are harmless because
        # each one is checked by evaluating the gain
        tol_im = 1e-6 * max(1.0, np.max(np.abs(ev)))
        w = np.sort(np.unique(np.round(np.abs(ev[np.abs(ev.real) < tol_im].imag), 14)))
        if w.size == 0 or it > 60:
            return HinfNorm(lower, wpk, lower, g, it)
        if w.size == 1:
            mids = w
        else:
            mids = np.concatenate([0.5 * (w[:-1] + w[1:]),
                                   np.sqrt(np.maximum(w[:-1], 1e-300) * w[1:])])
        sm = sigma_max(bal, mids)
        j = int(np.argmax(sm))
        if sm[j] <= lower * (1 + 1e-15):
            # imaginary eigenvalues are numerical artefacts at the peak: converged
            return HinfNorm(lower, wpk, lower, g, it)
        lower, wpk = float(sm[j]), float(mids[j])
