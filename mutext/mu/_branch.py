r"""Branch and bound on the real parameters: a D-G bound that closes on mixed :math:`\mu`.

With real blocks the D-G bound of :func:`mu_upper` can lie well above
:math:`\mu`, the more so the wider the parameters' ranges (on the three-mass
rig with 10 % uncertainty, 1.047 where :math:`\mu` is below 1).  Cutting the
range of the real parameters into boxes and bounding each box separately
removes that gap as the boxes shrink (Newlin and Young [NY]_; Ferreres [F]_).

A level :math:`\beta` is certified, :math:`\mu(M) < \beta`, when
:math:`I - M\Delta` is nonsingular for every structured :math:`\Delta` with
:math:`\bar\sigma(\Delta) \le 1/\beta`.  With :math:`N = M/\beta` and the real
parameters of a box written :math:`\hat\delta_i = c_i + r_i\tilde\delta_i`,
:math:`|\tilde\delta_i| \le 1`, the perturbation is :math:`\hat\Delta = C +
\tilde\Delta R` (``C`` the centres on the real blocks, ``R`` the radii on the
real blocks and 1 on the complex ones) and

.. math::
    \det(I - N\hat\Delta) = \det(I - NC)\,\det\!\big(I - \tilde N\tilde\Delta\big),
    \qquad \tilde N = R\,(I - NC)^{-1}N ,

so the box holds no singular point when :math:`I - NC` is nonsingular and the
D-G bound of :math:`\tilde N` (same structure, unit ranges) is below 1.  A box
whose bound is not below 1 is cut in two across its widest parameter; the
boxes are taken worst first.  Every box's bound is the certified value of
:func:`mu_upper` (recomputed from its scalings), so a level reported as
certified is a bound on :math:`\mu`, not an estimate.

References
----------
.. [NY] M. P. Newlin and P. M. Young, "Mixed mu problems and branch and bound
   techniques", *Int. J. Robust and Nonlinear Control* 7 (1997) 145-164.
.. [F] G. Ferreres, *A Practical Approach to Robustness Analysis with
   Aeronautical Applications*, Kluwer, 1999, ch. 6.
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from .._validation import Integer, NoneOr, Real, validate_params
from ..errors import ModelError
from ._fast import _DGParams, _fast_at, _fast_polish
from ._lower import mu_lower
from ._structure import BlockStructure, _as_structure
from ._upper import mu_upper

__all__ = ["MuBranch", "BranchPeak", "mu_upper_branch", "branch_certifies", "branch_peak"]


@dataclass(frozen=True)
class MuBranch:
    r"""An upper bound on mixed :math:`\mu` by branch and bound on the real parameters.

    Attributes
    ----------
    value : float
        The smallest level certified: :math:`\mu(M) <` ``value``.
    dg : float
        The D-G bound of the whole box (:func:`mu_upper`), where the search started.
    lower : float
        The lower bound the bisection started from (a level at which a
        destabilising perturbation is known, or the one given).
    boxes : int
        Boxes bounded in all (every level tried).
    levels : int
        Levels tried by the bisection.
    """
    value: float
    dg: float
    lower: float
    boxes: int
    levels: int

    def __float__(self):
        return float(self.value)


def _real_blocks(S: BlockStructure) -> list[int]:
    return [i for i, b in enumerate(S.blocks) if b.kind == "real"]


def _complex_lower(W, Sc: BlockStructure) -> float:
    """A lower bound on the complex mu of ``W`` (exact for one full block)."""
    if len(Sc.blocks) == 1 and Sc.blocks[0].kind == "full":
        return float(np.linalg.norm(W, 2))
    return mu_lower(W, Sc).value


def _box_bound(Nt, S: BlockStructure, params, x0):
    """The fast D-G bound of a box's matrix, only as far as deciding ``< 1`` needs: a short
    descent from the parent box's scalings, polished only when it ends just above 1.  Every
    value is recomputed from its scalings, so it is certified.  Returns (value, coordinates)."""
    up, x, _ = _fast_at(Nt, S, params, x0, None, ftol=1e-6, max_eval=120)
    if up.value < 1.0 or up.value >= 1.02 or x is None:
        return up.value, x
    # a close call: the full descent may still get below 1 and spare the split
    up2, x2 = _fast_polish(Nt, S, params, x)
    return (up2.value, x2) if up2.value < up.value else (up.value, x)


@validate_params({"level": Real(lo=0, closed="neither")})
def branch_certifies(M, structure, level: float, *, max_boxes: int = 2000) -> tuple[bool, int]:
    r"""Whether branch and bound proves :math:`\mu(M) <` ``level``, and the boxes it used.

    ``False`` means that no proof was found within ``max_boxes`` boxes, or that the
    level is refuted: a box's centre, with complex blocks of norm at most
    :math:`1/\text{level}`, makes :math:`I - M\Delta` singular (then
    :math:`\mu \ge` ``level``).

    Parameters
    ----------
    M : (ncols, nrows) array_like
        The complex matrix (e.g. ``M(j w)`` at one frequency).
    structure : BlockStructure or list
        The block structure, or a spec accepted by :meth:`BlockStructure.from_spec`.
    level : float
        The level to prove ``mu`` below (positive).
    max_boxes : int, optional
        Budget of boxes (of the real parameters) to split before giving up.
    """
    S = _as_structure(structure)
    M = S.check(M)
    real = _real_blocks(S)
    cplx = [i for i in range(len(S.blocks)) if i not in real]
    Sc = BlockStructure([S.blocks[i] for i in cplx]) if cplx else None
    out_c = np.r_[tuple(np.arange(S.col_slices[i].start, S.col_slices[i].stop) for i in cplx)] if cplx else None
    in_c = np.r_[tuple(np.arange(S.row_slices[i].start, S.row_slices[i].stop) for i in cplx)] if cplx else None
    N = M / level
    n_out, n_in = N.shape                    # M maps the nrows inputs w to the ncols outputs z
    eye = np.eye(n_out)
    # boxes of the normalised parameters, worst bound first: (-bound, tie, centres, radii)
    params = _DGParams(S, S.has_real)
    heap = [(-np.inf, 0, np.zeros(len(real)), np.ones(len(real)), None)]
    used, tie = 0, 1
    while heap:
        _, _, c, r, x0 = heapq.heappop(heap)
        used += 1
        if used > max_boxes:
            return False, used - 1
        C = np.zeros((n_in, n_out))
        R = np.ones(n_out)
        for j, i in enumerate(real):
            rs, cs = S.row_slices[i], S.col_slices[i]
            C[rs, cs] = c[j] * np.eye(rs.stop - rs.start)
            R[cs] = r[j]
        A = eye - N @ C
        if np.linalg.cond(A) > 1e12:
            return False, used                # a real perturbation in the box is destabilising
        W = np.linalg.solve(A, N)
        v, x = _box_bound(R[:, None] * W, S, params, x0)
        if v < 1.0:
            continue
        # the box's centre with the complex blocks free: a complex perturbation of norm at
        # most 1 that makes I - W Delta_c singular refutes the level
        if Sc is not None and _complex_lower(W[np.ix_(out_c, in_c)], Sc) >= 1.0:
            return False, used
        if not real:
            return False, used                # nothing to cut: the D-G bound is all there is
        j = int(np.argmax(r))
        for side in (-0.5, 0.5):
            c2, r2 = c.copy(), r.copy()
            r2[j] = r[j] / 2
            c2[j] = c[j] + side * r[j]
            heapq.heappush(heap, (-v, tie, c2, r2, x))
            tie += 1
    return True, used


@validate_params({"lower": NoneOr(Real(lo=0)), "rtol": Real(0, 1, closed="neither"),
                  "max_boxes": Integer(lo=1)})
def mu_upper_branch(M, structure, *, lower: float | None = None, rtol: float = 1e-3,
                    max_boxes: int = 2000) -> MuBranch:
    r"""Upper bound on mixed :math:`\mu` by branch and bound on the real parameters.

    Bisects on the level between a lower bound and the D-G bound of
    :func:`mu_upper`, each level decided by :func:`branch_certifies` (see the
    module notes for the box transform).  Without real blocks the D-G bound is
    returned as it is.

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
    lower : float, optional
        A known lower bound on :math:`\mu(M)` (default: :func:`mu_lower`).
    rtol : float
        Relative width of the final bracket.
    max_boxes : int
        Boxes allowed per level; a level not proven within them counts as not certified.

    Returns
    -------
    MuBranch

    Examples
    --------
    Two real parameters and a full complex block, where the D-G bound is 13 % above
    :math:`\mu`; the branch bound meets the lower bound:

    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, mu_lower, mu_upper_branch
    >>> S = BlockStructure([Block.real(1), Block.real(1), Block.full(1)])
    >>> M = np.array([[-0.3+0.3j, -1.5-0.3j, -0.1], [-0.4+0.2j, 0.8+0.2j, 0.2+0.4j],
    ...               [-1.6+0.1j, -1.2, 0.9-0.1j]])
    >>> b = mu_upper_branch(M, S)
    >>> print(f"{mu_lower(M, S).value:.3f} <= mu < {b.value:.3f}; D-G bound {b.dg:.3f}")
    1.443 <= mu < 1.44...; D-G bound 1.626
    """
    S = _as_structure(structure)
    M = S.check(M)
    dg = mu_upper(M, S, method="fast").value
    if lower is None:
        lower = mu_lower(M, S).value
    lower = float(min(max(lower, 0.0), dg))
    if not _real_blocks(S) or dg <= max(lower, 0.0) * (1 + rtol) or dg == 0.0:
        return MuBranch(dg, dg, lower, 0, 0)
    lo, hi, boxes, levels = max(lower, dg * 1e-3), dg, 0, 0
    while hi > lo * (1 + rtol):
        mid = np.sqrt(lo * hi)
        ok, used = branch_certifies(M, S, mid, max_boxes=max_boxes)
        boxes, levels = boxes + used, levels + 1
        if ok:
            hi = mid
        else:
            lo = mid
    return MuBranch(float(hi), dg, lower, boxes, levels)


@dataclass(frozen=True)
class BranchPeak:
    r"""The branch-and-bound bound over a frequency grid.

    Attributes
    ----------
    value : float
        :math:`\mu(M_k) <` ``value`` at every point ``k`` of the grid (certified).
    index : int
        The point that sets ``value`` (-1 for an empty grid or ``M = 0``).
    dg : float
        The largest D-G bound (:func:`mu_upper`) of the points whose ``upper`` could
        decide the peak (every point without ``upper``), for comparison.
    bounded : int
        Points at which branch and bound ran (the others were below the running peak
        already by their D-G bound).
    boxes : int
        Boxes bounded in all.
    """
    value: float
    index: int
    dg: float
    bounded: int
    boxes: int

    def __float__(self):
        return float(self.value)


@validate_params({"rtol": Real(0, 1, closed="neither"), "max_boxes": Integer(lo=1)})
def branch_peak(Ms, structure, *, upper=None, rtol: float = 1e-3, max_boxes: int = 2000) -> BranchPeak:
    r"""Certified peak of :func:`mu_upper_branch` over a grid of matrices.

    The points are taken from the largest D-G bound down (``upper``, if given,
    holds a valid upper bound per point, e.g. the complex bound of a sweep, and
    saves the D-G bounds of points that cannot decide the peak).  A point whose
    bound is above the running peak ``p`` is first tested at ``p``
    (:func:`branch_certifies`), and bisected only if that fails, so on an
    equalised loop most points cost one test.

    Parameters
    ----------
    Ms : (npoints, ncols, nrows) array_like
        The matrices, e.g. a loop's response on a grid.
    structure : BlockStructure
    upper : (npoints,) array_like, optional
        Valid upper bounds on mu at the points (default: none, every point's D-G bound is computed).
    rtol, max_boxes
        As for :func:`mu_upper_branch`.

    Returns
    -------
    BranchPeak
    """
    S = _as_structure(structure)
    Ms = np.asarray(Ms)
    if Ms.ndim != 3:
        raise ModelError(f"branch_peak: Ms must hold one matrix per point (3 dimensions), got {Ms.ndim}")
    cap = np.full(Ms.shape[0], np.inf) if upper is None else np.asarray(upper, float).ravel()
    if cap.size != Ms.shape[0]:
        raise ModelError(f"branch_peak: upper has {cap.size} values for {Ms.shape[0]} matrices")
    peak, index, dg_peak, bounded, boxes = 0.0, -1, 0.0, 0, 0
    for k in np.argsort(-cap, kind="stable"):
        if cap[k] <= peak:
            break                      # this point, and every later one, is below the peak already
        dg = min(mu_upper(S.check(Ms[k]), S, method="fast").value, cap[k])
        dg_peak = max(dg_peak, dg)
        if dg <= peak:
            continue
        bounded += 1
        if peak > 0:
            ok, used = branch_certifies(Ms[k], S, peak, max_boxes=max_boxes)
            boxes += used
            if ok:
                continue
        b = mu_upper_branch(Ms[k], S, rtol=rtol, max_boxes=max_boxes)
        boxes += b.boxes
        if b.value > peak:
            peak, index = b.value, int(k)
    return BranchPeak(float(peak), index, dg_peak, bounded, boxes)
