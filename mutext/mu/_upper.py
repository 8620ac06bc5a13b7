r""":func:`mu_upper`: the upper bound at one matrix, by the LMI, Osborne or fast method."""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import zheevd as _zheevd

from .._validation import NoneOr, Options, Real, validate_params
from ..errors import ModelError, SolverError
from ._certificate import (MuUpper, _diag_result, _gevp, _gevp_certified, _pow2_scale,
                           _relative_margin, _rounding_margin)
from ._fast import _DGParams, _fast_default, _fast_polish
from ._lmi import _lmi_bisect
from ._osborne import _upper_osborne
from ._structure import BlockStructure, _as_structure, _norm2, _per_structure


#: relative agreement required between a fast bound and its certificate recomputed from the
#: returned scalings (otherwise the LMI is run)
_CERT_RTOL = 1e-9
#: largest relative excess of the recomputed value over the descent's that is accepted (rounding
#: with scalings over many decades; the value returned is the recomputed one).  A recomputed
#: value below the descent's is always accepted: the scalings prove a lower bound than claimed
#: (the descent's own value carries the rounding of a graded form: 1e-3 too high at d^2 = 4e-14)
_CERT_LOOSE = 1e-7

_PARAMS_CACHE: dict = {}


def _params(S: BlockStructure, use_g: bool) -> _DGParams:
    return _per_structure(_PARAMS_CACHE, 64, S, use_g, _DGParams)


def _lmi_needed(S: BlockStructure, use_g: bool) -> bool:
    """Structures on which the fast descent is not trusted to reach the optimal D-G scalings:
    repeated real scalars with G scalings (their optimum sits on kinks where the descent can
    stop 1e-5..1e-4 above the LMI's value)."""
    return use_g and any(b.kind == "real" and b.rows > 1 for b in S.blocks)


def _gevp_diagonal(M, Dl, Dr, G):
    """:func:`_gevp` for diagonal ``Dl``, ``Dr`` (the scalings of full and 1 x 1 blocks) with
    elementwise square roots; None if a scaling is not diagonal (then :func:`_gevp`), inf if
    one is not positive."""
    dl, dr = Dl.diagonal(), Dr.diagonal()
    # off-diagonal entries (nonzeros beyond the diagonal's) or a complex diagonal: not this form
    if np.count_nonzero(Dl) != np.count_nonzero(dl) or np.count_nonzero(Dr) != np.count_nonzero(dr) \
            or np.count_nonzero(dl.imag) or np.count_nonzero(dr.imag):
        return None
    dl, dr = dl.real, dr.real
    if not (dl.min() > 0 and dr.min() > 0):
        return np.inf
    with np.errstate(over="ignore", invalid="ignore"):
        lh, ri = np.sqrt(dl), 1.0 / np.sqrt(dr)
        A = (lh[:, None] * M) * ri
        c = _pow2_scale(A)           # as in _gevp: exact rescaling of entries that would underflow when squared
        if c != 1.0:
            A = c * A
        H = A.conj().T @ A
        Gt = None
        if G is not None:
            Gt = (ri[:, None] * (c * G)) / lh
            GA = Gt @ A
            H = H + 1j * (GA - GA.conj().T)
    if not np.isfinite(H.sum()):
        return None                 # beyond the double range (or near it): _gevp decides
    w, _, info = _zheevd(H, compute_v=0)       # one triangle: H is Hermitian up to rounding
    lam = w[-1] if info == 0 else np.linalg.eigvalsh(0.5 * (H + H.conj().T))[-1]
    lam = max(float(lam), 0.0)
    return _gevp_certified(M, Dl, Dr, G, float(np.sqrt(lam)) / c,
                           _relative_margin(lam, _rounding_margin(A, Gt)))


def _certify(M, S: BlockStructure, up: MuUpper) -> MuUpper | None:
    """``up`` with its value recomputed from its scalings (the generalised eigenvalue of the
    D-G inequality, as :func:`dg_bound`), or None if that is above the value (beyond rounding)."""
    if up.Dl is None:
        return up
    cert = _gevp_diagonal(M, up.Dl, up.Dr, up.G)
    if cert is None or not abs(cert - up.value) <= _CERT_RTOL * max(up.value, 1e-300):
        cert = _gevp(M, up.Dl, up.Dr, up.G, S)
    # the recomputed value is the bound; above the descent's by more than rounding where the
    # scalings span many decades (_CERT_LOOSE), the descent went wrong; below it, the scalings
    # prove more than the descent saw in its rounding
    if not (np.isfinite(cert) and np.isfinite(up.value)) or cert - up.value > _CERT_LOOSE * max(up.value, 1e-300):
        return None
    up.value = float(cert)
    return up


def _upper_auto(M, S: BlockStructure, use_g: bool, lower, rtol: float, nrm: float | None = None) -> MuUpper:
    """The default bound: the fast D-G descent, certified by its scalings; the LMI where the
    certificate does not reproduce the value, the descent failed, or the structure has
    repeated real scalars (then started from the fast scalings, so one solve confirms them)."""
    up = None
    try:
        up, _ = _fast_default(M, S, _params(S, use_g), nrm=nrm)
        up = _certify(M, S, up)
    except (np.linalg.LinAlgError, ValueError, FloatingPointError):
        up = None
    if up is not None and not _lmi_needed(S, use_g):
        return up
    _, d0, _ = _upper_osborne(M, S)
    if up is None:
        return _lmi_bisect(M, S, use_g, d0, lower, rtol)
    try:
        lmi = _lmi_bisect(M, S, use_g, d0, lower, rtol, start=up, first=1 - 1e-5)
    except SolverError:
        return up
    if lmi.value < up.value:
        return lmi
    up.lower_level = lmi.lower_level
    return up


@validate_params({"method": Options(("auto", "lmi", "osborne", "fast")), "real": Options(("dg", "complex")),
                  "rtol": Real(0, 1, closed="neither"), "lower": NoneOr(Real(lo=0))})
def mu_upper(M, structure: BlockStructure, *, method: str = "auto", real: str = "dg",
             rtol: float = 1e-6, lower: float | None = None) -> MuUpper:
    r"""Upper bound on :math:`\mu_{\boldsymbol\Delta}(M)` by D (or D-G) scaling.

    Parameters
    ----------
    M : (ncols, nrows) array_like
    structure : BlockStructure
    method : {"auto", "lmi", "osborne", "fast"}
        ``"auto"`` (default): the ``"fast"`` D (or D-G) scalings, found by a
        descent that is restarted where it stalls at a kink, with the value
        recomputed from them (the generalised eigenvalue of the D-G
        inequality, as :func:`dg_bound`); the LMI instead when that
        recomputation does not reproduce the value or the descent fails, and
        after it (started from the fast scalings) for structures with
        repeated real scalars, where the descent can stop short of the
        optimum.  No SDP otherwise: on the AB13MD-compatible structures of
        ``tests/test_mu_defaults.py`` it equals SLICOT AB13MD's bound to 1e-6
        (or is below it).
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
        With real blocks (all methods but ``"osborne"``): use the G scalings (tighter) or
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
        cap = _norm2(M)
        if lower > cap * (1 + 1e-9):
            raise ModelError(f"lower={lower!r} cannot be a lower bound on mu: it exceeds sigma_max(M) = "
                             f"{cap:.6g}, an upper bound")
    S = structure
    # the size of M for the range check and the rescaling (mu is homogeneous): the largest
    # entry, within a factor sqrt(size) of sigma_max and without an SVD
    nrm = float(np.abs(M).max())
    if nrm != 0 and not 1e-100 <= nrm <= 1e100:
        # mu is homogeneous: bound mu(M / nrm) and scale back (entries near 1e+-150
        # overflow or underflow in the Gram matrices of the bound)
        low = None if lower is None else float(lower) / nrm
        up = mu_upper(M / nrm, S, method=method, real=real, rtol=rtol, lower=low)
        return MuUpper(float(up.value * nrm), up.method, d=up.d, Dl=up.Dl, Dr=up.Dr,
                       G=None if up.G is None else up.G * nrm, iterations=up.iterations,
                       lower_level=float(up.lower_level * nrm) if up.lower_level is not None else None)
    if nrm == 0 or (len(S) == 1 and S.blocks[0].kind != "real" and S.blocks[0].diagonal_scaling):
        # one full block or one complex 1 x 1 scalar: mu = sigma_max(M)
        return _diag_result(M, S, np.ones(len(S)), "sigma")
    if method == "osborne":
        _, d_os, it_os = _upper_osborne(M, S)
        return _diag_result(M, S, d_os, "osborne", it_os)
    use_g = real == "dg" and S.has_real
    if method == "fast":
        up = _fast_polish(M, S, _DGParams(S, use_g))[0]
        if up.Dl is not None:
            # the bound its scalings prove: where the descent drives the scalings nearly singular
            # with a large G, its double-precision value can sit below that (and below the optimal
            # D-G bound: 7.5e-6 on a repeated real scalar)
            cert = _gevp_diagonal(M, up.Dl, up.Dr, up.G)     # diagonal scalings: no block roots
            up.value = float(_gevp(M, up.Dl, up.Dr, up.G, S) if cert is None else cert)
        return up
    if method == "auto":
        return _upper_auto(M, S, use_g, lower, rtol, nrm)
    # Balance first: the LMI is posed for M0 = L0 M R0^-1 with the best diagonal
    # scaling (Osborne + ellipsoid).  Its remaining scalings are then close to I,
    # which keeps the solver accurate when M is badly scaled (the optimal d
    # spanning many decades).
    _, d0, _ = _upper_osborne(M, S)
    return _lmi_bisect(M, S, use_g, d0, lower, rtol)
