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


class _Modal:
    r"""A receptance from one eigen-decomposition: :math:`R(\omega) = X\,\mathrm{diag}(1/(j\omega - \lambda))\,Y`.

    The dynamic stiffness :math:`Z(\omega) = K - \omega^2 M + j\omega D` (``D`` any constant velocity matrix:
    modal or discrete damping, gyroscopic terms at the running speed) is taken to the modes of the undamped,
    symmetric part, :math:`\Phi^T M \Phi = I`, :math:`\Phi^T K_s \Phi = \Omega^2`, and its state space there
    with the states :math:`(\Omega\eta, \dot\eta)`: :math:`A = [[0, \Omega], [-\tilde M^{-1}\tilde K
    \Omega^{-1}, -\tilde M^{-1}\tilde D]]` (:math:`\tilde M = \Phi^T M \Phi \approx I`, :math:`\tilde K = \Phi^T
    K \Phi`, any skew part of K kept), nearly normal (well-conditioned eigenvectors however stiff the model).
    With :math:`A = V \mathrm{diag}(\lambda) V^{-1}`: :math:`X = \Phi\Omega^{-1} V_{1:n}`,
    :math:`Y = (V^{-1})_{:, n+1:2n}\tilde M^{-1}\Phi^T`.  One :math:`O(n^3)` step for the model; then any entry of
    :math:`R` at any frequency costs :math:`2n` products, a column or a row :math:`2n^2`, and only the entries
    asked for are formed (a dense :math:`Z` per frequency would cost :math:`O(n^3)` each).  The accuracy is
    that of a direct solve (the backward error is checked at the band's edges and middle; a model it does
    not suit raises :class:`_NotModal`).
    """

    def __init__(self, M, K, D, omega_check=None):
        import scipy.linalg as sla
        n = M.shape[0]
        try:
            lam0, Phi = sla.eigh(0.5 * (K + K.T), 0.5 * (M + M.T))
        except (np.linalg.LinAlgError, ValueError):
            raise _NotModal("the mass matrix is not positive definite") from None
        if not lam0.size or lam0[0] <= 1e-12 * max(lam0[-1], 1e-300):
            raise _NotModal("a rigid-body or unstable mode")
        om = np.sqrt(lam0)
        # the model in the computed modes exactly as they are (their M and K products formed, not taken as
        # I and Omega^2: the small modes of a stiff shaft are known to eps ||K||, and this keeps the result
        # at a direct solve's accuracy)
        Mi = np.linalg.inv(Phi.T @ M @ Phi)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.diag(om)
        A[n:, :n] = -(Mi @ (Phi.T @ K @ Phi)) / om[None, :]
        A[n:, n:] = -(Mi @ (Phi.T @ D @ Phi))
        lam, V = sla.eig(A, overwrite_a=True, check_finite=False)
        del A
        self.lam = lam
        self.X = (Phi / om[None, :]) @ V[:n]         # (n, 2n)
        # Y = V^-1 [0; M~^-1 Phi^T]: one solve with n right-hand sides, V^-1 itself not formed
        rhs = np.zeros((2 * n, n), complex)
        rhs[n:] = Mi @ Phi.T
        try:
            self.Y = sla.solve(V, rhs, overwrite_a=True, overwrite_b=True, check_finite=False)   # (2n, n)
        except np.linalg.LinAlgError:
            raise _NotModal("defective state matrix") from None
        del V, rhs
        self.n = n
        if omega_check is not None and np.size(omega_check):
            w = np.asarray(omega_check, float)
            for wk in (w.min(), np.median(w), w.max()):
                Z = K - wk * wk * M + 1j * wk * D
                x = self.apply(np.array([wk]), np.ones(n))[0]
                err = np.linalg.norm(Z @ x - 1.0) / (np.linalg.norm(Z, 1) * np.linalg.norm(x) + 1e-300)
                if not err < 1e-11:
                    raise _NotModal(f"backward error {err:.1e} at {wk:.4g} rad/s")

    def _s(self, w):
        return 1.0 / (1j * np.asarray(w, float)[:, None] - self.lam[None, :])      # (nw, 2n)

    def apply(self, w, b, rows=None):
        """``R(w) b`` at every DOF, ``(w.size, n)``, or at the DOFs ``rows``, ``(w.size, len(rows))``."""
        w = np.asarray(w, float)
        X = self.X if rows is None else self.X[np.atleast_1d(rows)]
        out = np.empty((w.size, X.shape[0]), complex)
        yb = self.Y @ b
        step = max(1, int(_CHUNK_BYTES // (16 * self.lam.size)))
        for k0 in range(0, w.size, step):
            out[k0:k0 + step] = (self._s(w[k0:k0 + step]) * yb[None, :]) @ X.T
        return out

    def row(self, w, o):
        """Row ``o`` of ``R(w)``: ``(w.size, n)``."""
        w = np.asarray(w, float)
        out = np.empty((w.size, self.n), complex)
        step = max(1, int(_CHUNK_BYTES // (16 * self.lam.size)))
        for k0 in range(0, w.size, step):
            out[k0:k0 + step] = (self._s(w[k0:k0 + step]) * self.X[o][None, :]) @ self.Y
        return out

    def block(self, w, rows, cols):
        """``R(w)[rows, cols]``: ``(w.size, len(rows), len(cols))``, one product of the frequency factors
        with the entries' mode products, in chunks of frequencies."""
        rows, cols = np.atleast_1d(rows), np.atleast_1d(cols)
        P = (self.X[rows][:, None, :] * self.Y[:, cols].T[None, :, :]).reshape(-1, self.lam.size)
        w = np.asarray(w, float)
        out = np.empty((w.size, rows.size * cols.size), complex)
        step = max(1, int(_CHUNK_BYTES // (16 * max(self.lam.size, P.shape[0]))))
        for k0 in range(0, w.size, step):
            out[k0:k0 + step] = self._s(w[k0:k0 + step]) @ P.T
        return out.reshape(w.size, rows.size, cols.size)


class _NotModal(Exception):
    """The model's receptance is not taken from its modes (see :class:`_Modal`)."""


#: Memory of one chunk of frequencies in the receptance's products.
_CHUNK_BYTES = 4_000_000


class _Receptance:
    """Receptance R = Z^-1 of the engineering model at a set of frequencies, and the pieces of it asked for.

    A rotor's is held as its modes (:class:`_Modal`): columns ``R b`` (:meth:`apply`), rows (:meth:`row`)
    and blocks on a hypothesis's DOFs (:meth:`block`) are formed when asked, so that the memory and the time
    grow with the number of entries used, not with the square of the number of DOFs at every frequency.  A
    lumped chain's (a few DOFs, perhaps a rational impedance element, which is not in M, C, K) is the inverse
    of its dynamic stiffness at every frequency, as are models the modal form does not suit."""

    def __init__(self, model, values, speed, omega, chunk_bytes=64_000_000, modal=None):
        M, C, K, G = model.matrices(values)
        self.B = model.input_matrix(values)
        self.D = C + speed * G
        self.omega = np.asarray(omega, float)
        self.model = model
        self.M, self.K = M, K
        self.n = M.shape[0]
        self._chunk = chunk_bytes
        self._R = None
        self.modal = None
        self._modal_scaled = {}
        from ..rotor.lumped_elements import impedances
        if modal is None:
            modal = model.layout.kind == "rotor" and not impedances(model)
        if modal:
            try:
                self.modal = _Modal(M, K, self.D, self.omega)
            except _NotModal:
                self.modal = None
        if self.modal is None:
            self._R = self._dense(self.omega)

    def _dense(self, omega):
        # a rational impedance element (a model extended by model-based identification) is not in
        # M, C, K: its K(jw) joins the dynamic stiffness at its DOF, as in rotor.analysis.frf
        from ..rotor.lumped_elements import add_impedances
        n = self.n
        R = np.empty((omega.size, n, n), complex)
        chunk = max(1, int(self._chunk // (16 * n * n)))
        for k0 in range(0, omega.size, chunk):
            w = omega[k0:k0 + chunk, None, None]
            Z = self.K[None] - w * w * self.M[None] + 1j * w * self.D[None]
            add_impedances(Z, self.model, omega[k0:k0 + chunk])
            R[k0:k0 + chunk] = np.linalg.inv(Z)
        return R

    @property
    def R(self) -> np.ndarray:
        """The whole receptance ``(nfreq, n, n)`` (formed from the modes on first use: memory grows with
        the square of the DOFs; the diagnosis itself asks only for pieces)."""
        if self._R is None:
            md = self.modal
            S = md._s(self.omega)
            self._R = np.empty((self.omega.size, self.n, self.n), complex)
            for k in range(self.omega.size):
                self._R[k] = (md.X * S[k][None, :]) @ md.Y
        return self._R

    def apply(self, idx, b) -> np.ndarray:
        """``R b`` at every DOF at the frequencies ``omega[idx]``: ``(len(idx), n)``."""
        if self.modal is None:
            return np.einsum("kij,j->ki", self._R[idx], b)
        return self.modal.apply(self.omega[idx], np.asarray(b, float))

    def row(self, idx, o) -> np.ndarray:
        """Row ``o`` of R at the frequencies ``omega[idx]``: ``(len(idx), n)``."""
        if self.modal is None:
            return self._R[idx, o, :]
        return self.modal.row(self.omega[idx], o)

    def block(self, idx, rows, cols) -> np.ndarray:
        """``R[rows, cols]`` at the frequencies ``omega[idx]``: ``(len(idx), len(rows), len(cols))``."""
        if self.modal is None:
            return self._R[np.ix_(np.atleast_1d(idx), np.atleast_1d(rows), np.atleast_1d(cols))]
        return self.modal.block(self.omega[idx], rows, cols)

    def scaled(self, a: float):
        """The modal receptance of the model with all its damping scaled by ``1 + a`` (the last one kept)."""
        if a == 0.0:
            return self.modal
        md = self._modal_scaled.get(a)
        if md is None:
            md = _Modal(self.M, self.K, (1 + a) * self.D)
            self._modal_scaled = {a: md}
        return md

    def release(self) -> None:
        """Forget the modes of the damping-scaled models (formed again if asked for)."""
        self._modal_scaled = {}

    def channel(self, chan, freq_hz) -> np.ndarray:
        """Channel ``chan``'s response (output row times input vector) at ``freq_hz``, which must be among
        this receptance's frequencies (the modal form only: formed at those frequencies alone)."""
        w = self.omega[np.searchsorted(self.omega, 2 * np.pi * np.asarray(freq_hz, float))]
        return self.modal.row(w, chan.out_dof) @ self.input_vector(chan.in_spec)

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
            Ro = rec.row(idx, self.chans[k].out_dof)
            Rb = rec.apply(idx, self.b[k])
            self._cols[k] = (Rb, Ro)
        return self._cols[k]


class _Evaluator:
    """Responses of the channels of a data set under one hypothesis, exactly for any size.

    A local hypothesis's pieces of the receptance (``R_Ub``, ``R_oU``, ``R_UU`` at every channel's
    frequencies) are stacked over the channels: one batched solve per evaluation, and ``R_UU`` formed once
    per frequency the channels share."""

    def __init__(self, rec: _Receptance, data: _Data, hyp: Hypothesis):
        self.hyp, self.data, self.rec = hyp, data, rec
        self.stack = None
        if hyp.gain is not None or hyp.glob is not None:
            return
        U = hyp.dofs
        ys, zs = [], []
        for k in range(len(data.chans)):
            Rb, Ro = data.columns(rec, k)
            ys.append(Rb[:, U])                       # R_Ub   (nf, |U|)
            zs.append(Ro[:, U])                       # R_oU   (nf, |U|)
        idx = np.concatenate([np.asarray(i, int) for i in data.idx])
        uniq, back = np.unique(idx, return_inverse=True)
        RUU = rec.block(uniq, U, U)[back]             # (sum nf, |U|, |U|)
        cuts = np.cumsum([0] + [len(i) for i in data.idx])
        self.stack = (np.concatenate(ys), np.concatenate(zs), RUU, rec.omega[idx], cuts)

    def _D(self, w, theta):
        return local_change(self.hyp, theta, w)

    def responses(self, theta: float, derivative: bool = False):
        """Per channel ``H(theta)`` (and ``dH/dtheta`` when asked)."""
        h = self.hyp
        if h.glob is not None:
            Hs = _structure.responses(self.rec, self.data, [h], [theta])
            return (Hs, [None] * len(Hs)) if derivative else Hs
        if h.gain is not None:
            Hs, dHs = [], []
            for k, (ch, H0) in enumerate(zip(self.data.chans, self.data.H0)):
                Roo = self.data.columns(self.rec, k)[1][:, ch.out_dof] if h.gain[0] == "sensor_mass" else None
                g, dg = _channel.factor(h, ch, self.data.freq_hz[k], theta, Roo)
                Hs.append(H0 if g is None else H0 * g)
                dHs.append(np.zeros_like(H0) if g is None else H0 * dg)
            return (Hs, dHs) if derivative else Hs
        y, z, RUU, w, cuts = self.stack
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
        dH = scale * np.einsum("ku,ku->k", z, Du)
        Hs = [H0 - dH[a:b] for H0, a, b in zip(self.data.H0, cuts[:-1], cuts[1:])]
        if not derivative:
            return Hs
        if h.crack is not None or h.change is not None:
            return Hs, [None] * len(Hs)
        A2 = np.eye(nU)[None] + theta * Dt @ RUU       # I + theta D R
        t = np.linalg.solve(A2, Du[:, :, None])[:, :, 0]
        d = -np.einsum("ku,ku->k", z, t)
        return Hs, [d[a:b] for a, b in zip(cuts[:-1], cuts[1:])]


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
                data = _Data([probe], [idx], [H0], [H0], [b], [fit.freq_hz[k]], {0: (Rb, rec.row(idx, d))})
                hs.append(_Evaluator(rec, data, h).responses(f.theta)[0])
            resp.append(np.concatenate(hs))
        sep = min(float(np.sqrt(np.mean(np.abs(np.log(resp[i] / resp[j])) ** 2)))
                  for i in range(len(resp)) for j in range(i + 1, len(resp)))
        if sep > best:
            best, best_station = sep, s
    return best_station
