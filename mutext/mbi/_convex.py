r"""Model-based identification as worst-case model matching: a convex program in the Youla parameter.

The uncertain parameters of the identification plant sit in the true system only, in parallel
with the engineering model and the controller.  With the engineering model's channels (the force
applied as :math:`-u`, as in :func:`mbi_plant`)

.. math::
    x_e = G_{ew} w + G_{eu} u,\quad y = G_{yw} w + G_{yu} u,\quad u = K y,

and :math:`G_e` stable, the Youla parameter :math:`Q = K(1 - G_{yu}K)^{-1}` makes the controlled
response affine,

.. math::
    F_\ell(G_e, K) = G_{ew} + G_{eu}\,Q\,G_{yw},\qquad K = Q(1 + G_{yu}Q)^{-1},

and every stable :math:`Q` is an internally stabilising :math:`K` (and back).  Robust performance,
:math:`|x_t(\delta, j\omega) - F_\ell(G_e, K)(j\omega)| \le W_z|S(j\omega)|` for every true
system :math:`\delta` in the box, is then a convex constraint on :math:`Q` (Boyd and Barratt
[BB]_: the parameterisation of the achievable loops, ch. 7; a finite (Ritz) basis, ch. 15):
with :math:`Q = \sum_j q_j\phi_j` on a fixed stable rational basis, samples
:math:`\delta_i` of the box and a frequency grid :math:`\omega_k`,

.. math::
    \gamma^\star = \min_{q, \gamma}\ \gamma\quad\text{s.t.}\quad
    |x_t(\delta_i, j\omega_k) - F(j\omega_k; q)| \le \gamma\,|S(j\omega_k)|
    \quad\forall i, k,

a second-order cone program.  Without the basis (a free complex value at each frequency) the
same program is the Chebyshev radius of the sampled responses at each frequency, a lower bound on
:math:`W_z` for any controller at all (it refines :func:`wz_floor`, half the diameter).  The
sampled optimum is not yet a certificate: the controller from :math:`q^\star` is closed on the
plant of :func:`mbi_plant` at :math:`W_z = \gamma^\star(1 + \text{margin})` and its robust
performance is certified by the D-G upper bound of :func:`mutext.mu.mu_sweep`, the margin grown
until :math:`\mu \le 1`.

References
----------
.. [BB] S. Boyd and C. Barratt, *Linear Controller Design: Limits of Performance*, Prentice Hall,
   1991.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import control as ct
import numpy as np

from .._solver import solve as _solve_program
from ..errors import ModelError, SolverError
from ..lti import as_ss, check_finite, freqresp, is_stable, lft_lower, ss
from ..mu import default_grid
from ._floor import _true_systems
from ._result import MBIResult, _fit_on_identifiable_band, _logger
from ._start import _start
from ._plant import MBIPlant, _index, _true_parts, controlled_engineering, mbi_plant
from ._search import WzTry


@dataclass
class ConvexMBIResult(MBIResult):
    r"""Result of :func:`identify_convex` (an :class:`MBIResult` with the convex program's data).

    Attributes
    ----------
    gamma : float
        The sampled optimum :math:`\gamma^\star` (output unit, times ``Ww``): the smallest bound
        any controller of the basis reaches on the sampled true systems and the grid.
    lower : float
        The Chebyshev bound: no controller at all reaches a smaller :math:`W_z` on the samples
        (the largest of ``radius`` over the bound's shape).
    radius : ndarray
        The Chebyshev radius of the sampled true responses at each grid frequency (times ``Ww``).
    Q : control.StateSpace
        The Youla parameter of the basis optimum.
    K_full : control.StateSpace
        :math:`K = Q(1 + G_{yu}Q)^{-1}` before order reduction.
    basis_order : int
        Number of states of the basis (of ``Q``).
    samples : int
        Number of true systems in the program.
    K, Wz, mu_upper, mu_lower, tries, plant, fit, controlled, dk, seconds, omega, notes, floor, measured_fit
        As in :class:`MBIResult` (``dk`` is None: no D-K run; ``mu_upper`` is the certified D-G
        bound of the closed loop at ``Wz``, judged by branch and bound where that bound decides).
    """
    gamma: float = float("nan")
    lower: float = float("nan")
    radius: np.ndarray = field(repr=False, default=None)
    Q: ct.StateSpace = field(repr=False, default=None)
    K_full: ct.StateSpace = field(repr=False, default=None)
    basis_order: int = 0
    samples: int = 0


# --------------------------------------------------------------------------- the engineering channels
def _engineering_channels(E: ct.StateSpace, ports: dict, omega):
    """``(G_ew, G_eu, G_yw, G_yu)`` on ``omega`` with the force applied as ``-u`` (as :func:`mbi_plant`),
    and the SISO state space of ``G_yu``.  The engineering model must be stable."""
    ie = _index(E, ports["excitation"], "input", "engineering model")
    iu = _index(E, ports["control_input"], "input", "engineering model")
    oe = _index(E, ports["measurement"], "output", "engineering model")
    oy = _index(E, ports["control_output"], "output", "engineering model")
    A = np.asarray(E.A, float)
    if A.size and not is_stable(E):
        lam = np.linalg.eigvals(A)
        raise ModelError(f"identify_convex: the engineering model is not stable (pole at "
                         f"{lam[np.argmax(lam.real)]:.4g}); the Youla parameterisation Q = K (1 - G_yu K)^-1 "
                         "used here needs a stable engineering model (a free-free model has poles at s = 0: "
                         "ground it, or use method='dk')")
    H = freqresp(E, omega)
    Gyu = ss(A, -np.asarray(E.B, float)[:, [iu]], np.asarray(E.C, float)[[oy]],
             -np.asarray(E.D, float)[np.ix_([oy], [iu])])
    return H[oe, ie], -H[oe, iu], H[oy, ie], -H[oy, iu], Gyu


# --------------------------------------------------------------------------- the basis
def _channel_zeros(E: ct.StateSpace, ports: dict) -> np.ndarray:
    """The finite zeros of :math:`G_{eu}` and :math:`G_{yw}` (empty where they cannot be computed)."""
    A, B, C, D = (np.asarray(X, float) for X in (E.A, E.B, E.C, E.D))
    out = []
    for o, i in ((ports["measurement"], ports["control_input"]), (ports["control_output"], ports["excitation"])):
        oi, ii = _index(E, o, "output", "engineering model"), _index(E, i, "input", "engineering model")
        try:
            out.append(np.asarray(ct.ss(A, B[:, [ii]], C[[oi]], D[[oi]][:, [ii]]).zeros(), complex))
        except Exception:     # noqa: BLE001 - the basis goes on without them
            continue
    return np.concatenate(out) if out else np.zeros(0, complex)


def _basis_poles(true, E, omega, per_decade: float = 3.0, zeta: float = 0.5, zeros=()) -> np.ndarray:
    """Poles of the basis of ``Q`` (one of each conjugate pair, upper half plane or real):
    the true system's nominal poles and the zeros of :math:`G_{eu}G_{yw}` (the exact match
    :math:`Q = (x_t - G_{ew})/(G_{eu}G_{yw})` has both; a zero in the right half plane mirrored,
    those far outside the grid left out), the engineering model's poles, and well-damped pairs
    spread over the grid (``per_decade``)."""
    from ..uncertain import UncertainModel
    nom = true.nominal() if isinstance(true, UncertainModel) else as_ss(true)
    poles = [np.linalg.eigvals(np.asarray(S.A, float)) for S in (nom, E) if S.nstates]
    lo, hi = float(omega.min()), float(omega.max())
    z = np.asarray(zeros, complex)
    z = z[np.isfinite(z) & (np.abs(z) >= lo / 100) & (np.abs(z) <= hi * 100)]
    z = np.where(z.real < 0, z, -np.conj(z))
    z = z[z.real < -1e-9 * np.abs(z)]                  # a zero on the axis has no stable image
    poles = np.concatenate(poles + [z]) if poles or z.size else np.zeros(0, complex)
    n = max(2, int(np.ceil(per_decade * np.log10(hi / lo))) + 1)
    wn = np.logspace(np.log10(lo), np.log10(hi), n)
    spread = wn * (-zeta + 1j * np.sqrt(1 - zeta ** 2))
    poles = np.concatenate([poles, spread])
    poles = poles[poles.imag >= 0]
    keep = []
    for p in poles:     # drop repeated poles (the true and engineering models share most)
        if all(abs(p - q) > 1e-6 * max(abs(p), 1e-12) for q in keep):
            keep.append(p)
    return np.array(keep, complex)


def _basis_ss(poles: np.ndarray) -> ct.StateSpace:
    """The basis as one state space: input 1, outputs ``[1, phi_1, ..., phi_m]``, each ``phi``
    normalised to a unit peak (a real pole: ``a/(s + a)``; a pair: ``w^2/(s^2 + 2 z w s + w^2)``
    and ``w s/(s^2 + 2 z w s + w^2)``)."""
    blocks, Cs = [], []
    for p in poles:
        if abs(p.imag) <= 1e-12 * abs(p):
            a = -p.real
            blocks.append((np.array([[-a]]), np.array([[a]])))
            Cs.append(np.array([[1.0]]))
        else:
            w2 = abs(p) ** 2
            Ab = np.array([[0.0, 1.0], [-w2, 2 * p.real]])
            Bb = np.array([[0.0], [1.0]])
            Cs.append(np.array([[w2, 0.0], [0.0, abs(p)]]))
            blocks.append((Ab, Bb))
    n = sum(b[0].shape[0] for b in blocks)
    m = sum(c.shape[0] for c in Cs)
    A, B, C = np.zeros((n, n)), np.zeros((n, 1)), np.zeros((m + 1, n))
    D = np.zeros((m + 1, 1))
    D[0, 0] = 1.0
    i = r = 0
    for (Ab, Bb), Cb in zip(blocks, Cs):
        k = Ab.shape[0]
        A[i:i + k, i:i + k] = Ab
        B[i:i + k] = Bb
        C[1 + r:1 + r + Cb.shape[0], i:i + k] = Cb
        i += k
        r += Cb.shape[0]
    return ss(A, B, C, D)


def _normalise_peaks(basis: ct.StateSpace, omega) -> ct.StateSpace:
    """The basis with each output scaled to a unit peak on ``omega``."""
    H = np.abs(freqresp(basis, omega)[:, 0, :]).max(axis=1)
    s = 1.0 / np.where(H > 0, H, 1.0)
    return ss(basis.A, basis.B, s[:, None] * np.asarray(basis.C), s[:, None] * np.asarray(basis.D))


# --------------------------------------------------------------------------- the programs
def _initial_pairs(X, per: int = 4):
    """Constraint pairs ``(sample, frequency)`` to start from: at each frequency the ``per``
    samples farthest from the samples' mean (the rim of the set, where the discs touch)."""
    S, nw = X.shape
    per = min(per, S)
    far = np.argsort(-np.abs(X - X.mean(axis=0)), axis=0)[:per]      # (per, nw)
    return set(zip(far.ravel().tolist(), np.tile(np.arange(nw), per).tolist()))


def _active_set(solve, residual, X, tol: float = 1e-6, add: int = 2, max_rounds: int = 40, pairs=None):
    """Solve a min-max program over all ``(sample, frequency)`` pairs by solving it over a
    working set and adding the violated pairs (the ``add`` worst per frequency) until none is
    violated by more than ``tol`` (relative, the data normalised to about 1).
    ``solve(pairs) -> (level, x)`` with ``level`` the bound (a scalar or one per frequency),
    ``residual(x) -> (samples, nw)`` the scaled residuals; ``pairs`` a working set to start from
    (default: :func:`_initial_pairs`).  Returns ``(level, x, working set)``."""
    pairs = _initial_pairs(X) if pairs is None else set(pairs)
    nw = X.shape[1]
    for _ in range(max_rounds):
        level, x = solve(np.array(sorted(pairs)))
        r = residual(x)
        lev = np.broadcast_to(np.asarray(level, float), (nw,)) * (1 + tol) + tol * 1e-6
        viol = r > lev[None, :]
        if not viol.any():
            return level, x, pairs
        order = np.argsort(-r, axis=0)[:add]                              # (add, nw)
        new = {(int(order[j, k]), k) for k in np.nonzero(viol.any(axis=0))[0].tolist()
               for j in range(order.shape[0]) if viol[order[j, k], k]}
        if not new - pairs:
            return level, x, pairs
        pairs |= new
    raise SolverError(f"identify_convex: the working set of the min-max program did not settle in "
                      f"{max_rounds} rounds")


def _solve(prob, what: str):
    # "optimal_inaccurate" is accepted, and checked by the caller
    if _solve_program(prob, what) not in ("optimal", "optimal_inaccurate"):
        raise SolverError(f"{what}: the program ended {prob.status}")


def model_matching(X, F0, A, scale=None, *, polish: float | None = None, target=None, weights=None):
    r"""The sampled worst-case model-matching program, solved over an active set.

    .. math::
        \min_{q \in \mathbb{R}^m,\ \gamma}\ \gamma\quad\text{s.t.}\quad
        |X_{ik} - F_{0,k} - (A q)_k| \le \gamma\, s_k\quad\forall i, k.

    Parameters
    ----------
    X : array_like, complex, shape (samples, nw)
        The sampled true responses.
    F0 : array_like, complex, shape (nw,)
        The controlled response at ``q = 0`` (:math:`G_{ew}`).
    A : array_like, complex, shape (nw, m)
        The response of each basis function (:math:`G_{eu} \phi_j G_{yw}`).
    scale : array_like, shape (nw,), optional
        The bound's shape :math:`s_k > 0` (default 1).
    polish : float, optional
        A second stage: among the coefficients whose bound is within ``(1 + polish)`` of the
        optimum, those that minimise :math:`\sum_k v_k |T_k - F_{0,k} - (Aq)_k|/s_k`: the
        controlled response as close to the target :math:`T` at every frequency as the bound
        allows (the min-max alone leaves the coefficients free wherever the bound is slack).
    target : array_like, complex, shape (nw,), optional
        The :math:`T` of ``polish`` (default: the mean of the samples).
    weights : array_like, shape (nw,), optional
        The :math:`v_k` of ``polish`` (default 1).

    Returns
    -------
    (gamma, q, pairs) : float, ndarray, int
        The optimum (of the first stage), the coefficients (of the last) and the number of
        constraints of the last working set.
    """
    import cvxpy as cp
    X = np.asarray(X, complex)
    nw = X.shape[1]
    scale = np.ones(nw) if scale is None else np.asarray(scale, float)
    R = X - np.asarray(F0, complex)[None, :]
    unit = float(np.max(np.abs(R) / scale[None, :])) or 1.0
    R = R / unit / scale[None, :]
    A = np.asarray(A, complex) / unit / scale[:, None]
    cn = np.linalg.norm(A, axis=0)
    cn = np.where(cn > 0, cn, 1.0)
    An = A / cn

    def solve(pairs):
        i, k = pairs[:, 0], pairs[:, 1]
        q, g = cp.Variable(An.shape[1]), cp.Variable()
        er = np.real(R[i, k]) - np.real(An[k]) @ q
        ei = np.imag(R[i, k]) - np.imag(An[k]) @ q
        prob = cp.Problem(cp.Minimize(g), [cp.SOC(g * np.ones(len(k)), cp.vstack([er, ei]), axis=0)])
        _solve(prob, "identify_convex: the model-matching program")
        return float(g.value), np.asarray(q.value)

    g, qn, pairs = _active_set(solve, lambda q: np.abs(R - (An @ q)[None, :]), R)
    if polish is None:
        return g * unit, qn / cn, len(pairs)
    # second stage: among the coefficients within (1 + polish) of the optimum, the one closest
    # to the target response over the whole grid (weighted sum of the distances)
    T = (X.mean(axis=0) if target is None else np.asarray(target, complex)) - np.asarray(F0, complex)
    T = T / unit / scale
    wts = np.ones(nw) if weights is None else np.asarray(weights, float)
    wts = wts / wts.sum()
    cap = g * (1 + polish)
    Tr, Ti, Ar, Ai = np.real(T), np.imag(T), np.real(An), np.imag(An)

    def solve2(pairs):
        i, k = pairs[:, 0], pairs[:, 1]
        q, t = cp.Variable(An.shape[1]), cp.Variable(nw)
        er = np.real(R[i, k]) - Ar[k] @ q
        ei = np.imag(R[i, k]) - Ai[k] @ q
        prob = cp.Problem(cp.Minimize(wts @ t), [
            cp.SOC(cap * np.ones(len(k)), cp.vstack([er, ei]), axis=0),
            cp.SOC(t, cp.vstack([Tr - Ar @ q, Ti - Ai @ q]), axis=0)])
        _solve(prob, "identify_convex: the model-matching program (second stage)")
        return cap, np.asarray(q.value)

    _, qn2, pairs = _active_set(solve2, lambda q: np.abs(R - (An @ q)[None, :]), R, pairs=pairs)
    return g * unit, qn2 / cn, len(pairs)


def chebyshev_radius(X, scale=None):
    r"""The Chebyshev radius of sampled complex responses at each frequency.

    .. math::
        r_k = \min_{c_k \in \mathbb{C}}\ \max_i |X_{ik} - c_k|,

    the radius of the smallest disc holding every sample at :math:`\omega_k`: no single
    response, whatever controller makes it, is closer than :math:`r_k` to all of them.  It is
    at least half the widest gap (:func:`wz_floor`'s bound) and at most :math:`2/\sqrt 3` times
    that.  Solved as one second-order cone program (the sum of the radii, which decouples over
    the frequencies) over an active set of the samples.

    Parameters
    ----------
    X : array_like, complex, shape (samples, nw)
        Sampled responses.
    scale : array_like, shape (nw,), optional
        Divides the radii (the shape of a frequency-dependent bound); default 1.

    Returns
    -------
    (radius, centre) : tuple of ndarray, shape (nw,)
        The radius (divided by ``scale``) and the centre of each disc.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.mbi import chebyshev_radius
    >>> X = np.array([[1.0], [-1.0], [1j]])          # three points on the unit circle
    >>> r, c = chebyshev_radius(X)
    >>> round(float(r[0]), 6), round(abs(complex(c[0])), 3)
    (1.0, 0.0)
    """
    import cvxpy as cp
    X = np.asarray(X, complex)
    if X.ndim != 2 or X.shape[0] < 1:
        raise ModelError(f"chebyshev_radius: X must be (samples, frequencies), got shape {X.shape}")
    nw = X.shape[1]
    scale = np.ones(nw) if scale is None else np.asarray(scale, float)
    mean = X.mean(axis=0)
    if X.shape[0] == 1:
        return np.zeros(nw), X[0].copy()
    # each frequency's program is separate: normalised to its own spread
    unit = np.max(np.abs(X - mean[None, :]), axis=0)
    unit = np.where(unit > 0, unit, 1.0)
    Y = (X - mean[None, :]) / unit[None, :]

    def solve(pairs):
        i, k = pairs[:, 0], pairs[:, 1]
        cr, ci, r = cp.Variable(nw), cp.Variable(nw), cp.Variable(nw)
        er = np.real(Y[i, k]) - cr[k]
        ei = np.imag(Y[i, k]) - ci[k]
        prob = cp.Problem(cp.Minimize(cp.sum(r)), [cp.SOC(r[k], cp.vstack([er, ei]), axis=0), r >= 0])
        _solve(prob, "chebyshev_radius")
        return np.asarray(r.value), np.asarray(cr.value) + 1j * np.asarray(ci.value)

    r, c, _ = _active_set(solve, lambda c: np.abs(Y - c[None, :]), Y)
    return r * unit / scale, mean + c * unit


# --------------------------------------------------------------------------- the controller
def _youla_controller(basis: ct.StateSpace, q, Gyu: ct.StateSpace):
    """``(Q, K)``: :math:`Q = \\sum_j q_j\\phi_j` and :math:`K = Q(1 + G_{yu}Q)^{-1}`."""
    C = np.asarray(q, float)[None, :] @ np.asarray(basis.C, float)
    D = np.asarray(q, float)[None, :] @ np.asarray(basis.D, float)
    Q = ss(np.asarray(basis.A, float), np.asarray(basis.B, float), C, D)
    K = ct.feedback(Q, Gyu, sign=-1)          # Q (1 + G_yu Q)^-1
    return Q, ss(np.asarray(K.A, float), np.asarray(K.B, float), np.asarray(K.C, float),
                 np.asarray(K.D, float))


def _sampled_error(probe: MBIPlant, K, X, omega, scale, Ww: float) -> float:
    """The largest :math:`W_w|x_t(\\delta_i) - F_\\ell(G_e, K)|/s` over the samples and the grid."""
    F = freqresp(controlled_engineering(probe, K), omega)[0, 0]
    return float(Ww * np.max(np.abs(X - F[None, :]) / scale[None, :]))


def _reduce(probe: MBIPlant, K, X, omega, scale, Ww: float, target: float, say):
    """The lowest-order balanced truncation of ``K`` (static gain kept) whose loop is stable and
    whose sampled error is at most ``target``; ``(K, its sampled error)`` (``K`` itself if none)."""
    full = _sampled_error(probe, K, X, omega, scale, Ww)
    for order in range(2, K.nstates, 2):
        try:
            with warnings.catch_warnings():       # an order below K's unstable part is raised to it
                warnings.simplefilter("ignore")
                Kr = ct.balred(K, order, method="matchdc")
        except Exception:     # noqa: BLE001 (slycot's reductions raise several kinds) - keep the full K
            continue
        Kr = ss(np.asarray(Kr.A, float), np.asarray(Kr.B, float), np.asarray(Kr.C, float), np.asarray(Kr.D, float))
        if not np.all(np.isfinite(np.asarray(Kr.A))) or not is_stable(lft_lower(probe.P, Kr, 1, 1)):
            continue
        e = _sampled_error(probe, Kr, X, omega, scale, Ww)
        if e <= target:
            say(f"K reduced from {K.nstates} to {order} states (sampled bound {full:.4g} -> {e:.4g})")
            return Kr, e
    return K, full


def _certify(plant_at, K, Wz0: float, lo: float, omega, tol: float, max_tries: int, final_points: int,
             branch: bool, say, progress, t0: float, time_limit):
    """D-G certificates of ``K`` at successive :math:`W_z` (log-log secant toward
    :math:`\\mu = 1 - \\text{tol}/2`, from ``Wz0``, never below ``lo``), each D-G bound that could
    decide judged by branch and bound on the real parameters (``branch``): the tries and their plants."""
    from ..mu import branch_peak, mu_sweep
    from ._search import _next_wz
    tries, plants = [], []
    Wz, hi = Wz0, None
    for k in range(max_tries):
        if time_limit is not None and k > 0 and time.perf_counter() - t0 > time_limit:
            break
        ti = time.perf_counter()
        plant = plant_at(Wz)
        CL = lft_lower(plant.P, K, 1, 1)
        if not is_stable(CL):
            raise SolverError("identify_convex: the loop of K = Q (1 + G_yu Q)^-1 is not stable "
                              "(it should be for any stable Q: a numerical cancellation went wrong)")
        if progress is not None:
            progress(f"certificate {k + 1}/{max_tries}: mu sweep at W_z = {Wz:.4g}", 0.5 + 0.5 * k / max_tries)
        grid = np.unique(np.concatenate([default_grid(CL, n=final_points, decades=1.5), omega]))
        sw = mu_sweep(CL, plant.structure, grid, real="dg")
        mu = mu_dg = float(sw.peak_upper)
        if branch and plant.structure.has_real and mu_dg > 1.0 - tol:
            if progress is not None:
                progress(f"certificate {k + 1}/{max_tries}: branch and bound on the real parameters",
                         0.5 + 0.5 * (k + 0.5) / max_tries)
            H = np.moveaxis(freqresp(CL, sw.omega), -1, 0)
            mu = min(mu_dg, float(branch_peak(H, plant.structure, upper=sw.upper).value))
        tries.append(WzTry(Wz, mu, float(sw.peak_lower), K.nstates, time.perf_counter() - ti, 0, mu_dg))
        plants.append(plant)
        say(f"certificate at W_z = {Wz:.4g}: mu <= {mu:.4f} (lower {sw.peak_lower:.4f}"
            + (f"; D-G bound {mu_dg:.4f})" if mu < mu_dg else ")"))
        if 1.0 - tol <= mu <= 1.0:
            break
        if mu > 1.0:
            lo = max(lo, Wz)
        else:
            hi = Wz if hi is None else min(hi, Wz)
        Wz = _next_wz(tries, Wz, mu, lo, hi, 1.0 - tol / 2)
    return tries, plants


# --------------------------------------------------------------------------- the entry point
def identify_convex(true, engineering, *, excitation: str, measurement: str, control_input: str,
                    control_output: str, Ww: float = 1.0, omega=None, weight: str = "flat",
                    tol: float = 0.01, margin: float = 0.02, max_tries: int = 6, branch: bool = True,
                    reduce_tol: float = 0.01,
                    per_decade: float = 3.0, final_points: int = 200, max_refine: int = 3,
                    polish: float | None = None,
                    max_fit_residual: float = 0.2,
                    time_limit: float | None = None, out=None, progress=None, rng=0) -> ConvexMBIResult:
    r"""Identify the unmodeled dynamics by convex worst-case model matching (Boyd and Barratt [BB91]_).

    The uncertain parameters sit in the true system only, so robust performance of the
    identification plant (:func:`mbi_plant`) asks for one controlled response within
    :math:`W_z` of every true response, and that response is affine in the Youla parameter
    :math:`Q` of the controller (the engineering model stable, the force applied as :math:`-u`):

    .. math::
        F_\ell(G_e, K) = G_{ew} + G_{eu} Q G_{yw},\qquad Q = K(1 - G_{yu}K)^{-1},\qquad
        K = Q(1 + G_{yu}Q)^{-1}.

    With :math:`Q = q_0 + \sum_j q_j\phi_j(s)` on a stable rational basis (the poles of the
    nominal true system and the zeros of :math:`G_{eu}G_{yw}`, which the exact match
    :math:`Q = (x_t - G_{ew})/(G_{eu}G_{yw})` without uncertainty has, mirrored into the left
    half plane where needed; the engineering model's poles; well-damped pairs spread over the
    grid), the true
    systems :math:`x_t(\delta_i)` on a grid of the uncertainty box (as :func:`wz_floor`) and
    the frequency grid :math:`\omega_k`, the smallest bound any controller of the basis reaches
    on the samples is the second-order cone program

    .. math::
        \gamma^\star = \min_{q,\gamma}\ \gamma\quad\text{s.t.}\quad
        W_w|x_t(\delta_i, j\omega_k) - G_{ew} - G_{eu}\,Q(j\omega_k; q)\,G_{yw}|
        \le \gamma\,|S(j\omega_k)|,

    solved by Clarabel over an active set of the constraints.  The same program with a free
    complex response at each frequency gives the Chebyshev radius of the samples
    (:func:`chebyshev_radius`): ``lower``, a bound no controller of any order beats.  The
    controller of :math:`q^\star` is reduced (balanced truncation keeping the static gain, to
    the lowest order within ``reduce_tol`` of its sampled bound) and certified on the
    unregularised plant: :math:`W_z = \gamma(1 + \text{margin})` first, then the log-log secant
    toward :math:`\mu = 1` as :func:`identify` does, each try one D-G sweep
    (:func:`mutext.mu.mu_sweep`, the real parameters kept real), judged by branch and bound on
    the real parameters where the D-G bound could decide it (``branch``).

    Parameters
    ----------
    true, engineering, excitation, measurement, control_input, control_output, Ww
        As in :func:`identify` (a measured FRF is fitted by :func:`true_from_frf`).  The
        engineering model must be stable.
    omega : array_like, optional
        Frequency grid (rad/s) of the program and of the reading of ``K`` (default: as
        :func:`identify`).
    weight : {"flat", "spread"}
        The shape of the bound, as in :func:`identify`.
    tol : float
        Accepted distance of the certified :math:`\mu` below 1.
    branch : bool
        Judge a certificate whose D-G bound is above ``1 - tol`` by branch and bound on the real
        parameters (:func:`mutext.mu.branch_peak`), which closes the D-G bound's gap to
        :math:`\mu` where several parameters are uncertain (trial 4: the D-G bound 1.033 at
        0.46 mm, branch and bound 0.978, the lower bound 0.977).  Some seconds per judged try.
    margin : float
        The first certificate is tried at :math:`\gamma(1 + \text{margin})`.
    max_tries : int
        Largest number of certificates (mu sweeps).
    reduce_tol : float
        Relative growth of the sampled bound allowed to the reduced controller (0: no
        reduction).
    per_decade : float
        Damped basis pairs per decade of the grid.
    final_points : int
        Points of the certificate's grid (added to ``omega``, around the loop's poles).
    polish : float, optional
        A second stage of the program (:func:`model_matching`): among the controllers within
        ``(1 + polish)`` of the sampled optimum, the one whose controlled response is closest to
        the nominal true response over the grid (weighted by the difference the controller has
        to make).  It pins ``K`` down where the bound is slack.  Measured with 0.002: trial 5
        certifies 4.38 mm instead of 4.41 with ``K`` of order 32 instead of 40; trial 4 reads
        ``K`` as 0.996 kg, 4.97 N s/m, 185.3 N/m (against 1, 5, 186) instead of 0.974, 5.03,
        184.7, at 0.448 mm instead of 0.446 mm; trial 1a keeps order 34 instead of 10.  Some
        seconds more per program.  Default None: off.
    max_refine : int
        Largest number of times the program is solved again with the frequencies added where
        the controller's error on the certificate's grid exceeds its sampled bound by more than
        half the ``margin`` (a narrow resonance between the program's frequencies).
    max_fit_residual : float
        For a measured FRF, as in :func:`identify`.
    time_limit : float, optional
        No new certificate is started once this many seconds are spent.
    out : file or None
        A log (default None: silent).
    progress : callable(stage: str, fraction: float), optional
        Called at each stage.
    rng : int or numpy.random.Generator
        Seed of the interior samples of the box (above five parameters only).

    Returns
    -------
    ConvexMBIResult
        ``Wz`` and ``mu_upper`` certified, ``gamma`` the sampled optimum, ``lower`` the
        Chebyshev bound, ``floor`` the :func:`wz_floor` bound, ``K`` (reduced) and ``K_full``.
        If no certificate reached :math:`\mu \le 1`, the try with the lowest :math:`\mu`, with
        a note.

    Raises
    ------
    ModelError
        An unstable engineering model (e.g. free-free: the parameterisation needs a stable
        one), bad ports, options or grid.
    IllPosedError
        An unstable true system, or responses that already agree.

    References
    ----------
    .. [BB91] S. Boyd and C. Barratt, *Linear Controller Design: Limits of Performance*,
       Prentice Hall, 1991 (the parameterisation of the achievable loops, ch. 7; the Ritz
       approximation on a finite basis, ch. 15).

    Examples
    --------
    Trial 1a of the thesis (the engineering spring ``k3`` 186 N/m short, the true one known
    to 1 %) on a grid of 100 frequencies (under a second): the sampled optimum meets the
    Chebyshev bound, and one D-G sweep certifies a bound within 3 % of it.

    >>> import numpy as np
    >>> from mutext.examples import three_mass as tm
    >>> from mutext.mbi import identify_convex
    >>> r = identify_convex(**tm.mbi_arguments(tm.TRIALS["1a"]), omega=np.logspace(-0.3, 1.6, 100),
    ...                     final_points=40)
    >>> bool(r.gamma <= 1.001 * r.lower), bool(r.mu_upper <= 1), bool(r.Wz <= 1.03 * r.lower)
    (True, True, True)
    >>> round(r.fit.dk)                                  # the missing spring [N/m]
    186
    """
    t0 = time.perf_counter()
    _check_options(weight, tol, margin, max_tries, reduce_tol, per_decade, final_points, max_refine, time_limit,
                   polish)
    E = _checked_inputs(true, engineering, weight, branch)
    say = _logger(out)
    ports = dict(excitation=excitation, measurement=measurement, control_input=control_input,
                 control_output=control_output)
    if progress is not None:
        progress("convex MBI: samples of the true systems", 0.0)
    kw = dict(**ports, Ww=Ww, regularization=None)
    start = _start(true, E, kw, omega, None, weight, max_fit_residual, say)
    true, omega, notes = start.true, start.omega, list(start.notes)
    probe = start.plant_at(1.0)
    systems, nominal, i, o = _sampled_true(true, excitation, measurement, rng)
    wp = _program_grid(omega, probe, start.floor, final_points)
    if progress is not None:
        progress("convex MBI: the Chebyshev bound and the model-matching program", 0.1)
    prog = _Program(start, E, ports, probe, systems, nominal, i, o, Ww, say)
    sol = prog.solve(wp, omega, per_decade, polish, reduce_tol, margin, max_refine, final_points)
    K, gamma = sol["K"], sol["gamma"]
    if sol["rounds"]:
        notes.append(f"the program's grid was refined {sol['rounds']} time(s) at the peaks of the controller's "
                     f"error between its frequencies ({sol['wp'].size} frequencies in the end)")
    radius, _ = chebyshev_radius(sol["X"], sol["scale"])
    lower = float(Ww * radius.max())
    say(f"Chebyshev bound {lower:.4g}; floor {start.floor.value:.4g}; sampled error of K on the certificate's "
        f"grid {sol['e_fine']:.4g}")
    if K is not sol["K_full"]:
        notes.append(f"K reduced by balanced truncation (static gain kept) from {sol['K_full'].nstates} to "
                     f"{K.nstates} states: sampled bound {gamma:.4g} -> {sol['e_red']:.4g} (reduce_tol "
                     f"{reduce_tol:g})")

    # the certificate
    base = max(sol["e_fine"], 1e-12 * float(np.max(np.abs(sol["X"]))) * Ww, np.finfo(float).tiny)

    def plant_at(Wz):
        return mbi_plant(true, E, Wz=Wz, **kw, Wz_shape=start.shape)

    tries, plants = _certify(plant_at, K, base * (1 + margin), base, omega, tol, max_tries, final_points,
                             branch, say, progress, t0, time_limit)
    ok = [k for k, t in enumerate(tries) if t.mu_upper <= 1.0]
    best = min(ok, key=lambda k: tries[k].Wz) if ok else int(np.argmin([t.mu_upper for t in tries]))
    plant, t = plants[best], tries[best]
    notes += _certificate_notes(tries, best, bool(ok), gamma, lower, len(systems), sol["wp"].size,
                                prog.basis.nstates)
    if start.measured_fit is not None:
        from types import SimpleNamespace

        from ._measured import _measured_notes
        notes += _measured_notes(plant, SimpleNamespace(K=K), start.measured, start.measured_fit)
    fit = _fit_on_identifiable_band(plant, K, omega, notes)
    if progress is not None:
        progress(f"convex MBI done: W_z = {t.Wz:.4g}, mu <= {t.mu_upper:.4f}", 1.0)
    return ConvexMBIResult(K, t.Wz, t.mu_upper, t.mu_lower, tries, plant, fit, controlled_engineering(plant, K),
                           None, time.perf_counter() - t0, omega, notes, start.floor, start.measured_fit,
                           gamma=gamma, lower=lower, radius=Ww * radius[np.isin(sol["wp"], omega)], Q=sol["Q"],
                           K_full=sol["K_full"], basis_order=prog.basis.nstates, samples=len(systems))


def _checked_inputs(true, engineering, weight: str, branch) -> ct.StateSpace:
    """The engineering model as a state space, checked finite and stable (the Youla
    parameterisation needs it), with ``branch`` and the bound's shape checked against ``true``."""
    from ..response import FRF
    if not isinstance(branch, (bool, np.bool_)):
        raise ModelError(f"identify_convex: branch must be True or False, got {branch!r}")
    if weight == "spread" and isinstance(true, FRF):
        raise ModelError("identify_convex: weight='spread' follows the spread of an uncertain true model; a "
                         "measured FRF has none (use weight='flat')")
    E = as_ss(engineering, "engineering model")
    check_finite(E, "engineering model")
    if E.nstates and not is_stable(E):
        lam = np.linalg.eigvals(np.asarray(E.A, float))
        raise ModelError(f"identify_convex: the engineering model is not stable (pole at "
                         f"{lam[np.argmax(lam.real)]:.4g}); the Youla parameterisation Q = K (1 - G_yu K)^-1 "
                         "needs a stable engineering model (a free-free model has poles at s = 0: ground "
                         "it, or use identify(method='dk'))")
    return E


def _sampled_true(true, excitation, measurement, rng):
    """``(systems, nominal, i, o)``: the true systems on samples of the uncertainty box (one, a
    fixed true system, otherwise), the nominal one, and the channel's input and output index."""
    from ..uncertain import UncertainModel
    if isinstance(true, UncertainModel):
        systems, _, i, o = _true_systems(true, excitation, measurement, "identify_convex", rng)
        return systems, true.nominal(), i, o
    systems = [_true_parts(true, excitation, measurement)[0]]
    return systems, systems[0], 0, 0


def _program_grid(omega, probe: MBIPlant, floor, final_points: int) -> np.ndarray:
    """The program's grid: the search grid, the certificate's span around the systems' poles (a
    measured band leaves K free outside it, where the certificate still looks) and the floor's
    zoom on the widest spread."""
    wp = np.unique(np.concatenate([omega, default_grid(probe.P, n=final_points // 2, decades=1.5)]))
    if np.isfinite(floor.omega):
        wp = np.unique(np.concatenate([wp, floor.omega * np.logspace(-0.02, 0.02, 41)]))
    return wp


class _Program:
    """The model-matching program of one identification: the sampled true responses, the basis
    of Q, and the controller from its optimum (:meth:`solve`)."""

    def __init__(self, start, E, ports, probe: MBIPlant, systems, nominal, i, o, Ww, say):
        self.start, self.E, self.ports, self.probe = start, E, ports, probe
        self.systems, self.nominal, self.i, self.o, self.Ww, self.say = systems, nominal, i, o, Ww, say
        self.basis = None

    def shape(self, w):
        return np.ones(w.size) if self.start.shape is None else np.abs(self.start.shape(w))

    def errors(self, K, w):
        """The sampled error of ``K`` at each frequency of ``w`` (the largest over the samples)."""
        F = freqresp(controlled_engineering(self.probe, K), w)[0, 0]
        X = np.array([freqresp(S, w)[self.o, self.i] for S in self.systems])
        return self.Ww * np.max(np.abs(X - F[None, :]), axis=0) / self.shape(w)

    def solve(self, wp, omega, per_decade, polish, reduce_tol, margin, max_refine, final_points) -> dict:
        """The program on ``wp``, solved again with frequencies added where the controller's error
        on the certificate's grid exceeds its sampled bound by more than half the ``margin``."""
        E, ports, probe, Ww, say = self.E, self.ports, self.probe, self.Ww, self.say
        self.basis = basis = _normalise_peaks(
            _basis_ss(_basis_poles(self.start.true, E, wp, per_decade, zeros=_channel_zeros(E, ports))), wp)
        for rnd in range(max_refine + 1):
            X = np.array([freqresp(S, wp)[self.o, self.i] for S in self.systems])
            scale = self.shape(wp)
            Gew, Geu, Gyw, _, Gyu = _engineering_channels(E, ports, wp)
            A = (Geu * Gyw)[:, None] * freqresp(basis, wp)[:, 0, :].T
            tp = time.perf_counter()
            X0, wts = None, None
            if polish is not None:
                # the polish: the controlled response closest to the nominal true one, relative to
                # the difference the controller has to make there
                X0 = freqresp(self.nominal, wp)[self.o, self.i]
                d = np.abs(X0 - Gew)
                wts = scale / np.maximum(d, 1e-6 * d.max()) if d.max() > 0 else None
            g, q, npairs = model_matching(X, Gew, A, scale, polish=polish, target=X0, weights=wts)
            gamma = float(Ww * g)
            say(f"sampled optimum {gamma:.4g} ({basis.nstates}-state basis, {len(self.systems)} true systems, "
                f"{wp.size} frequencies, {npairs} active constraints, {time.perf_counter() - tp:.2f} s)")
            Q, K_full = _youla_controller(basis, q, Gyu)
            K, e_red = (_reduce(probe, K_full, X, wp, scale, Ww, gamma * (1 + reduce_tol), say) if reduce_tol > 0
                        else (K_full, _sampled_error(probe, K_full, X, wp, scale, Ww)))
            fine = np.unique(np.concatenate([default_grid(lft_lower(probe.P, K, 1, 1), n=final_points,
                                                          decades=1.5), omega]))
            ef = self.errors(K, fine)
            e_fine = max(e_red, float(ef.max()))
            if e_fine <= e_red * (1 + margin / 2) or rnd == max_refine:
                break
            # the local maxima above the bound, each with a narrow zoom, join the program's grid
            peaks = [k for k in range(fine.size) if ef[k] > e_red * (1 + margin / 2)
                     and ef[k] >= ef[max(k - 1, 0)] and ef[k] >= ef[min(k + 1, fine.size - 1)]]
            say(f"  the controller's error reaches {e_fine:.4g} between the program's frequencies: "
                f"{len(peaks)} peak(s) added")
            wp = np.unique(np.concatenate([wp] + [fine[k] * np.logspace(-0.004, 0.004, 5) for k in peaks]))
        return {"K": K, "K_full": K_full, "Q": Q, "gamma": gamma, "X": X, "scale": scale, "wp": wp,
                "e_red": e_red, "e_fine": e_fine, "rounds": rnd}


def _certificate_notes(tries, best: int, passed: bool, gamma, lower, nsys: int, nfreq: int, order: int) -> list:
    """The notes on the program and on the certificate of the try kept."""
    notes = []
    t = tries[best]
    if not passed:
        notes.append(f"no certificate reached mu <= 1 in {len(tries)} tries; returning the lowest mu "
                     f"({t.mu_upper:.4f} at W_z = {t.Wz:.4g})")
    notes.append(f"convex model matching: sampled optimum {gamma:.4g} on {nsys} true systems x "
                 f"{nfreq} frequencies ({order}-state basis of Q); Chebyshev bound {lower:.4g} "
                 f"(no controller reaches less on the samples); certified W_z {t.Wz:.4g} at "
                 f"mu <= {t.mu_upper:.4f} ("
                 + (f"branch and bound; D-G bound {t.mu_dg:.4f}" if t.mu_upper < t.mu_dg else "D-G")
                 + f", unregularised plant) after {len(tries)} sweep(s)")
    return notes


def _check_options(weight, tol, margin, max_tries, reduce_tol, per_decade, final_points, max_refine,
                   time_limit, polish=None) -> None:
    """The options of :func:`identify_convex`, checked."""
    def number(x):
        return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_)) \
            and np.isfinite(x)
    if weight not in ("flat", "spread"):
        raise ModelError(f"identify_convex: weight must be 'flat' or 'spread', got {weight!r}")
    if not (number(tol) and 0 < tol < 1):
        raise ModelError(f"identify_convex: tol must lie in (0, 1), got {tol!r}")
    if not (number(margin) and margin >= 0):
        raise ModelError(f"identify_convex: margin must be a number >= 0, got {margin!r}")
    if not (number(reduce_tol) and reduce_tol >= 0):
        raise ModelError(f"identify_convex: reduce_tol must be a number >= 0, got {reduce_tol!r}")
    if polish is not None and not (number(polish) and polish >= 0):
        raise ModelError(f"identify_convex: polish must be a number >= 0 or None, got {polish!r}")
    if not (number(per_decade) and per_decade > 0):
        raise ModelError(f"identify_convex: per_decade must be positive, got {per_decade!r}")
    for name, v, least in (("max_tries", max_tries, 1), ("final_points", final_points, 3),
                           ("max_refine", max_refine, 0)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < least:
            raise ModelError(f"identify_convex: {name} must be an integer >= {least}, got {v!r}")
    if time_limit is not None and not (number(time_limit) and time_limit > 0):
        raise ModelError(f"identify_convex: time_limit must be a positive number of seconds or None, "
                         f"got {time_limit!r}")
