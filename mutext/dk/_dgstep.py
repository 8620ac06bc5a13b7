r"""The D-G scalings of every frequency, held fixed, and the trust-region model step on the
peak of the scaled bound that :func:`mutext.dk.refine_controller` takes.
"""
from __future__ import annotations

import numpy as np

from .._solver import solve
from ..errors import SolverError
from ..mu import BlockStructure, mu_upper
from ._sweep import _local_maxima


class _DGPoint:
    """Scalings of one frequency in the form lambda_max(Q) = bound^2,
    Q = R (M^H Dl M + j(GM - M^H G)) R, R = Dr^(-1/2)."""
    __slots__ = ("value", "Dl", "R", "G")

    def __init__(self, value, Dl, R, G):
        self.value, self.Dl, self.R, self.G = value, Dl, R, G

    def q(self, M):
        return self.R @ (M.conj().T @ self.Dl @ M + 1j * (self.G @ M - M.conj().T @ self.G.conj().T)) @ self.R


def _block_spectra(Dr, S: BlockStructure):
    """(largest eigenvalue of the block-diagonal ``Dr``, the eigenvalues and eigenvectors of each
    of its blocks): what :func:`_floored_scalings` and :func:`_graded` both look at."""
    parts = [np.linalg.eigh(Dr[rs, rs]) for rs in S.row_slices]
    return max(float(ev.max()) for ev, _ in parts), parts


def _floored_scalings(Dl, Dr, S: BlockStructure, floor: float = 1e-8, spectra=None):
    """The D scalings with each block's eigenvalues raised to at least ``floor`` times the
    largest, in D_l and D_r alike (so still a valid pair).  Where a parameter barely matters
    its optimal scaling tends to zero, D_r^(-1/2) to 1e8 and beyond, and the scaled form Q
    to entries of 1e16 whose eigenvalues no longer have a correct digit.  ``spectra``:
    :func:`_block_spectra` of ``Dr`` if already computed."""
    top, parts = _block_spectra(Dr, S) if spectra is None else spectra
    Dl, Dr = Dl.copy(), Dr.copy()
    for b, rs, cs, (ev, V) in zip(S.blocks, S.row_slices, S.col_slices, parts):
        if ev.min() >= floor * top:
            continue
        if b.kind == "full":
            d = max(float(ev.mean()), floor * top)
            Dr[rs, rs] = d * np.eye(b.rows)
            Dl[cs, cs] = d * np.eye(b.cols)
        else:
            Dk = (V * np.maximum(ev, floor * top)) @ V.conj().T
            Dr[rs, rs] = Dk
            Dl[cs, cs] = Dk
    return Dl, Dr


def _graded(spectra, floor: float = 1e-6) -> bool:
    """Whether scalings with these :func:`_block_spectra` have a D block below ``floor`` times the
    largest: a real parameter that barely matters, whose d the descent drives towards 0 (and
    its G to infinity) along a flat valley where it can stop short of the optimum (on the loop
    matrix of tests/data/two_mass_loop_matrix_tiny_scaling.npy: d at 1.7e-7 of the largest,
    3e-6 above the LMI's bound, whose d is 7e-12); there the LMI is solved too."""
    top, parts = spectra
    return any(ev.min() < floor * top for ev, _ in parts)


def _dg_point(M, S: BlockStructure) -> _DGPoint:
    """D-G scalings of one frequency: the fast descent's, or the LMI's where those do not
    reproduce the fast value to 1e-3 or are graded (:func:`_graded`: then the lower of the
    two), their small D blocks floored (:func:`_floored_scalings`) unless that loses the 1e-3.
    The value is sqrt(lambda_max(Q)) for the scalings kept, so certified by them."""
    best = None
    for method in ("fast", "lmi"):
        u = mu_upper(M, S, method=method)
        spectra = None
        if u.Dl is None:          # one full block: sigma_max is mu
            nr, nc = M.shape[1], M.shape[0]
            tries = [_DGPoint(u.value, np.eye(nc), np.eye(nr), np.zeros((nr, nc)))]
        else:
            spectra = _block_spectra(u.Dr, S)
            tries = []
            for Dl, Dr in (_floored_scalings(u.Dl, u.Dr, S, spectra=spectra), (u.Dl, u.Dr)):
                ev, V = np.linalg.eigh(Dr)
                R = (V * ev ** -0.5) @ V.conj().T
                tries.append(_DGPoint(u.value, Dl, R, np.zeros_like(Dl) if u.G is None else u.G))
        for pt in tries:
            lam = np.linalg.eigvalsh(pt.q(M))[-1]
            if lam <= u.value ** 2 * (1.0 + 1e-3):
                pt.value = float(np.sqrt(max(lam, 0.0)))
                if best is None or pt.value < best.value:
                    best = pt
                break
        if best is not None and (method == "lmi" or spectra is None or not _graded(spectra)):
            return best
    if best is not None:
        return best
    raise SolverError(f"no consistent D-G scalings for a {M.shape[0]}x{M.shape[1]} loop matrix")


def _dg_points(Ms, S, old=None, reject_at=np.inf):
    """Scalings of every frequency.  With ``old`` (the scalings of the previous controller):
    the old scalings' values are upper bounds; new scalings are computed from the largest of
    them down until the next cannot raise the peak (the same rule as :func:`_dg_peak`).
    Returns None as soon as one frequency's bound reaches ``reject_at``."""
    if old is None:
        return [_dg_point(M, S) for M in Ms]
    pts = []
    for M, o in zip(Ms, old):
        lam = np.linalg.eigvalsh(o.q(M))[-1]
        pts.append(_DGPoint(float(np.sqrt(max(lam, 0.0))), o.Dl, o.R, o.G))
    best = 0.0
    for k in np.argsort([-p.value for p in pts]):
        if pts[k].value <= best:
            break
        pts[k] = _dg_point(Ms[k], S)
        best = max(best, pts[k].value)
        if best >= reject_at:
            return None
    return pts


def _refine_step(modal, theta, pts, M, U, V, rho, w, band=0.01, gap=0.02, spread=120):
    """Trust-region model step: minimise max over the active frequencies of the linearised
    lambda_max of Q (on its top eigenspace), with every parameter moving at most ``rho`` of
    its size and K(jw) at most ``rho`` of its norm at the active frequencies and at ``spread``
    frequencies spread evenly in log over the grid ``w``.  Returns the step (in units of
    ``modal.scale``) and the predicted peak of lambda_max, or None."""
    import cvxpy as cp
    Q = np.array([p.q(m) for p, m in zip(pts, M)])
    lam, Y = np.linalg.eigh(Q)
    top = lam[:, -1]
    peak = top.max()
    # the local maxima within the band and their neighbours: an equalised bound has hundreds
    # of points within it, but between its maxima they add nothing the maxima do not say
    near = top > peak * (1.0 - 2.0 * band)
    idx = [i for i in _local_maxima(top, top.size) if near[i]]
    act = np.unique(np.clip(np.concatenate([np.asarray(idx, int) + k for k in (-1, 0, 1)]), 0, top.size - 1))
    act = act[near[act]]
    # K(jw) moves smoothly between grid points: its trust region on a log-even subset of the
    # grid (dense near the peaks) constrains the step as much, at a fraction of the cost
    # (on the distillation column's 527 frequencies, 0.3 s a solve instead of 1.8 s); the
    # controller's response is needed there and at the active frequencies only
    lw = np.log(w)
    keep = np.union1d(act, np.abs(lw[:, None] - np.linspace(lw[0], lw[-1], spread)[None, :]).argmin(axis=0))
    Kw, Cr, Br = modal.response(theta, 1j * w[keep])
    pos = {int(i): j for j, i in enumerate(keep)}
    nt = theta.size
    d = cp.Variable(nt)
    tau = cp.Variable()
    lin_rows, lin_rhs, lmis = [], [], []
    for k in act:
        sel = lam[k] > lam[k, -1] * (1.0 - gap)
        Yk = Y[k][:, sel]
        p = pts[k]
        Lft = Yk.conj().T @ p.R @ (M[k].conj().T @ p.Dl + 1j * p.G) @ U[k]
        Rgt = V[k] @ p.R @ Yk
        F = modal.sensitivity_factors(Lft, Rgt, Cr[pos[k]], Br[pos[k]]) * modal.scale[:, None, None]
        H = F + np.conj(np.swapaxes(F, 1, 2))
        m = Yk.shape[1]
        if m == 1:
            lin_rows.append(np.real(H[:, 0, 0]))
            lin_rhs.append(lam[k][sel][0])
        else:
            Hr = np.real(H).reshape(nt, m * m).T
            Hi = np.imag(H).reshape(nt, m * m).T
            Xr = cp.reshape(Hr @ d, (m, m), order="C") + np.diag(lam[k][sel])
            Xi = cp.reshape(Hi @ d, (m, m), order="C")
            big = cp.bmat([[Xr, -Xi], [Xi, Xr]])
            lmis.append(tau * np.eye(2 * m) - 0.5 * (big + big.T) >> 0)
    cons = list(lmis)
    if lin_rows:
        cons.append(np.array(lin_rhs) + np.array(lin_rows) @ d <= tau)
    J = modal.d_response(Cr, Br) * modal.scale[None, None, :]
    Kn = np.linalg.norm(Kw.reshape(Kw.shape[0], -1), axis=1)
    J = J / np.maximum(Kn, 1e-300)[:, None, None]
    nk = J.shape[1]
    Jr = np.real(J).reshape(-1, nt)
    Ji = np.imag(J).reshape(-1, nt)
    stacked = cp.reshape(cp.hstack([Jr @ d, Ji @ d]), (2 * nk, J.shape[0]), order="F")
    cons += [cp.abs(d) <= rho, cp.norm(stacked, 2, axis=0) <= rho]
    prob = cp.Problem(cp.Minimize(tau), cons)
    # a model step needs no more than a few digits (every step is checked on the true bound);
    # where Clarabel's factorisation fails, ten times its default regularisation nearly always
    # does it, and SCS, the last resort, is capped (uncapped it took 37 s for a step Clarabel
    # solves in 0.7 s)
    for solver, accuracy in (("CLARABEL", "step"), ("CLARABEL", "step-regularised"), ("SCS", "step")):
        try:
            solve(prob, "the D-G model step", solver=solver, accuracy=accuracy)
        except SolverError:
            continue
        if d.value is not None and tau.value is not None:
            return np.asarray(d.value, float), float(tau.value), float(peak)
    return None
