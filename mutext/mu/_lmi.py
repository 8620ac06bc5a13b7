r"""Upper bound by the D (or D-G) scaling LMI, bisected on :math:`\beta` ([PD]_, [FTD]_).

The feasibility problem is built once per structure (cvxpy parameters, solved
by Clarabel); the value at each level is decided by the certificate
(:func:`~mutext.mu._certificate._gevp`), not by the solver.
"""
from __future__ import annotations

import numpy as np

from .._solver import solve
from ..errors import SolverError
from ._certificate import MuUpper, _d_from_matrices, _diag_result, _gevp, _gevp_fast
from ._structure import BlockStructure, _per_structure


def _herm_basis(n: int):
    """Real basis of n x n Hermitian matrices."""
    out = []
    for i in range(n):
        E = np.zeros((n, n), complex)
        E[i, i] = 1
        out.append(E)
    for i in range(n):
        for j in range(i + 1, n):
            E = np.zeros((n, n), complex)
            E[i, j] = E[j, i] = 1
            out.append(E)
            E = np.zeros((n, n), complex)
            E[i, j], E[j, i] = 1j, -1j
            out.append(E)
    return out


def _embed(H):
    """Real symmetric embedding of a Hermitian matrix (PSD iff H is PSD)."""
    return np.block([[H.real, -H.imag], [H.imag, H.real]])


class _LMIProblem:
    r"""The D-G feasibility problem for one structure, with cvxpy parameters (built once).

    For a level :math:`\beta`: maximise :math:`t` subject to
    :math:`\sum_i x_i (M^HD_{\ell,i}M - \beta^2 D_{r,i}) + \sum_j y_j\,j(G_jM - M^HG_j^H)
    + tI \preceq 0`, :math:`D \succeq 0`, :math:`\operatorname{tr} D_r = 1`,
    :math:`t \le 1`, :math:`|y_j| \le 10^4`; the level is feasible when :math:`t > 0`.
    The normalisation keeps the problem bounded; Hermitian matrices enter
    through their real symmetric embedding.
    """

    def __init__(self, S: BlockStructure, use_g: bool):
        import cvxpy as cp
        self.S = S
        n = S.nrows
        # variables: coefficients of D blocks (Hermitian bases) and G blocks
        self.dterms = []   # (block index, basis matrix of size rows x rows, or None for d*I)
        self.gterms = []
        for k, b in enumerate(S.blocks):
            if b.kind == "full" or b.rows == 1:
                self.dterms.append((k, None))
            else:
                for E in _herm_basis(b.rows):
                    self.dterms.append((k, E))
            if use_g and b.kind == "real":
                for E in _herm_basis(b.rows):
                    self.gterms.append((k, E))
        nd, ng = len(self.dterms), len(self.gterms)
        self.xd = cp.Variable(nd)
        self.xg = cp.Variable(ng) if ng else None
        self.t = cp.Variable()
        self.Hd = [cp.Parameter((2 * n, 2 * n), symmetric=True) for _ in range(nd)]
        self.Hg = [cp.Parameter((2 * n, 2 * n), symmetric=True) for _ in range(ng)]
        expr = sum(self.xd[i] * self.Hd[i] for i in range(nd))
        if ng:
            expr = expr + sum(self.xg[i] * self.Hg[i] for i in range(ng))
        cons = [expr + self.t * np.eye(2 * n) << 0, self.t <= 1.0]
        # D blocks positive semidefinite; normalisation sum of traces of D_r = 1
        trace = 0
        for k, b in enumerate(S.blocks):
            idx = [i for i, (kk, _) in enumerate(self.dterms) if kk == k]
            if self.dterms[idx[0]][1] is None:
                cons.append(self.xd[idx[0]] >= 0)
                trace = trace + b.rows * self.xd[idx[0]]
            else:
                Dk = sum(self.xd[i] * _embed(self.dterms[i][1]) for i in idx)
                cons.append(Dk >> 0)
                trace = trace + sum(self.xd[i] * np.trace(self.dterms[i][1]).real for i in idx)
        cons.append(trace == 1)
        if ng:
            cons.append(cp.norm(self.xg, "inf") <= 1e4)
        self.prob = cp.Problem(cp.Maximize(self.t), cons)

    def _dmats(self, k, E):
        """(D_l, D_r) contribution of one D-basis element."""
        S = self.S
        b, rs, cs = S.blocks[k], S.row_slices[k], S.col_slices[k]
        Dl = np.zeros((S.ncols, S.ncols), complex)
        Dr = np.zeros((S.nrows, S.nrows), complex)
        if E is None:
            Dl[cs, cs] = np.eye(b.cols)
            Dr[rs, rs] = np.eye(b.rows)
        else:
            Dl[cs, cs] = E
            Dr[rs, rs] = E
        return Dl, Dr

    def _gmat(self, k, E):
        S = self.S
        G = np.zeros((S.nrows, S.ncols), complex)
        G[S.row_slices[k], S.col_slices[k]] = E
        return G

    def set(self, M):
        self.M = M
        self.dpairs = [self._dmats(k, E) for k, E in self.dterms]
        self.gmats = [self._gmat(k, E) for k, E in self.gterms]
        self.MDM = [M.conj().T @ Dl @ M for Dl, _ in self.dpairs]
        self.GM = [1j * (G @ M - M.conj().T @ G.conj().T) for G in self.gmats]
        for P, H in zip(self.Hg, self.GM):
            P.value = _embed(H)

    def solve(self, beta):
        """(t, xd, xg) at level beta, or the reason the solver gave no answer (a str)."""
        import cvxpy as cp
        for P, H, (_, Dr) in zip(self.Hd, self.MDM, self.dpairs):
            P.value = _embed(H - beta ** 2 * Dr)
        try:
            solve(self.prob, f"the D-G LMI at level {beta:.6g}")
        except SolverError as exc:
            return f"SolverError: {exc}"
        if self.prob.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or self.t.value is None:
            return f"status {self.prob.status}"
        xd = np.asarray(self.xd.value, float)
        xg = np.asarray(self.xg.value, float) if self.xg is not None else np.zeros(0)
        if not (np.all(np.isfinite(xd)) and np.all(np.isfinite(xg))):
            return "non-finite solution"
        return float(self.t.value), xd, xg

    def scalings(self, xd, xg):
        """(Dl, Dr, G) from the solver's coefficients, each D block made positive
        definite (eigenvalues floored at 1e-10 of the largest): the solver may
        return a block on the boundary of the cone, and any D > 0 gives a bound."""
        S = self.S
        blocks = {}
        for (k, E), x in zip(self.dterms, xd):
            b = S.blocks[k]
            blocks[k] = blocks.get(k, 0) + (x * np.eye(b.rows) if E is None else x * E)
        eig = {k: np.linalg.eigh(0.5 * (B + B.conj().T)) for k, B in blocks.items()}
        top = max(ev.max() for ev, _ in eig.values())
        floor = 1e-10 * top if top > 0 else 1.0
        Dl = np.zeros((S.ncols, S.ncols), complex)
        Dr = np.zeros((S.nrows, S.nrows), complex)
        for k, (ev, V) in eig.items():
            b, rs, cs = S.blocks[k], S.row_slices[k], S.col_slices[k]
            ev = np.maximum(ev, floor)
            if b.kind == "full":
                d = float(ev.mean())
                Dl[cs, cs] = d * np.eye(b.cols)
                Dr[rs, rs] = d * np.eye(b.rows)
            else:
                Dk = (V * ev) @ V.conj().T
                Dl[cs, cs] = Dk
                Dr[rs, rs] = Dk
        G = sum(x * g for x, g in zip(xg, self.gmats)) if len(xg) else None
        return Dl, Dr, G


_LMI_CACHE: dict = {}


def _lmi_problem(S: BlockStructure, use_g: bool) -> _LMIProblem:
    try:
        return _per_structure(_LMI_CACHE, 32, S, use_g, _LMIProblem)
    except ImportError as exc:
        raise SolverError(f"the LMI upper bound needs cvxpy and Clarabel ({exc}); "
                          "use method='osborne'") from None


def _eigvals_robust(M) -> np.ndarray:
    """Eigenvalues of ``M``, for the cheap lower bounds.  LAPACK's QR iteration does not converge on a
    few matrices (``mu_sweep`` at omega = 2e17: entries near 1e-18 and 1e-35 with parts near 1e-51;
    scaling by a power of two does not help, the failure follows the bits); then those of ``M``
    divided by its largest entry (the same eigenvalues, other rounding on the way), and if that
    fails too none: the bound from this term is then 0, still a lower bound."""
    try:
        return np.linalg.eigvals(M)
    except np.linalg.LinAlgError:
        pass
    s = float(np.abs(M).max(initial=0.0))
    if s > 0 and np.isfinite(s):
        try:
            return np.linalg.eigvals(M / s) * s
        except np.linalg.LinAlgError:
            pass
    return np.zeros(0, complex)


def _easy_lower(M, S: BlockStructure) -> float:
    r"""Cheap lower bounds on :math:`\mu`: each diagonal block alone, and
    :math:`\rho(M)` when :math:`\delta I` is in the structure."""
    best = 0.0
    for b, rs, cs in zip(S.blocks, S.row_slices, S.col_slices):
        Mk = M[cs, rs]
        if b.kind == "full":
            best = max(best, np.linalg.norm(Mk, 2))
        else:
            ev = _eigvals_robust(Mk)
            if b.kind == "real":
                ev = ev[np.abs(ev.imag) <= 1e-12 * np.abs(ev)]
            best = max(best, np.abs(ev).max(initial=0.0))
    if not S.has_real and all(b.rows == b.cols for b in S.blocks):
        best = max(best, np.abs(_eigvals_robust(M)).max(initial=0.0))
    return float(best)


def _lmi_bisect(M, S: BlockStructure, use_g: bool, d0, lower, rtol: float, start: MuUpper | None = None,
                first: float | None = None) -> MuUpper:
    r"""The LMI bound by bisection on :math:`\beta`, for ``M`` balanced by the diagonal scaling ``d0``.

    ``start``: a certified bound (scalings for ``M``) that is the first upper
    end of the bracket; ``first``: the first level tried (relative to
    ``start.value``), so that a near-optimal ``start`` is confirmed by one solve.
    """
    tag = "lmi-dg" if use_g else "lmi-d"
    prob = _lmi_problem(S, use_g)
    dl0, dr0 = S.expand_d(d0 / d0[-1])
    M0 = dl0[:, None] * M / dr0[None, :]
    nrm = np.linalg.norm(M0, 2)
    if nrm == 0:
        return _diag_result(M, S, d0, tag)
    Mn = M0 / nrm
    prob.set(Mn)
    # bracket [lo, hi] on the optimal level of the normalised problem: hi is the
    # best certified bound so far (the balancing scaling gives 1), lo a level at
    # which no certificate was found, or a known lower bound on mu
    known = max(0.0 if lower is None else float(lower), _easy_lower(M, S)) / nrm
    lo = min(known, 1.0)
    hi = 1.0
    best = (1.0, np.eye(S.ncols, dtype=complex), np.eye(S.nrows, dtype=complex), None)
    if start is not None and start.value / nrm < 1.0:
        # the start's scalings in the balanced, normalised coordinates (the inverse
        # of the transformation back to M below)
        Dl = start.Dl / dl0[:, None] / dl0[None, :]
        Dr = start.Dr / dr0[:, None] / dr0[None, :]
        G = None
        if use_g:
            G = (start.G if start.G is not None else np.zeros((S.nrows, S.ncols))) / nrm \
                / dr0[:, None] / dl0[None, :]
        v = _gevp_fast(Mn, Dl, Dr, G, S)[0]
        if v < best[0]:
            best = (v, Dl, Dr, G)
            hi = v
    it = 0
    errors = []
    solved = False
    while it < 80 and hi - lo > rtol * hi:
        it += 1
        beta = 0.5 * (lo + hi) if first is None or it > 1 else max(lo, hi * first)
        sol = prob.solve(beta)
        if isinstance(sol, str):
            errors.append(f"beta={beta * nrm:.6g}: {sol}")
            if len(errors) > 3:
                break
            lo = beta  # an unsolved level counts as infeasible; the bound stays certified
            continue
        solved = True
        t, xd, xg = sol
        Dl, Dr, G = prob.scalings(xd, xg)
        # feasibility is decided by the certificate, not by the solver's t: its value in double
        # precision here (the bisection's compass), the bound with rounding accounted for below
        val = _gevp_fast(Mn, Dl, Dr, G, S)[0]
        if val < best[0]:
            best = (val, Dl, Dr, G)
        if val <= beta * (1 + 1e-12):
            hi = min(hi, val)
        else:
            lo = beta
            hi = min(hi, best[0])
    if errors and not solved:
        raise SolverError("mu upper bound: the LMI solver (Clarabel via cvxpy) gave no answer for "
                          f"structure {S!r} ({'; '.join(errors)}); use method='osborne'")
    _, Dl, Dr, G = best
    # back to M: M0^H Dl M0 + j(G M0 - M0^H G^H) <= b^2 Dr is, after the congruence
    # by R0, the LMI for M with L0 Dl L0, R0 Dr R0 and nrm * R0 G L0
    Dl = dl0[:, None] * Dl * dl0[None, :]
    Dr = dr0[:, None] * Dr * dr0[None, :]
    if G is not None:
        G = nrm * dr0[:, None] * G * dl0[None, :]
    value = _gevp(M, Dl, Dr, G, S)
    return MuUpper(float(value), tag, d=_d_from_matrices(S, Dr), Dl=Dl, Dr=Dr, G=G,
                   iterations=it, lower_level=float(min(lo, hi) * nrm))
