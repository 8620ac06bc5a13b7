"""The exact screen: the engineering model's receptance, and every hypothesis's response and size from it."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._channels import _Chan
from ._hypotheses import Hypothesis
from .faults._base import local_change
from .faults import channel as _channel
from .faults import structure as _structure


class _Receptance:
    """Receptance R = Z^-1 of the engineering model at a set of frequencies, and channel pieces."""

    def __init__(self, model, values, speed, omega, chunk_bytes=64_000_000):
        M, C, K, G = model.matrices(values)
        self.B = model.input_matrix(values)
        self.D = C + speed * G
        self.omega = np.asarray(omega, float)
        n = M.shape[0]
        D = C + speed * G
        # a rational impedance element (a model extended by model-based identification) is not in
        # M, C, K: its K(jw) joins the dynamic stiffness at its DOF, as in rotor.analysis.frf
        from ..rotor.lumped_elements import add_impedances
        self.model = model
        R = np.empty((self.omega.size, n, n), complex)
        chunk = max(1, int(chunk_bytes // (16 * n * n)))
        for k0 in range(0, self.omega.size, chunk):
            w = self.omega[k0:k0 + chunk, None, None]
            Z = K[None] - w * w * M[None] + 1j * w * D[None]
            add_impedances(Z, model, self.omega[k0:k0 + chunk])
            R[k0:k0 + chunk] = np.linalg.inv(Z)
        self.R = R
        self.M, self.K = M, K

    def input_vector(self, spec) -> np.ndarray:
        kind, j = spec
        if kind == "port":
            return self.B[:, j]
        b = np.zeros(self.B.shape[0])
        b[j] = 1.0
        return b


@dataclass
class _Data:
    """Stacked channel data for one set of frequencies (fit or held-out)."""
    chans: list
    idx: list            # per channel: indices into the receptance frequency grid
    meas: list           # per channel: measured response at those points
    H0: list             # per channel: engineering-model response
    b: list              # per channel: input vector
    freq_hz: list = None  # per channel: the frequencies [Hz]
    _cols: dict = None

    @property
    def n_points(self) -> int:
        return sum(len(i) for i in self.idx)

    def columns(self, rec, k):
        """``(R b, R_o:)`` of channel k at its frequencies (computed once, shared by all hypotheses)."""
        if self._cols is None:
            self._cols = {}
        if k not in self._cols:
            idx = self.idx[k]
            Ro = rec.R[idx, self.chans[k].out_dof, :]
            Rb = np.einsum("kij,j->ki", rec.R[idx], self.b[k])
            self._cols[k] = (Rb, Ro)
        return self._cols[k]


class _Evaluator:
    """Responses of the channels of a data set under one hypothesis, exactly for any size."""

    def __init__(self, rec: _Receptance, data: _Data, hyp: Hypothesis):
        self.hyp, self.data, self.rec = hyp, data, rec
        self.pieces = []
        U = hyp.dofs
        for k, (ch, idx) in enumerate(zip(data.chans, data.idx)):
            if hyp.gain is not None or hyp.glob is not None:
                self.pieces.append(None)
                continue
            Rb, Ro = data.columns(rec, k)
            y = Rb[:, U]                              # R_U: b   (nf, |U|)
            z = Ro[:, U]                              # R_oU     (nf, |U|)
            RUU = rec.R[np.ix_(idx, U, U)]            # (nf, |U|, |U|)
            w = rec.omega[idx]
            self.pieces.append((y, z, RUU, w))

    def _D(self, w, theta):
        return local_change(self.hyp, theta, w)

    def responses(self, theta: float, derivative: bool = False):
        """Per channel ``H(theta)`` (and ``dH/dtheta`` when asked)."""
        h = self.hyp
        if h.glob is not None:
            Hs = _structure.responses(self.rec, self.data, [h], [theta])
            return (Hs, [None] * len(Hs)) if derivative else Hs
        Hs, dHs = [], []
        for k, (ch, H0, piece) in enumerate(zip(self.data.chans, self.data.H0, self.pieces)):
            if h.gain is not None:
                Roo = self.data.columns(self.rec, k)[1][:, ch.out_dof] if h.gain[0] == "sensor_mass" else None
                g, dg = _channel.factor(h, ch, self.data.freq_hz[k], theta, Roo)
                Hs.append(H0 if g is None else H0 * g)
                dHs.append(np.zeros_like(H0) if g is None else H0 * dg)
                continue
            y, z, RUU, w = piece
            nU = len(h.dofs)
            if h.crack is not None or h.change is not None:
                Dt = self._D(w, theta)            # already scaled by the depth / the parameter vector
                scale = 1.0
            else:
                Dt = self._D(w, 1.0)
                scale = theta
            A = np.eye(nU)[None] + scale * RUU @ Dt            # I + theta R D
            u = np.linalg.solve(A, y[:, :, None])[:, :, 0]
            Du = (Dt @ u[:, :, None])[:, :, 0]
            H = H0 - scale * np.einsum("ku,ku->k", z, Du)
            Hs.append(H)
            if derivative:
                if h.crack is not None or h.change is not None:
                    dHs.append(None)
                else:
                    A2 = np.eye(nU)[None] + theta * Dt @ RUU       # I + theta D R
                    t = np.linalg.solve(A2, Du[:, :, None])[:, :, 0]
                    dHs.append(-np.einsum("ku,ku->k", z, t))
        return (Hs, dHs) if derivative else Hs


def _rss(Hs, meas) -> float:
    r = np.concatenate([np.log(h / m) for h, m in zip(Hs, meas)])
    return float(np.sum(r.real ** 2 + r.imag ** 2))


def _fit_size(ev: _Evaluator, n_scan: int = 25, gn_iter: int = 30):
    """Least-squares size of one hypothesis: scan for a start, then Gauss-Newton (or golden section)."""
    h = ev.hyp
    meas = ev.data.meas

    def rss(t):
        try:
            Hs = ev.responses(t)
        except np.linalg.LinAlgError:
            return math.inf
        with np.errstate(all="ignore"):
            v = _rss(Hs, meas)
        return v if math.isfinite(v) else math.inf

    if h.gain is not None:
        # the measurement chain enters the log residual linearly: closed form (both signs of a gain)
        cands = _channel.fit(h, ev.data.chans, ev.data.H0, meas, ev.data.freq_hz)
        if cands is not None:
            return min(((t, rss(t)) for t in cands), key=lambda x: x[1])

    # scan: the null size, and sizes over four decades either side of the typical scale (a structure-wide
    # change costs a full solve per evaluation: a coarser scan, the bounded search refines it)
    mags = h.scale * np.logspace(-3, 1, n_scan if h.glob is None else 9)
    grid = [0.0] + [m for m in mags if h.lower <= m <= h.upper] + [-m for m in mags if h.lower <= -m <= h.upper]
    vals = [rss(t) for t in grid]
    k = int(np.argmin(vals))
    t, best = grid[k], vals[k]
    if h.crack is not None or h.glob is not None:
        # the bounds belong to the scan (the log grid's last point below a depth ratio of 0.5 is 0.464):
        # a crack at or near its bound must be reachable
        for e in (h.lower, h.upper):
            if e not in grid:
                grid.append(e)
                v = rss(e)
                if v < best:
                    t, best = e, v
        # one-dimensional and smooth: golden-section refinement between the scan neighbours
        srt = sorted(grid)
        j = srt.index(t)
        a, b = srt[max(j - 1, 0)], srt[min(j + 1, len(srt) - 1)]
        import scipy.optimize as so
        res = so.minimize_scalar(rss, bounds=(a, b), method="bounded", options={"xatol": 1e-6})
        if res.fun < best:
            t, best = float(res.x), float(res.fun)
        return t, best
    for _ in range(gn_iter):
        Hs, dHs = ev.responses(t, derivative=True)
        r = np.concatenate([np.log(hh / m) for hh, m in zip(Hs, meas)])
        J = np.concatenate([d / hh for d, hh in zip(dHs, Hs)])
        den = float(np.sum(np.abs(J) ** 2))
        if not den > 0:
            break
        step = -float(np.sum((np.conj(J) * r).real)) / den
        lam = 1.0
        improved = False
        while lam > 1e-4:
            tn = min(max(t + lam * step, h.lower), h.upper)
            vn = rss(tn)
            if vn < best:
                improved = True
                break
            lam *= 0.5
        if not improved:
            break
        rel = abs(tn - t) / max(abs(t), 1e-12 * h.scale)
        t, best = tn, vn
        if rel < 1e-9:
            break
    return t, best


def _fit_vector(ev: _Evaluator, s2: float, n_best: int = 3, quick: bool = False):
    """Least-squares parameter vector of a k-parameter hypothesis (all parameters positive).

    The hypothesis's starting vectors are ranked by the residual; the best ``n_best`` start a bounded
    least-squares fit in the logarithms of the parameters.  Returns ``(theta, rss, stds)``, the standard
    uncertainties from the Jacobian at the optimum (first order: ``std_i = theta_i * std(ln theta_i)``).
    ``quick``: the best start only, a short fit to loose tolerances (the screen's first pass over every
    location; the contenders are then fitted in full)."""
    import scipy.optimize as so
    h = ev.hyp
    meas = ev.data.meas
    lo = np.log([p.lower for p in h.params])
    hi = np.log([p.upper for p in h.params])

    def resid(x):
        try:
            Hs = ev.responses(np.exp(x))
        except np.linalg.LinAlgError:
            return np.full(2 * ev.data.n_points, 1e3)
        with np.errstate(all="ignore"):
            r = np.concatenate([np.log(hh / m) for hh, m in zip(Hs, meas)])
        r = np.concatenate([r.real, r.imag])
        return np.where(np.isfinite(r), r, 1e3)

    starts = [np.clip(np.log(np.asarray(t, float)), lo, hi) for t in h.starts]
    ranked = sorted(((float(np.sum(resid(x) ** 2)), k) for k, x in enumerate(starts)))
    best = None
    for _, k in ranked[:1 if quick else n_best]:
        # a lightly damped resonance of the added part is a narrow valley: its frequency first, by the first
        # parameter alone (a mass, at the others held), within 10 % either side of the start
        x = starts[k].copy()

        def along(v, x=x):
            y = x.copy()
            y[0] = v
            return float(np.sum(resid(y) ** 2))
        a, b = max(x[0] - 0.2, lo[0]), min(x[0] + 0.2, hi[0])
        if b > a:
            r1 = so.minimize_scalar(along, bounds=(a, b), method="bounded", options={"xatol": 1e-8})
            if r1.fun < along(x[0]):
                x[0] = float(r1.x)
        sol = so.least_squares(resid, x, bounds=(lo, hi), method="trf", x_scale="jac",
                               max_nfev=40 if quick else 1000, ftol=1e-6 if quick else 1e-12,
                               xtol=1e-6 if quick else 1e-12)
        rss = float(np.sum(sol.fun ** 2))
        if best is None or rss < best[1]:
            best = (sol.x, rss, sol.jac)
    x, rss, J = best
    theta = np.exp(x)
    try:
        cov = np.linalg.inv(J.T @ J) * s2
        stds = theta * np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        stds = np.full(theta.size, math.inf)
    return theta, rss, stds


def _jacobian_std(ev: _Evaluator, theta: float, s2: float) -> float:
    """Linearised standard uncertainty of the size: s * (J^T J)^{-1/2} (J from a central difference)."""
    h = ev.hyp
    if h.gain is not None:
        Hs, dHs = ev.responses(theta, derivative=True)
    elif h.crack is None and h.glob is None:
        Hs, dHs = ev.responses(theta, derivative=True)
    else:
        d = max(1e-4 * h.scale, 1e-3 * abs(theta))
        lo, hi = max(theta - d, h.lower), min(theta + d, h.upper)
        Hl, Hh = ev.responses(lo), ev.responses(hi)
        Hs = ev.responses(theta)
        dHs = [(b - a) / (hi - lo) for a, b in zip(Hl, Hh)]
    J = np.concatenate([d / hh for d, hh in zip(dHs, Hs)])
    den = float(np.sum(np.abs(J) ** 2))
    return math.sqrt(s2 / den) if den > 0 else math.inf


def _separating_station(rec: _Receptance, fit: _Data, cands: list, model) -> int | None:
    """Station whose (translational) response would best separate the candidates' fitted models."""
    lay = model.layout
    best, best_station = -1.0, None
    for s in range(1, lay.n_nodes + 1):
        d = lay.dof(s, "x" if lay.kind == "lumped" else "u")
        resp = []
        for f in cands:
            h = f.hypothesis
            hs = []
            for k, (ch, idx, b) in enumerate(zip(fit.chans, fit.idx, fit.b)):
                probe = _Chan(ch.frf, ch.label, ch.in_spec, ch.in_col, ch.in_name, ch.in_station, d, "probe", s,
                              ch.speed)
                Rb, _ = fit.columns(rec, k)
                H0 = Rb[:, d]
                data = _Data([probe], [idx], [H0], [H0], [b], [fit.freq_hz[k]], {0: (Rb, rec.R[idx, d, :])})
                hs.append(_Evaluator(rec, data, h).responses(f.theta)[0])
            resp.append(np.concatenate(hs))
        sep = min(float(np.sqrt(np.mean(np.abs(np.log(resp[i] / resp[j])) ** 2)))
                  for i in range(len(resp)) for j in range(i + 1, len(resp)))
        if sep > best:
            best, best_station = sep, s
    return best_station
