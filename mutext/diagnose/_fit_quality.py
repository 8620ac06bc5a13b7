r"""Goodness of fit: is what is left after the best model at the noise, and if not, where is it?

The noise reference
-------------------
Every channel is described once without any physical model: a stable
rational function fitted by vector fitting (:func:`mutext.frfit.fit_frf`),
its order chosen by the Bayesian information criterion over even orders.
Its log residual :math:`\rho_{ck} = \ln(\tilde H_c(j\omega_k)/\hat H_c(j\omega_k))`
estimates the noise without assuming the engineering model is right:

.. math::
    s^2 = \frac{\sum_{c,k} |\rho_{ck}|^2}{\nu},\qquad \nu = \sum_c (2N_c - p_c),

per real component (:math:`N_c` frequencies, :math:`p_c` real parameters of
the rational fit: a pole and a residue per state, and a constant and a
:math:`1/s^2` term for the modes outside the band), so :math:`s^2` has
:math:`\nu` degrees of freedom.  Unlike fourth differences along frequency, it is not biased
upwards on coarse grids where a resonance curves the response between
neighbouring lines (with 40 lines over three modes: 1.0 against 1.8 times the
true level).

Lack of fit
-----------
The best physical model (the engineering model with the accepted effects)
leaves :math:`\mathrm{RSS}` on :math:`N` real residuals with :math:`k` fitted
sizes.  Its misfit ratio

.. math::
    \phi = \frac{\mathrm{RSS}/(N-k)}{s^2}

is, when the model is right, the ratio of two variance estimates with
:math:`N-k` and :math:`\nu` degrees of freedom, :math:`F(N-k, \nu)`
distributed (both come from the same noise, which makes the ratio scatter
less than an F variable and the test conservative).  The result is
*explained* only if :math:`\phi` is below the :math:`1-\alpha` quantile.

Bin-to-bin correlation
----------------------
An analyser's FFT with a window correlates neighbouring lines: the variance of
each line is unchanged, but there are fewer independent ones, so the
degrees of freedom above are too many and the test would call a good model
wrong.  The lag-1 autocorrelation :math:`r_1` of the noise reference's
residual (pooled over channels) is measured; when it is significant
(:math:`|r_1| > 2/\sqrt{n}`), both degrees of freedom are divided by the
variance inflation of a sum of squares of a first-order correlated sequence,
:math:`(1 + r_1^2)/(1 - r_1^2)` (a Hann window's :math:`|r_1| = 2/3`: 2.6).
A stepped-sine sweep has independent lines (:math:`r_1 \approx 0`).  Noise
given by the user (``noise=``, e.g. from repeated sweeps) is taken as exact
(:math:`\nu = \infty`).

Data the rational reference does not describe
---------------------------------------------
Correlated noise spreads evenly over the band; a nonlinearity (a response
that depends on the amplitude), a time-varying system, leakage -- or simply
more modes than the reference's order holds -- leave *structure* where the
response is large.  When the rational reference of a channel leaves bands
above its own level (the window test below) and its level exceeds the local
fourth-difference level (:func:`mutext.frfit.noise_level`) by more than 30 %,
the reference is not at the noise: the local level is used as the noise (with
the fourth differences' smaller, approximate degrees of freedom), and the bands
the final model misses too are reported.  The reference cannot say which of
those causes it is; repeated sweeps at another force level can (amplitude
dependence).

Where the misfit is
-------------------
Per channel, :math:`\phi_c` is the same ratio on its points; over frequency,
windows of :math:`w` lines whose :math:`\sum|r|^2/s^2` exceeds the
:math:`\chi^2_{2w}` quantile at :math:`1-\alpha/(\text{number of windows})`
are merged into bands and listed with their excess.
"""
from __future__ import annotations

import logging
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.stats as sst

from ..errors import ModelError
from ..frfit import _basis, _lstsq, _realisation, _split_poles, noise_level

log = logging.getLogger("mutext.diagnose")

#: Largest order of the rational noise reference (and at most a third of a channel's lines).
MAX_REFERENCE_ORDER = 40


@dataclass
class NoiseReference:
    """The noise level of the data and how well it is known (see the module docstring)."""
    sigma: float                 # relative noise, rms of the complex relative error
    dof: float                   # real degrees of freedom of s^2 = sigma^2/2 (inf when given)
    r1: float = 0.0              # lag-1 autocorrelation of the reference residual (pooled)
    inflation: float = 1.0       # variance inflation applied to degrees of freedom
    method: str = "rational"     # "rational", "fourth differences" or "given"
    channels: list = field(default_factory=list)   # (label, sigma, real parameters) per channel
    structured: list = field(default_factory=list)  # (label, f_lo, f_hi, misfit): no linear model fits there

    @property
    def linear(self) -> bool:
        """Whether a linear time-invariant (rational) model describes every channel at the noise."""
        return not self.structured

    def as_dict(self) -> dict:
        return {"sigma": self.sigma, "dof": self.dof, "r1": self.r1, "inflation": self.inflation,
                "method": self.method, "linear": self.linear,
                "structured": [{"channel": c, "from_hz": a, "to_hz": b, "misfit": m}
                               for c, a, b, m in self.structured],
                "channels": [{"channel": c, "sigma": s, "parameters": o} for c, s, o in self.channels]}


def _rational_reference(w, G, order: int, iterations: int = 20):
    """Vector fitting with a constant and a :math:`1/s^2` term besides the poles (what the modes outside
    the band leave in it: a residual flexibility above, a residual mass below).  Returns the fitted
    response and the number of real parameters."""
    w0 = float(np.sqrt(w.min() * w.max()))
    g0 = float(np.abs(G).max())
    s, F = 1j * w / w0, G / g0
    npairs, nreal = order // 2, order % 2
    beta = np.logspace(np.log10(abs(s).min()), np.log10(abs(s).max()), max(npairs, 1))[:npairs]
    poles = np.array([complex(-0.01 * b, b) for b in beta]
                     + ([complex(-float(np.sqrt(abs(s).min() * abs(s).max())), 0.0)] if nreal else []))
    extra = np.column_stack([np.ones_like(s), 1.0 / (s * s)])
    wgt = 1.0 / np.abs(F)
    for _ in range(iterations):
        Phi = _basis(s, poles)
        m = Phi.shape[1]
        sol = _lstsq(np.hstack([extra, Phi, -F[:, None] * Phi]), F.astype(complex), wgt)
        A, B, C = _realisation(poles, sol[-m:])
        poles = _split_poles(np.linalg.eigvals(A - B @ C))
    X = np.hstack([extra, _basis(s, poles)])
    x = _lstsq(X, F.astype(complex), wgt)
    return (X @ x) * g0, X.shape[1] + sum(1 if p.imag == 0 else 2 for p in poles)


def _reference_fit(f_hz, H):
    """(log residual, real parameters) of the BIC-best rational reference of one channel."""
    w = 2 * np.pi * np.asarray(f_hz, float)
    N = w.size
    top = min(MAX_REFERENCE_ORDER, N // 3)
    best = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for n in range(2, top + 1, 2):
            try:
                Hf, k = _rational_reference(w, H, n)
            except (np.linalg.LinAlgError, ValueError):
                continue
            with np.errstate(all="ignore"):
                r = np.log(Hf / H)
            if not np.all(np.isfinite(r)):
                continue
            rss = float(np.sum(np.abs(r) ** 2))
            bic = 2 * N * math.log(max(rss, 1e-300) / N) + k * math.log(2 * N)
            if best is None or bic < best[0]:
                best = (bic, n, r, k)
            elif n >= best[1] + 10:         # the criterion has turned up for good
                break
    if best is None:
        raise ModelError("no rational fit of the channel")
    return best[2], best[3]


def _structured_bands(r, f, s2, alpha):
    """Bands where a residual is above ``s2`` beyond chance (windows of w lines, Bonferroni): list of
    (f_lo, f_hi, misfit in the band)."""
    w = max(5, r.size // 40)
    if r.size < w:
        return []
    sums = np.convolve(np.abs(r) ** 2 / s2, np.ones(w), mode="valid")
    crit = float(sst.chi2.isf(alpha / sums.size, 2 * w))
    bad = sums > crit
    edges = np.flatnonzero(np.diff(np.r_[0, bad.astype(int), 0]))
    return [(float(f[i]), float(f[min(j + w - 2, f.size - 1)]), float(np.max(sums[i:j]) / (2 * w)))
            for i, j in zip(edges[::2], edges[1::2])]


def noise_reference(chans, noise: float | None = None, alpha: float = 0.01) -> NoiseReference:
    """The data's noise level from model-free rational fits of each channel (or ``noise`` as given)."""
    if noise is not None:
        return NoiseReference(float(noise), math.inf, method="given")
    rss, dof, lag, lag0, per, structured = 0.0, 0.0, 0.0, 0.0, [], []
    local = []
    try:
        for c in chans:
            r, k = _reference_fit(c.frf.freq_hz, c.frf.response)
            N = r.size
            if 2 * N - k < 8:
                raise ModelError(f"{c.label}: too few lines ({N}) for a noise reference")
            rss_c = float(np.sum(np.abs(r) ** 2))
            s2_c = rss_c / (2.0 * N - k)
            d4 = noise_level(c.frf.freq_hz, c.frf.response)
            local.append(d4)
            bands = _structured_bands(r, c.frf.freq_hz, s2_c, alpha)
            # a reference that leaves structure in bands and sits well above the local (fourth-difference)
            # level is not at the noise: no linear model of its order describes the channel there
            if bands and math.sqrt(2 * s2_c) > 1.3 * d4:
                structured += [(c.label, a, b, m) for a, b, m in bands]
            rss += rss_c
            dof += 2.0 * N - k
            lag += float(np.sum((r[1:] * np.conj(r[:-1])).real))
            lag0 += rss_c
            per.append((c.label, math.sqrt(2 * s2_c), k))
    except ModelError as exc:
        # the robust fourth-difference estimate; its scatter calibrated on simulated sweeps
        # (var of s^2 about 2 / (0.55 N)): a smaller, approximate number of degrees of freedom
        log.debug("rational noise reference failed (%s): fourth differences", exc)
        lv = [noise_level(c.frf.freq_hz, c.frf.response) for c in chans]
        npts = [c.frf.freq_hz.size for c in chans]
        sigma = float(math.sqrt(np.average(np.square(lv), weights=npts)))
        return NoiseReference(max(sigma, 1e-6), 0.55 * sum(npts), method="fourth differences",
                              channels=[(c.label, s, 0) for c, s in zip(chans, lv)])
    if structured:
        # the local level is the better noise estimate; the data are not those of a linear system there
        npts = [c.frf.freq_hz.size for c in chans]
        sigma = float(math.sqrt(np.average(np.square(local), weights=npts)))
        return NoiseReference(max(sigma, 1e-6), 0.55 * sum(npts), method="fourth differences",
                              channels=[(c.label, s, 0) for c, s in zip(chans, local)], structured=structured)
    s2 = rss / dof
    r1 = lag / lag0 if lag0 > 0 else 0.0
    n_lines = sum(c.frf.freq_hz.size for c in chans)
    # sum of squares of a correlated sequence: variance inflated by 1 + 2 sum rho_k^2 (AR(1): (1+r^2)/(1-r^2))
    inflation = (1 + r1 ** 2) / (1 - r1 ** 2) if (abs(r1) > 2 / math.sqrt(n_lines) and abs(r1) < 0.95) else 1.0
    return NoiseReference(max(math.sqrt(2 * s2), 1e-6), dof / inflation, r1, inflation, "rational", per)


@dataclass
class FitQuality:
    """The lack-of-fit test of the final model (see the module docstring)."""
    misfit: float                # phi: residual variance over the noise's (about 1 when right)
    limit: float                 # the (1 - alpha) quantile of F(N - k, nu) the misfit is held against
    p_value: float
    at_noise: bool
    dof: float                   # N - k (after the correlation inflation)
    channels: list = field(default_factory=list)   # (label, misfit of the channel)
    bands: list = field(default_factory=list)      # (label, f_lo, f_hi, misfit in the band)
    nonlinear: list = field(default_factory=list)  # bands no linear model describes, missed here too

    def as_dict(self) -> dict:
        return {"misfit": self.misfit, "limit": self.limit, "p_value": self.p_value, "at_noise": self.at_noise,
                "dof": self.dof, "channels": [{"channel": c, "misfit": m} for c, m in self.channels],
                "bands": [{"channel": c, "from_hz": a, "to_hz": b, "misfit": m} for c, a, b, m in self.bands],
                "not_linear": [{"channel": c, "from_hz": a, "to_hz": b, "misfit": m}
                               for c, a, b, m in self.nonlinear]}

    def where(self, n: int = 3) -> str:
        """Where the misfit lies, in words (worst bands first)."""
        if not self.bands:
            worst = sorted(self.channels, key=lambda x: -x[1])[:n]
            return "spread over the band; by channel: " + ", ".join(f"{c} {m:.3g}x" for c, m in worst)
        return "; ".join(f"{c} {a:.4g}-{b:.4g} Hz ({m:.3g}x the noise)"
                         for c, a, b, m in sorted(self.bands, key=lambda x: -x[3] * (x[2] - x[1]))[:n])


def fit_quality(residuals, freqs, labels, s2: float, k: int, ref: NoiseReference, alpha: float) -> FitQuality:
    """Lack-of-fit test of a model whose complex log residuals per channel are ``residuals``."""
    r_all = np.concatenate(residuals)
    N = 2 * r_all.size
    rss = float(np.sum(np.abs(r_all) ** 2))
    df1 = max(N - k, 1) / ref.inflation
    phi = (rss / max(N - k, 1)) / s2
    if math.isfinite(ref.dof):
        limit = float(sst.f.isf(alpha, df1, ref.dof))
        p = float(sst.f.sf(phi, df1, ref.dof))
    else:
        limit = float(sst.chi2.isf(alpha, df1) / df1)
        p = float(sst.chi2.sf(phi * df1, df1))
    chans = [(lab, float(np.sum(np.abs(r) ** 2) / (2 * r.size) / s2)) for lab, r in zip(labels, residuals)]
    n_win = max(sum(max(r.size - max(5, r.size // 40) + 1, 0) for r in residuals), 1)
    bands = []
    for lab, r, f in zip(labels, residuals, freqs):
        # Bonferroni over every window of every channel; correlated lines: fewer independent ones
        bands += [(lab, a, b, m) for a, b, m in _structured_bands(r, f, s2 * ref.inflation,
                                                                  alpha * max(r.size, 1) / n_win)]
    # bands no linear model of the reference's order fits count only where this model misses them too
    # (a reference that underfits the edge of the band is not evidence against a model that fits it)
    unlinear = [(c, a, b, m) for c, a, b, m in ref.structured
                if any(c == c2 and a <= b2 and a2 <= b for c2, a2, b2, _ in bands)]
    return FitQuality(phi, limit, p, bool(phi <= limit), df1, chans, bands, unlinear)
