r"""How far the analyzer's responses are from the untruncated harmonic balance, and the truncation
chosen for a tolerance (:func:`analyzer_truncation`, ``harmonics="auto"`` of :func:`analyzer_frf`
and :func:`analyzer_combination`).

The truncation :math:`|k| \le N` converges fast when the breathing law is a
trigonometric polynomial (Mayes: orders up to 3, the gaping crack: 2) and
slowly when it switches: the Gasch law's stiffness is a square wave whose
Fourier coefficients fall like :math:`1/m`, and the analyzer's FRF converges
like :math:`1/N` (on the thesis rotor at 10 Hz: 7 % of the peak at N = 6,
0.13 % at N = 64).  The responses are therefore computed at
:math:`N = 2, 4, 8, \ldots` (doubling keeps any odd-even pattern of the
coefficients in step) and the estimate of the truncation error is taken from
the changes between them:

* the last level :math:`H_j` itself, with its error estimated as the tail of
  the changes :math:`d_j = |H_j - H_{j-1}|` continued geometrically with their
  last ratio :math:`\rho = d_j / d_{j-1}`: :math:`d_j \max(1, \rho / (1 - \rho))`
  (:math:`\rho \le 0.9`; exact for a :math:`1/N` convergence, :math:`\rho = 1/2`,
  and at least the last change), times a safety factor 1.5 (``SAFETY``);
* the Richardson extrapolation in :math:`1/N`, :math:`R_j = 2H_j - H_{j-1}`,
  which removes the :math:`1/N` term, with its error estimated in the same
  way from the changes :math:`e_j = |R_j - R_{j-1}|`.  The extrapolation
  converges irregularly while the sidebands :math:`\omega + k\Omega` still
  cross the modes of the basis (up to N of about 100 on the thesis rotor):
  there its changes can be small while it is still 1e-3 off, so its estimate
  is never taken below an eighth of the last level's (``CREDIT``).  This is
  a heuristic, checked on the thesis rotor's Gasch crack against N = 1024
  (sweeps, single frequencies at the peaks; tolerances 1e-2 to 3e-4).

The result is the one of the two with the smaller estimate.  The changes are
measured like :func:`harmonic_convergence`'s: the largest change over the
frequencies over the channel's largest response, the worst channel.  Each
level is solved through the range of the cracks' stiffness changes (rank 2
for one crack: a block system of size :math:`2(2N+1)` instead of
:math:`(2N+1)n`, 20 times faster on the reduced thesis rotor at N = 16, equal
to rounding; above N of about 100 by GMRES with an FFT for the block-Toeplitz
product), so that N = 256 costs about 10 CPU-s on a 411-point sweep.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ...errors import ModelError
from ._balance import _crack_range, _freqs, _harmonic_balance, _harmonic_balance_lowrank, _harmonics
from ._model import PeriodicRotor, _as_periodic
from ._window import ANALYZER, _correlated, _settle

#: The automatic truncation's defaults: relative tolerance, the largest N, and the first N.
AUTO = {"tol": 1e-4, "max_harmonics": 512, "start": 2}


@dataclass
class Truncation:
    r"""The analyzer's responses at a chosen harmonic-balance truncation, with its estimated error.

    Attributes
    ----------
    responses : dict
        ``{k: FRFMatrix}``: ``k = 0`` the analyzer's FRF (:func:`analyzer_frf`), ``k != 0`` the
        combination-frequency responses (:func:`analyzer_combination`).
    harmonics : int
        The largest truncation N solved (the responses' N, or the finer level of the extrapolation).
    error : float
        Estimated truncation error: the largest deviation from the untruncated harmonic balance over
        the channel's largest response, the worst channel and order.
    extrapolated : bool
        True when the responses are the Richardson extrapolation in 1/N from ``harmonics // 2``
        and ``harmonics``.
    tol : float or None
        The tolerance asked for (None: the error of a given N was estimated).
    converged : bool
        ``error <= tol`` (always True without ``tol``).
    steps : list of dict
        Per level: ``harmonics``, ``change`` (against the level before), ``estimate`` and
        ``estimate_richardson`` (inf where not yet defined) and ``seconds``.
    seconds : float
        Wall time of the whole choice.
    """
    responses: dict
    harmonics: int
    error: float
    extrapolated: bool
    tol: float | None
    converged: bool
    steps: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def note(self) -> str:
        """One line for a measurement's metadata: N, the method and the estimated error."""
        how = (f"Richardson extrapolation in 1/N from N = {self.harmonics // 2} and {self.harmonics}"
               if self.extrapolated else f"N = {self.harmonics}")
        s = f"harmonic balance {how}, estimated truncation error {self.error:.1e}"
        if self.tol is not None:
            s += f" (tolerance {self.tol:.1e}" + ("" if self.converged else
                                                   ", NOT met: the cap max_harmonics was reached") + ")"
        return s


def _check_options(harmonics, tol, max_harmonics, where: str):
    """``(auto, N, tol, cap)`` from the truncation options of ``where``, or a named ModelError."""
    auto = isinstance(harmonics, str)
    if auto and harmonics != "auto":
        raise ModelError(f"{where}: harmonics must be a non-negative integer (k = -N..N) or 'auto', "
                         f"got {harmonics!r}")
    if not auto:
        N = _harmonics(harmonics)
        if tol is not None or max_harmonics is not None:
            raise ModelError(f"{where}: tol and max_harmonics choose the truncation; they go with "
                             f"harmonics='auto', not with harmonics={N}")
        return False, N, None, None
    tol = AUTO["tol"] if tol is None else tol
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)) or not (0 < tol < 1):
        raise ModelError(f"{where}: tol must be a relative truncation error in (0, 1), got {tol!r}")
    cap = AUTO["max_harmonics"] if max_harmonics is None else max_harmonics
    if isinstance(cap, bool) or not isinstance(cap, (int, np.integer)) or cap < AUTO["start"]:
        raise ModelError(f"{where}: max_harmonics must be an integer of at least {AUTO['start']} (the cap "
                         f"on N of harmonics='auto'), got {max_harmonics!r}")
    return True, None, float(tol), int(cap)


def _solve(pr: PeriodicRotor, f, N: int, U):
    t0 = time.perf_counter()
    if U is None:
        return _harmonic_balance(pr, f, N, t0)
    return _harmonic_balance_lowrank(pr, f, N, t0, U)


def _level(pr, f, N, ks, window, U) -> dict:
    """The analyzer's responses ``{k: H}`` (arrays) at truncation ``N`` (``N + max|k|`` solved)."""
    t_s, T, phase = window
    hr = _solve(pr, f, N + max(abs(k) for k in ks), U)
    return {k: _correlated(pr, hr, k, t_s, T, phase, descending=(k == 0)).H for k in ks}


def _scales(H: dict) -> dict:
    """Per order, the channels' largest responses (floored by 1e-9 of the excitation frequency's)."""
    ref = np.max(np.abs(H[0]), axis=-1) if 0 in H else None
    out = {}
    for k, h in H.items():
        s = np.max(np.abs(h), axis=-1)
        floor = 1e-9 * ref if ref is not None else 1e-300
        out[k] = np.maximum(s, np.maximum(floor, 1e-300))
    return out


def _change(A: dict, B: dict, scale: dict) -> float:
    return float(max(np.max(np.max(np.abs(A[k] - B[k]), axis=-1) / scale[k]) for k in A))


#: Safety factor on the estimates from the changes (module docstring).
SAFETY = 1.5
#: The most the extrapolation's estimate may be below the last level's (module docstring).
CREDIT = 8.0


def _tail(d, d_prev) -> float:
    """The error of the last level from its change ``d`` and the one before (module docstring)."""
    rho = min(d / d_prev, 0.9) if d_prev is not None and d_prev > 0 else 0.5
    return SAFETY * d * max(1.0, rho / (1.0 - rho))


def _choose(pr, f, ks, window, *, N_fixed=None, tol=None, cap=None) -> Truncation:
    t0 = time.perf_counter()
    U = _crack_range(pr) if not pr.time_invariant() else None
    if pr.time_invariant():
        # no sidebands: N = 0 is exact
        H = _level(pr, f, 0, ks, window, None)
        return Truncation(_wrap(pr, f, H), 0, 0.0, False, tol, True,
                          [{"harmonics": 0, "change": 0.0, "estimate": 0.0, "estimate_richardson": math.inf,
                            "seconds": time.perf_counter() - t0}], time.perf_counter() - t0)
    if N_fixed is not None:
        # the error of a given N: the changes to 2N and 4N, continued geometrically
        levels = [max(N_fixed, 1) * m for m in (1, 2, 4)]
        Hs, steps = [], []
        for N in levels:
            t1 = time.perf_counter()
            Hs.append(_level(pr, f, N, ks, window, U))
            steps.append({"harmonics": N, "seconds": time.perf_counter() - t1})
        sc = _scales(Hs[-1])
        d1, d2 = _change(Hs[0], Hs[1], sc), _change(Hs[1], Hs[2], sc)
        rho = min(d2 / d1, 0.9) if d1 > 0 else 0.0
        err = SAFETY * d1 * max(2.0, 1.0 / (1.0 - rho))
        for s, c in zip(steps, (math.inf, d1, d2)):
            s.update(change=c, estimate=math.inf, estimate_richardson=math.inf)
        steps[0]["estimate"] = err
        H0 = Hs[0] if N_fixed > 0 else _level(pr, f, 0, ks, window, U)
        return Truncation(_wrap(pr, f, H0), N_fixed, err, False, None, True, steps, time.perf_counter() - t0)
    N = AUTO["start"]
    Hs, Rs, steps = [], [], []
    d_prev = e_prev = None
    best = None
    while True:
        t1 = time.perf_counter()
        Hs.append(_level(pr, f, N, ks, window, U))
        sc = _scales(Hs[-1])
        step = {"harmonics": N, "change": math.inf, "estimate": math.inf, "estimate_richardson": math.inf}
        if len(Hs) >= 2:
            d = _change(Hs[-1], Hs[-2], sc)
            step["change"] = d
            step["estimate"] = _tail(d, d_prev)
            d_prev = d
            Rs.append({k: 2.0 * Hs[-1][k] - Hs[-2][k] for k in Hs[-1]})
            if len(Rs) >= 2:
                e = _change(Rs[-1], Rs[-2], sc)
                step["estimate_richardson"] = max(_tail(e, e_prev), step["estimate"] / CREDIT)
                e_prev = e
        step["seconds"] = time.perf_counter() - t1
        steps.append(step)
        if step["estimate"] <= step["estimate_richardson"]:
            cand = (step["estimate"], Hs[-1], False, N)
        else:
            cand = (step["estimate_richardson"], Rs[-1], True, N)
        if best is None or cand[0] <= best[0]:
            best = cand
        if best[0] <= tol or 2 * N > cap:
            break
        if len(Hs) > 2:          # keep the two last levels only
            Hs.pop(0)
        if len(Rs) > 2:
            Rs.pop(0)
        N *= 2
    err, H, extrap, Nb = best
    return Truncation(_wrap(pr, f, H), Nb, float(err), extrap, tol, bool(err <= tol), steps,
                      time.perf_counter() - t0)


def _wrap(pr, f, H: dict) -> dict:
    from ...response import FRFMatrix
    return {k: FRFMatrix(f, h, list(pr.inputs), list(pr.outputs), pr.speed, dict(pr.ports)) for k, h in H.items()}


def _warn_unconverged(res: Truncation, where: str):
    if not res.converged:
        warnings.warn(f"{where}: {res.note}; raise max_harmonics or loosen tol", RuntimeWarning, stacklevel=3)


def analyzer_truncation(model, freqs_hz, *, harmonics="auto", tol: float | None = None,
                        max_harmonics: int | None = None, orders=(0,), revolutions: int | None = None,
                        settle_s: float | None = None, excitation_phase: float = 0.0,
                        inputs=None, outputs=None) -> Truncation:
    r"""The analyzer's responses with the harmonic-balance truncation error estimated (module docstring).

    With ``harmonics="auto"`` N doubles from 2 until the estimated error is
    at most ``tol`` or N would pass ``max_harmonics``; the responses are the
    last level or its Richardson extrapolation in :math:`1/N`, whichever has
    the smaller estimate (``converged`` False, and a note saying so, when
    the cap stopped it).  With an integer ``harmonics`` the responses are
    those at that N and ``error`` its estimated truncation error, from the
    changes to 2N and 4N: :math:`d_1 + d_2/(1 - \rho)`, :math:`\rho = d_2/d_1`
    (at most 0.9), the geometric continuation of the changes (exact for a
    :math:`1/N` convergence).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).
    harmonics : int or "auto", optional
        ``"auto"``: choose N for ``tol``; an integer: estimate the error of that N.
    tol : float, optional
        Relative truncation error to reach (``"auto"`` only; default ``AUTO["tol"]``, 1e-4).
    max_harmonics : int, optional
        The cap on N (``"auto"`` only; default ``AUTO["max_harmonics"]``, 512).
    orders : sequence of int, optional
        The responses: 0 the analyzer's FRF, ``k != 0`` the combination frequencies
        :math:`\omega + k\Omega` (each solved with ``N + max|k|`` harmonics, as
        :func:`analyzer_combination`).
    revolutions : int, optional
        Turns of the correlation window (default ``ANALYZER["revolutions"]``).
    settle_s : float, optional
        Settling time before the window [s] (default ``ANALYZER["settle_s"]``).
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.

    Returns
    -------
    Truncation

    Examples
    --------
    >>> from mutext.examples.cracked_rotor import cracked_rotor
    >>> from mutext.rotor.periodic import periodic_rotor, analyzer_truncation
    >>> pr = periodic_rotor(cracked_rotor(0.4, breathing="gaping"), inputs=["i12"], outputs=["x13"])
    >>> t = analyzer_truncation(pr.reduce(1000.0), [40.0, 80.0])
    >>> t.harmonics, t.error < 1e-12, t.converged
    (4, True, True)
    """
    where = "analyzer_truncation"
    auto, N, tol, cap = _check_options(harmonics, tol, max_harmonics, where)
    pr = _as_periodic(model, inputs, outputs)
    f = _freqs(freqs_hz)
    ks = _orders(orders, where, allow_zero=True)
    if 0 not in ks:
        ks = (0,) + ks
    t_s, T = _settle(pr, ANALYZER["settle_s"] if settle_s is None else settle_s,
                     ANALYZER["revolutions"] if revolutions is None else revolutions)
    res = _choose(pr, f, ks, (t_s, T, excitation_phase), N_fixed=N, tol=tol, cap=cap)
    want = _orders(orders, where, allow_zero=True)
    res.responses = {k: res.responses[k] for k in want}
    return res


def _orders(orders, where: str, allow_zero: bool) -> tuple:
    ks = []
    try:
        seq = list(orders)
    except TypeError:
        raise ModelError(f"{where}: orders must be a sequence of integers, got {orders!r}") from None
    for k in seq:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise ModelError(f"{where}: orders must be integers (the k of f_exc + k F), got {k!r}")
        ks.append(int(k))
    if not ks:
        raise ModelError(f"{where}: orders must name at least one order k")
    return tuple(dict.fromkeys(ks))
