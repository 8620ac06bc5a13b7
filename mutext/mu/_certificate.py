r"""Upper bounds certified by explicit scalings: :func:`dg_bound`, :func:`scaled_sigma`, :class:`MuUpper`.

Every upper bound of the package is recomputed here from the scalings returned
with it (a generalised eigenvalue of the D-G inequality, or a singular value).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ._structure import BlockStructure, _as_structure


def scaled_sigma(M, structure: BlockStructure, d) -> float:
    r""":math:`\bar\sigma(D_\ell M D_r^{-1})` for one positive scaling per block (a valid upper bound).

    ``d`` holds one positive number per block; :math:`D_\ell` and :math:`D_r` repeat
    it over the block's columns and rows (:meth:`BlockStructure.expand_d`).

    Parameters
    ----------
    M : (ncols, nrows) array_like
        The complex matrix.
    structure : BlockStructure
        Its block structure.
    d : (len(structure),) array_like
        One positive scaling per block.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, scaled_sigma
    >>> M = np.array([[0.5, 2.0], [0.0, 0.5]])       # mu = 0.5 for two scalar blocks
    >>> S = BlockStructure([Block.scalar(), Block.scalar()])
    >>> round(scaled_sigma(M, S, [1.0, 1.0]), 4), round(scaled_sigma(M, S, [1.0, 100.0]), 4)
    (2.118, 0.5101)
    """
    structure = _as_structure(structure)
    d = np.asarray(d, dtype=float)
    if d.shape != (len(structure),) or not np.all(d > 0) or not np.all(np.isfinite(d)):
        raise ModelError(f"d must hold {len(structure)} positive finite numbers (one per block), got {d!r}")
    dl, dr = structure.expand_d(d)
    return float(np.linalg.norm(dl[:, None] * np.asarray(M) / dr[None, :], 2))


def _block_power(D, slices, p: float):
    """D**p for a Hermitian positive definite D that is block diagonal on ``slices``
    (computed block by block, so scalings spanning many orders of magnitude across
    blocks lose no accuracy); None if D is not positive definite."""
    out = np.zeros_like(D, dtype=complex)
    for sl in slices:
        X = D[sl, sl]
        ev, V = np.linalg.eigh(0.5 * (X + X.conj().T))
        if ev.min() <= 0:
            return None
        out[sl, sl] = (V * ev ** p) @ V.conj().T
    return out


_EPS = float(np.finfo(float).eps)


def _pow2_scale(A) -> float:
    """A power of two ``c`` with ``c * max|A|`` near 1 when ``max|A|`` is outside 1e-100..1e100,
    else 1: the D-G forms are quadratic in ``A``, so entries near 1e-162 square to 0 (and near
    1e+155 to inf); scaling by a power of two before squaring and back after is exact."""
    a = float(np.abs(A).max()) if A.size else 0.0
    if a == 0.0 or not np.isfinite(a) or 1e-100 <= a <= 1e100:
        return 1.0
    return float(np.ldexp(1.0, min(max(-int(np.frexp(a)[1]), -1000), 1000)))   # 2**1073 would overflow


def _rounding_margin(A, Gt) -> float:
    r"""A bound on the rounding error of the largest eigenvalue of
    :math:`A^HA + j(\tilde GA - A^H\tilde G^H)` as computed in floating point: forming
    the products errs by at most :math:`n\varepsilon|A|^H|A|` and
    :math:`n\varepsilon|\tilde G||A|` entrywise, and a backward-stable eigensolver adds
    :math:`p(n)\varepsilon\|H\|` (Weyl), both below :math:`4n\varepsilon(\|A\|_F^2 +
    2\||\tilde G||A|\|_F)`.  A few :math:`\varepsilon` of the value where the scalings are
    well conditioned; where a solver's scalings are nearly singular and its :math:`G` large,
    terms of 1e12 cancel to an eigenvalue of 1 and the double-precision value can sit below a
    true lower bound on :math:`\mu` (seen: by 1.1e-8 relative).  The product of the
    absolute values, not of the norms: a large :math:`\tilde G` meets only the rows of
    :math:`A` of its real block, which the scalings often make small (:math:`\|\tilde G\|_F
    \|A\|_F` overstated the error 1e12-fold on a real block whose G approached infinity)."""
    n = A.shape[0] + A.shape[1]
    a2 = float(np.vdot(A, A).real)                  # ||A||_F^2
    if Gt is None:
        return 4.0 * n * _EPS * a2
    GA = np.abs(Gt) @ np.abs(A)
    return 4.0 * n * _EPS * (a2 + 2.0 * math.sqrt(float(np.vdot(GA, GA))))


# relative rounding margin (of beta**2) above which the certificate is recomputed in extended
# precision; below it the margin is added (the bound moves by at most 5e-11 of itself)
_MARGIN_RTOL = 1e-10


def _dg_form(M, Dl, G):
    r""":math:`X = M^HD_\ell M + j(GM - M^HG^H)` in double precision (no G term if ``G`` is None),
    formed as :math:`M^H(D_\ell M)`: the order whose rounding :func:`_gevp_cholesky` bounds."""
    X = M.conj().T @ (Dl @ M)
    if G is not None:
        GM = G @ M
        X = X + 1j * (GM - GM.conj().T)
    return X


def _top_direction(M, Dl, Dr, G):
    """The top generalised eigenvector of ``(M^H Dl M + j(GM - M^H G^H), Dr)`` in double precision
    (any vector gives a lower bound through its Rayleigh quotient; this one nearly the best), or
    None where it cannot be computed (scalings beyond the double range among them)."""
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            X = _dg_form(M, Dl, G)
            ev, Q = np.linalg.eigh(0.5 * (Dr + Dr.conj().T))
            if not ev[0] > 0:
                return None
            Ri = (Q / np.sqrt(ev)) @ Q.conj().T
            Y = Ri @ X @ Ri
            v = np.linalg.eigh(0.5 * (Y + Y.conj().T))[1][:, -1]
            w = Ri @ v
    except (np.linalg.LinAlgError, ValueError, FloatingPointError):
        return None
    return w if np.all(np.isfinite(w)) else None


def _gevp_mp(M, Dl, Dr, G, dps: int = 40) -> float:
    r"""The generalised eigenvalue of :func:`_gevp` as a double at or above it, decided in
    ``dps``-digit arithmetic (mpmath) by Cholesky factorisations: the certificate of given
    double-precision scalings, whatever their conditioning.  Used only where the rounding
    margin of the double-precision evaluation matters.

    :math:`\beta` bounds the level exactly when :math:`\beta^2D_r - X \succ 0`
    (:math:`X = M^HD_\ell M + j(GM - M^HG^H)`), which a Cholesky factorisation decides without
    forming :math:`D_r^{-1/2}` (an eigensolver in 40 digits on that congruence loses the level
    where the scalings span more than 40 decades).  First the Rayleigh quotient
    :math:`\theta = w^HXw / w^HD_rw` of the double-precision top eigenvector (a lower bound) and one
    factorisation 1e-13 above it; where that fails, bisection between the two by factorisations
    to 1e-15 (about 50 of them)."""
    import mpmath as mp

    def proves(beta) -> bool:
        Z = mp.mpf(beta) ** 2 * R - X
        try:
            mp.cholesky(0.5 * (Z + Z.H))
            return True
        except (ValueError, ZeroDivisionError):
            return False

    w = _top_direction(M, Dl, Dr, G)
    with mp.workdps(dps):
        Mm, L, R = (mp.matrix(np.asarray(Y, complex).tolist()) for Y in (M, Dl, Dr))
        X = Mm.H * L * Mm
        if G is not None:
            GM = mp.matrix(np.asarray(G, complex).tolist()) * Mm
            X = X + 1j * (GM - GM.H)
        X = 0.5 * (X + X.H)
        R = 0.5 * (R + R.H)
        lo = 0.0
        if w is not None:
            wm = mp.matrix(w.tolist())
            num, den = mp.re((wm.H * X * wm)[0]), mp.re((wm.H * R * wm)[0])
            if den > 0 and num > 0:
                lo = float(mp.sqrt(num / den))
                cand = float(np.nextafter(lo * (1.0 + 1e-13), np.inf))
                if proves(cand):
                    return cand
                lo = lo * (1.0 - 1e-15)     # the quotient rounded to a double: still below the level
        if lo == 0.0 and proves(0.0):
            return 0.0                      # the exact inequality holds at beta = 0
        hi = max(2.0 * lo, 1e-300)
        while not proves(hi):
            lo, hi = hi, hi * 1e3
            if not math.isfinite(hi):
                return np.inf
        for _ in range(400):
            if lo > 0 and hi <= lo * (1.0 + 1e-15):
                break
            mid = math.sqrt(lo * hi) if lo > 0 else hi * 1e-3
            if proves(mid):
                hi = mid
            else:
                lo = mid
        return float(hi)


#: relative steps above the double-precision level at which :func:`_gevp_cholesky` tries to prove
#: the bound (the last as large as the margin :func:`_gevp_certified` adds without a proof)
_CHOLESKY_STEPS = (1e-13, 1e-11, 1e-10)


def _gevp_cholesky(M, Dl, Dr, G, beta: float) -> float | None:
    r"""A bound just above the double-precision level ``beta``, proved by a Cholesky factorisation
    in double precision with all rounding accounted for; None where no step of
    ``_CHOLESKY_STEPS`` can be proved that way (then only extended precision can decide).

    :math:`\sqrt b` bounds the level when :math:`Z = bD_r - X \succ 0`
    (:math:`X = M^HD_\ell M + j(GM - M^HG^H)`).  Definiteness is invariant under the diagonal
    congruence :math:`Y = SZS`, :math:`S = \mathrm{diag}(z_{ii}^{-1/2})`, which gives ``Y`` a unit
    diagonal: the scale-free form of the question, where a graded ``Z`` (entries of 1e9 beside
    entries of 1 when ``G`` approaches infinity on a real block) is as easy to decide as a
    well-scaled one, while a bound through :math:`\|Z\|` is not.  With
    :math:`|\Delta Z| \le E = 4(2n+6)arepsilon(|M|^H|D_\ell||M| + 2|G||M| + b|D_r|)` entrywise
    (forming ``Z`` in complex arithmetic: N. J. Higham, *Accuracy and Stability of Numerical
    Algorithms*, 2002, sec. 3.5), the rounding of the scaling
    (:math:`3arepsilon|Y|`) and, for a floating-point Cholesky factorisation that runs to
    completion on a symmetric ``A`` of order ``m``, :math:`\lambda_{\min}(A) \ge
    -rac{\gamma_{m+1}}{1-\gamma_{m+1}}\operatorname{tr}A` (from Demmel's
    :math:`\hat R^T\hat R = A + \Delta A`, :math:`|\Delta A| \le \gamma_{m+1}|\hat R^T||\hat R|`;
    S. M. Rump, "Verification of positive definiteness", *BIT* 46, 2006), a factorisation of the real form of :math:`Y - cI` (order ``2n``) with
    :math:`c = 2(lpha\operatorname{tr}Y + arepsilon\max_i y_{ii}) + 4arepsilon\|Y\|_F +
    \|SES\|_F`, doubled, proves :math:`Z \succ 0`: the exact inequality, not its rounded form.
    """
    from scipy.linalg.lapack import dpotrf

    eps = np.finfo(float).eps
    n = Dr.shape[0]
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        aM = np.abs(M)
        X = _dg_form(M, Dl, G)
        E0 = aM.T @ (np.abs(Dl) @ aM)
        if G is not None:
            E0 = E0 + 2.0 * (np.abs(G) @ aM)
        aDr = np.abs(Dr)
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(E0))):
            return None
        m = 2 * n
        gam = (m + 1) * eps / (1.0 - (m + 1) * eps)
        alpha = gam / (1.0 - gam)
        kE = 4.0 * (2 * n + 6) * eps
        low = np.tril_indices(n, -1)
        for step in _CHOLESKY_STEPS:
            b = beta * beta * (1.0 + step)
            Z = b * Dr - X
            # Hermitian from one triangle (the error bound E holds entrywise for either)
            Z[(low[1], low[0])] = Z[low].conj()
            dz = Z.diagonal().real.copy()
            Z[np.diag_indices(n)] = dz
            if not dz.min() > 0 or not np.isfinite(b):
                return None
            s = 1.0 / np.sqrt(dz)
            Y = (s[:, None] * Z) * s
            Es = (s[:, None] * (kE * (E0 + b * aDr))) * s
            c = 2.0 * (2.0 * alpha * float(Y.diagonal().real.sum()) + 2.0 * eps
                       + 4.0 * eps * float(np.linalg.norm(Y)) + float(np.linalg.norm(Es))) + 1e-290
            if not c < 0.5:
                continue            # too little room: a larger step, or extended precision
            Yr = np.empty((m, m))
            Yr[:n, :n] = Yr[n:, n:] = Y.real
            Yr[:n, n:] = -Y.imag
            Yr[n:, :n] = Y.imag
            Yr[np.diag_indices(m)] -= c
            _, info = dpotrf(Yr, lower=1, clean=0)
            if info == 0:
                return float(np.nextafter(math.sqrt(b), np.inf))
    return None


def _gevp_fast(M, Dl, Dr, G, S: BlockStructure) -> tuple[float, float]:
    r"""The largest eigenvalue of :math:`A^HA + j(\tilde G A - A^H\tilde G^H)` in double
    precision, with :math:`A = D_\ell^{1/2}MD_r^{-1/2}` and :math:`\tilde G =
    D_r^{-1/2}GD_\ell^{-1/2}` (a congruence by :math:`D_r^{-1/2}`, square roots taken block by
    block): ``(beta, rel)`` with ``beta`` its square root (what an optimiser compares
    levels by) and ``rel`` the bound of :func:`_rounding_margin` on the error of
    ``beta ** 2`` relative to it; ``(inf, 0)`` when a scaling is not positive definite,
    ``(nan, inf)`` when the form overflows double precision."""
    Lh = _block_power(Dl, S.col_slices, 0.5)
    Ri = _block_power(Dr, S.row_slices, -0.5)
    if Lh is None or Ri is None:
        return np.inf, 0.0
    with np.errstate(over="ignore", invalid="ignore"):
        A = Lh @ M @ Ri
        c = _pow2_scale(A)           # the value is homogeneous in (M, G): computed for (c M, c G)
        if c != 1.0:
            A = c * A
        H = A.conj().T @ A
        Gt = None
        if G is not None:
            Lhi = _block_power(Dl, S.col_slices, -0.5)
            Gt = c * (Ri @ G @ Lhi)
            GA = Gt @ A
            H = H + 1j * (GA - GA.conj().T)
        H = 0.5 * (H + H.conj().T)
        if not np.all(np.isfinite(H)):
            # scalings spanning more than the double range (a D of 1e-300 with a G of 1e10):
            # only the extended-precision evaluation can say
            return np.nan, np.inf
        lam = max(float(np.linalg.eigvalsh(H).max()), 0.0)
        return float(np.sqrt(lam)) / c, _relative_margin(lam, _rounding_margin(A, Gt))


def _relative_margin(lam: float, margin: float) -> float:
    """``margin / lam`` (0 where both vanish, inf where only the eigenvalue does)."""
    if margin == 0.0:
        return 0.0
    return margin / lam if lam > 0 else np.inf


def _gevp_certified(M, Dl, Dr, G, beta: float, rel: float) -> float:
    """The bound from a double-precision evaluation ``(beta, rel)`` of :func:`_gevp_fast`:
    ``beta`` with the margin added where it is negligible, the extended-precision value
    where it is not."""
    if beta == np.inf:
        return beta                 # a scaling not positive definite
    if rel <= _MARGIN_RTOL:
        return float(beta * np.sqrt(1.0 + rel))
    if math.isfinite(beta) and beta > 0:
        proved = _gevp_cholesky(M, Dl, Dr, G, beta)
        if proved is not None:
            return proved
    return _gevp_mp(M, Dl, Dr, G)


def _gevp(M, Dl, Dr, G, S: BlockStructure) -> float:
    r"""Smallest :math:`\beta\ge 0` with :math:`M^HD_\ell M + j(GM - M^HG^H) \preceq \beta^2 D_r`,
    a bound for the exact inequality: evaluated in double precision
    (:func:`_gevp_fast`) with its rounding margin, and in extended precision where that
    margin would move it by more than 5e-11 of itself (:func:`_gevp_mp`); ``inf`` when a
    scaling is not positive definite."""
    beta, rel = _gevp_fast(M, Dl, Dr, G, S)
    return _gevp_certified(M, Dl, Dr, G, beta, rel)


def dg_bound(M, structure: BlockStructure, Dl, Dr, G=None, *, tol: float = 1e-9) -> float:
    r"""The upper bound on :math:`\mu` certified by given scalings, recomputed from scratch.

    For :math:`D_\ell, D_r \succ 0` commuting with the structure and a Hermitian
    :math:`G` that is nonzero only on real blocks ([FTD]_; [ZDG]_ ch. 11 for
    square structures), every :math:`\beta` with

    .. math::
        M^H D_\ell M + j\,(G M - M^H G^H) \preceq \beta^2 D_r

    satisfies :math:`\mu_{\boldsymbol\Delta}(M)\le\beta`.  This returns the smallest
    such :math:`\beta` (a generalised eigenvalue).  Without ``G`` it equals
    :math:`\bar\sigma(D_\ell^{1/2} M D_r^{-1/2})`.

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
    Dl : (ncols, ncols) array_like
        Acts on ``z``: ``d_k I`` on a full block, a Hermitian positive definite
        ``n x n`` matrix on an ``n``-fold repeated scalar.
    Dr : (nrows, nrows) array_like
        Acts on ``w``: the same blocks as ``Dl`` (``d_k I`` of the other size for
        a non-square full block).
    G : (nrows, ncols) array_like, optional
        Hermitian blocks on the real blocks, zero elsewhere.
    tol : float
        Relative tolerance of the structure checks.

    Returns
    -------
    float
        The smallest such :math:`\beta` for the exact inequality: rounding is accounted for
        (a bound on the error of the double-precision evaluation is added, and where it
        would move the value by more than 5e-11 of itself the level is computed in 40-digit
        arithmetic), so that nearly singular scalings with a large :math:`G` cannot
        return a value below :math:`\mu`.

    Raises
    ------
    ModelError
        Wrong sizes, scalings that do not commute with the structure, ``G``
        nonzero off the real blocks or not Hermitian, ``D`` not positive definite.
    """
    S = structure
    M = S.check(M)
    Dl = np.asarray(Dl, dtype=complex)
    Dr = np.asarray(Dr, dtype=complex)
    if Dl.shape != (S.ncols, S.ncols) or Dr.shape != (S.nrows, S.nrows):
        raise ModelError(f"Dl must be {S.ncols}x{S.ncols} and Dr {S.nrows}x{S.nrows}, "
                         f"got {Dl.shape} and {Dr.shape}")
    if not (np.all(np.isfinite(Dl)) and np.all(np.isfinite(Dr))):
        raise ModelError("the scalings contain non-finite entries")
    # entries outside the block pattern, relative to the diagonal they couple
    for nm, X, slices in (("Dl", Dl, S.col_slices), ("Dr", Dr, S.row_slices)):
        mask = np.ones(X.shape, bool)
        for sl in slices:
            mask[sl, sl] = False
        dg = np.sqrt(np.abs(np.diag(X)))
        if np.any(np.abs(X)[mask] > tol * np.outer(dg, dg)[mask]):
            raise ModelError(f"{nm} must be block diagonal with the structure's blocks")
    # the certificate is computed for the scalings projected exactly onto the
    # structure, so it is valid whatever rounding the checks let through
    Dlp = np.zeros_like(Dl)
    Drp = np.zeros_like(Dr)
    for k, (b, rs, cs) in enumerate(zip(S.blocks, S.row_slices, S.col_slices)):
        L, R = Dl[cs, cs], Dr[rs, rs]
        scale = max(np.abs(L).max(), np.abs(R).max())
        if b.kind == "full":
            d = float(np.real(np.trace(R))) / b.rows
            bad = (np.abs(L - d * np.eye(b.cols)).max() > tol * scale
                   or np.abs(R - d * np.eye(b.rows)).max() > tol * scale)
            Lp, Rp = d * np.eye(b.cols), d * np.eye(b.rows)
        else:
            bad = np.abs(L - R).max() > tol * scale
            Lp = Rp = 0.5 * (L + R)
        if bad:
            raise ModelError(f"block {k} ({b.kind} {b.rows}x{b.cols}): the scalings do not commute with "
                             "the structure (a full block needs d*I on both sides, a repeated scalar "
                             "the same matrix in Dl and Dr)")
        if np.abs(Rp - Rp.conj().T).max() > tol * scale:
            raise ModelError(f"block {k}: the scalings are not Hermitian")
        Dlp[cs, cs], Drp[rs, rs] = Lp, Rp
    if _block_power(Drp, S.row_slices, 0.5) is None:
        raise ModelError("the scalings are not positive definite")
    Gp = None
    if G is not None:
        G = np.asarray(G, dtype=complex)
        if G.shape != (S.nrows, S.ncols):
            raise ModelError(f"G must be {S.nrows}x{S.ncols}, got {G.shape}")
        if not np.all(np.isfinite(G)):
            raise ModelError("G contains non-finite entries")
        gscale = max(np.abs(G).max(), 1e-300)
        Gp = np.zeros_like(G)
        for b, rs, cs in zip(S.blocks, S.row_slices, S.col_slices):
            if b.kind == "real":
                Gk = G[rs, cs]
                if np.abs(Gk - Gk.conj().T).max() > tol * max(np.abs(Gk).max(), 1e-300):
                    raise ModelError(f"G is not Hermitian on real block {b.name or ''}".rstrip())
                Gp[rs, cs] = 0.5 * (Gk + Gk.conj().T)
        if np.abs(G - Gp).max() > tol * gscale:
            raise ModelError("G must be zero outside the real blocks")
    return _gevp(M, Dlp, Drp, Gp, S)


@dataclass
class MuUpper:
    r"""An upper bound on :math:`\mu` and the scalings that certify it.

    Attributes
    ----------
    value : float
        The bound, recomputed from the scalings below (:func:`dg_bound` with
        ``Dl, Dr, G`` returns it to rounding).
    method : str
        Which bound was used: ``"lmi-d"`` (D scalings, LMI), ``"lmi-dg"`` (D-G
        scalings, LMI), ``"osborne"`` (diagonal D by Osborne balancing and the
        ellipsoid method), ``"fast-d"`` / ``"fast-dg"`` (D or D-G scalings by
        the quasi-Newton descent of ``method="fast"``) or ``"sigma"`` (one full block, or ``M = 0``: the
        largest singular value, which is then exact).
    d : ndarray or None
        One positive scaling per block, normalised so that the last block has
        d = 1.  For diagonal methods :math:`\text{value} = \bar\sigma(D_\ell M D_r^{-1})`
        with these ``d`` (:func:`scaled_sigma`); for the LMI and fast methods it summarises
        ``Dr`` (square root of the mean of each block's diagonal).
    Dl, Dr, G : ndarray or None
        Scalings in the LMI form :math:`M^HD_\ell M + j(GM - M^HG^H) \preceq
        \beta^2 D_r` (``Dl`` acts on ``z``, ``Dr`` on ``w``; ``G`` is None
        without D-G scaling).  For the diagonal methods ``Dl = diag(d)^2``.
    iterations : int
        Bisection steps (LMI), ellipsoid steps (Osborne) or function evaluations (fast).
    lower_level : float
        LMI methods, and fast bounds checked by the LMI in :func:`mu_sweep`:
        the lower end of the final bisection bracket, a level at
        which no certificate was found (or a known lower bound on mu).  Not a
        certified bound on mu; ``value - lower_level`` indicates how close
        ``value`` is to the optimal scaling.  ``nan`` otherwise.
    """
    value: float
    method: str
    d: np.ndarray | None = None
    Dl: np.ndarray | None = None
    Dr: np.ndarray | None = None
    G: np.ndarray | None = None
    iterations: int = 0
    lower_level: float = np.nan

    def __float__(self):
        return float(self.value)


def _d_from_matrices(S, Dr):
    """One scalar per block from a D_r matrix (root mean of its diagonal), normalised by the last."""
    d = np.array([np.real(np.trace(Dr[rs, rs])) / (rs.stop - rs.start) for rs in S.row_slices])
    d = np.sqrt(np.maximum(d, 1e-300))
    return d / d[-1]


def _diag_result(M, S, d, method, iterations=0) -> MuUpper:
    """MuUpper for diagonal scalings d, with the value recomputed from d."""
    d = np.asarray(d, float) / float(d[-1])
    dl, dr = S.expand_d(d)
    val = float(np.linalg.norm(dl[:, None] * M / dr[None, :], 2))
    return MuUpper(val, method, d=d, Dl=np.diag(dl ** 2).astype(complex),
                   Dr=np.diag(dr ** 2).astype(complex), iterations=iterations)
