r"""Frequency grids and the peak-refined mu sweeps: the D-step grid (near-axis poles left out),
the fine sweep of the final analysis with its maxima refined, and the D-G bound at the
frequencies that decide its peak.
"""
from __future__ import annotations

import numpy as np

from ..lti import as_ss, freqresp
from ..mu import BlockStructure, default_grid, mu_sweep, mu_upper, MuSweep
from ._dstep import _sweep_upper
from ._report import _Heartbeat


#: a stable pole counts as near the axis when its magnitude is below this fraction of the
#: smallest magnitude of the plant's other poles (a cluster at least three decades below the rest)
NEAR_AXIS_GAP = 1e-3


def near_axis_poles(P, gap: float = NEAR_AXIS_GAP) -> np.ndarray:
    r"""Poles of ``P`` in the closed left half plane, or at 0, that lie far below the rest.

    A pole :math:`p` with :math:`|p| <` ``gap`` times the smallest magnitude of the
    poles above it (sorted by magnitude, the first gap of that size from below
    separates the cluster): typically a weight that approximates an integrator
    by a pole at -1e-6 rad/s, or an exact integrator.  Poles in the open right
    half plane are never listed.

    Parameters
    ----------
    P : control.StateSpace or control.TransferFunction
        The plant (any number of inputs and outputs).
    gap : float
        Ratio of magnitudes that separates the cluster from the poles above it
        (default :data:`NEAR_AXIS_GAP`, 1e-3: three decades).

    Returns
    -------
    ndarray of complex
        The poles of the cluster [rad/s] in the closed left half plane, by
        increasing magnitude; empty when there is no such gap.
    """
    P = as_ss(P)
    if P.nstates == 0:
        return np.zeros(0, complex)
    p = np.linalg.eigvals(np.asarray(P.A, float))
    p = p[np.argsort(np.abs(p))]
    mags = np.abs(p)
    for k in range(p.size - 1):
        if mags[k] < gap * mags[k + 1]:
            low = p[:k + 1]
            return low[low.real <= 0]
    return np.zeros(0, complex)


def _default_dk_grid(P, n: int) -> np.ndarray:
    """Log grid over the plant's dynamics (1.5 decades beyond its pole magnitudes),
    leaving out near-axis poles (:func:`near_axis_poles`; see the module docstring)."""
    near = near_axis_poles(P)
    if near.size:
        P = as_ss(P)
        p = np.linalg.eigvals(np.asarray(P.A, float))
        rest = p[np.abs(p) > np.abs(near).max()]
        lo, hi = np.abs(rest).min() / 10 ** 1.5, np.abs(rest).max() * 10 ** 1.5
        return _clip_grid(default_grid(P, n=n, decades=1.5), lo, hi, n)
    return default_grid(P, n=n, decades=1.5)


def _clip_grid(w, lo, hi, n):
    """``n`` log-spaced points on [lo, hi] plus the points of ``w`` inside it (resonances)."""
    inside = w[(w >= lo) & (w <= hi)]
    return np.unique(np.concatenate([np.logspace(np.log10(lo), np.log10(hi), n), inside]))


def _local_maxima(values, count):
    """Indices of the ``count`` largest local maxima (plateaus included), largest first."""
    v = np.asarray(values)
    pk = [i for i in range(v.size) if (i == 0 or v[i] >= v[i - 1]) and (i == v.size - 1 or v[i] >= v[i + 1])]
    return sorted(pk, key=lambda i: -v[i])[:count]


def _around_peaks(w, values, npeaks: int, points: int, floor: float = -np.inf) -> list:
    """``points`` log-spaced frequencies strictly between the neighbours of each of the
    ``npeaks`` largest local maxima of ``values`` on the grid ``w`` (those at least ``floor``)."""
    out = []
    for i in _local_maxima(values, npeaks):
        if values[i] < floor:
            break
        a, b = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]
        if b > a:
            out.append(np.logspace(np.log10(a), np.log10(b), points + 2)[1:-1])
    return out


def _refine_around_maxima(w, data, evaluate, rounds, points: int):
    """The grid ``w`` (sorted) and the arrays ``data`` on it (``data[0]`` the values), with
    ``points`` log-spaced frequencies added between the neighbours of local maxima, round by
    round: ``rounds`` holds ``(npeaks, within)``, the ``npeaks`` largest maxima at least
    ``1 - within`` times the peak (``within=None``: all of them).  ``evaluate(wn)`` returns the
    data at new frequencies.  Each round shrinks the spacing at a maximum by ``points + 1``,
    and a smooth peak's error by its square.  Returns the grid, the data and the frequencies
    added."""
    added = []
    for npeaks, within in rounds:
        values = data[0]
        floor = -np.inf if within is None else values.max() * (1.0 - within)
        new = _around_peaks(w, values, npeaks, points, floor=floor)
        wn = np.setdiff1d(np.concatenate(new), w) if new else np.zeros(0)
        if wn.size == 0:
            break
        dn = evaluate(wn)
        added.append(wn)
        order = np.argsort(np.concatenate([w, wn]))
        w = np.concatenate([w, wn])[order]
        data = tuple(np.concatenate([a, b])[order] for a, b in zip(data, dn))
    return w, data, (np.concatenate(added) if added else np.zeros(0))


def _fine_sweep(CL, S: BlockStructure, omega, npeaks: int = 4, rounds: int = 3, points: int = 16,
                progress=None) -> tuple[MuSweep, np.ndarray]:
    """Diagonal-D upper bound on ``omega`` with its largest local maxima refined:
    ``rounds`` times, ``points`` log-spaced frequencies between the neighbours of
    each peak are added (each round shrinks the spacing there by ``points + 1``).
    Returns the sweep and the loop's response on its grid, (nw, ncols, nrows)."""
    w = np.unique(np.asarray(omega, float))
    H = np.moveaxis(freqresp(CL, w), -1, 0)
    up, X = _sweep_upper(H, S, progress=progress)

    def evaluate(wn):
        Hn = np.moveaxis(freqresp(CL, wn), -1, 0)
        return (*_sweep_upper(Hn, S), Hn)

    w, (up, X, H), _ = _refine_around_maxima(w, (up, X, H), evaluate, [(npeaks, None)] * rounds, points)
    k = int(np.argmax(up))
    return MuSweep(w, up, np.full(w.size, np.nan), np.exp(X), "osborne", float(up[k]), float(w[k]),
                   float("nan"), float("nan"), None, ["osborne"] * w.size), H


def _dg_values(H, S: BlockStructure, upper) -> np.ndarray:
    """min(D-G bound, complex bound ``upper``) over the grid, both certified at each frequency,
    where it can decide the peak (zero elsewhere).  The D-G bound
    (``mutext.mu.mu_upper(method="fast")``) is computed from the largest complex values down,
    until the next complex value cannot raise the peak.  Where the complex bound is flat (an
    equalised D-K loop) that is every frequency of the flat part: stopping earlier would report
    the complex value of a frequency whose D-G bound is lower, and miss the gain of a controller
    that exploits the real parameters."""
    dg = np.zeros(len(upper))
    best = 0.0
    for k in np.argsort(-np.asarray(upper)):
        if upper[k] <= best:
            break
        dg[k] = min(mu_upper(H[k], S, method="fast").value, float(upper[k]))
        best = max(best, dg[k])
    return dg


def _dg_peak(H, S: BlockStructure, upper) -> tuple[float, int]:
    """Peak over the grid of :func:`_dg_values` and its index in the grid."""
    dg = _dg_values(H, S, upper)
    k = int(np.argmax(dg))
    return float(dg[k]), k


def _dg_refined_peak(CL, H, S: BlockStructure, omega, upper, rounds=((8, 0.02), (4, 0.002)),
                     points: int = 6) -> tuple[float, float, np.ndarray]:
    """The D-G peak of :func:`_dg_peak` with the local maxima of the D-G bound refined
    (:func:`_refine_around_maxima`; by default the 8 largest within 2 % of the peak, then the
    4 largest within 0.2 %).  A controller that exploits the real parameters equalises the
    D-G bound, so many local maxima are nearly equal and the true peak can lie between the
    points of a grid refined around the complex bound's peaks.  Returns the peak, its
    frequency and the frequencies added."""
    def evaluate(wn):
        Hn = np.moveaxis(freqresp(CL, wn), -1, 0)
        return (np.array([mu_upper(h, S, method="fast").value for h in Hn]),)

    w, (dg,), added = _refine_around_maxima(np.asarray(omega, float), (_dg_values(H, S, upper),), evaluate,
                                            rounds, points)
    k = int(np.argmax(dg))
    return float(dg[k]), float(w[k]), added


def _final_analysis(CL, S: BlockStructure, grid, final_points: int, dg: bool, npeaks: int = 4,
                    report=None):
    """Certified complex upper bound on a fine grid, lower bounds at the peaks and the D-G bound
    (refined around its own peaks).  Returns the complex sweep, the real and complex lower
    bounds, the D-G peak and the frequencies added for it."""
    beat = report                   # no heartbeat thread when nobody listens
    report = report or (lambda stage, fraction: None)
    Sc = S.complexified()
    fine = np.unique(np.concatenate([default_grid(CL, n=final_points, decades=1.5), grid]))
    final, H = _fine_sweep(CL, Sc, fine, npeaks=npeaks,
                        progress=lambda f: report(f"final-analysis: mu sweep, {fine.size} frequencies", 0.4 * f))
    ups = final.upper
    wpk = final.omega[_local_maxima(ups, npeaks)]
    mu_dg = float(final.peak_upper)
    wreal, extra = wpk, np.zeros(0)
    if S.has_real and dg:
        # minutes on large loops, in one call: a heartbeat with the elapsed time
        with _Heartbeat(beat, lambda t: f"final-analysis: D-G bound ({t:.0f} s)", 0.4):
            mu_dg, w_dg, extra = _dg_refined_peak(CL, H, S, final.omega, ups)
        # the real lower bound also where the D-G bound peaks: a loop that uses the
        # parameters' realness has its complex peaks elsewhere
        wreal = np.union1d(wpk, [w_dg])
    with _Heartbeat(beat, lambda t: f"final-analysis: lower bounds at the peaks ({t:.0f} s)", 0.7):
        low_c = mu_sweep(CL, Sc, wpk, method="osborne", lower="all", refine=False)
        low = mu_sweep(CL, S, wreal, method="osborne", lower="all", refine=False) if S.has_real else low_c
    final.lower = np.full(final.omega.size, np.nan)
    final.lower[np.searchsorted(final.omega, low.omega)] = low.lower
    final.peak_lower = float(low.peak_lower)
    final.lower_frequency = float(low.lower_frequency)
    final.lower_delta = low.lower_delta
    return final, float(low.peak_lower), float(low_c.peak_lower), mu_dg, extra
