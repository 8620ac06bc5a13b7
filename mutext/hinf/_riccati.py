r"""The Riccati route: the stabilizing solutions of the two Hamiltonians (for the plant brought
to normalised ``D12``, ``D21``), the existence conditions at a level and the gamma iteration
on them.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import IllPosedError
from ._plant import _sym, PlantParts


def _quasi_eigs(T: np.ndarray) -> np.ndarray:
    """Eigenvalues of a real Schur factor (1x1 and standardised 2x2 diagonal blocks),
    read off the blocks instead of recomputed from scratch."""
    m = T.shape[0]
    ev = np.empty(m, complex)
    i = 0
    while i < m:
        if i + 1 < m and T[i + 1, i] != 0.0:
            a, b, c, d = T[i, i], T[i, i + 1], T[i + 1, i], T[i + 1, i + 1]
            h = 0.5 * (a + d)
            s = np.sqrt(complex((0.5 * (a - d)) ** 2 + b * c))
            ev[i], ev[i + 1] = h + s, h - s
            i += 2
        else:
            ev[i] = T[i, i]
            i += 1
    return ev


def _ric(H: np.ndarray):
    """Stabilizing solution X of the Riccati equation with Hamiltonian H.

    Returns ``(X, "")``, or ``(None, why)`` if H has eigenvalues on (or within
    rounding of) the imaginary axis or its stable subspace is not a graph."""
    n = H.shape[0] // 2
    if not np.all(np.isfinite(H)):
        return None, "the Hamiltonian has non-finite entries"
    try:
        T, Z, sdim = sla.schur(H, output="real", sort="lhp")
    except (np.linalg.LinAlgError, ValueError):  # reordering failed: eigenvalues too close to split
        return None, "the Schur reordering failed (eigenvalues too close to the imaginary axis to separate)"
    ev = _quasi_eigs(T)
    # H is Hamiltonian: its eigenvalues come in pairs (lam, -conj(lam)); one within
    # 1e-10 of the spectral radius from the axis cannot be assigned to either half
    near = np.abs(ev.real) < 1e-10 * max(1.0, float(np.abs(ev).max()))
    if np.any(near) or sdim != n:
        k = int(np.argmin(np.abs(ev.real)))
        return None, f"the Hamiltonian has an eigenvalue on the imaginary axis ({ev[k]:.3g})"
    U1, U2 = Z[:n, :n], Z[n:, :n]
    c = np.linalg.cond(U1)
    if not c < 1e13:
        return None, f"the stable invariant subspace is not a graph (cond U1 = {c:.2g})"
    X = np.linalg.solve(U1.T, U2.T).T
    return _sym(X), ""


_UNDECIDED = "undecided: "


class _Undecided(Exception):
    """The Riccati test cannot be evaluated at a level (see :data:`_UNDECIDED`)."""


def _riccati_solutions(p: PlantParts, g: float):
    """``(X_inf, Y_inf, "")`` at level ``g`` if the four conditions of ZDG Theorem 17.1
    hold, else ``(None, None, why)``; see :func:`riccati_feasible`.  ``why`` starts with
    :data:`_UNDECIDED` when the test could not be evaluated in double precision (``R`` or
    ``R~`` singular to working precision: ``g**2`` lost against the gain of ``D11``)."""
    n, nw, nu, nz, ny = p.sizes
    A, B1, B2, C1, C2, D11, D12, D21 = p.A, p.B1, p.B2, p.C1, p.C2, p.D11, p.D12, p.D21
    P12 = D12 @ np.linalg.pinv(D12)
    P21 = np.linalg.pinv(D21) @ D21
    d = max(np.linalg.norm((np.eye(nz) - P12) @ D11, 2), np.linalg.norm(D11 @ (np.eye(nw) - P21), 2))
    if d >= g:
        return None, None, f"the part of D11 that neither u nor y reaches has gain {d:.6g} >= {g:.6g}"
    B = np.hstack([B1, B2])
    D1 = np.hstack([D11, D12])
    R = D1.T @ D1 - sla.block_diag(g * g * np.eye(nw), np.zeros((nu, nu)))
    try:
        RiX = np.linalg.solve(R, np.hstack([D1.T @ C1, B.T]))
    except np.linalg.LinAlgError:
        # with D12 of full column rank and condition (i) met R is nonsingular; singular here means
        # g**2 vanished against D11'D11 in rounding, so the conditions cannot be checked
        return None, None, (f"{_UNDECIDED}R = D1'D1 - diag(g^2 I, 0) is singular to working precision at "
                            f"g = {g:.6g} (gain of [D11 D12] {np.linalg.norm(D1, 2):.3g})")
    Hx = np.block([[A, np.zeros((n, n))], [-C1.T @ C1, -A.T]]) - np.vstack([B, -C1.T @ D1]) @ RiX
    X, why = _ric(Hx)
    if X is None:
        return None, None, "X_inf: " + why
    C = np.vstack([C1, C2])
    Dc = np.vstack([D11, D21])
    Rt = Dc @ Dc.T - sla.block_diag(g * g * np.eye(nz), np.zeros((ny, ny)))
    try:
        RiY = np.linalg.solve(Rt, np.hstack([Dc @ B1.T, C]))
    except np.linalg.LinAlgError:
        return None, None, (f"{_UNDECIDED}R~ = D.1 D.1' - diag(g^2 I, 0) is singular to working precision at "
                            f"g = {g:.6g} (gain of [D11; D21] {np.linalg.norm(Dc, 2):.3g})")
    Jy = np.block([[A.T, np.zeros((n, n))], [-B1 @ B1.T, -A]]) - np.vstack([C.T, -B1 @ Dc.T]) @ RiY
    Y, why = _ric(Jy)
    if Y is None:
        return None, None, "Y_inf: " + why
    tol = 1e-10
    for name, M in (("X_inf", X), ("Y_inf", Y)):
        e = float(np.linalg.eigvalsh(M).min())
        if e < -tol * max(1.0, np.abs(M).max()):
            return None, None, f"{name} is not positive semidefinite (eigenvalue {e:.3g})"
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    if not rho < g * g:
        return None, None, f"rho(X_inf Y_inf) = {rho:.6g} >= gamma^2 = {g * g:.6g}"
    return X, Y, ""


def riccati_feasible(p: PlantParts, g: float) -> bool:
    r"""Exact test of whether a controller with closed-loop norm < g exists, for
    regular problems (``D12`` full column rank, ``D21`` full row rank).

    The conditions of Zhou, Doyle and Glover, *Robust and Optimal Control*,
    Theorem 17.1 (general case, no normalisation of ``D12``, ``D21``): with
    :math:`R = D_{1\bullet}^TD_{1\bullet} - \mathrm{diag}(g^2I, 0)`,
    :math:`\tilde R = D_{\bullet1}D_{\bullet1}^T - \mathrm{diag}(g^2I, 0)`,
    (i) ``g`` exceeds the gain of the parts of ``D11`` that neither ``u`` nor
    ``y`` can reach; (ii) the Hamiltonian :math:`H_\infty` has a stabilizing
    Riccati solution :math:`X_\infty \succeq 0`; (iii) likewise
    :math:`Y_\infty \succeq 0` for :math:`J_\infty`; (iv)
    :math:`\rho(X_\infty Y_\infty) < g^2`.

    Parameters
    ----------
    p : PlantParts
        The blocks of the generalized plant (:func:`check_plant`).
    g : float
        The level tested (> 0; the closed-loop H-infinity norm to stay below).

    Returns
    -------
    bool
        True when the four conditions hold at ``g``; False when one fails, or when they
        cannot be evaluated in double precision (``R`` or :math:`\tilde R` singular to
        working precision, ``g**2`` lost against the gain of ``D11``).
    """
    return _riccati_solutions(p, g)[2] == ""


def _decided(p: PlantParts, g: float) -> bool:
    """:func:`riccati_feasible` for the bisections: raises :class:`_Undecided` where the test
    cannot be evaluated, instead of counting the level as infeasible (which would move the
    bracket to where double precision gives out, not to the optimum)."""
    why = _riccati_solutions(p, g)[2]
    if why.startswith(_UNDECIDED):
        raise _Undecided(why)
    return why == ""


def _normalise_d12_d21(p: PlantParts):
    r"""The plant with :math:`D_{12} = [0;\ I]` and :math:`D_{21} = [0\ \ I]`.

    ``z`` and ``w`` are rotated (orthogonal, so every closed-loop norm is
    unchanged) and ``u``, ``y`` transformed invertibly: ``u = Tu u_n``,
    ``y_n = Ty y``.  A controller ``K_n`` of the normalised plant is
    ``K = Tu K_n Ty`` for the original.  Raises :class:`IllPosedError` if
    ``D12`` or ``D21`` is rank deficient (singular problem)."""
    _, nw, nu, nz, ny = p.sizes
    U, s, Vt = np.linalg.svd(p.D12)
    U2, s2, Vt2 = np.linalg.svd(p.D21)
    for name, sv, r in (("D12", s, nu), ("D21", s2, ny)):
        if sv.size < r or not sv[-1] > 1e-13 * max(sv[0], 1e-300):
            raise IllPosedError(f"{name} is rank deficient (singular values {np.array2string(sv, precision=3)}): "
                                "the central controller needs D12 full column rank and D21 full row rank")
    Uz = np.hstack([U[:, nu:], U[:, :nu]])            # range of D12 last
    Tu = Vt.T / s[None, :]
    Ww = np.vstack([Vt2[ny:], Vt2[:ny]]).T             # row space of D21 last
    Ty = (U2 / s2[None, :]).T
    D12 = np.vstack([np.zeros((nz - nu, nu)), np.eye(nu)])
    D21 = np.hstack([np.zeros((ny, nw - ny)), np.eye(ny)])
    q = PlantParts(p.A, p.B1 @ Ww, p.B2 @ Tu, Uz.T @ p.C1, Ty @ p.C2, Uz.T @ p.D11 @ Ww, D12, D21,
                   Ty @ p.D22 @ Tu)
    return q, Tu, Ty


def _riccati_level(p: PlantParts, rtol: float = 1e-10, max_steps: int = 200):
    """Optimal level of a regular plant by bisection on :func:`riccati_feasible`
    (the gamma iteration of the Riccati method; geometric bisection).

    Returns ``(gamma, steps)``: ``gamma`` is a level where the Riccati
    conditions hold and ``gamma (1 - rtol)`` one where they fail; or ``None``
    if no feasible level is found or the test cannot be evaluated at a level the
    bisection needs (numerical trouble: the LMIs take over)."""
    q, _, _ = _normalise_d12_d21(p)
    try:
        return _bisect_level(q, rtol, max_steps)
    except _Undecided:
        return None


def _bisect_level(q: PlantParts, rtol: float, max_steps: int):
    """The bisection of :func:`_riccati_level` on the normalised plant ``q``."""
    _, nw, nu, nz, ny = q.sizes
    m1, p1 = nw - ny, nz - nu
    # condition (i): below the gain of [D1111 D1112] and [D1111; D1121] nothing is feasible
    lo = max(np.linalg.norm(q.D11[:p1], 2) if p1 else 0.0, np.linalg.norm(q.D11[:, :m1], 2) if m1 else 0.0)
    steps = 0
    hi = max(2.0 * lo, 1.0)
    while not _decided(q, hi):
        steps += 1
        lo, hi = hi, 4.0 * hi
        if steps > 40 or not np.isfinite(hi):
            return None
    if lo == 0.0:
        lo = hi
        while _decided(q, lo):
            steps += 1
            hi, lo = lo, 0.25 * lo
            if steps > 80:
                return hi, steps      # the level is 0 to double precision
    while hi > lo * (1.0 + rtol) and steps < max_steps:
        steps += 1
        mid = np.sqrt(lo * hi)
        if _decided(q, mid):
            hi = mid
        else:
            lo = mid
    return hi, steps


def _regularised(p: PlantParts, eps: float) -> PlantParts:
    """The plant with ``eps * u`` appended to ``z`` and ``eps * v`` (a new disturbance)
    added to ``y``: ``D12 = [D12; eps I]`` and ``D21 = [D21, eps I]`` have full rank.
    ``w -> z`` of the original is a sub-block of the regularised closed loop, so a
    controller achieving ``g`` on it achieves ``g`` on ``p``."""
    n, _, nu, _, ny = p.sizes
    return PlantParts(p.A, np.hstack([p.B1, np.zeros((n, ny))]), p.B2,
                      np.vstack([p.C1, np.zeros((nu, n))]), p.C2,
                      sla.block_diag(p.D11, np.zeros((nu, ny))), np.vstack([p.D12, eps * np.eye(nu)]),
                      np.hstack([p.D21, eps * np.eye(ny)]), p.D22)


def _near_axis_hint(P, ratio: float = 1e-6) -> str:
    """A note for failure messages when the plant has stable poles so slow, against
    its fastest ones, that an LMI solver cannot resolve them (typically an integrator
    in a performance weight approximated by a pole at 1e-6)."""
    A = np.asarray(P.A, float)
    if A.size == 0:
        return ""
    lam = np.linalg.eigvals(A)
    fast = float(np.abs(lam).max())
    slow = lam[(lam.real < 0) & (np.abs(lam.real) < ratio * fast)]
    if fast == 0 or slow.size == 0:
        return ""
    worst = float(np.abs(slow.real).min())
    return (f" [the plant has {slow.size} stable pole(s) with real part down to {-worst:.3g} against modes up to "
            f"{fast:.3g} rad/s (ratio {worst / fast:.1g}): the LMIs cannot resolve them in double precision; "
            f"moving them to at least {ratio * 10 * fast:.2g} rad/s (e.g. a weight's integrator "
            f"approximation) usually fixes this]")


def _refine_level(p: PlantParts, g_lmi: float, rtol: float = 1e-10):
    """Bisection on :func:`riccati_feasible` around the LMI level.  Returns the
    refined level, or None if the test does not bracket the LMI level or cannot be
    evaluated at a level the bisection needs (the LMI level then stands)."""
    try:
        return _bisect_refine(p, g_lmi, rtol)
    except _Undecided:
        return None


def _bisect_refine(p: PlantParts, g_lmi: float, rtol: float):
    """The bisection of :func:`_refine_level`."""
    hi = g_lmi * (1 + 1e-3)
    for _ in range(8):
        if _decided(p, hi):
            break
        hi *= 1.5
    else:
        return None
    lo = g_lmi * (1 - 1e-2)
    for _ in range(8):
        if not _decided(p, lo):
            break
        lo *= 0.5
    else:
        return None
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if _decided(p, mid):
            hi = mid
        else:
            lo = mid
    return hi
