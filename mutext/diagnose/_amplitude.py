r"""Amplitude dependence: the same channels measured again at another excitation level, compared.

A linear structure's FRF does not depend on the force that measures it; a
nonlinear one (a cubic spring, a joint that slips, a clearance) does, and no
linear hypothesis can hold at two levels at once.  Given sweeps of the same
channels at another excitation level (``diagnose(..., repeat=...)``), each
channel present in both sets is compared on the frequencies both hold,

.. math::
    r_{ck} = \ln\frac{\tilde H^{(b)}_c(j\omega_k)}{\tilde H^{(a)}_c(j\omega_k)} ,

without any model: the noise of both sets is in :math:`r`, so each real part
has variance :math:`s_a^2 + s_b^2 = 2s^2` (:math:`s^2` the variance of one real
part of a log residual, the same in both sets).

The noise is estimated as the diagnosis estimates it (a model-free rational fit
of each channel, :func:`mutext.diagnose._fit_quality.noise_reference`, with
its degrees of freedom :math:`\nu`), but of the channels' geometric mean
:math:`\ln\bar H_c = \ln\tilde H^{(a)}_c + r_c/2`, not of one set: its log
residual carries :math:`(n_a + n_b)/2`, of variance :math:`s^2/2` per real part,
and for noise of the same level in both sets it is independent of
:math:`r`'s :math:`n_b - n_a`.  (The measured set's own estimate, the
diagnosis's :math:`s^2`, shares :math:`n_a` with :math:`r`: the ratio below
would then scatter about half as much as an :math:`F` variable, and the test
would hold a far smaller false-alarm rate than :math:`\alpha`, at the cost of
its power.)  The ratio

.. math::
    \phi = \frac{\sum_{c,k}|r_{ck}|^2 / n}{4\bar s^2}

over the :math:`n` real parts (:math:`\bar s^2` the mean's noise estimate,
:math:`4\bar s^2` estimating :math:`2s^2`) is held against the
:math:`1-\alpha` quantile of :math:`F(n, \nu)`, as the lack-of-fit test holds
a model's misfit, with :math:`n` and :math:`\nu` divided by the variance
inflation of correlated neighbouring lines; with the noise given
(``noise=``, taken as exact) against :math:`\chi^2_n/n`.  It is reported as
:math:`\chi^2 = n\phi` against the threshold :math:`n` times that quantile.
Where :math:`|r|` is largest is found with the windows of the lack-of-fit test
(Bonferroni over the windows), and the resonance in that band is located in
both sets (the peak of :math:`|H|`, refined by a least-squares parabola in
:math:`\ln|H|` over its top) to say how far it moved between the levels.

The excitation level of a file is read when it carries one (a CSV header line
``# excitation: 2 N``, or ``excitation_level``, ``force_amplitude``,
``force_level``; a Universal File's ID line with ``excitation=2N``); it is
reported, never required.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.stats as sst

from ..errors import ModelError
from ..response import FRF, local_extrema
from ._channels import _src
from ._fit_quality import NoiseReference, _structured_bands, noise_reference

#: Header keys of an FRF file (metadata) read as the excitation level, first found first.
LEVEL_KEYS = ("excitation", "excitation_level", "force_amplitude", "force_level")


@dataclass
class LevelTest:
    """The comparison of the same channels at two excitation levels (see the module docstring).

    ``chi2`` and ``threshold`` in units of the noise (``n`` real parts), ``significant`` when ``chi2``
    exceeds ``threshold``; ``channels``: ``(label, lines, misfit)`` per compared channel (misfit about 1 at
    the noise); ``bands``: ``(label, f_lo, f_hi, misfit)`` where the levels differ beyond chance; ``worst``:
    the band where ``|r|`` is largest ``(label, f_lo, f_hi, max |r|)``; ``resonance``: the resonance in it at
    both levels (``channel``, ``measured_hz``, ``repeat_hz``, ``shift`` and ``peak_change`` relative) or None;
    ``levels``: the excitation level of the measured and of the repeated sweeps as the files state them
    (None when not stated); ``lower``: which set is at the lower level (``"measured"``, ``"repeat"`` or None
    when the levels do not say)."""
    chi2: float
    threshold: float
    n: int
    dof_noise: float
    p_value: float
    significant: bool
    alpha: float
    channels: list = field(default_factory=list)
    bands: list = field(default_factory=list)
    worst: tuple | None = None
    resonance: dict | None = None
    levels: tuple = (None, None)
    lower: str | None = None
    files: list = field(default_factory=list)

    def levels_text(self) -> str:
        """The two levels in words ("at 0.2 N and 1 N"), or "" when the files do not state them."""
        a, b = self.levels
        if a is None and b is None:
            return ""
        return f" (measured at {a or 'a level not stated'}, repeated at {b or 'a level not stated'})"

    def evidence(self) -> str:
        """Where and how much the levels differ, in words: the band, the resonance that moved, the test."""
        out = []
        if self.worst is not None:
            lab, a, b, _ = self.worst
            out.append(f"largest on {lab} at {a:.4g}-{b:.4g} Hz")
        res = self.resonance
        if res is not None:
            out.append(f"the resonance at {res['measured_hz']:.4g} Hz moved to {res['repeat_hz']:.4g} Hz "
                       f"({100 * res['shift']:+.2g} %, peak {100 * res['peak_change']:+.2g} %) between the levels")
        others = sorted({lab for lab, _, _, _ in self.bands} - ({self.worst[0]} if self.worst else set()))
        if others:
            out.append("also on " + ", ".join(others))
        out.append(f"chi2 {self.chi2:.1f} on {self.n} real parts, threshold {self.threshold:.1f} "
                   f"(false-alarm rate {100 * self.alpha:g} %)")
        return "; ".join(out)

    def sentence(self) -> str:
        """The verdict of the test in one sentence (what the headline and the first note say)."""
        if self.significant:
            return f"the response depends on the excitation level{self.levels_text()}: {self.evidence()}"
        return (f"the sweeps repeated at another excitation level{self.levels_text()} agree with the measured "
                f"ones within the noise (chi2 {self.chi2:.1f} on {self.n} real parts, threshold "
                f"{self.threshold:.1f}): no amplitude dependence seen; the repeat adds nothing else to the "
                "diagnosis")

    def as_dict(self) -> dict:
        return {"significant": self.significant, "chi2": self.chi2, "threshold": self.threshold, "n": self.n,
                "noise_dof": self.dof_noise, "p_value": self.p_value, "alpha": self.alpha,
                "channels": [{"channel": c, "lines": k, "misfit": m} for c, k, m in self.channels],
                "bands": [{"channel": c, "from_hz": a, "to_hz": b, "misfit": m} for c, a, b, m in self.bands],
                "largest": None if self.worst is None else {"channel": self.worst[0], "from_hz": self.worst[1],
                                                            "to_hz": self.worst[2], "max_abs_log_ratio":
                                                            self.worst[3]},
                "resonance": self.resonance, "levels": {"measured": self.levels[0], "repeat": self.levels[1]},
                "lower": self.lower, "files": self.files, "sentence": self.sentence()}


@dataclass
class _Pair:
    """A measured channel and its repeat on the frequencies both hold (indices into each)."""
    chan: object          # the measured channel (_Chan)
    rep: object           # the repeated one (_Chan)
    ia: np.ndarray
    ib: np.ndarray


def pair_channels(chans: list, rep_chans: list) -> list:
    """Each repeated channel with the measured channel(s) of the same ports and speed, on the frequencies both
    hold; a repeated channel that matches none, or shares no frequency with it, is an error naming its file."""
    pairs = []
    for k, r in enumerate(rep_chans, start=1):
        same = [c for c in chans if (c.in_spec, c.out_dof, c.speed) == (r.in_spec, r.out_dof, r.speed)]
        if not same:
            have = ", ".join(dict.fromkeys(c.label for c in chans))
            raise ModelError(f"repeat {_src(r.frf, k)}: its channel {r.label}"
                             + (f" at {r.speed / (2 * math.pi):g} Hz running speed" if r.speed else "")
                             + f" matches no measured channel (measured: {have}); a repeat is the same channel "
                             "measured at another excitation level")
        free = np.ones(r.frf.freq_hz.size, bool)
        n0 = len(pairs)
        for c in same:
            ia, ib = _common(c.frf.freq_hz, r.frf.freq_hz)
            keep = free[ib]
            ia, ib = ia[keep], ib[keep]       # a repeated line is compared once
            if ia.size:
                free[ib] = False
                pairs.append(_Pair(c, r, ia, ib))
        if len(pairs) == n0:
            raise ModelError(f"repeat {_src(r.frf, k)}: channel {r.label} shares no frequency with the measured "
                             f"{_src(same[0].frf, 0)}; repeated sweeps are compared on the frequencies both hold")
    return pairs


def _common(fa, fb):
    """Indices of the frequencies ``fa`` and ``fb`` hold both (equal within 1e-9 relative)."""
    j = np.clip(np.searchsorted(fb, fa), 1, max(fb.size - 1, 1))
    cand = np.stack([j - 1, np.minimum(j, fb.size - 1)])
    d = np.abs(fb[cand] - fa[None])
    jb = cand[np.argmin(d, axis=0), np.arange(fa.size)]
    ok = np.abs(fb[jb] - fa) <= 1e-9 * np.maximum(np.abs(fa), 1e-12)
    return np.flatnonzero(ok), jb[ok]


def level_of(frf) -> str | None:
    """The excitation level an FRF's file states (see the module docstring), or None."""
    md = frf.metadata or {}
    for k in LEVEL_KEYS:
        v = md.get(k)
        if v is not None and str(v).strip():
            return str(v).strip()
    for k in ("uff_id1", "uff_id2", "uff_id3", "uff_id4", "uff_id5"):
        m = re.search(r"(?:excitation|force_amplitude|force_level)=(\S+)", str(md.get(k, "")))
        if m:
            return m.group(1)
    return None


def _set_level(frfs) -> str | None:
    levels = list(dict.fromkeys(x for x in (level_of(f) for f in frfs) if x is not None))
    return None if not levels else ", ".join(levels)


def _number(level: str | None):
    """``(value, unit)`` of a level such as ``"2 N"`` or ``"0.1A rms"``, or None."""
    if level is None:
        return None
    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*", level)
    return None if m is None else (float(m.group(1)), m.group(2))


def _lower(la, lb) -> str | None:
    a, b = _number(la), _number(lb)
    if a is None or b is None or a[1] != b[1] or a[0] == b[0]:
        return None
    return "measured" if a[0] < b[0] else "repeat"


@dataclass
class _Mean:
    frf: object
    label: str


def pair_noise(pairs: list, noise: float | None = None) -> NoiseReference:
    """The noise of one set, as :func:`noise_reference` gives it (``sigma``: rms of the complex relative
    error of one sweep), estimated from the geometric mean of each channel and its repeat (see the module
    docstring; ``noise`` given: taken as it is)."""
    if noise is not None:
        return noise_reference([], noise)
    means = []
    for p in pairs:
        ha = p.chan.frf.response[p.ia]
        with np.errstate(all="ignore"):
            r = np.log(p.rep.frf.response[p.ib] / ha)
        means.append(_Mean(FRF(p.chan.frf.freq_hz[p.ia], ha * np.exp(r / 2)), p.chan.label))
    ref = noise_reference(means)
    # the mean's log residual has half the variance of one sweep's
    return replace(ref, sigma=ref.sigma * math.sqrt(2.0), channels=[(c, s * math.sqrt(2.0), k)
                                                                    for c, s, k in ref.channels])


def level_test(pairs: list, ref: NoiseReference, alpha: float) -> LevelTest:
    """The test of the module docstring on the paired channels, ``ref`` the noise of one sweep
    (:func:`pair_noise`)."""
    v = ref.sigma ** 2                      # variance of one real part of r: twice a sweep's sigma^2 / 2
    dof, inflation = ref.dof, ref.inflation         # (the dof already counts correlated lines as fewer)
    rs, fs, labels = [], [], []
    for p in pairs:
        with np.errstate(all="ignore"):
            r = np.log(p.rep.frf.response[p.ib] / p.chan.frf.response[p.ia])
        rs.append(r)
        fs.append(p.chan.frf.freq_hz[p.ia])
        labels.append(p.chan.label)
    r_all = np.concatenate(rs)
    n = 2 * r_all.size
    rss = float(np.sum(np.abs(r_all) ** 2))
    phi = rss / n / v
    df1 = n / inflation
    if math.isfinite(dof):
        limit, p_val = float(sst.f.isf(alpha, df1, dof)), float(sst.f.sf(phi, df1, dof))
    else:
        limit, p_val = float(sst.chi2.isf(alpha, df1) / df1), float(sst.chi2.sf(phi * df1, df1))
    chans: dict = {}
    for lab, r in zip(labels, rs):
        k, s = chans.get(lab, (0, 0.0))
        chans[lab] = (k + r.size, s + float(np.sum(np.abs(r) ** 2)))
    per = [(lab, k, s / (2 * k) / v) for lab, (k, s) in chans.items()]
    n_win = max(sum(max(r.size - max(5, r.size // 40) + 1, 0) for r in rs), 1)
    bands, worst, best_sum = [], None, -1.0
    for lab, r, f in zip(labels, rs, fs):
        bands += [(lab, a, b, m) for a, b, m in _structured_bands(r, f, v * inflation, alpha * max(r.size, 1) / n_win)]
        w = max(5, r.size // 40)
        if r.size >= w:
            sums = np.convolve(np.abs(r) ** 2, np.ones(w), mode="valid")
            i = int(np.argmax(sums))
            if sums[i] > best_sum:
                best_sum = float(sums[i])
                worst = (lab, float(f[i]), float(f[i + w - 1]), float(np.max(np.abs(r[i:i + w]))))
    if bands:
        # the band where the levels differ most: the significant band around the worst window, else the
        # band of largest excess
        lab, a, b, m = max(bands, key=lambda x: x[3] * (x[2] - x[1]))
        if worst is not None:
            lab = worst[0]
            inside = [x for x in bands if x[0] == lab and x[1] <= worst[2] and worst[1] <= x[2]]
            if inside:
                _, a, b, m = inside[0]
        k = labels.index(lab)
        sel = (fs[k] >= a) & (fs[k] <= b)
        worst = (lab, float(a), float(b), float(np.max(np.abs(rs[k][sel]))) if sel.any() else 0.0)
    sig = bool(phi > limit)
    res = None
    if sig and worst is not None:
        k = labels.index(worst[0])
        res = _moved(pairs[k], worst[1], worst[2])
    return LevelTest(phi * n, limit * n, n, dof, p_val, sig, alpha, per, bands, worst, res)


def _peak(f, H, lo, hi):
    """Frequency and magnitude of the largest local maximum of ``|H|`` within ``[lo, hi]``, or None: a
    parabola in ``ln|H|`` fitted by least squares to the lines about it within 10 % of its top (at least
    three; on a 1 %-noisy peak of 6 lines a third of the scatter of the parabola through three)."""
    mag = np.abs(H)
    fx, _ = local_extrema(f, mag)
    idx = [int(np.searchsorted(f, x)) for x in fx if lo <= x <= hi]
    if not idx:
        return None
    i = max(idx, key=lambda j: mag[j])
    j0, j1 = i - 1, i + 1
    while j0 > 0 and mag[j0 - 1] > 0.9 * mag[i]:
        j0 -= 1
    while j1 < f.size - 1 and mag[j1 + 1] > 0.9 * mag[i]:
        j1 += 1
    x = f[j0:j1 + 1] - f[i]
    c = np.polyfit(x, np.log(mag[j0:j1 + 1]), 2)
    if not c[0] < 0:
        return float(f[i]), float(mag[i])
    xv = float(np.clip(-c[1] / (2 * c[0]), x[0], x[-1]))
    return float(f[i] + xv), float(math.exp(np.polyval(c, xv)))


def _moved(pair, a, b):
    """The resonance in the band ``[a, b]`` (widened by its width on either side) at both levels."""
    f = pair.chan.frf.freq_hz[pair.ia]
    width = max(b - a, 4 * float(np.median(np.diff(f))) if f.size > 1 else 0.0)
    lo, hi = a - width, b + width
    pa = _peak(f, pair.chan.frf.response[pair.ia], lo, hi)
    pb = _peak(f, pair.rep.frf.response[pair.ib], lo, hi)
    if pa is None or pb is None or abs(pb[0] / pa[0] - 1) > 0.2:
        return None
    return {"channel": pair.chan.label, "measured_hz": pa[0], "repeat_hz": pb[0], "shift": pb[0] / pa[0] - 1,
            "peak_change": pb[1] / pa[1] - 1}


def describe_levels(test: LevelTest, fit_frfs, rep_frfs) -> None:
    """The levels the files state, and which set is the lower one (into ``test``)."""
    la, lb = _set_level(fit_frfs), _set_level(rep_frfs)
    test.levels = (la, lb)
    test.lower = _lower(la, lb)
