r""":func:`mu_upper`: the upper bound at one matrix, by the LMI, Osborne or fast method."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._certificate import MuUpper, _diag_result
from ._fast import _DGParams, _fast_polish
from ._lmi import _lmi_bisect
from ._osborne import _upper_osborne
from ._structure import BlockStructure, _as_structure, _norm2


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
    >>> import numpy as np
    >>> from mutext.mu import Block, BlockStructure, mu_upper
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
