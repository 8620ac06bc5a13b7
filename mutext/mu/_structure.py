r"""Block structures of the perturbation :math:`\Delta` and the checks of ``M`` against them."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .._validation import Integer, check_param
from ..errors import ModelError

_KINDS = ("full", "scalar", "real")


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
            check_param(f"block {self.name or self.kind}", what, v, Integer(lo=1))
        if self.kind != "full" and self.rows != self.cols:
            raise ModelError(f"a repeated scalar block ({self.kind}) must be square, got {self.rows}x{self.cols}")

    @classmethod
    def full(cls, rows: int, cols: int | None = None, name: str = "") -> "Block":
        """A full complex ``rows x cols`` block (``cols`` defaults to ``rows``).

        Parameters
        ----------
        rows : int
            Number of rows of the block (inputs ``w`` of ``M`` it drives).
        cols : int, optional
            Number of columns of the block (outputs ``z`` of ``M`` it reads); default ``rows``.
        name : str, optional
            Label of the block in reports and error messages.
        """
        return cls("full", rows, rows if cols is None else cols, name)

    @classmethod
    def scalar(cls, n: int = 1, name: str = "") -> "Block":
        """A repeated complex scalar :math:`\\delta I_n`.

        Parameters
        ----------
        n : int, optional
            Number of repetitions (the block is n x n).
        name : str, optional
            Label of the block in reports and error messages.
        """
        return cls("scalar", n, n, name)

    @classmethod
    def real(cls, n: int = 1, name: str = "") -> "Block":
        """A repeated real scalar :math:`\\delta I_n`.

        Parameters
        ----------
        n : int, optional
            Number of repetitions (the block is n x n), e.g. how often a physical
            parameter appears in the LFT.
        name : str, optional
            Label of the block, typically the parameter's name.
        """
        return cls("real", n, n, name)

    @property
    def diagonal_scaling(self) -> bool:
        """True if the optimal D for this block is a scalar times identity."""
        return self.kind == "full" or self.rows == 1


_TINY = float(np.finfo(float).tiny)


class BlockStructure:
    r"""Block-diagonal structure :math:`\boldsymbol\Delta = \{\operatorname{diag}(\Delta_1,\dots,\Delta_m)\}`.

    ``M`` must have ``ncols`` rows and ``nrows`` columns (it maps ``w`` to
    ``z``; ``Delta`` maps ``z`` back to ``w``).

    Parameters
    ----------
    blocks : sequence of Block
        The diagonal blocks, in the order of the rows and columns of ``Delta``.

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
        repeated real scalar, ``[n, 0]`` repeated complex scalar.

        Parameters
        ----------
        spec : sequence of pairs of int
            One ``[rows, cols]`` pair per block, MATLAB's ``blk`` convention.

        Examples
        --------
        >>> from mutext.mu import BlockStructure
        >>> S = BlockStructure.from_spec([[-1, 0], [2, 0], [1, 2]])   # real, repeated complex, full 1 x 2
        >>> [b.kind for b in S.blocks], S.nrows, S.ncols
        (['real', 'scalar', 'full'], 4, 5)
        """
        blocks = []
        try:
            items = list(spec)
        except TypeError:
            raise ModelError(f"block structure: expected a list of [rows, cols] pairs, got {spec!r}") from None
        for k, item in enumerate(items):
            try:
                pair = list(item)
            except TypeError:
                raise ModelError(f"block structure, entry {k}: expected a pair [rows, cols], got {item!r}") \
                    from None
            if len(pair) != 2:
                raise ModelError(f"block structure, entry {k}: expected a pair [rows, cols] ([r, c] full block, "
                                 f"[-n, 0] repeated real scalar, [n, 0] repeated complex scalar), got {item!r}")
            for v in pair:
                ok = isinstance(v, (int, np.integer)) or (isinstance(v, (float, np.floating)) and float(v).is_integer())
                if isinstance(v, bool) or not ok:
                    raise ModelError(f"block structure, entry {k}: sizes must be integers, got {item!r}")
            r, c = (int(v) for v in pair)
            if r == 0 or c < 0 or (c > 0 and r < 0):
                raise ModelError(f"block structure, entry {k}: {item!r} is not a block ([r, c] with r, c >= 1, "
                                 "or [n, 0] / [-n, 0] with n >= 1)")
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
        """Return ``M`` as a complex array after checking its size against the structure.

        Parameters
        ----------
        M : (ncols, nrows) array_like
            The matrix to test (maps ``w`` to ``z``).
        """
        M = np.asarray(M)
        if M.ndim != 2:
            raise ModelError(f"M must be a matrix, got an array with {M.ndim} dimensions")
        if M.shape != (self.ncols, self.nrows):
            raise ModelError(f"M is {M.shape[0]}x{M.shape[1]} but the block structure {self!r} "
                             f"needs {self.ncols}x{self.nrows} (rows = total block columns, "
                             f"columns = total block rows)")
        M = M.astype(complex, order="C")
        # real and imaginary parts side by side (a view of the new array)
        parts = M.view(float)
        if not np.isfinite(parts).all():
            raise ModelError("M contains non-finite entries")
        # subnormal parts (below 2.2e-308) next to normal entries: zero them.  mu moves by about
        # 1e-308 relative, and the scalings would otherwise meet numbers that some loaded
        # libraries make the CPU read as zero (0/0 inside the SVD)
        a = np.abs(parts)
        small = a < _TINY
        if a.max(initial=0.0) >= _TINY and (small & (a > 0.0)).any():
            parts[small] = 0.0
        return M

    # -- perturbations -----------------------------------------------------
    def assemble(self, parts: Sequence) -> np.ndarray:
        """Block-diagonal ``Delta`` from one entry per block (a scalar for
        scalar/real blocks, a matrix for full blocks).

        Parameters
        ----------
        parts : sequence
            One entry per block: a number for a scalar or real block (real for a real
            block), a ``rows x cols`` matrix for a full block.
        """
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
        """A random member with every block of norm at most ``norm`` (at least one equal).

        Parameters
        ----------
        rng : numpy.random.Generator or int, optional
            Random generator or seed (``numpy.random.default_rng``).
        norm : float, optional
            Largest singular value of the returned ``Delta``.
        """
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
        """Spectral norm of each diagonal block of ``Delta`` (one number per block).

        Parameters
        ----------
        Delta : (nrows, ncols) array_like
            A matrix of this structure's size.
        """
        return np.array([np.linalg.norm(np.asarray(Delta)[rs, cs], 2)
                         for rs, cs in zip(self.row_slices, self.col_slices)])

    def contains(self, Delta, tol: float = 1e-10) -> bool:
        """True if ``Delta`` has this structure (zero off-diagonal blocks, real/repeated blocks).

        Parameters
        ----------
        Delta : (nrows, ncols) array_like
            The matrix to test.
        tol : float, optional
            Tolerance relative to ``max(1, max |Delta_ij|)`` for the zero blocks, the
            repeated diagonals and the imaginary parts of real blocks.
        """
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
        ``D_r = diag(dr)`` on ``w``.

        Parameters
        ----------
        d : (len(blocks),) array_like
            One positive scaling per block.
        """
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


def _per_structure(cache: dict, limit: int, S: BlockStructure, use_g: bool, build):
    """``build(S, use_g)``, kept in ``cache`` by the structure's blocks and ``use_g`` (emptied when it
    holds more than ``limit``): the work that depends on the structure only, done once per structure."""
    key = (S.blocks, use_g)
    if key not in cache:
        if len(cache) > limit:
            cache.clear()
        cache[key] = build(S, use_g)
    return cache[key]


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
