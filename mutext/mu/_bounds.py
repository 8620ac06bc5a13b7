r"""Both bounds at one matrix: :func:`mu_bounds`, the lower bound restarted from the upper one's scalings."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._certificate import MuUpper
from ._lower import MuLower, mu_lower
from ._structure import BlockStructure, _as_structure
from ._upper import mu_upper


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


def mu_bounds(M, structure: BlockStructure, *, method: str = "auto", real: str = "dg", rng=0) -> MuBounds:
    r"""Both bounds: :func:`mu_lower`, then :func:`mu_upper` with the lower bound
    starting its bisection, then (complex structures, if they differ) the lower
    bound again from the upper bound's scalings.

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
        Or a list of :class:`Block`, or a MATLAB-like ``blk`` spec.
    method, real
        Upper-bound method (see :func:`mu_upper`).
    rng : int or numpy Generator
        Seed of the lower bound's random starting points.

    Returns
    -------
    MuBounds
        ``lower.value <= mu <= upper.value``; ``lower.Delta`` proves the lower
        bound, ``upper``'s scalings the upper one.

    Examples
    --------
    Two repeated complex scalars on a rank-one ``M`` ([SP]_ example 8.5):
    :math:`\mu = 3` while :math:`\bar\sigma(M) = 3.16`, and both bounds meet.

    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, mu_bounds
    >>> M = np.array([[2.0, 2.0], [-1.0, -1.0]])
    >>> S = BlockStructure([Block.scalar(), Block.scalar()])
    >>> b = mu_bounds(M, S)
    >>> round(b.lower.value, 6), round(b.upper.value, 6)
    (3.0, 3.0)

    The perturbation of the lower bound has norm :math:`1/\mu` and makes
    :math:`I - M\Delta` singular:

    >>> D = b.lower.Delta
    >>> round(float(np.linalg.norm(D, 2)), 6), S.contains(D)
    (0.333333, True)
    >>> bool(abs(np.linalg.det(np.eye(2) - M @ D)) < 1e-12)
    True
    """
    structure = _as_structure(structure)
    up, lo = _both(structure.check(M), structure, method, real, np.random.default_rng(rng))
    return MuBounds(up, lo)


def _both_lower(M, S: BlockStructure, up: MuUpper, rng, gap_tol: float = 1e-7) -> "MuLower":
    """Lower bound at one matrix, restarted from the upper bound's scalings (complex
    structures) when the two do not meet (as in :func:`_both`)."""
    lo = mu_lower(M, S, rng=rng)
    if not S.has_real and up.value - lo.value > gap_tol * up.value and up.Dl is not None:
        lo2 = mu_lower(M, S, rng=rng, scalings=(up.Dl, up.Dr))
        if lo2.value > lo.value:
            lo = lo2
    return lo
