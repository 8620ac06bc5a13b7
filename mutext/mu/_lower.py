r"""Lower bounds with the perturbation that proves them: :func:`mu_lower`.

The complex power iteration ([PFD]_), the real-only local search and the
search over real perturbations with the complex blocks closed exactly.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ._structure import BlockStructure, _as_structure, _norm2


@dataclass
class MuLower:
    r"""A lower bound on :math:`\mu` with the perturbation that proves it.

    Attributes
    ----------
    value : float
    Delta : ndarray or None
        Structured perturbation with :math:`\bar\sigma(\Delta) = 1/\text{value}` and
        :math:`\det(I - M\Delta) = 0` (``None`` when ``value`` is 0).
    method : str
        ``"sigma"`` (one full block), ``"power"`` (complex power iteration),
        ``"real-eig"`` (one real block: exact), ``"real-local"`` (real blocks
        only: local search), ``"real-search"`` (real and complex blocks) or
        ``"failed"`` (the search broke down numerically; the bound is then 0).
    residual : float
        Smallest singular value of :math:`I - M\Delta` (should be ~0).
    """
    value: float
    Delta: np.ndarray | None
    method: str
    residual: float = np.nan

    def __float__(self):
        return float(self.value)


def _align(S: BlockStructure, c, x):
    """Structured Q (blocks of norm 1) maximising |sum_k c_k^H Q_k x_k| with every term
    real and positive."""
    parts = []
    for b, rs, cs in zip(S.blocks, S.row_slices, S.col_slices):
        ck, xk = c[rs], x[cs]
        if b.kind == "full":
            nc, nx = np.linalg.norm(ck), np.linalg.norm(xk)
            if nc == 0 or nx == 0:
                Q = np.zeros((b.rows, b.cols), complex)
                Q[0, 0] = 1
            else:
                Q = np.outer(ck, xk.conj()) / (nc * nx)
            parts.append(Q)
        else:
            ip = np.vdot(ck, xk)
            ph = 1.0 if ip == 0 else ip.conjugate() / abs(ip)
            parts.append(ph)
    return S.assemble(parts)


def _eig_lr(A):
    """Eigenvalues with left and right eigenvectors (``y^H A = lam y^H``)."""
    import scipy.linalg as sla
    return sla.eig(A, left=True, right=True, check_finite=False)


def _power(M, S: BlockStructure, rng, starts: int = 4, iters: int = 200, Q0=None, tol: float = 1e-12):
    r"""Complex power iteration [PFD]_: a local maximiser of :math:`\rho(MQ)` over
    structured :math:`Q` with unit blocks.  Returns (rho, Q, lam).

    At each step the eigenvalue :math:`\lambda` of :math:`MQ` of largest modulus,
    with right and left eigenvectors :math:`x, y`, moves by
    :math:`y^H M\,\delta Q\,x/(y^Hx)`; the next :math:`Q` aligns every block with
    :math:`(M^Hy)_k x_k^H`, the fixed-point condition of a local maximum.
    """
    best = (0.0, None, 0.0)
    n = S.ncols
    for s in range(starts):
        if s == 0 and Q0 is not None:
            Q = Q0
        elif s == 0 or (s == 1 and Q0 is not None):
            # start from the top singular vectors of M
            U, sv, Vh = np.linalg.svd(M)
            Q = _align(S, Vh[0].conj(), U[:, 0])
        else:
            Q = _align(S, rng.standard_normal(S.nrows) + 1j * rng.standard_normal(S.nrows),
                       rng.standard_normal(n) + 1j * rng.standard_normal(n))
        prev = -1.0
        for _ in range(iters):
            w, VL, VR = _eig_lr(M @ Q)
            k = int(np.argmax(np.abs(w)))
            lam = w[k]
            if abs(lam) > best[0]:
                best = (float(abs(lam)), Q.copy(), lam)
            if abs(abs(lam) - prev) <= tol * max(abs(lam), 1e-300):
                break
            prev = abs(lam)
            Q = _align(S, M.conj().T @ VL[:, k], VR[:, k])
    return best


def _start_from_scalings(M, S: BlockStructure, Dl, Dr):
    r"""Starting Q for the power iteration from upper-bound scalings.

    With :math:`A = D_\ell^{1/2} M D_r^{-1/2}`, :math:`Av = \bar\sigma u`: at optimal
    scalings with a simple :math:`\bar\sigma`, :math:`\|u_k\| = \|v_k\|` on every
    block and the Q aligning :math:`u_k` with :math:`v_k` gives
    :math:`\rho(MQ) = \bar\sigma` ([PD]_), so the two bounds meet.
    """
    def sqrtm(D, p):
        ev, V = np.linalg.eigh(0.5 * (D + D.conj().T))
        return (V * np.maximum(ev, 1e-300) ** p) @ V.conj().T
    A = sqrtm(Dl, 0.5) @ M @ sqrtm(Dr, -0.5)
    U, _, Vh = np.linalg.svd(A)
    return _align(S, Vh[0].conj(), U[:, 0])


def _complex_lower(M, S: BlockStructure, rng, starts: int = 4, iters: int = 200, Q0=None):
    """(value, Delta) for a structure of complex blocks; Delta is None when value is 0."""
    if np.linalg.norm(M) == 0:
        return 0.0, None
    if len(S) == 1 and S.blocks[0].kind == "full":
        U, s, Vh = np.linalg.svd(M)
        if s[0] == 0:
            return 0.0, None
        # M Delta = u1 u1^H has the eigenvalue 1
        Delta = np.outer(Vh[0].conj(), U[:, 0].conj()) / s[0]
        return float(s[0]), Delta
    rho, Q, lam = _power(M, S, rng, starts=starts + (Q0 is not None), iters=iters, Q0=Q0)
    if Q is None or rho == 0:
        return 0.0, None
    # the eigenvalue lam of MQ becomes 1
    return rho, Q * (np.conj(lam) / abs(lam)) / rho


def _split(S: BlockStructure, real_idx):
    """Permutations putting the given blocks first."""
    order = list(real_idx) + [k for k in range(len(S)) if k not in real_idx]
    rperm = np.concatenate([np.arange(S.row_slices[k].start, S.row_slices[k].stop) for k in order])
    cperm = np.concatenate([np.arange(S.col_slices[k].start, S.col_slices[k].stop) for k in order])
    return order, rperm, cperm


def _directions(m: int, rng, vertices: int = 6, extra: int = 16):
    """Search directions in R^m: the vertices of the cube (up to sign) when m is
    small, random sign patterns otherwise, the axes and random Gaussian directions."""
    if m <= vertices:
        dirs = [np.array((1.0,) + v) for v in itertools.product((-1.0, 1.0), repeat=m - 1)]
    else:
        dirs = [rng.choice((-1.0, 1.0), m) for _ in range(2 ** vertices)]
    if m > 1:
        dirs += list(np.eye(m))
    for _ in range(extra if m > 1 else 0):
        g = rng.standard_normal(m)
        dirs.append(g / np.abs(g).max())
    return dirs


def _real_only_lower(M, S: BlockStructure, rng, nstarts: int = 8):
    r"""Lower bound for structures of real blocks only.

    One block (:math:`\delta I`): exact, :math:`\mu = \max|\lambda|` over the real
    eigenvalues of :math:`M`.  Several: :math:`\mu^{-1} = \min\|\delta\|_\infty`
    subject to :math:`\lambda(M\Delta(\delta)) = 1` for an eigenvalue
    :math:`\lambda`; two real equations, solved locally (Gauss-Newton onto the
    constraint, then SLSQP with the eigenvalue derivative
    :math:`\partial\lambda/\partial\delta_i = y^HME_ix/(y^Hx)`) from the
    directions where :math:`M\Delta` has a nearly real eigenvalue.
    Returns (value, Delta, method).
    """
    from scipy.optimize import minimize
    m = len(S)
    reps = np.array([b.rows for b in S.blocks])
    idx = [np.arange(rs.start, rs.stop) for rs in S.row_slices]   # square blocks: rows == cols

    def Dm(delta):
        return np.diag(np.repeat(np.asarray(delta, float), reps)).astype(complex)

    if m == 1:
        ev = np.linalg.eigvals(M)
        ok = ev[(np.abs(ev.imag) <= 1e-10 * np.abs(ev)) & (ev != 0)]
        if ok.size == 0:
            return 0.0, None, "real-eig"
        lam = ok[np.argmax(np.abs(ok))].real
        return float(abs(lam)), Dm([1.0 / lam]), "real-eig"

    def lam_grad(delta):
        w, VL, VR = _eig_lr(M @ Dm(delta))
        k = int(np.argmin(np.abs(w - 1.0)))
        x, y = VR[:, k], VL[:, k]
        yx = np.vdot(y, x)
        c = M.conj().T @ y
        g = np.array([np.vdot(c[i], x[i]) for i in idx]) / (yx if abs(yx) > 1e-300 else 1e-300)
        return w[k], g

    # starting points: scale a direction so that a nearly real eigenvalue becomes ~1
    cands = []
    for d in _directions(m, rng):
        for lam in np.linalg.eigvals(M @ Dm(d)):
            if lam == 0 or abs(lam.imag) > 0.5 * abs(lam):
                continue
            c = lam.real / abs(lam) ** 2       # real c minimising |c lam - 1|
            cands.append((abs(c) * (1 + abs(lam.imag) / abs(lam)), c * d))
    cands.sort(key=lambda t: t[0])
    best_r, best_d = np.inf, None
    for _, d0 in cands[:nstarts]:
        d = d0.copy()
        # Gauss-Newton (minimum-norm steps) onto lambda(delta) = 1
        for _ in range(30):
            lam, g = lam_grad(d)
            res = np.array([lam.real - 1.0, lam.imag])
            if np.abs(res).max() < 1e-13:
                break
            J = np.vstack([g.real, g.imag])
            d = d - np.linalg.lstsq(J, res, rcond=None)[0]
        if not np.all(np.isfinite(d)):
            continue
        z0 = np.append(d, np.abs(d).max())

        def cons_eq(z):
            lam, _ = lam_grad(z[:-1])
            return np.array([lam.real - 1.0, lam.imag])

        def jac_eq(z):
            _, g = lam_grad(z[:-1])
            return np.column_stack([np.vstack([g.real, g.imag]), np.zeros(2)])

        A_in = np.vstack([np.column_stack([-np.eye(m), np.ones(m)]),
                          np.column_stack([np.eye(m), np.ones(m)])])
        try:
            r = minimize(lambda z: z[-1], z0, jac=lambda z: np.eye(m + 1)[-1], method="SLSQP",
                         constraints=[{"type": "eq", "fun": cons_eq, "jac": jac_eq},
                                      {"type": "ineq", "fun": lambda z: A_in @ z, "jac": lambda z: A_in}],
                         options={"maxiter": 100, "ftol": 1e-14})
            d = r.x[:-1] if np.all(np.isfinite(r.x)) else d
        except (ValueError, np.linalg.LinAlgError):
            pass
        # make the eigenvalue exactly real and equal to 1 (up to its imaginary part)
        lam, _ = lam_grad(d)
        if abs(lam.imag) > 1e-9 or abs(lam.real - 1.0) > 1e-6 or lam.real <= 0:
            continue
        d = d / lam.real
        rd = np.abs(d).max()
        if rd < best_r:
            best_r, best_d = rd, d
    if best_d is None:
        return 0.0, None, "real-local"
    return 1.0 / best_r, Dm(best_d), "real-local"


def _mixed_lower(M, S: BlockStructure, rng, budget: int = 120, ray: int = 16):
    r"""Lower bound for real and complex blocks (module docstring): maximise over
    real :math:`\delta` the value :math:`\min(1/\|\delta\|_\infty, \mu_c(\mathcal F_u(M, \Delta_r)))`,
    the complex part by a cheap warm-started power iteration during the search
    and a full one at the end.  Returns (value, Delta, method)."""
    from scipy.optimize import minimize
    ridx = [k for k, b in enumerate(S.blocks) if b.kind == "real"]
    cidx = [k for k, b in enumerate(S.blocks) if b.kind != "real"]
    order, rperm, cperm = _split(S, ridx)
    Mp = M[np.ix_(cperm, rperm)]
    nr = sum(S.blocks[k].rows for k in ridx)
    M11, M12, M21, M22 = Mp[:nr, :nr], Mp[:nr, nr:], Mp[nr:, :nr], Mp[nr:, nr:]
    Sc = BlockStructure([S.blocks[k] for k in cidx])
    reps = [S.blocks[k].rows for k in ridx]
    single_full = len(Sc) == 1 and Sc.blocks[0].kind == "full"
    warm = {"Q": None}

    def Dr(delta):
        return np.diag(np.repeat(delta, reps)).astype(complex)

    def closed(delta):
        E = np.eye(nr) - M11 @ Dr(delta)
        if np.linalg.svd(E, compute_uv=False)[-1] < 1e-13:
            return None
        return M22 + M21 @ Dr(delta) @ np.linalg.solve(E, M12)

    def value(delta):
        r = np.max(np.abs(delta)) if len(delta) else 0.0
        Mc = closed(delta)
        if Mc is None:
            return 1.0 / r if r > 0 else 0.0
        if single_full:
            g = np.linalg.norm(Mc, 2)
        else:
            g, Q, _ = _power(Mc, Sc, rng, starts=2, iters=30, Q0=warm["Q"], tol=1e-9)
            if Q is not None:
                warm["Q"] = Q
        return min(1.0 / r if r > 0 else np.inf, g)

    m = len(ridx)
    best_v, best_d = value(np.zeros(m)), np.zeros(m)
    for dvec in _directions(m, rng, extra=4):
        for sgn in (1.0, -1.0):
            # only r < 1/best can improve, since the value is at most 1/r
            rmax = 1.0 / max(best_v, 1e-12)
            for r in np.linspace(rmax / ray, rmax, ray):
                v = value(sgn * r * dvec)
                if v > best_v:
                    best_v, best_d = v, sgn * r * dvec
    # local refinement (derivative-free) from the best point
    if best_v > 0:
        res = minimize(lambda d: -value(d), best_d, method="Nelder-Mead",
                       options={"maxfev": budget * m, "xatol": 1e-10, "fatol": 1e-12 * best_v})
        if -res.fun > best_v:
            best_v, best_d = -res.fun, res.x
    if best_v <= 0:
        return 0.0, None, "real-search"
    # polish along the ray through the best point: the optimum on a ray is where
    # the complex part g(r u) meets 1/r, found by bisection on r g(r u) - 1
    u = best_d / np.abs(best_d).max() if np.abs(best_d).max() > 0 else None
    if u is not None:
        def h(r):
            Mc = closed(r * u)
            if Mc is None:
                return 1.0
            g = np.linalg.norm(Mc, 2) if single_full else _power(Mc, Sc, rng, starts=2, iters=30,
                                                                   Q0=warm["Q"], tol=1e-9)[0]
            return r * g - 1.0
        r_hi = np.abs(best_d).max()
        if h(r_hi) >= 0:
            r_lo = 0.0
            for _ in range(60):
                r_mid = 0.5 * (r_lo + r_hi)
                if h(r_mid) >= 0:
                    r_hi = r_mid
                else:
                    r_lo = r_mid
                if r_hi - r_lo <= 1e-13 * r_hi:
                    break
            v = value(r_hi * u)
            if v > best_v:
                best_v, best_d = v, r_hi * u
    dvec = best_d
    Mc = closed(dvec)
    Dp = np.zeros((S.nrows, S.ncols), complex)
    Dp[:nr, :nr] = Dr(dvec)
    if Mc is not None:
        g, Dc = _complex_lower(Mc, Sc, rng, Q0=warm["Q"])
        if Dc is None:
            return 0.0, None, "real-search"
        Dp[nr:, nr:] = Dc
    v = 1.0 / max(np.abs(dvec).max(initial=0.0), np.linalg.norm(Dp[nr:, nr:], 2))
    # undo the permutation: Dp is indexed (rperm, cperm)
    Delta = np.zeros((S.nrows, S.ncols), complex)
    Delta[np.ix_(rperm, cperm)] = Dp
    return float(v), Delta, "real-search"


def mu_lower(M, structure: BlockStructure, *, rng=0, scalings=None) -> MuLower:
    r"""Lower bound on :math:`\mu_{\boldsymbol\Delta}(M)` with a destabilising perturbation.

    * One full block: :math:`\bar\sigma(M)`, exact.
    * Complex blocks: power iteration of Packard, Fan and Doyle [PFD]_ (several
      starts), a local maximiser of :math:`\rho(MQ)` over structured unitary ``Q``.
    * One real block: the largest real eigenvalue of ``M`` in modulus, exact.
    * Real blocks only: local minimisation of :math:`\|\delta\|_\infty` on
      :math:`\det(I - M\Delta) = 0`.  Real :math:`\mu` can be discontinuous in
      ``M`` and the search can miss the minimiser: 0 means that none was found,
      not that there is none.
    * Real and complex blocks: search over the real perturbations with the
      complex blocks treated exactly on :math:`\mathcal F_u(M, \Delta_r)`
      (module docstring).

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
    rng : int or numpy Generator
        Seed of the random starting points (the result is reproducible).
    scalings : (Dl, Dr), optional
        Scalings of an upper bound (``MuUpper.Dl``, ``MuUpper.Dr``).  For
        complex structures the power iteration then also starts from the top
        singular vectors of :math:`D_\ell^{1/2}MD_r^{-1/2}`, which reaches the
        upper bound whenever that bound is exact and its largest singular value
        simple (used by :func:`mu_bounds`).

    Returns
    -------
    MuLower
        ``Delta`` is in the structure, satisfies :math:`\det(I - M\Delta) = 0`
        (``residual``, the smallest singular value of :math:`I - M\Delta`, is
        at rounding level) and :math:`\bar\sigma(\Delta) = 1/\text{value}`;
        ``value`` is recomputed from ``Delta``.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, mu_lower
    >>> M = np.array([[0.5, 2.0], [0.0, 0.5]])       # det(I - M Delta) = (1 - d1/2)(1 - d2/2): mu = 0.5
    >>> r = mu_lower(M, BlockStructure([Block.scalar(), Block.scalar()]))
    >>> round(r.value, 6)
    0.5
    """
    structure = _as_structure(structure)
    M = structure.check(M)
    # mu is homogeneous, mu(cM) = |c| mu(M): work on M / ||M|| so that badly
    # scaled matrices (entries near 1e+-150) do not overflow or underflow
    nrm = _norm2(M)
    if nrm == 0:
        return MuLower(0.0, None, "sigma" if len(structure) == 1 and structure.blocks[0].kind == "full"
                       else "power", np.nan)
    if not np.isfinite(nrm):
        raise ModelError("M is too large: its largest singular value overflows")
    if abs(nrm - 1.0) > 1e-12:
        if scalings is not None:
            scalings = tuple(np.asarray(X, dtype=complex) for X in scalings)
        low = mu_lower(M / nrm, structure, rng=rng, scalings=scalings)
        if low.Delta is None or low.value == 0:
            return low
        Delta = low.Delta / nrm
        res = float(np.linalg.svd(np.eye(structure.ncols) - M @ Delta, compute_uv=False)[-1])
        return MuLower(float(low.value * nrm), Delta, low.method, res)
    rng = np.random.default_rng(rng)
    S = structure
    Q0 = None
    if not S.has_real and scalings is not None:
        Dl, Dr = (np.asarray(X, dtype=complex) for X in scalings)
        if Dl.shape != (S.ncols, S.ncols) or Dr.shape != (S.nrows, S.nrows):
            raise ModelError(f"scalings must be (Dl, Dr) of sizes {S.ncols}x{S.ncols} and "
                             f"{S.nrows}x{S.nrows}, got {Dl.shape} and {Dr.shape}")
    try:
        with np.errstate(all="ignore"):
            if not S.has_real:
                if scalings is not None:
                    Q0 = _start_from_scalings(M, S, Dl, Dr)
                v, Delta = _complex_lower(M, S, rng, Q0=Q0)
                method = "sigma" if len(S) == 1 and S.blocks[0].kind == "full" else "power"
            elif all(b.kind == "real" for b in S.blocks):
                v, Delta, method = _real_only_lower(M, S, rng)
            else:
                v, Delta, method = _mixed_lower(M, S, rng)
    except (np.linalg.LinAlgError, ValueError, FloatingPointError):
        # the iterations can overflow on matrices whose entries span hundreds of decades even
        # after normalisation; a search that breaks down proves nothing, and 0 is a valid bound
        return MuLower(0.0, None, "failed", np.nan)
    if Delta is None or v == 0 or not np.all(np.isfinite(Delta)):
        return MuLower(0.0, None, method, np.nan)
    res = float(np.linalg.svd(np.eye(S.ncols) - M @ Delta, compute_uv=False)[-1])
    # tolerance of the singularity test: rounding in forming I - M Delta
    if res > 1e-8 * (1.0 + np.linalg.norm(M, 2) * np.linalg.norm(Delta, 2)):
        return MuLower(0.0, None, method, res)
    return MuLower(float(1.0 / np.linalg.norm(Delta, 2)), Delta, method, res)
