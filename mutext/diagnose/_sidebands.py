r"""Sidebands: the signature of a stiffness that turns with the shaft.

A rotor whose stiffness changes within a revolution (a breathing crack, an
asymmetric shaft) is linear time-periodic: forced at :math:`\omega` it also
responds at :math:`\omega + k\Omega`, and the measured FRF resonates where
:math:`\omega + k\Omega` meets a natural frequency, i.e. at

.. math::
    f = f_n - k F, \qquad k = \pm 1, \pm 2, \pm 3, \qquad F = \Omega / 2\pi,

a small copy of the mode's resonance shifted by :math:`kF`.  No
time-invariant model has a resonance there.  :math:`|k| = 1` (and 3) comes
from a stiffness that changes once per turn (the crack opening under
weight), :math:`|k| = 2` from one that changes twice per turn (an open crack
or any asymmetric shaft seen from the fixed frame).

**The test** (one candidate :math:`f_c = f_n - kF` at a time, on the data
alone): in a window around :math:`f_c` the measured response is fitted by
weighted linear least squares with a smooth baseline (a constant, a slope,
and the resonance shape of every nearby mode),

.. math::
    H(f) \approx c_0 + c_1 (f - f_c) + \sum_j b_j L(f; f_j, \zeta_j)
    \quad [+\; a\,L(f + kF; f_n, \zeta_n)],\qquad
    L(f; f_n, \zeta) = \frac{1}{f_n^2 - f^2 + 2j\zeta f_n f},

with and without the shifted resonance :math:`a\,L(f + kF)`.  With
circular complex noise of relative size :math:`\sigma` (estimated from the
data, :func:`mutext.frfit.noise_level`), the drop of the weighted residual
:math:`\Delta\chi^2` is :math:`\chi^2` with 2 degrees of freedom per channel
when there is no sideband.  A candidate is found when its p-value is below
``alpha`` divided by the number of candidates (Bonferroni).  The mode
frequencies and damping come from the data (each mode fitted by its own
resonance shape near the given natural frequency), so the model is only
used to say where to look.

A candidate closer to a mode than three half-power bandwidths is masked by
the mode itself and reported as such, not tested.  A sideband counts only
with its mirror image: :math:`f_n - kF` found while :math:`f_n + kF` could be
tested (in the band, not masked) and was not found is more likely a mode the
model misplaces than a sideband, and is reported as *unpaired*.

**Combination-frequency channels** (first-order evidence).  The sidebands
above are second-order effects: in the response at the excitation frequency a
stiffness change :math:`\Delta K` appears as :math:`\Delta K^2`, or near the
few frequencies where :math:`f + kF` meets a mode.  An analyzer that also
correlates the response at :math:`f + kF`
(:func:`mutext.rig.measure_rotor` with ``combination=``, files with an
``order: k`` header) measures the off-diagonal harmonic transfer function
:math:`H_k`, of first order in :math:`\Delta K`, which is zero for a
time-invariant rotor.  To first order :math:`H_k(f) = C Z(f + kF)^{-1}
K_k Z(f)^{-1} B`, so near the modes it is a combination of the resonance
shapes at the response frequency and at the excitation frequency,

.. math::
    H_k(f) \approx c_0 + \sum_n \big[a_n L(f + kF; f_n, \zeta_n)
    + a_n' \partial_{f_n} L(f + kF) + b_n L(f; f_n, \zeta_n)
    + b_n' \partial_{f_n} L(f)\big].

Each combination channel is tested against "noise only" (:math:`H_k = 0`)
by the F-test of this linear fit, weighted by :math:`1/|\hat H_0|` (the
noise of the correlation scales with the excitation-frequency response, as
:func:`mutext.rig.measure_rotor` simulates it); the F-test needs no noise
level, only that the noise be circular and proportional to
:math:`|\hat H_0|`.  A channel is found when its p-value is below ``alpha``
over the number of channels (Bonferroni).  With channels at several running
speeds an order counts only when it is found at every speed measured: the
crack's response moves with the speed as predicted (the shapes are placed at
:math:`f_n - kF` for each speed's :math:`F`), a fixed-frequency artefact
does not.  When combination channels are present their verdict is the
evidence (``source = "combination"``); the stepped-sine sideband test is still
run on the excitation-frequency channels and reported beside it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ..errors import ModelError

__all__ = ["SidebandCandidate", "CombinationTest", "SidebandEvidence", "sideband_evidence", "frf_order"]


@dataclass
class SidebandCandidate:
    """One place where a sideband of order ``k`` of the mode at ``mode_hz`` would appear.

    Attributes
    ----------
    mode_hz : float
        The mode's frequency [Hz].
    k : int
        Order of the sideband (at ``mode_hz - k F``).
    freq_hz : float
        Where the sideband would appear [Hz].
    delta_chi2 : float
        Improvement of the local fit with the sideband.
    p_value : float
        Its p-value under noise only.
    relative_size : float
        Size relative to the local response.
    snr : float
        Size over what the noise lets the test see.
    found : bool
        Significant at the threshold.
    masked : bool
        Not tested: too close to a mode (three half-power bandwidths) or too few samples around it.
    unpaired : bool
        Found, but its mirror was testable and not found (not counted).
    """
    mode_hz: float
    k: int
    freq_hz: float
    delta_chi2: float = float("nan")
    p_value: float = float("nan")
    relative_size: float = float("nan")
    snr: float = float("nan")
    found: bool = False
    masked: bool = False
    unpaired: bool = False      # found, but its mirror f_n + kF testable and not found: not counted

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class CombinationTest:
    """The test of one combination-frequency channel (response at f + kF to excitation at f)."""
    k: int
    speed_hz: float
    channel: str
    f_stat: float = float("nan")
    p_value: float = float("nan")
    snr: float = float("nan")          # largest fitted response over the noise of the main channel
    found: bool = False
    consistent: bool = True            # found at every speed measured for this |k|

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def frf_order(frf) -> int:
    """The combination order ``k`` of an FRF (its ``order`` metadata; 0 for an ordinary FRF)."""
    v = frf.metadata.get("order") if isinstance(frf.metadata, dict) else None
    if v is None:
        return 0
    try:
        k = int(str(v).strip())
    except ValueError:
        raise ModelError(f"sideband_evidence: FRF metadata 'order' must be an integer k (response at "
                         f"f + k F), got {v!r}") from None
    if k != 0 and not (frf.speed_hz and frf.speed_hz > 0):
        raise ModelError(f"sideband_evidence: a combination channel (order {k}) needs its running speed "
                         f"(speed_hz), got {frf.speed_hz!r}")
    return k


@dataclass
class SidebandEvidence:
    """Result of :func:`sideband_evidence`.

    Attributes
    ----------
    candidates : list of SidebandCandidate
    modes : list of (frequency [Hz], damping ratio)
        The modes as fitted on the data.
    speed_hz : float
    noise : float
        Relative noise level used.
    threshold : float
        p-value below which a candidate counts (alpha / number tested).
    orders_found : list of int
        The orders :math:`|k|` with at least one sideband found.
    verdict : str
        ``"once per revolution"`` (|k| = 1 or 3 found: a breathing crack),
        ``"twice per revolution"`` (only |k| = 2: an open crack or asymmetric
        shaft), or ``"none"`` (a time-invariant model explains the data).
    detectable : float
        The smallest sideband (relative to the local response) this noise
        level lets the test see, roughly.
    combination : list
        The tests of the combination-frequency channels, when the data hold any.
    source : str
        What the verdict rests on: ``"stepped sine"`` or ``"combination"``.
    stepped_sine_verdict : str
        The stepped-sine sideband test's own verdict.
    """
    candidates: list
    modes: list
    speed_hz: float
    noise: float
    threshold: float
    orders_found: list = field(default_factory=list)
    verdict: str = "none"
    detectable: float = float("nan")
    combination: list = field(default_factory=list)
    source: str = "stepped sine"
    stepped_sine_verdict: str = "none"

    def found(self) -> list:
        return [c for c in self.candidates if c.found and not c.unpaired]

    def meaning(self) -> str:
        """What the verdict says about the rotor, in words."""
        if self.verdict == "once per revolution":
            return ("a stiffness that changes once per turn: a crack opening and closing under the "
                    "shaft's weight (breathing)")
        if self.verdict == "twice per revolution":
            return ("a stiffness that changes twice per turn only: an asymmetric shaft (an open crack, a "
                    "keyway), or a breathing crack whose 1X sidebands stay below the noise "
                    f"(about {100 * self.detectable:.2g} % here)")
        return ("no sidebands above the noise (smallest detectable about "
                f"{100 * self.detectable:.2g} % of the response): a time-invariant model explains the data")

    def summary(self) -> str:
        lines = [f"sidebands at {self.speed_hz:g} Hz running speed (noise {100 * self.noise:.3g} %, "
                 f"threshold p < {self.threshold:.2g}, from the {self.source} channels): {self.verdict}: "
                 f"{self.meaning()}"]
        if self.combination:
            lines.append(f"  combination-frequency channels (first order); stepped-sine sidebands alone: "
                         f"{self.stepped_sine_verdict}")
            for c in self.combination:
                mark = ("FOUND" if c.consistent else "FOUND, not at every speed") if c.found else "-"
                lines.append(f"  k={c.k:+d} at {c.speed_hz:g} Hz  {c.channel}  F {c.f_stat:9.2f}  "
                             f"p {c.p_value:9.2e}  snr {c.snr:8.2f}  {mark}")
        for c in self.candidates:
            if c.masked:
                continue
            mark = "FOUND, unpaired" if c.unpaired else "FOUND" if c.found else "-"
            lines.append(f"  mode {c.mode_hz:8.2f} Hz  k={c.k:+d}  at {c.freq_hz:8.2f} Hz  "
                         f"size {100 * c.relative_size:7.3f} %  dchi2 {c.delta_chi2:9.1f}  p {c.p_value:9.2e}  {mark}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {"speed_hz": self.speed_hz, "noise": self.noise, "threshold": self.threshold,
                "verdict": self.verdict, "meaning": self.meaning(), "orders_found": list(self.orders_found),
                "detectable": self.detectable, "modes": [list(m) for m in self.modes],
                "candidates": [c.to_dict() for c in self.candidates], "source": self.source,
                "stepped_sine_verdict": self.stepped_sine_verdict,
                "combination": [c.to_dict() for c in self.combination]}


def _shape(f, fn, zeta):
    return 1.0 / (fn * fn - f * f + 2j * zeta * fn * f)


def _data_modes(f, H, noise, clusters, reach):
    """(frequency, damping) of each given mode, read from the data by vector fitting.

    Each cluster of given natural frequencies is matched to the fitted
    resonances within 5 % (all of them, so that close modes stay apart); a
    mode outside the band, or not found, keeps its given frequency and 1 %
    damping.  Modes further than ``reach`` outside the band are dropped.
    """
    from ..frfit import resonances
    try:
        res = resonances(f, H, noise=noise, n_boot=0)
    except Exception:           # noqa: BLE001 - a failed fit leaves the given frequencies
        res = []
    modes = []
    for c in clusters:
        fn0 = float(np.mean(c))
        if not (f.min() - reach <= fn0 <= f.max() + reach):
            continue
        # 5 %: a crack moves its modes that far (the rig's 40 % crack, both compliances, always
        # open: the first pair by 3.2 %); a narrower reach picks a spurious resonance instead
        near = [r for r in res if abs(r.freq_hz - fn0) <= 0.05 * fn0 + 0.5 * (max(c) - min(c))]
        if near and f.min() <= fn0 <= f.max():
            near = sorted(near, key=lambda r: abs(r.freq_hz - fn0))[:len(c)]
            modes.extend((float(r.freq_hz), float(r.damping_ratio)) for r in near)
        else:
            modes.append((fn0, 0.01))
    return sorted(set(modes))


def _as_list(frfs):
    from ..response import FRF
    if isinstance(frfs, FRF):
        return [frfs]
    out = list(frfs)
    if not out or not all(isinstance(x, FRF) for x in out):
        raise ModelError("sideband_evidence: give one FRF or a list of FRFs (mutext.rig.FRF)")
    return out


def sideband_evidence(frfs, natural_frequencies_hz, speed_hz: float, *, orders=(1, 2, 3),
                      noise: float | None = None, alpha: float = 0.01) -> SidebandEvidence:
    r"""Evidence for sidebands :math:`f_n - kF` in measured FRFs (module docstring).

    Parameters
    ----------
    frfs : FRF or list of FRF
        Measured at the running speed, on one frequency grid (several
        channels add their evidence).
    natural_frequencies_hz : sequence of float
        Where the modes are (the model's natural frequencies are good
        enough: each is refined on the data within 5 %).  Modes outside the
        band widened by the largest shift are ignored.
    speed_hz : float
        Running speed :math:`F` [Hz].
    orders : sequence of int
        The :math:`|k|` to look for.
    noise : float, optional
        Relative noise level (default: estimated from the data).
    alpha : float
        False-alarm probability over all candidates.

    Returns
    -------
    SidebandEvidence
    """
    from ..frfit import noise_level
    combos, mains, f, Hs, orders = _checked_data(frfs, speed_hz, orders, alpha)
    if noise is None:
        noise = float(np.median([noise_level(f, H) for H in Hs]))
    noise = max(float(noise), 1e-12)
    df = float(np.median(np.diff(f)))
    F = float(speed_hz)
    # the modes, refined on the data (the largest channel)
    ref = Hs[int(np.argmax([np.max(np.abs(H)) for H in Hs]))]
    modes = _data_modes(f, ref, noise, _clusters(natural_frequencies_hz), F * max(orders))
    cands = _candidates(modes, orders, f, F, df)
    tested = [c for c in cands if not c.masked]
    threshold = alpha / max(len(tested), 1)
    for c in tested:
        _test_candidate(c, cands, modes, f, Hs, F, df, noise, threshold)
    _mark_unpaired(cands)
    found = sorted({abs(c.k) for c in cands if c.found and not c.unpaired})
    verdict = ("once per revolution" if (1 in found or 3 in found) else
               "twice per revolution" if 2 in found else "none")
    n_win = max(8, int(round(2 * 2.5 / df)))
    detectable = noise * float(np.sqrt(stats.chi2.isf(threshold, 2) / n_win)) * 2.0
    ev = SidebandEvidence(cands, [(float(a), float(b)) for a, b in modes], F, noise, threshold, found,
                          verdict, detectable, stepped_sine_verdict=verdict)
    if combos:
        ev.combination = _combination_tests(combos, mains, modes, noise, alpha)
        ks = sorted({abs(c.k) for c in ev.combination if c.found and c.consistent})
        ev.orders_found = ks
        ev.verdict = ("once per revolution" if (1 in ks or 3 in ks) else
                      "twice per revolution" if 2 in ks else "none")
        ev.source = "combination"
        ev.threshold = alpha / len(ev.combination)
    return ev


def _checked_data(frfs, speed_hz, orders, alpha):
    """The arguments of :func:`sideband_evidence` checked: ``(combination FRFs, excitation-frequency FRFs,
    frequency grid, responses of the channels at ``speed_hz``, sorted positive orders)``."""
    everything = _as_list(frfs)
    combos = [d for d in everything if frf_order(d) != 0]
    mains = [d for d in everything if frf_order(d) == 0]
    if not mains:
        raise ModelError(f"sideband_evidence: no excitation-frequency FRF (without an 'order') among the "
                         f"{len(everything)} given; the mode frequencies and the noise are read from it")
    # with channels at several speeds, the stepped-sine test uses those at speed_hz
    numeric = isinstance(speed_hz, (int, float, np.integer, np.floating)) and not isinstance(speed_hz, bool)
    data = [d for d in mains if numeric and (d.speed_hz is None
                                             or abs(d.speed_hz - speed_hz) <= 1e-9 * abs(speed_hz))] or mains
    f = np.asarray(data[0].freq_hz, float)
    for d in data[1:]:
        if d.freq_hz.shape != f.shape or not np.allclose(d.freq_hz, f, rtol=1e-9, atol=0):
            raise ModelError("sideband_evidence: every FRF must share one frequency grid")
    if not (np.isfinite(speed_hz) and speed_hz > 0):
        raise ModelError(f"sideband_evidence: speed_hz must be a positive running speed [Hz], got {speed_hz!r}")
    orders = sorted({int(abs(k)) for k in orders})
    if not orders or orders[0] < 1:
        raise ModelError(f"sideband_evidence: orders must be positive integers, got {orders!r}")
    if not (0 < alpha < 1):
        raise ModelError(f"sideband_evidence: alpha must lie in (0, 1), got {alpha!r}")
    if f.size < 20:
        raise ModelError(f"sideband_evidence: need at least 20 frequencies, got {f.size}")
    Hs = [np.asarray(d.response, complex) for d in data]
    return combos, mains, f, Hs, orders


def _clusters(natural_frequencies_hz) -> list:
    """The given natural frequencies (finite, positive), sorted, those within 1 % of each other grouped."""
    fn_in = np.sort(np.asarray(natural_frequencies_hz, float).ravel())
    fn_in = fn_in[np.isfinite(fn_in) & (fn_in > 0)]
    clusters = []
    for x in fn_in:
        if clusters and x - clusters[-1][-1] < 0.01 * x:
            clusters[-1].append(x)
        else:
            clusters.append([x])
    return clusters


def _candidates(modes, orders, f, F, df) -> list:
    """A :class:`SidebandCandidate` for each mode and order ``-/+k`` whose sideband falls inside the band,
    marked masked when a mode of its own frequency hides it."""
    cands = []
    for fn, z in modes:
        for k in orders:
            for kk in (k, -k):
                fc = fn - kk * F
                if not (f.min() < fc < f.max()):
                    continue
                c = SidebandCandidate(float(fn), int(kk), float(fc))
                # masked by a mode of its own frequency (within 3 half-power bandwidths, or 3 samples)
                c.masked = any(abs(fc - fm) < max(3.0 * zm * fm, 3 * df) for fm, zm in modes)
                cands.append(c)
    return cands


def _test_candidate(c, cands, modes, f, Hs, F, df, noise, threshold) -> None:
    """The drop-one test of the candidate ``c`` in a window around it, on every channel: its delta chi2,
    p-value, size and whether it is found are set on ``c`` (or it is marked masked: too few samples)."""
    zn = dict(modes)[c.mode_hz]
    half = max(2.5, 4.0 * zn * c.mode_hz, 6 * df)
    sel = (f >= c.freq_hz - half) & (f <= c.freq_hz + half)
    if sel.sum() < 8:
        c.masked = True
        return
    fs = f[sel]
    base = [np.ones_like(fs), fs - c.freq_hz]
    for fm, zm in modes:
        if abs(fm - c.freq_hz) < half + 40 * zm * fm + 3 * F:
            # the shape and its derivatives in f_n and zeta: small errors of the mode's
            # parameters are absorbed linearly instead of being read as a sideband
            Dn = fm * fm - fs * fs + 2j * zm * fm * fs
            base += [1.0 / Dn, (2 * fm + 2j * zm * fs) / Dn**2, (2j * fm * fs) / Dn**2]
    side = _shape(fs + c.k * F, c.mode_hz, zn)
    # other candidates whose sideband falls in this window stay in both fits, so that a
    # strong neighbour is not read as this one (a drop-one test)
    zmap = dict(modes)
    base += [_shape(fs + o.k * F, o.mode_hz, zmap[o.mode_hz]) for o in cands
             if o is not c and abs(o.freq_hz - c.freq_hz) < half and abs(o.freq_hz - c.freq_hz) > 2 * df]
    d2, sizes = 0.0, []
    for H in Hs:
        y = H[sel]
        wt = 1.0 / (noise * np.maximum(np.abs(y), 1e-300))     # sigma_i = noise * |H_i|
        X0 = np.column_stack(base) * wt[:, None]
        X1 = np.column_stack(base + [side]) * wt[:, None]
        r0 = y * wt - X0 @ np.linalg.lstsq(X0, y * wt, rcond=None)[0]
        coef1 = np.linalg.lstsq(X1, y * wt, rcond=None)[0]
        r1 = y * wt - X1 @ coef1
        # circular complex noise: |n|^2 / (sigma^2 / 2) is chi-square with 2 degrees of freedom
        d2 += 2.0 * float(np.sum(np.abs(r0) ** 2) - np.sum(np.abs(r1) ** 2))
        sizes.append(float(np.max(np.abs(coef1[-1] * side) / np.maximum(np.abs(y), 1e-300))))
    c.delta_chi2 = d2
    c.p_value = float(stats.chi2.sf(max(d2, 0.0), 2 * len(Hs)))
    c.relative_size = float(max(sizes))
    c.snr = c.relative_size / noise
    c.found = bool(c.p_value < threshold)


def _mark_unpaired(cands) -> None:
    """A sideband comes with its mirror image about the mode (f_n - kF and f_n + kF): one found alone, its
    partner testable and not found, is more likely a mode the model misplaces than a sideband."""
    def paired(c):
        partner = next((o for o in cands if o.mode_hz == c.mode_hz and o.k == -c.k), None)
        return partner is None or partner.masked or partner.found
    for c in cands:
        c.unpaired = bool(c.found and not paired(c))


def _same_channel(a, b) -> bool:
    return (a.input_station == b.input_station and a.output_station == b.output_station
            and a.input_direction == b.input_direction and a.output_direction == b.output_direction)


def _combination_tests(combos, mains, modes, noise, alpha) -> list:
    """F-test of every combination channel against noise only (module docstring)."""
    tests = []
    for c in combos:
        k, F = frf_order(c), float(c.speed_hz)
        f = np.asarray(c.freq_hz, float)
        y = np.asarray(c.response, complex)
        ref = next((m for m in mains if _same_channel(m, c) and m.speed_hz is not None
                    and abs(m.speed_hz - F) <= 1e-9 * F and m.freq_hz.shape == f.shape
                    and np.allclose(m.freq_hz, f, rtol=1e-9, atol=0)), None)
        wt = np.ones(f.size) if ref is None else 1.0 / np.maximum(np.abs(ref.response), 1e-300)
        cols = [np.ones_like(f)]
        for fn, zn in modes:
            for fx in (f + k * F, f):
                if f.min() - 3 * F <= fn <= f.max() + 3 * F or fx.min() <= fn <= fx.max():
                    Dn = fn * fn - fx * fx + 2j * zn * fn * fx
                    cols += [1.0 / Dn, (2 * fn + 2j * zn * fx) / Dn ** 2]
        X = np.column_stack(cols) * wt[:, None]
        yw = y * wt
        p = X.shape[1]
        name = f"{c.output_name or c.output_station}/{c.input_name or c.input_station}"
        t = CombinationTest(k, F, name)
        n = f.size
        if n - p < 4:
            raise ModelError(f"sideband_evidence: the combination channel {name} (order {k}) has {n} "
                             f"frequencies, too few for its {p} shapes")
        # a column scale that keeps the least-squares problem well conditioned
        sc = np.linalg.norm(X, axis=0)
        coef = np.linalg.lstsq(X / sc, yw, rcond=None)[0]
        fit = (X / sc) @ coef
        rss1 = float(np.sum(np.abs(yw - fit) ** 2))
        rss0 = float(np.sum(np.abs(yw) ** 2))
        t.f_stat = ((rss0 - rss1) / (2 * p)) / max(rss1 / (2 * (n - p)), 1e-300)
        t.p_value = float(stats.f.sf(max(t.f_stat, 0.0), 2 * p, 2 * (n - p)))
        sigma = np.sqrt(rss1 / (n - p))         # residual noise in weighted units
        t.snr = float(np.max(np.abs(fit)) / max(sigma, 1e-300))
        tests.append(t)
    threshold = alpha / max(len(tests), 1)
    for t in tests:
        t.found = bool(t.p_value < threshold)
    for t in tests:
        same = [o for o in tests if abs(o.k) == abs(t.k)]
        speeds = {o.speed_hz for o in same}
        found_speeds = {o.speed_hz for o in same if o.found}
        t.consistent = found_speeds == speeds
    return tests
