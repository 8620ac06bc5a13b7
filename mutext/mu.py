r"""The structured singular value :math:`\mu`: block structures, bounds and frequency sweeps.

For a complex matrix :math:`M` and a set :math:`\boldsymbol\Delta` of
block-diagonal perturbations,

.. math::
    \mu_{\boldsymbol\Delta}(M) = \Big(\min\{\bar\sigma(\Delta) : \Delta\in\boldsymbol\Delta,\
    \det(I - M\Delta) = 0\}\Big)^{-1},

and :math:`\mu = 0` if no :math:`\Delta` makes :math:`I - M\Delta` singular
(Packard and Doyle [PD]_; [ZDG]_ ch. 11; [SP]_ ch. 8).  ``M`` maps
the inputs ``w`` of the uncertainty channels to their outputs ``z``;
``Delta`` maps ``z`` back to ``w``.  A block of :math:`\Delta` is

* ``"full"``: a complex ``rows x cols`` matrix (unmodelled dynamics, the
  performance block of a robust-performance test);
* ``"scalar"``: a repeated complex scalar :math:`\delta I_n`;
* ``"real"``: a repeated real scalar :math:`\delta I_n`, :math:`\delta\in\mathbb R`
  (an uncertain physical parameter).

Bounds computed here
--------------------
*Upper bound, LMI form* (:func:`mu_upper`, ``method="lmi"``).  For every
positive definite :math:`D` commuting with the structure,
:math:`\mu(M)\le\bar\sigma(D_\ell^{1/2} M D_r^{-1/2})` ([PD]_).  The best
such bound is the smallest :math:`\beta` for which the linear matrix inequality

.. math::
    M^H D_\ell M + j\,(G M - M^H G^H) - \beta^2 D_r \preceq 0

has a solution :math:`D \succ 0` (block structure of :math:`\boldsymbol\Delta`) and,
with ``real="dg"``, a Hermitian :math:`G` that is nonzero only on real blocks
(Fan, Tits and Doyle [FTD]_; [ZDG]_ ch. 11).  For fixed :math:`\beta` this is
a convex feasibility problem (an SDP solved by Clarabel through cvxpy); the
smallest :math:`\beta` is found by bisection, accelerated by evaluating the
exact generalised eigenvalue of the :math:`(D, G)` found at each level.  The
LMI is posed for :math:`M` balanced by the best diagonal scaling (below), so
that its own scalings stay well conditioned when the optimal :math:`D` spans
many decades.  Every value returned is recomputed from the scalings returned
with it (:func:`dg_bound` does the same from scratch), so it is a certified
bound and not a solver tolerance.

*Upper bound, independent* (``method="osborne"``).  Osborne balancing of the
matrix of block norms gives a starting :math:`D`; the function
:math:`x\mapsto\log\bar\sigma(e^{X}Me^{-X})`, :math:`X = \operatorname{diag}(x)`,
is convex (Sezginer and Overton [SO]_), and is minimised by the ellipsoid
method with the exact subgradient :math:`\|u_k\|^2 - \|v_k\|^2` (``u``, ``v`` the
top singular vectors).  Only diagonal scalings (one scalar per block) are
used, so the two bounds agree for complex full and ``1 x 1`` blocks and this
one is conservative for repeated scalars (and ignores that real blocks are real).

*Upper bound, fast* (``method="fast"``).  The same D-G bound without an SDP.
With :math:`D = LL^H` and :math:`G = \beta_0 L\hat GL^H` the LMI is congruent to
:math:`\lambda_{\max}\big(A^HA + j\beta_0(\hat GA - A^H\hat G)\big) \le \beta^2`,
:math:`A = L_\ell^HML_r^{-H}`, a form in which :math:`\hat G` is
dimensionless (Young, Newlin and Doyle [YND]_ scale G by the level in the same
way).  Its logarithm is minimised over the factors of :math:`D` (log
diagonal) and :math:`\hat G` by BFGS with the weak Wolfe line search that
suits eigenvalue functions (Lewis and Overton [LO]_), with the exact gradient
from the top eigenvector.  Along a frequency grid each descent starts from the
previous frequency's scalings and Hessian approximation, so that it takes a
handful of steps; :func:`mu_sweep` then polishes the values near its peak and
checks the largest by the LMI.

*Lower bound* (:func:`mu_lower`).  For complex blocks, the power iteration of
Packard, Fan and Doyle [PFD]_ (also [PD]_) alternates between the dominant
eigenvectors of :math:`MQ` and the structured unitary :math:`Q` that aligns them;
:math:`\rho(MQ)` is a lower bound and :math:`\Delta = Q e^{-j\arg\lambda}/|\lambda|`
makes :math:`I - M\Delta` singular with :math:`\bar\sigma(\Delta) = 1/\rho`.  It
is a local method; :func:`mu_bounds` restarts it from the singular vectors of
the scaled matrix of the upper bound, which closes the gap whenever the upper
bound is exact (:math:`2S + F \le 3` [PD]_) and its largest singular
value simple.  With one real block :math:`\delta I`, :math:`\mu` is the largest
real eigenvalue of :math:`M` in modulus.  With several real blocks only,
:math:`\min\|\delta\|_\infty` subject to :math:`\lambda(M\Delta(\delta)) = 1` is
solved locally (SLSQP with eigenvalue derivatives) from several starting
directions.  With real and complex blocks, a search over the real
perturbations ``Delta_r`` is made and the complex blocks are handled on the
partially closed loop:

.. math::
    \mu \ \ge\ \min\Big(\frac{1}{\bar\sigma(\Delta_r)},\
    \mu_{\rm complex}\big(\mathcal F_u(M, \Delta_r)\big)\Big),

because :math:`\det(I - M\Delta) = \det(I - M_{11}\Delta_r)\,
\det(I - \mathcal F_u(M,\Delta_r)\Delta_c)`.  Every lower bound comes with the
perturbation that proves it, and its value is recomputed from that
perturbation.  Real :math:`\mu` can be discontinuous in :math:`M` and the
searches with real blocks are local: their lower bounds can be far below
:math:`\mu`, and 0 means "no destabilising perturbation found".

*Frequency sweeps* (:func:`mu_sweep`).  Bounds at each frequency of a grid;
the frequencies around lightly damped poles are added and the largest local
maxima are refined by golden-section search, so that a resonance narrower
than the grid spacing is not missed.

References
----------
.. [PD] A. Packard and J. C. Doyle, "The complex structured singular value",
   *Automatica* 29 (1993) 71-109.
.. [PFD] A. Packard, M. K. H. Fan and J. C. Doyle, "A power method for the
   structured singular value", *Proc. 27th IEEE CDC* (1988) 2132-2137.
.. [FTD] M. K. H. Fan, A. L. Tits and J. C. Doyle, "Robustness in the presence
   of mixed parametric uncertainty and unmodeled dynamics", *IEEE TAC* 36
   (1991) 25-38.
.. [SO] R. Sezginer and M. Overton, "The largest singular value of
   e^X A e^-X is convex on convex sets of commuting matrices", *IEEE TAC* 35
   (1990) 229-230.
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 11.
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005, ch. 8.
.. [YND] P. M. Young, M. P. Newlin and J. C. Doyle, "Computing bounds for the
   mixed mu problem", *Int. J. Robust Nonlinear Control* 5 (1995) 573-590.
.. [LO] A. S. Lewis and M. L. Overton, "Nonsmooth optimization via quasi-Newton
   methods", *Math. Programming* 141 (2013) 135-163.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .errors import IllPosedError, ModelError, SolverError

__all__ = ["Block", "BlockStructure", "MuUpper", "MuLower", "MuBounds", "MuSweep",
           "mu_upper", "mu_lower", "mu_bounds", "mu_sweep", "default_grid", "scaled_sigma",
           "dg_bound"]

_KINDS = ("full", "scalar", "real")


# ----------------------------------------------------------------------------
# block structures
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Block:
    """One block of the perturbation :math:`\\Delta`.

    Parameters
    ----------
    kind : {"full", "scalar", "real"}
        Full complex matrix, repeated complex scalar or repeated real scalar.
    rows, cols : int
        Size of the block of ``Delta`` (``rows`` inputs of ``M`` driven by the
        block, ``cols`` outputs of ``M`` feeding it).  Scalar blocks are square.
    name : str
    """
    kind: str
    rows: int
    cols: int
    name: str = ""

    def __post_init__(self):
        if self.kind not in _KINDS:
            raise ModelError(f"block kind must be one of {_KINDS}, got {self.kind!r}")
        for what, v in (("rows", self.rows), ("cols", self.cols)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ModelError(f"block {self.name or self.kind}: {what} must be a positive integer, got {v!r}")
        if self.kind != "full" and self.rows != self.cols:
            raise ModelError(f"a repeated scalar block ({self.kind}) must be square, got {self.rows}x{self.cols}")

    @classmethod
    def full(cls, rows: int, cols: int | None = None, name: str = "") -> "Block":
        """A full complex ``rows x cols`` block (``cols`` defaults to ``rows``)."""
        return cls("full", rows, rows if cols is None else cols, name)

    @classmethod
    def scalar(cls, n: int = 1, name: str = "") -> "Block":
        """A repeated complex scalar :math:`\\delta I_n`."""
        return cls("scalar", n, n, name)

    @classmethod
    def real(cls, n: int = 1, name: str = "") -> "Block":
        """A repeated real scalar :math:`\\delta I_n`."""
        return cls("real", n, n, name)

    @property
    def diagonal_scaling(self) -> bool:
        """True if the optimal D for this block is a scalar times identity."""
        return self.kind == "full" or self.rows == 1


class BlockStructure:
    r"""Block-diagonal structure :math:`\boldsymbol\Delta = \{\operatorname{diag}(\Delta_1,\dots,\Delta_m)\}`.

    ``M`` must have ``ncols`` rows and ``nrows`` columns (it maps ``w`` to
    ``z``; ``Delta`` maps ``z`` back to ``w``).

    Examples
    --------
    >>> S = BlockStructure([Block.real(1, "k1"), Block.full(2, name="performance")])
    >>> S.nrows, S.ncols
    (3, 3)
    """

    def __init__(self, blocks: Sequence[Block]):
        blocks = tuple(blocks)
        if not blocks:
            raise ModelError("a block structure needs at least one block")
        for b in blocks:
            if not isinstance(b, Block):
                raise ModelError(f"expected Block instances, got {type(b).__name__}")
        self.blocks = blocks
        self.row_slices, self.col_slices = [], []
        r = c = 0
        for b in blocks:
            self.row_slices.append(slice(r, r + b.rows))
            self.col_slices.append(slice(c, c + b.cols))
            r += b.rows
            c += b.cols
        self.nrows, self.ncols = r, c
        #: block index of each row / column of Delta (w and z entries)
        self.row_block = np.concatenate([np.full(b.rows, k) for k, b in enumerate(blocks)])
        self.col_block = np.concatenate([np.full(b.cols, k) for k, b in enumerate(blocks)])

    # -- description -------------------------------------------------------
    @classmethod
    def from_spec(cls, spec) -> "BlockStructure":
        """From a list like MATLAB's ``blk``: ``[r, c]`` full block, ``[-n, 0]``
        repeated real scalar, ``[n, 0]`` repeated complex scalar."""
        blocks = []
        for item in spec:
            r, c = (int(v) for v in item)
            if c == 0:
                blocks.append(Block.real(-r) if r < 0 else Block.scalar(r))
            else:
                blocks.append(Block.full(r, c))
        return cls(blocks)

    def __len__(self):
        return len(self.blocks)

    def __iter__(self):
        return iter(self.blocks)

    def __eq__(self, other):
        return isinstance(other, BlockStructure) and self.blocks == other.blocks

    def __repr__(self):
        parts = []
        for b in self.blocks:
            nm = f" {b.name}" if b.name else ""
            if b.kind == "full":
                parts.append(f"full {b.rows}x{b.cols}{nm}")
            else:
                parts.append(f"{b.kind} x{b.rows}{nm}")
        return "BlockStructure[" + ", ".join(parts) + "]"

    @property
    def has_real(self) -> bool:
        return any(b.kind == "real" for b in self.blocks)

    @property
    def diagonal_scalings(self) -> bool:
        """True when optimal D-scalings are one scalar per block."""
        return all(b.diagonal_scaling for b in self.blocks)

    def complexified(self) -> "BlockStructure":
        """The same structure with real blocks replaced by complex scalars."""
        return BlockStructure([Block("scalar", b.rows, b.cols, b.name) if b.kind == "real" else b
                               for b in self.blocks])

    def check(self, M) -> np.ndarray:
        """Return ``M`` as a complex array after checking its size against the structure."""
        M = np.asarray(M)
        if M.ndim != 2:
            raise ModelError(f"M must be a matrix, got an array with {M.ndim} dimensions")
        if M.shape != (self.ncols, self.nrows):
            raise ModelError(f"M is {M.shape[0]}x{M.shape[1]} but the block structure {self!r} "
                             f"needs {self.ncols}x{self.nrows} (rows = total block columns, "
                             f"columns = total block rows)")
        M = M.astype(complex)
        if not np.all(np.isfinite(M)):
            raise ModelError("M contains non-finite entries")
        # subnormal parts (below 2.2e-308) next to normal entries: zero them.  mu moves by about
        # 1e-308 relative, and the scalings would otherwise meet numbers that some loaded
        # libraries make the CPU read as zero (0/0 inside the SVD)
        tiny = np.finfo(float).tiny
        if np.abs(M).max(initial=0.0) >= tiny:
            re, im = M.real.copy(), M.imag.copy()
            re[np.abs(re) < tiny] = 0.0
            im[np.abs(im) < tiny] = 0.0
            M = re + 1j * im
        return M

    # -- perturbations -----------------------------------------------------
    def assemble(self, parts: Sequence) -> np.ndarray:
        """Block-diagonal ``Delta`` from one entry per block (a scalar for
        scalar/real blocks, a matrix for full blocks)."""
        if len(parts) != len(self.blocks):
            raise ModelError(f"expected {len(self.blocks)} blocks, got {len(parts)}")
        D = np.zeros((self.nrows, self.ncols), dtype=complex)
        for b, rs, cs, p in zip(self.blocks, self.row_slices, self.col_slices, parts):
            if b.kind == "full":
                p = np.asarray(p, dtype=complex).reshape(b.rows, b.cols)
                D[rs, cs] = p
            else:
                p = complex(np.asarray(p).item())
                if b.kind == "real" and abs(p.imag) > 1e-12 * max(1.0, abs(p)):
                    raise ModelError(f"block {b.name or 'real'} is real; got {p}")
                D[rs, cs] = (p.real if b.kind == "real" else p) * np.eye(b.rows)
        return D

    def random(self, rng=None, norm: float = 1.0) -> np.ndarray:
        """A random member with every block of norm at most ``norm`` (at least one equal)."""
        rng = np.random.default_rng(rng)
        parts = []
        for b in self.blocks:
            if b.kind == "real":
                parts.append(rng.uniform(-1, 1))
            elif b.kind == "scalar":
                parts.append(rng.uniform(0, 1) * np.exp(2j * np.pi * rng.uniform()))
            else:
                X = rng.standard_normal((b.rows, b.cols)) + 1j * rng.standard_normal((b.rows, b.cols))
                parts.append(X / np.linalg.norm(X, 2) * rng.uniform(0, 1))
        D = self.assemble(parts)
        return D * (norm / np.linalg.norm(D, 2))

    def block_norms(self, Delta) -> np.ndarray:
        return np.array([np.linalg.norm(np.asarray(Delta)[rs, cs], 2)
                         for rs, cs in zip(self.row_slices, self.col_slices)])

    def contains(self, Delta, tol: float = 1e-10) -> bool:
        """True if ``Delta`` has this structure (zero off-diagonal blocks, real/repeated blocks)."""
        Delta = np.asarray(Delta)
        if Delta.shape != (self.nrows, self.ncols):
            return False
        scale = max(1.0, np.abs(Delta).max(initial=0.0))
        mask = np.zeros(Delta.shape, bool)
        for b, rs, cs in zip(self.blocks, self.row_slices, self.col_slices):
            mask[rs, cs] = True
            X = Delta[rs, cs]
            if b.kind != "full":
                d = X[0, 0]
                if np.abs(X - d * np.eye(b.rows)).max() > tol * scale:
                    return False
                if b.kind == "real" and abs(d.imag) > tol * scale:
                    return False
        return bool(np.abs(Delta[~mask]).max(initial=0.0) <= tol * scale)

    # -- scalings ------------------------------------------------------------
    def expand_d(self, d) -> tuple[np.ndarray, np.ndarray]:
        """Diagonal scalings ``(dl, dr)`` (length ``ncols`` and ``nrows``) from one
        positive number per block: ``D_l = diag(dl)`` acts on ``z`` and
        ``D_r = diag(dr)`` on ``w``."""
        d = np.asarray(d, dtype=float)
        dl = np.concatenate([np.full(b.cols, v) for b, v in zip(self.blocks, d)])
        dr = np.concatenate([np.full(b.rows, v) for b, v in zip(self.blocks, d)])
        return dl, dr


def _as_structure(structure, what: str = "structure") -> "BlockStructure":
    """``structure`` as a :class:`BlockStructure` (a list of :class:`Block` or a
    MATLAB-like ``blk`` spec is converted), or a :class:`ModelError` naming it."""
    if isinstance(structure, BlockStructure):
        return structure
    if structure is None or isinstance(structure, (str, bytes, int, float, complex, np.ndarray)) \
            and not (isinstance(structure, np.ndarray) and structure.ndim == 2):
        raise ModelError(f"{what} must be a BlockStructure (e.g. BlockStructure([Block.scalar(), "
                         f"Block.full(2)])), got {structure!r}")
    try:
        items = list(structure)
    except TypeError:
        raise ModelError(f"{what} must be a BlockStructure, got {type(structure).__name__}") from None
    if items and all(isinstance(b, Block) for b in items):
        return BlockStructure(items)
    try:
        return BlockStructure.from_spec(items)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ModelError):
            raise
        raise ModelError(f"{what}: {structure!r} is neither a BlockStructure nor a list of Blocks nor a "
                         f"blk spec like [[1, 1], [-1, 0]] ({exc})") from None


def _norm2(M) -> float:
    """Largest singular value, computed on a scaled copy so that entries near the
    overflow or underflow limits do not break the SVD (inf if it overflows)."""
    M = np.asarray(M)
    amax = float(np.abs(M).max(initial=0.0))
    if amax == 0 or not np.isfinite(amax):
        return amax
    if amax < np.finfo(float).tiny:
        # subnormal numbers: some loaded libraries set the CPU to read them as zero, so no
        # arithmetic on them can be trusted
        raise ModelError(f"M's entries are all subnormal (largest {amax:.3g} < {np.finfo(float).tiny:.3g}): "
                         "scale M up (mu(cM) = |c| mu(M))")
    with np.errstate(over="ignore"):
        return float(np.linalg.norm(M / amax, 2) * amax)


def scaled_sigma(M, structure: BlockStructure, d) -> float:
    r""":math:`\bar\sigma(D_\ell M D_r^{-1})` for one positive scaling per block (a valid upper bound).

    ``d`` holds one positive number per block; :math:`D_\ell` and :math:`D_r` repeat
    it over the block's columns and rows (:meth:`BlockStructure.expand_d`).
    """
    structure = _as_structure(structure)
    d = np.asarray(d, dtype=float)
    if d.shape != (len(structure),) or not np.all(d > 0) or not np.all(np.isfinite(d)):
        raise ModelError(f"d must hold {len(structure)} positive finite numbers (one per block), got {d!r}")
    dl, dr = structure.expand_d(d)
    return float(np.linalg.norm(dl[:, None] * np.asarray(M) / dr[None, :], 2))


# ----------------------------------------------------------------------------
# certificates of the upper bound
# ----------------------------------------------------------------------------

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


def _gevp(M, Dl, Dr, G, S: BlockStructure) -> float:
    r"""Smallest :math:`\beta\ge 0` with :math:`M^HD_\ell M + j(GM - M^HG^H) \preceq \beta^2 D_r`.

    Evaluated as the largest eigenvalue of
    :math:`A^HA + j(\tilde G A - A^H\tilde G^H)` with :math:`A = D_\ell^{1/2}MD_r^{-1/2}`
    and :math:`\tilde G = D_r^{-1/2}GD_\ell^{-1/2}` (a congruence by
    :math:`D_r^{-1/2}`), the square roots taken block by block; ``inf`` when a
    scaling is not positive definite.
    """
    Lh = _block_power(Dl, S.col_slices, 0.5)
    Ri = _block_power(Dr, S.row_slices, -0.5)
    if Lh is None or Ri is None:
        return np.inf
    A = Lh @ M @ Ri
    H = A.conj().T @ A
    if G is not None:
        Lhi = _block_power(Dl, S.col_slices, -0.5)
        GA = (Ri @ G @ Lhi) @ A
        H = H + 1j * (GA - GA.conj().T)
    H = 0.5 * (H + H.conj().T)
    lam = np.linalg.eigvalsh(H).max()
    return float(np.sqrt(max(lam, 0.0)))


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


# ----------------------------------------------------------------------------
# upper bound: Osborne + ellipsoid (independent)
# ----------------------------------------------------------------------------

def _osborne(M, S: BlockStructure, iterations: int = 30) -> np.ndarray:
    """Log-scalings (one per block) that balance the matrix of block norms (Osborne).

    Only a starting point for the ellipsoid method.  Zero block norms are
    replaced by 1e-14 of the largest one, so that a reducible pattern (a
    triangular M, whose infimum over D is not attained) still gives finite,
    strongly graded scalings; they are kept within exp(+-30).
    """
    m = len(S)
    if m == 1:
        return np.zeros(1)
    B = np.array([[np.linalg.norm(M[S.col_slices[i], S.row_slices[j]], "fro") for j in range(m)]
                  for i in range(m)])
    np.fill_diagonal(B, 0.0)
    if B.max() == 0:
        return np.zeros(m)
    B = B / B.max()
    B = np.maximum(B, 1e-14)
    np.fill_diagonal(B, 0.0)
    x = np.zeros(m)
    for _ in range(iterations):
        for i in range(m):
            e = np.exp(x)
            r = np.sqrt(np.sum((B[i, :] / e) ** 2))      # row i of D B D^-1, without d_i
            c = np.sqrt(np.sum((B[:, i] * e) ** 2))      # column i, without 1/d_i
            x[i] = np.clip(0.5 * (np.log(c) - np.log(r)), -30.0, 30.0)
    return x - x[-1]


def _sigma_and_grad(M, S, x):
    r""":math:`\bar\sigma(e^X M e^{-X})` and the gradient of its logarithm, :math:`|u_k|^2 - |v_k|^2`."""
    # in the log domain, scaled by the largest entry: exp(x) overflowing (and 0 * inf)
    # made the SVD fail for badly scaled M
    absM = np.abs(M)
    nz = absM > 0
    if not nz.any():
        m = len(x)
        return 0.0, np.zeros(m)
    with np.errstate(divide="ignore"):
        logA = np.where(nz, x[S.col_block][:, None] - x[S.row_block][None, :] + np.log(np.where(nz, absM, 1.0)),
                        -np.inf)
    L = float(logA.max())
    A = np.where(nz, np.exp(logA - L) * (M / np.where(nz, absM, 1.0)), 0.0)
    U, s, Vh = np.linalg.svd(A)
    with np.errstate(over="ignore", invalid="ignore"):
        s0 = 0.0 if s[0] == 0 else float(s[0] * np.exp(L))
    m = len(x)
    g = (np.bincount(S.col_block, np.abs(U[:, 0]) ** 2, minlength=m)
         - np.bincount(S.row_block, np.abs(Vh[0]) ** 2, minlength=m))
    return s0, g


def _ellipsoid(M, S: BlockStructure, x0, tol: float, max_iter: int, radius: float):
    """Minimise log sigma_max over the free log-scalings x (last block fixed to 0) in the
    ball of the given radius around x0.  Returns (best f, best x, iterations)."""
    n = len(S) - 1
    x = x0[:-1].copy()
    s0, _ = _sigma_and_grad(M, S, x0)
    if s0 == 0.0:
        return -np.inf, x, 0
    best_f, best_x = np.log(s0), x.copy()
    if n == 1:
        # one free variable: bisection on the sign of the subgradient
        lo, hi = x[0] - radius, x[0] + radius
        it = 0
        while hi - lo > tol and it < 200:
            it += 1
            mid = 0.5 * (lo + hi)
            s, g = _sigma_and_grad(M, S, np.array([mid, 0.0]))
            if s > 0 and np.log(s) < best_f:
                best_f, best_x = np.log(s), np.array([mid])
            if g[0] > 0:
                hi = mid
            elif g[0] < 0:
                lo = mid
            else:
                break
        return best_f, best_x, it
    # central-cut ellipsoid method; f - sqrt(g'Pg) is a lower bound on the minimum
    # over the current ellipsoid, which gives the stopping test
    P = radius ** 2 * np.eye(n)
    lower = -np.inf
    it = 0
    for it in range(1, max_iter + 1):
        s, g = _sigma_and_grad(M, S, np.append(x, 0.0))
        if s <= 0:
            return -np.inf, x, it
        f = np.log(s)
        if f < best_f:
            best_f, best_x = f, x.copy()
        g = g[:-1]
        gPg = float(g @ P @ g)
        if gPg <= 1e-300:
            break
        lower = max(lower, f - np.sqrt(gPg))
        if best_f - lower < tol:
            break
        gt = g / np.sqrt(gPg)
        Pg = P @ gt
        x = x - Pg / (n + 1)
        P = (n * n / (n * n - 1.0)) * (P - (2.0 / (n + 1)) * np.outer(Pg, Pg))
        P = 0.5 * (P + P.T)
    return best_f, best_x, it


def _upper_osborne(M, S: BlockStructure, tol: float = 1e-8, max_iter: int = 3000, radius: float = 12.0,
                   restarts: int = 4):
    """Minimise log sigma_max(D M D^-1) over one log-scaling per block (last fixed to 0).

    The ellipsoid method searches a ball around the Osborne scaling; when the
    best point lies near its edge (the infimum is approached as some d -> 0, as
    for a triangular M) the search is restarted around it.
    Returns (value, d, iterations); the caller recomputes the value from ``d``.
    """
    x0 = _osborne(M, S)
    if len(S) == 1:
        s0, _ = _sigma_and_grad(M, S, x0)
        return s0, np.exp(x0), 0
    total = 0
    for _ in range(restarts + 1):
        f, xb, it = _ellipsoid(M, S, x0, tol, max_iter, radius)
        total += it
        xb = np.append(xb, 0.0)
        if not np.isfinite(f):
            return 0.0, np.exp(xb), total
        moved = np.linalg.norm(xb - x0)
        x0 = xb
        if moved < 0.5 * radius:
            break
    return float(np.exp(f)), np.exp(x0), total


# ----------------------------------------------------------------------------
# upper bound: LMI (D or D-G scalings)
# ----------------------------------------------------------------------------

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
        import warnings

        import cvxpy as cp
        for P, H, (_, Dr) in zip(self.Hd, self.MDM, self.dpairs):
            P.value = _embed(H - beta ** 2 * Dr)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                self.prob.solve(solver="CLARABEL")
        except (cp.SolverError, ValueError, ArithmeticError) as exc:
            return f"{type(exc).__name__}: {exc}"
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
    key = (S.blocks, use_g)
    if key not in _LMI_CACHE:
        if len(_LMI_CACHE) > 32:
            _LMI_CACHE.clear()
        try:
            _LMI_CACHE[key] = _LMIProblem(S, use_g)
        except ImportError as exc:
            raise SolverError(f"the LMI upper bound needs cvxpy and Clarabel ({exc}); "
                              "use method='osborne'") from None
    return _LMI_CACHE[key]


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


def _easy_lower(M, S: BlockStructure) -> float:
    r"""Cheap lower bounds on :math:`\mu`: each diagonal block alone, and
    :math:`\rho(M)` when :math:`\delta I` is in the structure."""
    best = 0.0
    for b, rs, cs in zip(S.blocks, S.row_slices, S.col_slices):
        Mk = M[cs, rs]
        if b.kind == "full":
            best = max(best, np.linalg.norm(Mk, 2))
        else:
            ev = np.linalg.eigvals(Mk)
            if b.kind == "real":
                ev = ev[np.abs(ev.imag) <= 1e-12 * np.abs(ev)]
            best = max(best, np.abs(ev).max(initial=0.0))
    if not S.has_real and all(b.rows == b.cols for b in S.blocks):
        best = max(best, np.abs(np.linalg.eigvals(M)).max())
    return float(best)


def mu_upper(M, structure: BlockStructure, *, method: str = "lmi", real: str = "dg",
             rtol: float = 1e-6, lower: float | None = None) -> MuUpper:
    r"""Upper bound on :math:`\mu_{\boldsymbol\Delta}(M)` by D (or D-G) scaling.

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
    method : {"lmi", "osborne", "fast"}
        ``"lmi"``: the optimal D (``real="complex"``) or D-G (``real="dg"``)
        scaling bound by bisection on the LMI
        :math:`M^H D_\ell M + j(GM - M^HG^H) - \beta^2 D_r \preceq 0`
        ([PD]_, [FTD]_), solved by Clarabel through cvxpy.
        ``"osborne"``: diagonal D only (one scalar per block), by Osborne
        balancing and the ellipsoid method on the convex function
        :math:`\log\bar\sigma(DMD^{-1})` [SO]_; real blocks are treated as
        complex.  The two agree where diagonal D is optimal (full and ``1 x 1``
        blocks, no D-G); elsewhere ``"osborne"`` is more conservative.
        ``"fast"``: the same D (or D-G) scalings as ``"lmi"``, found by a
        quasi-Newton descent on the largest eigenvalue of the scaled form
        (no SDP; see :func:`mu_sweep`); a valid bound from explicit scalings,
        usually equal to the LMI's to about 1e-6 but without its optimality.
    real : {"dg", "complex"}
        With real blocks and ``method="lmi"``: use the G scalings (tighter) or
        treat real parameters as complex.
    rtol : float
        Relative width of the final bisection bracket (``"lmi"``).
    lower : float, optional
        A known lower bound on mu (starts the bisection bracket).

    Returns
    -------
    MuUpper
        ``value`` is recomputed from the returned scalings (a generalised
        eigenvalue for the LMI, a singular value for Osborne), so it is a
        valid bound even if the solver was inaccurate; ``method`` says which
        bound was used.

    Raises
    ------
    ModelError
        Size of ``M`` not matching the structure, non-finite ``M``, unknown method.
    SolverError
        The LMI solver failed at the first levels tried (no bound was obtained).

    Examples
    --------
    >>> M = np.array([[2.0, 2.0], [-1.0, -1.0]])      # [SP]_ example 8.5
    >>> S = BlockStructure([Block.scalar(), Block.scalar()])
    >>> round(mu_upper(M, S).value, 4), round(float(np.linalg.norm(M, 2)), 4)
    (3.0, 3.1623)
    """
    structure = _as_structure(structure)
    M = structure.check(M)
    if lower is not None:
        if isinstance(lower, (bool, np.bool_)) or not isinstance(lower, (int, float, np.integer, np.floating)) \
                or not np.isfinite(lower) or lower < 0:
            raise ModelError(f"lower must be a non-negative finite lower bound on mu (or None), got {lower!r}")
        cap = _norm2(M)
        if lower > cap * (1 + 1e-9):
            raise ModelError(f"lower={lower!r} cannot be a lower bound on mu: it exceeds sigma_max(M) = "
                             f"{cap:.6g}, an upper bound")
    if method not in ("lmi", "osborne", "fast"):
        raise ModelError(f"method must be 'lmi', 'osborne' or 'fast', got {method!r}")
    if real not in ("dg", "complex"):
        raise ModelError(f"real must be 'dg' or 'complex', got {real!r}")
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ModelError(f"rtol must lie in (0, 1), got {rtol}")
    S = structure
    nrm = _norm2(M)
    if nrm != 0 and not 1e-100 <= nrm <= 1e100:
        # mu is homogeneous: bound mu(M / nrm) and scale back (entries near 1e+-150
        # overflow or underflow in the Gram matrices of the bound)
        low = None if lower is None else float(lower) / nrm
        up = mu_upper(M / nrm, S, method=method, real=real, rtol=rtol, lower=low)
        return MuUpper(float(up.value * nrm), up.method, d=up.d, Dl=up.Dl, Dr=up.Dr,
                       G=None if up.G is None else up.G * nrm, iterations=up.iterations,
                       lower_level=float(up.lower_level * nrm) if up.lower_level is not None else None)
    if nrm == 0 or (len(S) == 1 and S.blocks[0].kind == "full"):
        return _diag_result(M, S, np.ones(len(S)), "sigma")
    if method == "osborne":
        _, d_os, it_os = _upper_osborne(M, S)
        return _diag_result(M, S, d_os, "osborne", it_os)
    use_g = real == "dg" and S.has_real
    if method == "fast":
        return _fast_polish(M, S, _DGParams(S, use_g))[0]
    # Balance first: the LMI is posed for M0 = L0 M R0^-1 with the best diagonal
    # scaling (Osborne + ellipsoid).  Its remaining scalings are then close to I,
    # which keeps the solver accurate when M is badly scaled (the optimal d
    # spanning many decades).
    _, d0, _ = _upper_osborne(M, S)
    return _lmi_bisect(M, S, use_g, d0, lower, rtol)


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
        v = _gevp(Mn, Dl, Dr, G, S)
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
        # feasibility is decided by the certificate, not by the solver's t
        val = _gevp(Mn, Dl, Dr, G, S)
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


# ----------------------------------------------------------------------------
# upper bound: fast D-G scalings (quasi-Newton, warm-started along a grid)
# ----------------------------------------------------------------------------

class _DGParams:
    r"""Coordinates of the scalings of the fast D-G bound for one structure.

    Block ``k`` has a factor :math:`L_k` with :math:`D_k = L_kL_k^H`: a positive
    scalar :math:`e^{x}` on full and ``1 x 1`` blocks, a lower-triangular
    matrix (log diagonal, complex entries below) on repeated scalars.  A real
    block also has a Hermitian :math:`\hat G_k` (each real coordinate of it the
    ``sinh`` of a coordinate here, so that the flat approach of the bound to its
    infimum as :math:`G\to\infty`, common for nearly real ``M``, takes few
    steps) and :math:`G_k = \beta_0 L_k\hat G_kL_k^H`, so that in the congruent form

    .. math::
        H = A^HA + j\beta_0(\hat GA - A^H\hat G), \qquad A = L_\ell^H M L_r^{-H},

    :math:`\hat G` is dimensionless and independent of :math:`D` (the
    :math:`D,\,G/\beta` form of Young, Newlin and Doyle [YND]_); its value
    carries over from one frequency to the next.  The first coordinate of the
    last block is fixed to 0 (the bound is invariant to scaling all of D).
    """

    def __init__(self, S: BlockStructure, use_g: bool):
        self.S = S
        self.use_g = use_g
        self.diag = S.diagonal_scalings
        self.lslots, self.gslots = [], []
        n = 0
        for b in S.blocks:
            k = 1 if b.diagonal_scaling else b.rows * b.rows
            self.lslots.append(slice(n, n + k))
            n += k
        for b in S.blocks:
            if use_g and b.kind == "real":
                k = b.rows * b.rows
                self.gslots.append(slice(n, n + k))
                n += k
            else:
                self.gslots.append(None)
        self.size = n
        self.fixed = self.lslots[-1].start
        self.free = np.delete(np.arange(n), self.fixed)
        if self.diag:
            # coordinates are [log d per block, G-hat per real block]
            self.m = len(S)
            self.real_idx = np.array([k for k, g in enumerate(self.gslots) if g is not None], int)
            self.nreal = self.real_idx.size
            self.grow = np.array([S.row_slices[k].start for k in self.real_idx], int)
            self.gcol = np.array([S.col_slices[k].start for k in self.real_idx], int)
            self.El = np.eye(self.m)[S.col_block]
            self.Er = np.eye(self.m)[S.row_block]

    # -- small matrices from coordinates -------------------------------------
    @staticmethod
    def _lower(p, n):
        """Lower-triangular factor: exp(p) on the diagonal, complex entries below."""
        L = np.zeros((n, n), complex)
        L[np.diag_indices(n)] = np.exp(p[:n])
        il = np.tril_indices(n, -1)
        m = len(il[0])
        L[il] = p[n:n + m] + 1j * p[n + m:n + 2 * m]
        return L

    @staticmethod
    def _herm(p, n):
        G = np.zeros((n, n), complex)
        G[np.diag_indices(n)] = p[:n]
        iu = np.triu_indices(n, 1)
        m = len(iu[0])
        G[iu] = p[n:n + m] + 1j * p[n + m:n + 2 * m]
        G[(iu[1], iu[0])] = np.conj(G[iu])
        return G

    def initial(self, d) -> np.ndarray:
        """Coordinates for diagonal scalings ``d`` (one per block, L = d) and G = 0."""
        x = np.zeros(self.size)
        for b, sl, dk in zip(self.S.blocks, self.lslots, d):
            x[sl.start:sl.start + (1 if b.diagonal_scaling else b.rows)] = np.log(dk)
        return x - x[self.fixed] * self._log_mask()

    def _log_mask(self):
        m = np.zeros(self.size)
        for b, sl in zip(self.S.blocks, self.lslots):
            m[sl.start:sl.start + (1 if b.diagonal_scaling else b.rows)] = 1.0
        return m

    # -- the bound and its gradient -------------------------------------------
    def value_grad(self, x, M, beta0, grad: bool = True):
        r"""(lambda, grad log lambda) with :math:`\lambda = \lambda_{\max}(H)` (the squared bound)."""
        S = self.S
        if self.diag:
            # one scaling per block (coordinates 0..m-1), G-hat on 1 x 1 real blocks after them
            m = self.m
            e = np.exp(x[:m])
            A = e[S.col_block][:, None] * M / e[S.row_block][None, :]
            H = A.conj().T @ A
            if self.nreal:
                gs = np.sinh(x[m:])
                # G A: G maps column gcol of A (z of the real block) to row grow (its w)
                GA = np.zeros((S.nrows, S.nrows), complex)
                GA[self.grow] = (beta0 * gs)[:, None] * A[self.gcol]
                H = H + 1j * (GA - GA.conj().T)
            ev, V = np.linalg.eigh(H)
            lam = float(ev[-1])
            if not grad:
                return lam, None
            v = V[:, -1]
            a = A @ v
            g = np.empty(self.size)
            g[:m] = 2.0 * ((a.real ** 2 + a.imag ** 2) @ self.El - lam * ((v.real ** 2 + v.imag ** 2) @ self.Er))
            if self.nreal:
                im = (np.conj(v[self.grow]) * a[self.gcol]).imag
                g[self.real_idx] -= 4.0 * beta0 * gs * im
                g[m:] = -2.0 * beta0 * im * np.cosh(x[m:])
            return lam, g / max(lam, 1e-300)
        # general structure (repeated scalars): block-diagonal factors
        Lc = np.zeros((S.ncols, S.ncols), complex)
        Lri = np.zeros((S.nrows, S.nrows), complex)
        Gh = np.zeros((S.nrows, S.ncols), complex) if self.use_g else None
        Ls, Ghs = [], []
        for b, rs, cs, sl, gs in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots):
            if b.diagonal_scaling:
                l = np.exp(x[sl.start])
                Lc[cs, cs] = l * np.eye(b.cols)
                Lri[rs, rs] = np.eye(b.rows) / l
                Ls.append(l)
            else:
                L = self._lower(x[sl], b.rows)
                Lc[cs, cs] = L
                Lri[rs, rs] = np.linalg.inv(L)
                Ls.append(L)
            Gk = None
            if gs is not None:
                Gk = self._herm(np.sinh(x[gs]), b.rows)
                Gh[rs, cs] = beta0 * Gk
            Ghs.append(Gk)
        A = Lc.conj().T @ M @ Lri.conj().T
        H = A.conj().T @ A
        if Gh is not None:
            GA = Gh @ A
            H = H + 1j * (GA - GA.conj().T)
        ev, V = np.linalg.eigh(H)
        lam = float(ev[-1])
        if not grad:
            return lam, None
        v = V[:, -1]
        a = A @ v
        u = Lri.conj().T @ v
        z = M @ u
        g = np.zeros(self.size)
        for b, rs, cs, sl, gs, L, Gk in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots,
                                             Ls, Ghs):
            if b.diagonal_scaling:
                gl = 2.0 * (np.vdot(a[cs], a[cs]).real - lam * np.vdot(v[rs], v[rs]).real)
                if Gk is not None:
                    gl -= 4.0 * beta0 * Gk[0, 0].real * np.imag(np.conj(v[rs][0]) * a[cs][0])
                g[sl.start] = gl
            else:
                n = b.rows
                zk, ak, uk, vk = z[cs], a[cs], u[rs], v[rs]
                gL = 2.0 * (np.outer(zk, ak.conj()) - lam * np.outer(uk, vk.conj()))
                if Gk is not None:
                    gL = gL + 2.0 * beta0 * 1j * (np.outer(zk, vk.conj()) - np.outer(uk, ak.conj())) @ Gk
                il = np.tril_indices(n, -1)
                m = len(il[0])
                p = g[sl]
                p[:n] = np.real(np.diag(gL)) * np.real(np.diag(L))
                p[n:n + m] = gL[il].real
                p[n + m:] = gL[il].imag
                g[sl] = p
            if Gk is not None:
                n = b.rows
                K = beta0 * 1j * (np.outer(a[cs], v[rs].conj()) - np.outer(v[rs], a[cs].conj()))
                iu = np.triu_indices(n, 1)
                m = len(iu[0])
                p = np.empty(n + 2 * m)
                p[:n] = np.real(np.diag(K))
                p[n:n + m] = 2.0 * K[iu].real
                p[n + m:] = 2.0 * K[iu].imag
                g[gs] = p * np.cosh(x[gs])
        return lam, g / max(lam, 1e-300)

    def scalings(self, x, beta0):
        """(Dl, Dr, G) of the LMI form from coordinates."""
        S = self.S
        if self.diag:
            d2 = np.exp(2.0 * x[:self.m])
            G = None
            if self.use_g:
                G = np.zeros((S.nrows, S.ncols), complex)
                G[self.grow, self.gcol] = beta0 * d2[self.real_idx] * np.sinh(x[self.m:])
            return np.diag(d2[S.col_block]).astype(complex), np.diag(d2[S.row_block]).astype(complex), G
        Dl = np.zeros((S.ncols, S.ncols), complex)
        Dr = np.zeros((S.nrows, S.nrows), complex)
        G = np.zeros((S.nrows, S.ncols), complex) if self.use_g else None
        for b, rs, cs, sl, gs in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots):
            if b.diagonal_scaling:
                L = np.exp(x[sl.start]) * np.eye(b.rows)
                Dl[cs, cs] = np.exp(2 * x[sl.start]) * np.eye(b.cols)
                Dr[rs, rs] = np.exp(2 * x[sl.start]) * np.eye(b.rows)
            else:
                L = self._lower(x[sl], b.rows)
                Dl[cs, cs] = Dr[rs, rs] = L @ L.conj().T
            if gs is not None:
                G[rs, cs] = beta0 * L @ self._herm(np.sinh(x[gs]), b.rows) @ L.conj().T
        return Dl, Dr, G


def _bfgs(fun, x0, B0=None, max_iter: int = 100, ftol: float = 1e-10, max_step: float = 1.0,
          max_eval: int = 400):
    r"""Minimise a (possibly nonsmooth at optimum) function by BFGS with a weak Wolfe line search.

    The line search of Lewis and Overton [LO]_ (bisection/doubling on the
    Armijo and weak curvature conditions), which keeps BFGS working on max
    eigenvalue functions.  Stops when an iteration lowers ``f`` by less than
    ``ftol`` (absolute: ``f`` is a logarithm) twice in a row or the line search fails.
    ``max_eval`` bounds the function evaluations (the result is then the best
    point found, still a valid bound).  Returns (f, x, inverse Hessian
    approximation, evaluations).
    """
    x = x0.copy()
    f, g = fun(x)
    nev = 1
    n = x.size
    B = np.eye(n) if B0 is None else B0.copy()
    reset = B0 is None
    small = 0
    for _ in range(max_iter):
        if nev >= max_eval:
            break
        p = -B @ g
        gp = float(g @ p)
        if not gp < 0:
            B = np.eye(n)
            p = -g
            gp = float(g @ p)
            if not gp < 0:
                break
        # at most a factor e^max_step in any scaling per step (a stale or nearly
        # singular Hessian approximation points far out along flat directions)
        big = np.abs(p).max()
        t = min(1.0, max_step / big) if big > 0 else 1.0
        lo, hi = 0.0, np.inf
        ok = False
        for _ls in range(30):
            xt = x + t * p
            ft, gt = fun(xt)
            nev += 1
            if not ft <= f + 1e-4 * t * gp:
                hi = t
            elif float(gt @ p) < 0.9 * gp:
                lo = t
            else:
                ok = True
                break
            t = 0.5 * (lo + hi) if np.isfinite(hi) else 2.0 * lo
        if not ok:
            if ft < f:          # a decrease without the curvature condition: keep it
                x, f = xt, ft
                g = fun(x)[1]
                nev += 1
            if reset:
                break
            # a stale Hessian approximation (a warm start from another matrix): restart once
            B = np.eye(n)
            reset = True
            continue
        s, y = t * p, gt - g
        drop = f - ft
        x, f, g = xt, ft, gt
        sy = float(s @ y)
        if sy > 1e-14 * float(s @ s):
            By = B @ y
            rho = 1.0 / sy
            B = B + ((sy + y @ By) * rho * rho) * (s[:, None] * s) - rho * (By[:, None] * s + s[:, None] * By)
        small = small + 1 if drop < ftol else 0
        if small >= 2:
            break
    return f, x, B, nev


#: restarts of the descent of ``mu_upper(method="fast")``
_FAST_RESTARTS = 6
#: largest |G-hat| entry kept in a warm start of the fast D-G bound
_G_CLIP = 8.0


def _upper_fast(M, S: BlockStructure, params: _DGParams, x0=None, B0=None, ftol: float = 1e-10,
                max_eval: int = 400):
    """Fast D (or D-G) bound at one matrix, from coordinates ``x0`` (None: Osborne balancing).

    Returns (MuUpper, x, inverse Hessian) with the value recomputed from the
    scalings' coordinates (the exact largest eigenvalue of the congruent form).
    """
    if x0 is None:
        x0 = params.initial(np.exp(_osborne(M, S)))
    else:
        # a warm start: G-hat near a previous frequency's, but not the large values
        # of a frequency where the infimum is approached as G -> infinity (a flat
        # region from which the descent at the next frequency stalls)
        x0 = x0.copy()
        for gs in params.gslots:
            if gs is not None:
                x0[gs] = np.clip(x0[gs], -_G_CLIP, _G_CLIP)
    beta0 = np.sqrt(max(params.value_grad(x0, M, 1.0, grad=False)[0], 0.0))
    if params.use_g and beta0 == 0:
        beta0 = 1.0
    # the first G-free sigma_max: with a warm start G carries over (it is scaled by beta0)
    free = params.free

    def fun(y):
        x = x0.copy()
        x[free] = y
        if np.abs(y).max(initial=0.0) > 200.0:
            return np.inf, np.zeros(free.size)     # a line-search trial far out: reject it
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                lam, g = params.value_grad(x, M, beta0)
            except np.linalg.LinAlgError:
                return np.inf, np.zeros(free.size)
        if not np.isfinite(lam):
            return np.inf, np.zeros(free.size)
        if not lam > 0:
            return -np.inf, np.zeros(free.size)
        return np.log(lam), g[free]
    _, y, B, nev = _bfgs(fun, x0[free], B0, ftol=ftol, max_eval=max_eval)
    x = x0.copy()
    x[free] = y
    lam, _ = params.value_grad(x, M, beta0, grad=False)
    Dl, Dr, G = params.scalings(x, beta0)
    tag = "fast-dg" if params.use_g else "fast-d"
    return (MuUpper(float(np.sqrt(max(lam, 0.0))), tag, d=_d_from_matrices(S, Dr), Dl=Dl, Dr=Dr, G=G,
                    iterations=nev), x, B)



def _fast_at(M, S: BlockStructure, params: _DGParams, x0=None, B0=None, ftol: float = 1e-10,
             max_eval: int = 400):
    """:func:`_upper_fast` with the shortcuts of :func:`mu_upper` (one full block, ``M = 0``,
    extreme norms); returns (MuUpper, coordinates or None, inverse Hessian or None)."""
    nrm = _norm2(M)
    if nrm == 0 or (len(S) == 1 and S.blocks[0].kind == "full"):
        return _diag_result(M, S, np.ones(len(S)), "sigma"), None, None
    if not 1e-100 <= nrm <= 1e100:
        up, x, B = _upper_fast(M / nrm, S, params, x0, B0, ftol, max_eval)
        return MuUpper(float(up.value * nrm), up.method, d=up.d, Dl=up.Dl, Dr=up.Dr,
                       G=None if up.G is None else up.G * nrm, iterations=up.iterations), x, B
    return _upper_fast(M, S, params, x0, B0, ftol, max_eval)



def _fast_polish(M, S: BlockStructure, params: _DGParams, x0=None):
    """The fast bound to full accuracy: long descents, restarted from the point reached
    (BFGS can stall at a kink of lambda_max, e.g. with repeated real scalars, and a
    fresh Hessian approximation often continues).  Returns (MuUpper, coordinates)."""
    up, x, _ = _fast_at(M, S, params, x0, None, ftol=1e-12, max_eval=400)
    for _ in range(_FAST_RESTARTS):
        if x is None:
            break
        up2, x2, _ = _fast_at(M, S, params, x, None, ftol=1e-12, max_eval=400)
        if not up2.value < up.value * (1 - 1e-10):
            break
        up, x = up2, x2
    return up, x


# ----------------------------------------------------------------------------
# lower bound
# ----------------------------------------------------------------------------

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


@dataclass
class MuBounds:
    r"""Upper and lower bounds at one matrix: :math:`\text{lower} \le \mu \le \text{upper}`.

    Attributes
    ----------
    upper : MuUpper
    lower : MuLower
    gap : float
        ``upper.value - lower.value`` (property).
    """
    upper: MuUpper
    lower: MuLower

    @property
    def gap(self) -> float:
        return self.upper.value - self.lower.value


def _both(M, S: BlockStructure, method: str, real: str, rng, gap_tol: float = 1e-7):
    """(MuUpper, MuLower): lower bound, upper bound bracketed by it, and for complex
    structures a second lower bound started from the upper bound's scalings when
    the two do not meet."""
    lo = mu_lower(M, S, rng=rng)
    up = mu_upper(M, S, method=method, real=real, lower=lo.value)
    if not S.has_real and up.value - lo.value > gap_tol * up.value and up.Dl is not None:
        lo2 = mu_lower(M, S, rng=rng, scalings=(up.Dl, up.Dr))
        if lo2.value > lo.value:
            lo = lo2
    return up, lo


def mu_bounds(M, structure: BlockStructure, *, method: str = "lmi", real: str = "dg", rng=0) -> MuBounds:
    """Both bounds: :func:`mu_lower`, then :func:`mu_upper` with the lower bound
    starting its bisection, then (complex structures, if they differ) the lower
    bound again from the upper bound's scalings."""
    structure = _as_structure(structure)
    up, lo = _both(structure.check(M), structure, method, real, np.random.default_rng(rng))
    return MuBounds(up, lo)


# ----------------------------------------------------------------------------
# frequency sweeps
# ----------------------------------------------------------------------------

def _resonance_points(poles, lo: float = 0.0, hi: float = np.inf) -> np.ndarray:
    r"""Frequencies :math:`|\Im p| + k|\Re p|`, :math:`k\in\{0, \pm\frac12, \pm 1, \pm 2\}`,
    of the oscillatory poles with :math:`|\Im p|` in ``[lo, hi]``: a resonance of
    half-power width :math:`2|\Re p|` cannot fall between them."""
    pts = []
    for p in poles:
        wi = abs(p.imag)
        if wi > 0 and lo <= wi <= hi:
            pts.append(wi + abs(p.real) * np.array([-2, -1, -0.5, 0, 0.5, 1, 2]))
    if not pts:
        return np.zeros(0)
    w = np.concatenate(pts)
    return w[w > 0]


def _poles(sys) -> np.ndarray:
    return np.linalg.eigvals(np.asarray(sys.A, float)) if sys.nstates else np.zeros(0)


def default_grid(sys, n: int = 200, decades: float = 1.5) -> np.ndarray:
    """Log-spaced frequencies spanning the pole magnitudes, plus each pole's frequency.

    Lightly damped poles (resonances) get extra points at :math:`|\\Im p|` and
    :math:`|\\Im p| \\pm k|\\Re p|` so that a narrow peak is not stepped over.
    """
    from .lti import as_ss
    sys = as_ss(sys)
    poles = _poles(sys)
    mags = np.abs(poles[np.abs(poles) > 0])
    if mags.size:
        lo, hi = mags.min() / 10 ** decades, mags.max() * 10 ** decades
    else:
        lo, hi = 1e-2, 1e2
    w = np.concatenate([np.logspace(np.log10(lo), np.log10(hi), n), _resonance_points(poles)])
    return np.unique(w[w > 0])


@dataclass
class MuSweep:
    r"""Bounds on :math:`\mu(M(j\omega))` over frequency.

    Attributes
    ----------
    omega : ndarray
        Frequencies (rad/s), sorted, including refinement points.
    upper, lower : ndarray
        Bounds at each frequency (``lower`` is nan where it was not computed).
    d : ndarray
        Diagonal scaling per block at each frequency, shape (len(omega), nblocks),
        normalised so the last block has d = 1.
    method : str
        Upper-bound methods used, joined by ``+`` (``"osborne"``, ``"lmi-d"``,
        ``"lmi-dg"``, ``"sigma"`` where the single-block or ``M = 0`` shortcut applied).
    peak_upper, peak_frequency : float
        Largest upper bound and where.
    peak_lower, lower_frequency : float
        Largest lower bound and where; ``lower_delta`` proves it.
    lower_delta : ndarray or None
    methods : list of str
        Upper-bound method at each frequency.
    peak : MuUpper or None
        The bound at ``peak_frequency`` with its scalings (the certificate:
        :func:`dg_bound` on the response there returns ``peak_upper``).
    """
    omega: np.ndarray
    upper: np.ndarray
    lower: np.ndarray
    d: np.ndarray
    method: str
    peak_upper: float
    peak_frequency: float
    peak_lower: float
    lower_frequency: float
    lower_delta: np.ndarray | None = None
    methods: list = field(default_factory=list)
    peak: MuUpper | None = None


def _freqresp_fn(sys):
    from .lti import as_ss, freqresp
    sys = as_ss(sys)

    def f(w):
        return freqresp(sys, np.atleast_1d(w))[:, :, 0]
    return f, sys


def _local_maxima(values) -> list:
    n = len(values)
    return [i for i in range(n) if (i == 0 or values[i] >= values[i - 1]) and
            (i == n - 1 or values[i] >= values[i + 1])]


def _both_lower(M, S: BlockStructure, up: MuUpper, rng, gap_tol: float = 1e-7) -> "MuLower":
    """Lower bound at one matrix, restarted from the upper bound's scalings (complex
    structures) when the two do not meet (as in :func:`_both`)."""
    lo = mu_lower(M, S, rng=rng)
    if not S.has_real and up.value - lo.value > gap_tol * up.value and up.Dl is not None:
        lo2 = mu_lower(M, S, rng=rng, scalings=(up.Dl, up.Dr))
        if lo2.value > lo.value:
            lo = lo2
    return lo


#: fast sweep: function evaluations per frequency of the warm-started descent
_GRID_EVALS = 40
#: fast sweep: an unconverged warm start is repeated from a cold start when its value is
#: above this fraction of the largest so far
_COLD_BAND = 0.8
#: fast sweep: below this fraction of the largest value so far, half the evaluations
_LOW_BAND = 0.5
#: fast sweep: a value this fraction above both neighbours is a spike, redone from their
#: scalings (at most _SPIKE_MAX, the largest first)
_SPIKE, _SPIKE_MAX = 1e-3, 12
#: fast sweep: values within this fraction of the largest are polished
_POLISH_BAND = 0.01
#: at most this many points polished, and this many LMI checks
_POLISH_MAX, _LMI_MAX = 12, 4


def _fast_peaks(res, coords, response, S: BlockStructure, params: _DGParams, certify: bool):
    """Polish the largest values of a fast sweep and check them by the LMI (in place).

    The grid pass stops each descent after a few dozen evaluations (a valid
    bound, possibly a little above the optimum where the descent is slow); only
    the values that decide the peak are worth more.  Spikes (values above both
    neighbours by ``_SPIKE``) are first redone from the neighbours' scalings.  Those within
    ``_POLISH_BAND`` of the largest get a longer descent from their own
    scalings and from a cold (Osborne) start; then, from the largest down, the
    LMI is run from the polished scalings until the largest value left
    unchecked is below the largest checked value.
    """
    # a descent that stalled shows as a spike above both neighbours: redo the largest
    # spikes from the neighbours' scalings
    grid = sorted(res)
    vals = np.array([res[w][0].value for w in grid])
    spikes = [i for i in range(1, len(grid) - 1)
              if vals[i] > (1 + _SPIKE) * max(vals[i - 1], vals[i + 1])]
    for i in sorted(spikes, key=lambda i: -vals[i])[:_SPIKE_MAX]:
        w = grid[i]
        M = response([w])[:, :, 0]
        for x0 in (coords.get(grid[i - 1]), coords.get(grid[i + 1])):
            if x0 is None:
                continue
            up, x, _ = _fast_at(M, S, params, x0, None, ftol=1e-10, max_eval=2 * _GRID_EVALS)
            if up.value < res[w][0].value:
                res[w], coords[w] = (up, res[w][1]), x
    ws = sorted(res, key=lambda w: -res[w][0].value)
    top = res[ws[0]][0].value
    for w in [w for w in ws if res[w][0].value >= (1 - _POLISH_BAND) * top][:_POLISH_MAX]:
        M = response([w])[:, :, 0]
        best = res[w][0]
        for x0 in (coords.get(w), None):
            up, x = _fast_polish(M, S, params, x0)
            if up.value < best.value:
                best, coords[w] = up, x
        res[w] = (best, res[w][1])
    if not certify:
        return
    checked, level = set(), -np.inf
    while len(checked) < _LMI_MAX:
        rest = [w for w in res if w not in checked]
        if not rest:
            break
        w = max(rest, key=lambda v: res[v][0].value)
        up = res[w][0]
        if up.value <= level:
            break
        checked.add(w)
        if up.method == "sigma":
            level = max(level, up.value)
            continue
        M = response([w])[:, :, 0]
        try:
            lmi = _lmi_bisect(M, S, params.use_g, up.d, None, 1e-7, start=up, first=1 - 1e-5)
        except SolverError:
            level = max(level, up.value)
            continue
        if lmi.value < up.value:
            up = lmi
        else:
            up.lower_level = lmi.lower_level
        res[w] = (up, res[w][1])
        level = max(level, up.value)


def mu_sweep(sys, structure: BlockStructure, omega=None, *, method: str = "osborne", real: str = "dg",
             lower="peaks", refine: bool = True, npeaks: int = 3, rng=0, xtol: float = 1e-7,
             certify: bool = True) -> MuSweep:
    r"""Bounds on :math:`\mu` of a system's frequency response over a frequency grid.

    Parameters
    ----------
    sys : control.StateSpace
        Stable system ``M(s)`` with ``structure.ncols`` outputs and
        ``structure.nrows`` inputs.
    structure : BlockStructure
    omega : array_like, optional
        Frequencies (rad/s, non-negative).  Default: :func:`default_grid`.
    method, real
        Upper-bound method (see :func:`mu_upper`).  ``"fast"``: the D-G (or D)
        bound by quasi-Newton descent (BFGS with the weak Wolfe line search of
        Lewis and Overton [LO]_) on :math:`\log\lambda_{\max}` of the scaled
        form, warm-started from the previous frequency's scalings and
        Hessian approximation; the frequencies within 1 % of the largest value
        are then polished (a cold start as well) and the largest are checked by
        the LMI (``certify``).  Every value is the bound of explicit scalings.
        Away from the peak each descent stops after a few dozen evaluations
        (half as many below half the largest value so far), so single values
        there can stay above the optimal D-G bound: on the 500-frequency
        problem of ``benchmarks/bench_mu_sweep.py``, 5 of 500 values are more
        than 0.1 % above AB13MD's and the worst 4.6 % above, at 27 % of the
        peak; on coarse grids (poor warm starts) and with real blocks only,
        more.
    lower : {"peaks", "all", "none"} or bool
        Where to compute lower bounds (:func:`mu_lower`): at the ``npeaks``
        largest local maxima of the upper bound (default), at every frequency
        (``"all"`` or True) or nowhere.
    refine : bool
        Add the frequencies around the lightly damped poles of ``sys`` that lie
        within the grid (:math:`|\Im p| + k|\Re p|`, so that a resonance narrower
        than the grid spacing is not stepped over), then refine the ``npeaks``
        largest local maxima of the upper bound by golden-section search in
        :math:`\log\omega` between the neighbouring points, down to a relative
        bracket of ``xtol``.
    npeaks : int
    rng : int or Generator
        Seed for the lower bounds.
    xtol : float
        Relative frequency tolerance of the peak refinement.
    certify : bool
        ``method="fast"``: run the LMI (:func:`mu_upper`, ``method="lmi"``)
        at the largest values, from the fast scalings, until the largest value
        left unchecked is below the largest checked one.  The LMI either lowers
        the bound there or confirms it within ``1e-5`` relative (its
        ``lower_level`` is then recorded in the point's :class:`MuUpper`).

    Returns
    -------
    MuSweep

    Raises
    ------
    ModelError
        Sizes not matching the structure, an empty grid, negative or non-finite
        frequencies, an unknown ``lower``, a response that is singular or not
        finite on the grid (a pole on the imaginary axis).
    """
    structure = _as_structure(structure)
    _, sysss = _freqresp_fn(sys)
    poles = _poles(sysss)
    unstable = poles[poles.real > 1e-9 * np.maximum(np.abs(poles), 1e-300)] if poles.size else poles
    if unstable.size:
        raise IllPosedError("mu_sweep needs a stable system M(s) (mu of the frequency response says nothing "
                            "about robust stability when the nominal loop is unstable); unstable pole(s) at s = "
                            + ", ".join(f"{p:.6g}" for p in unstable[:6]))
    if sysss.noutputs != structure.ncols or sysss.ninputs != structure.nrows:
        raise ModelError(f"the system has {sysss.noutputs} outputs and {sysss.ninputs} inputs; the "
                         f"block structure {structure!r} needs {structure.ncols} outputs and "
                         f"{structure.nrows} inputs")
    if omega is None:
        omega = default_grid(sysss)
    omega = np.asarray(omega, dtype=float).ravel()
    if omega.size == 0:
        raise ModelError("the frequency grid is empty")
    if not np.all(np.isfinite(omega)) or np.any(omega < 0):
        raise ModelError("frequencies must be finite and non-negative")
    if lower is True:
        lower = "all"
    elif lower is False or lower is None:
        lower = "none"
    if lower not in ("peaks", "all", "none"):
        raise ModelError(f"lower must be 'peaks', 'all' or 'none', got {lower!r}")
    if method not in ("lmi", "osborne", "fast"):
        raise ModelError(f"method must be 'lmi', 'osborne' or 'fast', got {method!r}")
    if real not in ("dg", "complex"):
        raise ModelError(f"real must be 'dg' or 'complex', got {real!r}")
    if not isinstance(npeaks, (int, np.integer)) or npeaks < 0:
        raise ModelError(f"npeaks must be a non-negative integer, got {npeaks!r}")
    omega = np.unique(omega)
    if refine and omega.size >= 2:
        extra = _resonance_points(_poles(sysss), omega[0], omega[-1])
        omega = np.unique(np.concatenate([omega, extra[(extra >= omega[0]) & (extra <= omega[-1])]]))
    rng = np.random.default_rng(rng)

    def response(w):
        try:
            return freqresp(sysss, w)
        except np.linalg.LinAlgError:
            raise ModelError("the frequency response is singular on the grid "
                             f"[{np.min(w):.6g}, {np.max(w):.6g}] rad/s: a pole on the imaginary "
                             "axis") from None

    from .lti import freqresp
    H = response(omega)
    res = {}

    fast = method == "fast"
    if fast:
        params = _DGParams(structure, real == "dg" and structure.has_real)
        coords = {}                  # frequency -> coordinates of its fast scalings
        warm = {"x": None, "B": None, "top": 0.0, "last": 0.0}

    def evaluate(w, Mw):
        if not np.all(np.isfinite(Mw)):
            raise ModelError(f"the frequency response is not finite at omega = {w:.6g} rad/s "
                             "(a pole on the imaginary axis?)")
        if fast:
            if coords and warm["x"] is None:
                # a refinement point: start from the nearest frequency done
                near = min(coords, key=lambda v: abs(np.log(max(v, 1e-300)) - np.log(max(w, 1e-300))))
                warm["x"] = coords[near]
            # half the evaluations where the last value was far below the peak so far: the
            # bound stays valid, and its last digits there do not matter
            budget = _GRID_EVALS if warm["last"] >= _LOW_BAND * warm["top"] else _GRID_EVALS // 2
            up, x, B = _fast_at(Mw, structure, params, warm["x"], warm["B"], ftol=1e-9, max_eval=budget)
            if up.iterations >= budget and x is not None and up.value >= _COLD_BAND * warm["top"]:
                # the warm start did not converge (it can lose its way where the infimum
                # is approached as a real block's d -> 0 and G -> infinity): a cold start
                # too, where the value may matter for the peak
                up2, x2, B2 = _fast_at(Mw, structure, params, None, None, ftol=1e-9, max_eval=4 * _GRID_EVALS)
                if up2.value < up.value:
                    up, x, B = up2, x2, B2
            coords[float(w)] = x
            warm["x"], warm["B"] = x, B
            warm["top"] = max(warm["top"], up.value)
            warm["last"] = up.value
            lo = _both_lower(Mw, structure, up, rng) if lower == "all" else None
        elif lower == "all":
            up, lo = _both(Mw, structure, method, real, rng)
        else:
            up, lo = mu_upper(Mw, structure, method=method, real=real), None
        res[float(w)] = (up, lo)
        return up.value

    for k, w in enumerate(omega):
        evaluate(w, H[:, :, k])
    if fast:
        warm["x"] = warm["B"] = None
    if refine and omega.size >= 3:
        ws = np.array(sorted(res))
        ups = np.array([res[w][0].value for w in ws])
        gr = (np.sqrt(5) - 1) / 2
        for i in sorted(_local_maxima(ups), key=lambda i: -ups[i])[:npeaks]:
            a = np.log(ws[i - 1] if i > 0 and ws[i - 1] > 0 else ws[i] / 2 if ws[i] > 0 else ws[1] / 2)
            b = np.log(ws[min(i + 1, len(ws) - 1)])
            if b <= a:
                continue

            def g(lw):
                w = float(np.exp(lw))
                if w in res:
                    return res[w][0].value
                return evaluate(w, response([w])[:, :, 0])
            c, d = b - gr * (b - a), a + gr * (b - a)
            fc, fd = g(c), g(d)
            for _ in range(100):
                if b - a <= xtol:
                    break
                if fc > fd:
                    b, d, fd = d, c, fc
                    c = b - gr * (b - a)
                    fc = g(c)
                else:
                    a, c, fc = c, d, fd
                    d = a + gr * (b - a)
                    fd = g(d)
    if fast:
        _fast_peaks(res, coords, response, structure, params, certify)
    ws = np.array(sorted(res))
    ups = np.array([res[w][0].value for w in ws])
    if lower == "peaks":
        for i in sorted(_local_maxima(ups), key=lambda i: -ups[i])[:npeaks]:
            w = float(ws[i])
            up = res[w][0]
            Mw = response([w])[:, :, 0]
            lo = mu_lower(Mw, structure, rng=rng)
            if not structure.has_real and up.value - lo.value > 1e-7 * up.value:
                lo2 = mu_lower(Mw, structure, rng=rng, scalings=(up.Dl, up.Dr))
                lo = lo2 if lo2.value > lo.value else lo
            res[w] = (up, lo)
    lows = np.array([res[w][1].value if res[w][1] is not None else np.nan for w in ws])
    dd = np.array([res[w][0].d for w in ws])
    methods = [res[w][0].method for w in ws]
    k = int(np.argmax(ups))
    if np.any(np.isfinite(lows)):
        kl = int(np.nanargmax(lows))
        pl, wl, dl = float(lows[kl]), float(ws[kl]), res[ws[kl]][1].Delta
    else:
        pl, wl, dl = np.nan, np.nan, None
    used = sorted(set(methods))
    return MuSweep(ws, ups, lows, dd, "+".join(used), float(ups[k]), float(ws[k]), pl, wl, dl, methods,
                   peak=res[ws[k]][0])
