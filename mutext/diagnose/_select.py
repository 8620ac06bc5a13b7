r"""Several effects at once: exact responses under a set of hypotheses, their joint fit, forward selection.

With accepted effects :math:`h_1,\dots,h_m` (sizes :math:`\theta_i`) the
structural ones change the dynamic stiffness by
:math:`\sum_i \theta_i D_i(\omega)` on the union :math:`U` of their degrees of
freedom; the response follows exactly from the engineering model's receptance
by the same Woodbury identity as one hypothesis
(:mod:`mutext.diagnose`), with :math:`D` now the sum embedded in
:math:`U`.  Gains multiply the channels they act on.

Forward selection: given the accepted set :math:`A`, every other hypothesis
:math:`h` is fitted with the sizes of :math:`A` held, and the best is refitted
jointly with :math:`A`.  It is accepted only if

* its improvement :math:`\Delta\chi^2 = (\mathrm{RSS}_A - \mathrm{RSS}_{A+h})/s^2`
  passes the same Bonferroni threshold as the first effect, given the first
  (the test of a nested model with one more parameter), and
* it improves the held-out data too, by more than noise alone would
  (:math:`\Delta\chi^2_{\mathrm{held}} > \chi^2_1(1-\alpha)`), and
* no size of the joint fit sits at a bound of its range.

Selection stops when the residual is at the noise (the lack-of-fit test of
:mod:`mutext.diagnose._fit_quality`), when no candidate is accepted, or at
:data:`MAX_EFFECTS`.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.optimize as so

from ._screen import _Data, _Receptance
from .faults import channel as _channel
from .faults._base import local_change
from .faults import structure as _structure

#: Largest number of effects forward selection accepts.
MAX_EFFECTS = 3


class Compound:
    """Responses of the channels of a data set under several hypotheses, exactly for any sizes."""

    def __init__(self, rec: _Receptance, data: _Data, hyps: list):
        self.hyps, self.data, self.rec = list(hyps), data, rec
        struct = [h for h in self.hyps if h.gain is None and h.glob is None]
        U = sorted({d for h in struct for d in h.dofs})
        self.U = U
        nU = len(U)
        # each structural hypothesis's pattern embedded in U once (D = sum theta s(w) P)
        self.embed = {}
        for h in struct:
            p = [U.index(d) for d in h.dofs]
            E = np.zeros((nU, len(p)))
            E[p, range(len(p))] = 1.0
            self.embed[id(h)] = E
        self.pieces = []
        for k, idx in enumerate(data.idx):
            if not U:
                self.pieces.append(None)
                continue
            Rb, Ro = data.columns(rec, k)
            self.pieces.append((Rb[:, U], Ro[:, U], rec.block(idx, U, U), rec.omega[idx]))

    def _D(self, w, thetas):
        nU = len(self.U)
        D = np.zeros((w.size, nU, nU), complex)
        for h, t in zip(self.hyps, thetas):
            if h.gain is not None or h.glob is not None:
                continue
            E = self.embed[id(h)]
            D += E[None] @ local_change(h, t, w) @ E.T[None]
        return D

    def responses(self, thetas) -> list:
        if any(h.glob is not None or (h.gain is not None and h.gain[0] == "sensor_mass") for h in self.hyps):
            return _structure.responses(self.rec, self.data, self.hyps, thetas)
        out = []
        nU = len(self.U)
        for k, (ch, H0, piece) in enumerate(zip(self.data.chans, self.data.H0, self.pieces)):
            H = H0
            if piece is not None:
                y, z, RUU, w = piece
                D = self._D(w, thetas)
                u = np.linalg.solve(np.eye(nU)[None] + RUU @ D, y[:, :, None])
                H = H0 - np.einsum("ku,ku->k", z, (D @ u)[:, :, 0])
            for h, t in zip(self.hyps, thetas):
                if h.gain is not None:
                    g, _ = _channel.factor(h, ch, self.data.freq_hz[k], t)
                    if g is not None:
                        H = H * g
            out.append(H)
        return out


def _rss_of(Hs, meas) -> float:
    with np.errstate(all="ignore"):
        r = np.concatenate([np.log(h / m) for h, m in zip(Hs, meas)])
        v = float(np.sum(r.real ** 2 + r.imag ** 2))
    return v if math.isfinite(v) else math.inf


def _safe_rss(comp: Compound, thetas) -> float:
    try:
        return _rss_of(comp.responses(thetas), comp.data.meas)
    except np.linalg.LinAlgError:
        return math.inf


def _bounds(h):
    return h.lower, h.upper


def _scan_grid(h, n=25):
    if _channel.is_log_sized(h):
        g = np.exp(np.linspace(math.log(h.lower), math.log(h.upper), 4 * n))
        return sorted(list(-g) + list(g))
    mags = h.scale * np.logspace(-3, 1, n)
    grid = [0.0] + [m for m in mags if h.lower <= m <= h.upper] + [-m for m in mags if h.lower <= -m <= h.upper]
    grid += [b for b in (h.lower, h.upper) if math.isfinite(b) and b not in grid]
    return sorted(grid)


def fit_one_given(rec, data, fixed: list, thetas: list, h):
    """Size of ``h`` with the hypotheses ``fixed`` held at ``thetas``: (theta, rss)."""
    comp = Compound(rec, data, fixed + [h])

    def rss(t):
        return _safe_rss(comp, list(thetas) + [t])
    if h.gain is not None:
        # the measurement chain is (mostly) linear in the log residual: closed form on the responses given the others
        base = Compound(rec, data, fixed).responses(thetas) if fixed else data.H0
        cands = _channel.fit(h, data.chans, base, data.meas, data.freq_hz)
        if cands is not None:
            return min(((t, rss(t)) for t in cands), key=lambda x: x[1])
    grid = _scan_grid(h, n=10)
    vals = [rss(t) for t in grid]
    j = int(np.argmin(vals))
    t, best = grid[j], vals[j]
    a, b = grid[max(j - 1, 0)], grid[min(j + 1, len(grid) - 1)]
    if b > a:
        res = so.minimize_scalar(rss, bounds=(a, b), method="bounded",
                                 options={"xatol": 1e-6 * max(abs(t), h.scale), "maxiter": 40})
        if res.fun < best:
            t, best = float(res.x), float(res.fun)
    return t, best


def joint_fit(rec, data, hyps: list, start: list, s2: float, iters: int = 40):
    """Levenberg-Marquardt fit of all sizes at once, in bounds: (thetas, rss, stds).

    A k-parameter hypothesis (all parameters positive) is fitted in the logarithms of its parameters;
    its size and std in the result are vectors."""
    comp = Compound(rec, data, hyps)
    meas = data.meas
    # a gain keeps the sign it starts with (a reversed polarity stays reversed)
    neg = [_channel.is_log_sized(h) and not h.params and np.ndim(t) == 0 and t < 0 for h, t in zip(hyps, start)]
    lo, hi, scale, logp, x0, cuts = [], [], [], [], [], [0]
    for h, n, t in zip(hyps, neg, start):
        if h.params:
            lo += [math.log(p.lower) for p in h.params]
            hi += [math.log(p.upper) for p in h.params]
            scale += [1.0] * len(h.params)
            logp += [True] * len(h.params)
            x0 += list(np.log(np.maximum(np.asarray(t, float), 1e-300)))
        else:
            lo.append(-h.upper if n else h.lower)
            hi.append(-h.lower if n else h.upper)
            scale.append(1.0 if _channel.is_log_sized(h) else max(h.scale, 1e-300))
            logp.append(False)
            x0.append(float(t))
        cuts.append(len(lo))
    lo, hi, scale, logp = (np.array(lo, float), np.array(hi, float), np.array(scale, float),
                           np.array(logp, bool))

    def unpack(y):
        v = np.where(logp, np.exp(np.clip(y, lo, hi)), np.clip(y, lo, hi))
        return [v[a:b] if h.params else float(v[a]) for h, a, b in zip(hyps, cuts[:-1], cuts[1:])]

    def resid(x):
        th = unpack(x * scale)
        with np.errstate(all="ignore"):
            r = np.concatenate([np.log(hh / m) for hh, m in zip(comp.responses(th), meas)])
        r = np.concatenate([r.real, r.imag])
        return np.where(np.isfinite(r), r, 1e3)

    x0 = np.clip(np.asarray(x0, float), lo, hi) / scale
    try:
        sol = so.least_squares(resid, x0, bounds=(lo / scale, hi / scale), method="trf", x_scale="jac",
                               max_nfev=iters * (len(x0) + 1))
        x = sol.x
        J = sol.jac
    except (ValueError, np.linalg.LinAlgError):
        x = x0
        J = None
    th = unpack(x * scale)
    rss = _safe_rss(comp, th)
    sd = np.full(len(x0), math.inf)
    if J is not None:
        try:
            cov = np.linalg.inv(J.T @ J) * s2
            sd = np.sqrt(np.maximum(np.diag(cov), 0.0)) * scale
        except np.linalg.LinAlgError:
            pass
    flat = np.concatenate([np.atleast_1d(t) for t in th])
    sd = np.where(logp, flat * sd, sd)                       # first order: std(p) = p std(ln p)
    stds = [sd[a:b] if h.params else float(sd[a]) for h, a, b in zip(hyps, cuts[:-1], cuts[1:])]
    return [t if h.params else float(t) for h, t in zip(hyps, th)], rss, stds


def at_bound(h, theta: float, rel: float = 1e-4) -> bool:
    """Whether a fitted size sits at a bound of its range (an added element at 0 is no effect, not a bound)."""
    if h.params:                      # k parameters, all positive: any one at a bound (in log terms)
        return any(abs(math.log(max(float(t), 1e-300) / b)) <= rel * math.log(p.upper / p.lower)
                   for p, t in zip(h.params, theta) for b in (p.lower, p.upper))
    log_sized = _channel.is_log_sized(h)
    span = math.log(h.upper / h.lower) if log_sized else (h.upper - h.lower)
    for b in (h.lower, h.upper):
        if h.added and b == 0.0:
            continue
        d = abs(math.log(abs(theta) / b)) if log_sized else abs(theta - b)
        if d <= rel * span:
            return True
    return False
