"""Stability with the evidence: the scale-aware imaginary-axis rule (:func:`_axis_poles`), the state
balancing it works on (:func:`balance_states`), :func:`stability`, :func:`is_stable` and
:func:`closed_loop_poles`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import Real, validate_params
from ._interconnect import lft_lower
from ._ss import as_ss, ss


def balance_states(sys, iterations: int = 50):
    """Diagonal state scaling that balances the rows and columns of [A B; C 0].

    Returns ``(scaled_sys, t)`` with ``x = diag(t) x_scaled``; the transfer
    function is unchanged.  Powers of two keep the scaling exact in floating
    point (an Osborne/Parlett-Reinsch iteration restricted to the states).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The system to scale.
    iterations : int, optional
        Maximum number of sweeps over the states (stops earlier when no scale changes).
    """
    sys = as_ss(sys)
    A, B, C = (np.asarray(X, float).copy() for X in (sys.A, sys.B, sys.C))
    n = A.shape[0]
    t = np.ones(n)
    for _ in range(iterations):
        changed = False
        for i in range(n):
            r = np.linalg.norm(np.concatenate([np.delete(A[i], i), B[i]]))
            c = np.linalg.norm(np.concatenate([np.delete(A[:, i], i), C[:, i]]))
            if r == 0 or c == 0:
                continue
            f = 2.0 ** np.round(0.5 * np.log2(r / c))
            if f != 1.0:
                # x_i = f * x_i_new: row i divided by f, column i multiplied by f
                A[i, :] /= f
                B[i, :] /= f
                A[:, i] *= f
                C[:, i] *= f
                t[i] *= f
                changed = True
        if not changed:
            break
    out = ss(A, B, C, sys.D, inputs=sys.input_labels, outputs=sys.output_labels)
    return out, t


def _axis_poles(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Eigenvalues of ``A`` and a mask of those treated as on the imaginary axis.

    Scale-aware rule: pole :math:`p_i` is on the axis when

    .. math::
        |\operatorname{Re} p_i| \le \max\bigl(10^{-12} |p_i|,\;
        10\,\varepsilon \|A\|_1\bigr),

    i.e. its real part is negligible against *its own* magnitude, or it is within
    ten rounding units of ``A`` (the absolute accuracy of a well-conditioned
    eigenvalue) from the axis: an integrator or an undamped mode of a stiff
    system comes out with a real part of that size and either sign, and a stable
    pole that close to the axis cannot be told from an axis pole in double
    precision.  ``A`` should be balanced first (:func:`balance_states`), so that
    :math:`\|A\|` is that of the best-scaled coordinates.  The old rule,
    :math:`|\operatorname{Re} p| \le 10^{-12}\max_j|p_j|`, flagged well-determined
    stable poles at -1e-6 as soon as another pole passed 1e6 rad/s.  (A bound
    with each eigenvalue's condition number, :math:`\varepsilon\|A\|\kappa_i`, was
    tried and rejected: on graded matrices, slycot's controllers with poles near
    1e9, it is pessimistic by orders of magnitude and flagged poles at -11 rad/s.)
    """
    lam, tol = _axis_tolerance(A)
    return lam, np.abs(lam.real) <= tol


def _axis_tolerance(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of ``A`` and, per eigenvalue, the distance from the imaginary axis
    below which its sign is not decided (see :func:`_axis_poles`)."""
    if A.size == 0:
        return np.zeros(0, complex), np.zeros(0)
    lam = np.linalg.eigvals(A)
    return lam, np.maximum(1e-12 * np.abs(lam), 10 * np.finfo(float).eps * np.linalg.norm(A, 1))


@dataclass
class Stability:
    """Result of :func:`stability`.

    Attributes
    ----------
    stable : bool
        Every pole has real part below ``-threshold`` (its own threshold).
    poles : ndarray
        Eigenvalues of the (balanced) state matrix.
    thresholds : ndarray
        Per pole: ``max(margin, 1e-12 |p|, 10 eps ||A_bal||_1)``.
    worst : complex
        The pole closest to failing (largest ``Re p + threshold``); ``nan`` without states.
    max_real_part : float
        Largest real part of any pole (``-inf`` without states).
    message : str
        What was found, naming the deciding pole, its real part and its threshold.
    """
    stable: bool
    poles: np.ndarray
    thresholds: np.ndarray
    worst: complex
    max_real_part: float
    message: str

    def __bool__(self):
        return self.stable


@validate_params({"margin": Real(lo=0)})
def stability(sys, margin: float = 0.0) -> Stability:
    r"""Scale-aware stability test of a continuous-time system, with the evidence.

    Pole :math:`p_i` of the state-balanced system (:func:`balance_states`)
    counts as stable when

    .. math::
        \operatorname{Re} p_i < -\max\bigl(\text{margin},\; 10^{-12}|p_i|,\;
        10\,\varepsilon\|A\|_1\bigr),

    the rule of :func:`_axis_poles` (used by :func:`hinf_norm`): a real part
    below ``1e-12`` of the pole's own magnitude, or within ten rounding units of
    ``A`` from the axis, cannot be told from zero in double precision, so such a
    pole is reported as undecidable, not as stable.  The threshold is relative to
    each pole and to the balanced ``A``, not to the largest pole: a weight pole
    at -1e-6 next to a controller pole at 1e8 rad/s is stable.  The raw-sign
    test it replaces called a pole at +1e-17 (rounding noise of an integrator)
    unstable or stable by chance.

    Parameters
    ----------
    sys : StateSpace
        Continuous-time system.
    margin : float
        Required distance of every pole from the imaginary axis (rad/s).

    Returns
    -------
    Stability
        The verdict (truthy when stable), the poles, their thresholds and a
        message naming the deciding pole.

    Examples
    --------
    >>> from mutext.lti import ss, stability
    >>> stability(ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])).stable
    True
    >>> s = stability(ss([[0.0, 1.0], [-1.0, 0.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]))   # undamped
    >>> s.stable, s.message[:26]
    (False, 'not decidably stable: pole')
    """
    sys = as_ss(sys)
    if sys.nstates == 0:
        return Stability(True, np.zeros(0, complex), np.zeros(0), complex(np.nan), -np.inf,
                         "no states: stable")
    bal, _ = balance_states(sys)
    A = np.asarray(bal.A, float)
    lam, tol = _axis_tolerance(A)
    thr = np.maximum(tol, float(margin))
    k = int(np.argmax(lam.real + thr))
    p, re, t = lam[k], float(lam[k].real), float(thr[k])
    stable = bool(np.all(lam.real < -thr))
    where = f"pole at s = {p:.6g} (real part {re:.3g}, threshold {-t:.3g})"
    if stable:
        msg = f"stable: all {lam.size} poles have real part below their threshold; the closest is the {where}"
    elif re > t:
        msg = f"unstable: {where} is in the right half plane"
    elif re >= -tol[k]:
        msg = (f"not decidably stable: {where} is within rounding of the imaginary axis "
               f"(|Re p| <= max(1e-12 |p|, 10 eps ||A_bal||) = {tol[k]:.3g})")
    else:
        msg = f"not stable with margin {margin:g}: {where}"
    return Stability(stable, lam, thr, complex(p), float(lam.real.max()), msg)


def is_stable(sys, margin: float = 0.0) -> bool:
    """True if every pole has real part < -margin and is decidably off the
    imaginary axis (scale-aware rule, see :func:`stability`).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The continuous-time system.
    margin : float, optional
        Required distance of every pole to the left of the imaginary axis (1/s).
    """
    return stability(sys, margin).stable


def closed_loop_poles(P, K, nmeas: int, ncon: int) -> np.ndarray:
    """Poles of the closed loop F_l(P, K).

    Parameters
    ----------
    P : StateSpace or as accepted by :func:`as_ss`
        Generalised plant, inputs ``[w; u]`` and outputs ``[z; y]``.
    K : StateSpace or as accepted by :func:`as_ss`
        Controller from ``y`` to ``u``.
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``).
    ncon : int
        Number of controls ``u`` (the last inputs of ``P``).
    """
    CL = lft_lower(P, K, nmeas, ncon)
    return np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
