r"""What the time-periodic rotor responds and what an analyzer reports: the harmonic transfer
functions (:func:`harmonic_response`), the stepped-sine analyzer's FRF and combination-frequency
responses in steady state (:func:`analyzer_frf`, :func:`analyzer_combination`; their truncation
chosen for a tolerance with ``harmonics="auto"``, in ``_truncation``), and the convergence of the
truncation (:func:`harmonic_convergence`).
"""
from __future__ import annotations

import time
from typing import Sequence

import numpy as np

from ...errors import ModelError
from ...response import FRFMatrix
from ._balance import HarmonicResponse, _freqs, _harmonic_balance, _harmonics
from ._model import _as_periodic
from ._truncation import _check_options, _warn_unconverged, analyzer_truncation
from ._window import ANALYZER, _correlated, _settle



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
    return _harmonic_balance(pr, _freqs(freqs_hz), _harmonics(harmonics), t0)


def analyzer_frf(model, freqs_hz, *, harmonics: int | str = 6, revolutions: int = ANALYZER["revolutions"],
                 settle_s: float = ANALYZER["settle_s"], excitation_phase: float = 0.0,
                 inputs=None, outputs=None, tol: float | None = None,
                 max_harmonics: int | None = None) -> FRFMatrix:
    r"""The FRF a stepped-sine analyzer reports for a time-periodic rotor (steady state).

    :math:`\hat H = H_0 + e^{-2j\varphi}\sum_k \overline{H_{-k}}\,\langle e^{j(k\Omega-2\omega)t}\rangle`
    (module docstring), with the window :math:`[t_s, t_s + T]`, :math:`T` =
    ``revolutions`` turns, and the excitation :math:`a\cos(\omega t +
    \varphi)` starting with the rotor at its angle zero.  Transients are not
    included (see :func:`stepped_sine` for those).

    The default N = 6 is converged for the Mayes law (1e-4 of the peak) and
    the gaping crack (exact from N = 2) but not for the Gasch law (7 % on the
    thesis rotor, converging like 1/N); ``harmonics="auto"`` chooses N, with
    a Richardson extrapolation in 1/N where it is better, for the relative
    truncation error ``tol`` (:func:`analyzer_truncation`, which also
    returns the estimate; a ``RuntimeWarning`` when ``max_harmonics`` stops
    it first).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).
    harmonics : int or "auto", optional
        Truncation N of the harmonic balance (orders -N..N), or ``"auto"``.
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.
    tol : float, optional
        Relative truncation error of ``harmonics="auto"`` (default 1e-4).
    max_harmonics : int, optional
        The cap on N of ``harmonics="auto"`` (default 512).

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
    if isinstance(harmonics, str) or tol is not None or max_harmonics is not None:
        return _auto("analyzer_frf", model, freqs_hz, (0,), harmonics, tol, max_harmonics, revolutions,
                     settle_s, excitation_phase, inputs, outputs)[0]
    pr = _as_periodic(model, inputs, outputs)
    hr = harmonic_response(pr, freqs_hz, harmonics=harmonics)
    t_s, T = _settle(pr, settle_s, revolutions)
    return _correlated(pr, hr, 0, t_s, T, excitation_phase, descending=True)


def _auto(where, model, freqs_hz, orders, harmonics, tol, max_harmonics, revolutions, settle_s,
          excitation_phase, inputs, outputs) -> dict:
    """The responses ``{k: FRFMatrix}`` of :func:`analyzer_truncation` for ``where``, warning when
    the cap stopped the automatic truncation before its tolerance."""
    _check_options(harmonics, tol, max_harmonics, where)
    res = analyzer_truncation(model, freqs_hz, harmonics=harmonics, tol=tol, max_harmonics=max_harmonics,
                              orders=orders, revolutions=revolutions, settle_s=settle_s,
                              excitation_phase=excitation_phase, inputs=inputs, outputs=outputs)
    _warn_unconverged(res, where)
    return res.responses


def analyzer_combination(model, freqs_hz, orders=(-2, -1, 1, 2), *, harmonics: int | str = 6,
                         revolutions: int = ANALYZER["revolutions"], settle_s: float = ANALYZER["settle_s"],
                         excitation_phase: float = 0.0, inputs=None, outputs=None, tol: float | None = None,
                         max_harmonics: int | None = None) -> dict:
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
    :math:`H_{-k-2f/F}`).  ``harmonics="auto"`` chooses N for the relative
    truncation error ``tol`` of every order, each over its own peak
    (:func:`analyzer_truncation`, as for :func:`analyzer_frf`).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).

    orders : sequence of int, optional
        Orders k of the combination frequencies :math:`\omega + k\Omega`.
    harmonics : int or "auto", optional
        Truncation N of the harmonic balance (orders -N..N), or ``"auto"``.
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.
    inputs, outputs : sequence of str, optional
        Ports of a Rotor ``model`` (default: all); not with a :class:`PeriodicRotor`.
    tol : float, optional
        Relative truncation error of ``harmonics="auto"`` (default 1e-4).
    max_harmonics : int, optional
        The cap on N of ``harmonics="auto"`` (default 512).

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
    if isinstance(harmonics, str) or tol is not None or max_harmonics is not None:
        return _auto("analyzer_combination", pr, freqs_hz, ks, harmonics, tol, max_harmonics, revolutions,
                     settle_s, excitation_phase, None, None)
    N = _harmonics(harmonics)
    N = N + max(abs(k) for k in ks)
    hr = harmonic_response(pr, freqs_hz, harmonics=N)
    t_s, T = _settle(pr, settle_s, revolutions)
    return {k: _correlated(pr, hr, k, t_s, T, excitation_phase) for k in ks}


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
