r"""The D-G bound as a complex problem: each real interval replaced by a disc.

A real parameter :math:`\delta\in[-1/\beta, 1/\beta]` lies in every disc
through :math:`\pm 1/\beta` whose centre is on the imaginary axis,
:math:`\delta = (j b + \rho\,\delta_c)/\beta` with :math:`\rho = \sqrt{1+b^2}`
and :math:`|\delta_c| \le 1`.  Substituting this into the loop
:math:`w = \Delta z`, :math:`z = M w` closes the centres as a feedback and
leaves a complex scalar :math:`\delta_c` where :math:`\delta` was:

.. math::
    M_b = (I - M C/\beta)^{-1} M R, \qquad C = \operatorname{diag}(j b_k),\quad
    R = \operatorname{diag}(\rho_k)

(on the real blocks; 0 and 1 on the complex ones), and
:math:`\mu_{\rm complex}(M_b) \le \beta` implies :math:`\mu(M) \le \beta`.
With :math:`b_k = g_k / (d_k \beta)`, where :math:`d_k, g_k` are block
:math:`k`'s D-G scalings certifying level :math:`\beta`, the per-block
quadratic forms of the two tests coincide, so the complex D bound of
:math:`M_b` at that level is exactly the D-G bound: the G scaling of a real
``1 x 1`` block *is* the choice of disc (Fan, Tits and Doyle's D-G bound;
the disc view is the one of Young's mixed-mu synthesis).

This is the form a D-G-K iteration needs for its K step: the centres become a
feedback :math:`j b_k(\omega)/\beta` around the real channels of the plant.
Its difficulty is visible here: :math:`b_k(\omega)` is odd in :math:`\omega`
(real systems), so :math:`j b_k(j\omega)` is real-rational only as an
improper odd function, and any stable rational fit has a real part, which
widens the disc that must contain the interval to
:math:`\rho \ge \sqrt{(1+|\operatorname{Re}h|)^2 + (\operatorname{Im}h)^2}`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import Real, validate_params
from ..errors import ModelError
from ._certificate import MuUpper
from ._structure import BlockStructure, _as_structure

__all__ = ["DiscForm", "dg_disc", "disc_transform"]


@dataclass
class DiscForm:
    r"""The complex problem equivalent to a D-G bound (:func:`dg_disc`).

    Attributes
    ----------
    level : float
        :math:`\beta`: the discs cover the real parameters of size up to :math:`1/\beta`.
    centres : ndarray
        :math:`b_k`, one per real block (in structure order): disc centre
        :math:`j b_k/\beta`.
    radii : ndarray
        :math:`\rho_k = \sqrt{1 + b_k^2}`: disc radius :math:`\rho_k/\beta`.
    M : ndarray
        :math:`M_b`, to be bounded with ``structure``.
    structure : BlockStructure
        The complex structure (real blocks as complex scalars).
    upper : MuUpper
        The D-G bound the discs come from.
    """
    level: float
    centres: np.ndarray
    radii: np.ndarray
    M: np.ndarray
    structure: BlockStructure
    upper: MuUpper


def _real_channels(S: BlockStructure):
    real = [k for k, b in enumerate(S.blocks) if b.kind == "real"]
    for k in real:
        b = S.blocks[k]
        if b.rows != 1:
            raise ModelError(f"dg_disc: block {k} ({b.name or 'real'}) is a {b.rows}-fold repeated real "
                             f"scalar; the disc form is written for real 1 x 1 blocks")
    return real, [S.row_slices[k].start for k in real], [S.col_slices[k].start for k in real]


@validate_params({"level": Real(lo=0, closed="neither")})
def disc_transform(M, structure, centres, radii, level: float) -> np.ndarray:
    r"""The matrix :math:`M_b = (I - MC/\beta)^{-1} M R` of the disc form (module docstring).

    Parameters
    ----------
    M : (ncols, nrows) array_like, or (nw, ncols, nrows) for a frequency grid
    structure : BlockStructure
        Real blocks must be ``1 x 1``.
    centres : array_like
        One (complex, in general) centre per real block, or an ``(nw, nreal)``
        array: :math:`C = \operatorname{diag}(\text{centre}_k)`; on the axis the
        exact D-G form has :math:`j b_k`.
    radii : array_like
        One positive radius per real block (or ``(nw, nreal)``).
    level : float
        :math:`\beta > 0`.

    Returns
    -------
    ndarray
        Same shape as ``M``.

    Raises
    ------
    ModelError
        Sizes that do not match, repeated real blocks, a non-positive level or
        radius, or :math:`I - MC/\beta` singular (the centre itself
        destabilises the loop).
    """
    S = _as_structure(structure)
    real, rows, cols = _real_channels(S)
    A = np.asarray(M, complex)
    single = A.ndim == 2
    if single:
        A = A[None]
    if A.ndim != 3 or A.shape[1:] != (S.ncols, S.nrows):
        raise ModelError(f"disc_transform: M must be {S.ncols} x {S.nrows} (or a stack of such), "
                         f"got shape {np.shape(M)}")
    nw = A.shape[0]
    c = np.broadcast_to(np.asarray(centres, complex), (nw, len(real)))
    r = np.broadcast_to(np.asarray(radii, float), (nw, len(real)))
    if np.any(~np.isfinite(r)) or np.any(r <= 0):
        raise ModelError("disc_transform: the radii must be positive and finite")
    C = np.zeros((nw, S.nrows, S.ncols), complex)
    R = np.ones((nw, S.nrows))
    for j, (i, o) in enumerate(zip(rows, cols)):
        C[:, i, o] = c[:, j]
        R[:, i] = r[:, j]
    loop = np.eye(S.ncols)[None] - A @ C / level
    try:
        out = np.linalg.solve(loop, A * R[:, None, :])
    except np.linalg.LinAlgError:
        out = np.full(A.shape, np.nan)
    if not np.all(np.isfinite(out)):
        raise ModelError("disc_transform: I - M C / level is singular: the disc centres close a "
                         "loop with a pole on the axis (choose a higher level or other centres)")
    return out[0] if single else out


def dg_disc(M, structure, *, upper: MuUpper | None = None, level: float | None = None) -> DiscForm:
    r"""The complex problem whose D bound equals the D-G bound of ``M`` (module docstring).

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
        Real blocks must be ``1 x 1`` (one uncertain parameter each).
    upper : MuUpper, optional
        A D-G bound of ``M`` (default: ``mu_upper(M, structure, method="fast")``).
    level : float, optional
        :math:`\beta`, at least ``upper.value`` (default ``upper.value``): the
        same scalings certify every higher level.

    Returns
    -------
    DiscForm
        ``mu_upper(form.M, form.structure, method="osborne").value`` is at
        most ``level``, and equal to it when ``level == upper.value``.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, mu_upper, dg_disc
    >>> S = BlockStructure([Block.real(1), Block.full(1)])
    >>> M = np.array([[0.5 + 0.5j, 1.0], [-0.7 + 0.4j, 0.6j]])
    >>> form = dg_disc(M, S)
    >>> bool(np.isclose(mu_upper(form.M, form.structure, method="osborne").value, form.level, rtol=1e-6))
    True
    >>> bool(form.level < mu_upper(M, S.complexified(), method="osborne").value)
    True
    """
    from ._upper import mu_upper
    S = _as_structure(structure)
    _, rows, _ = _real_channels(S)
    A = S.check(M)
    if upper is None:
        upper = mu_upper(A, S, method="fast")
    if upper.Dr is None:
        raise ModelError(f"dg_disc: the bound ({upper.method}) carries no D-G scalings")
    beta = float(upper.value if level is None else level)
    if not beta >= upper.value * (1 - 1e-12) or not np.isfinite(beta) or beta <= 0:
        raise ModelError(f"dg_disc: level {level!r} is below the bound {upper.value:.6g} it comes from")
    G = np.zeros((S.nrows, S.ncols)) if upper.G is None else np.asarray(upper.G)
    Dr = np.asarray(upper.Dr)
    b = np.array([G[i, i].real / (Dr[i, i].real * beta) for i in rows])
    rho = np.sqrt(1.0 + b * b)
    Mb = disc_transform(A, S, 1j * b, rho, beta)
    return DiscForm(beta, b, rho, Mb, S.complexified(), upper)
