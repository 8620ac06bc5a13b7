r"""The central controller of Glover and Doyle from the Riccati solutions (and the ``D22``
correction).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import IllPosedError, InfeasibleError
from ._plant import _sym, PlantParts
from ._riccati import _normalise_d12_d21, _riccati_solutions


def central_controller(p: PlantParts, g: float):
    r"""The central H-infinity controller at level ``g`` from the Riccati solutions.

    Glover and Doyle's formulas for the general case (Zhou, Doyle and Glover
    [ZDG]_ ch. 17, with the normalisation of ``D12`` and ``D21``), written here
    for a plant with :math:`D_{12} = [0;\ I]`, :math:`D_{21} = [0\ \ I]`
    (any regular plant is brought to this form by :func:`_normalise_d12_d21`:
    orthogonal changes of ``z`` and ``w``, invertible ones of ``u`` and ``y``)
    and :math:`D_{22} = 0` (added back at the end, below).  With
    :math:`D_{1\bullet} = [D_{11}\ D_{12}]`, :math:`D_{\bullet1} = [D_{11};\ D_{21}]`,
    :math:`B = [B_1\ B_2]`, :math:`C = [C_1;\ C_2]`, the stabilizing
    solutions :math:`X_\infty, Y_\infty \succeq 0` of :math:`H_\infty, J_\infty`
    (:func:`riccati_feasible`) and

    .. math::
        F = \begin{bmatrix} F_{11}\\ F_{12}\\ F_2\end{bmatrix}
          = -R^{-1}\bigl(D_{1\bullet}^TC_1 + B^TX_\infty\bigr),\qquad
        L = [L_{11}\ L_{12}\ L_2] = -\bigl(B_1D_{\bullet1}^T + Y_\infty C^T\bigr)\tilde R^{-1},

    partitioned like :math:`w = (w_1, w_2)`, ``u`` and :math:`z = (z_1, z_2)`,
    ``y`` (:math:`w_2` and :math:`z_2` the channels that ``y`` and ``u``
    reach, so :math:`D_{11} = [D_{1111}\ D_{1112};\ D_{1121}\ D_{1122}]`), the
    central controller is :math:`K = (\hat A, \hat B_1, \hat C_1, \hat D_{11})` with

    .. math::
        \hat D_{11} &= -D_{1121}D_{1111}^T(g^2I - D_{1111}D_{1111}^T)^{-1}D_{1112} - D_{1122},\\
        \hat D_{12}\hat D_{12}^T &= I - D_{1121}(g^2I - D_{1111}^TD_{1111})^{-1}D_{1121}^T,\quad
        \hat D_{21}^T\hat D_{21} = I - D_{1112}^T(g^2I - D_{1111}D_{1111}^T)^{-1}D_{1112},\\
        Z_\infty &= (I - g^{-2}Y_\infty X_\infty)^{-1},\quad
        \hat B_2 = Z_\infty(B_2 + L_{12})\hat D_{12},\quad \hat C_2 = -\hat D_{21}(C_2 + F_{12}),\\
        \hat B_1 &= -Z_\infty L_2 + \hat B_2\hat D_{12}^{-1}\hat D_{11},\quad
        \hat C_1 = F_2 + \hat D_{11}\hat D_{21}^{-1}\hat C_2,\quad
        \hat A = A + BF + \hat B_1\hat D_{21}^{-1}\hat C_2 .

    :math:`\hat B_2, \hat C_2, \hat D_{12}, \hat D_{21}` parametrise the other
    suboptimal controllers; in the central one they cancel,
    :math:`\hat B_1 = Z_\infty\bigl((B_2 + L_{12})\hat D_{11} - L_2\bigr)`,
    :math:`\hat C_1 = F_2 - \hat D_{11}(C_2 + F_{12})`, and only the existence of
    :math:`\hat D_{12}, \hat D_{21}` (``g`` above the gains of the ``D11`` blocks)
    is checked.  The realisation is formed in descriptor form,
    :math:`Z_\infty^{-1}\dot x_K = \dots`, and :math:`Z_\infty^{-1}` inverted once
    through its SVD (see the comment in the code for why).  With
    :math:`D_{22} \ne 0` the controller is :math:`K(I + D_{22}K)^{-1}`.

    Parameters
    ----------
    p : PlantParts
        Regular plant (``D12`` full column rank, ``D21`` full row rank).
    g : float
        Level, strictly above the optimal one.

    Returns
    -------
    Ak, Bk, Ck, Dk : ndarray
        The controller ``u = K y`` (same order as the plant).
    info : dict
        ``cond_Z`` (conditioning of :math:`I - g^{-2}Y_\infty X_\infty`, which
        grows as ``g`` nears the optimum) and the largest entries of
        :math:`X_\infty`, :math:`Y_\infty`.

    Raises
    ------
    InfeasibleError
        The Riccati conditions fail at ``g`` (the reason is named).
    IllPosedError
        ``D12`` or ``D21`` rank deficient, or ``I + D22 Dk`` singular.

    References
    ----------
    K. Glover and J. C. Doyle, "State-space formulae for all stabilizing
    controllers that satisfy an H-infinity norm bound and relations to risk
    sensitivity", *Systems & Control Letters* 11 (1988) 167-172; [ZDG]_ ch. 16-17.
    """
    q, Tu, Ty = _normalise_d12_d21(p)
    n, nw, nu, nz, ny = q.sizes
    X, Y, why = _riccati_solutions(q, g)
    if X is None:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: Riccati conditions fail ({why})")
    A, B1, B2, C1, C2, D11 = q.A, q.B1, q.B2, q.C1, q.C2, q.D11
    B, C = np.hstack([B1, B2]), np.vstack([C1, C2])
    D1, Dc = np.hstack([D11, q.D12]), np.vstack([D11, q.D21])
    g2 = g * g
    R = D1.T @ D1 - sla.block_diag(g2 * np.eye(nw), np.zeros((nu, nu)))
    Rt = Dc @ Dc.T - sla.block_diag(g2 * np.eye(nz), np.zeros((ny, ny)))
    F = -np.linalg.solve(R, D1.T @ C1 + B.T @ X)
    L = -np.linalg.solve(Rt.T, (B1 @ Dc.T + Y @ C.T).T).T
    m1, p1 = nw - ny, nz - nu
    F12, F2 = F[m1:nw], F[nw:]
    L12, L2 = L[:, p1:nz], L[:, nz:]
    Dh11 = _dh11(D11, p1, m1, nu, ny, g)
    # Descriptor form: multiplying the controller's state equation by
    # E = I - Y X / g^2 = Z_inf^-1 removes the inverse of E from every product,
    #   E xk' = (E (A + B F) + Bb Dh21^-1 Ch2) xk + Bb y,  u = Ch1 xk + Dh11 y,
    # with Bb = (B2 + L12) Dh11 - L2 (so that Bh1 = Z_inf Bb); E is then inverted
    # once, through its SVD E = U diag(s) V^T, in the coordinates xk = V xt.
    # Near the optimum E is nearly singular; forming Z_inf first and multiplying
    # it into B and A (the textbook order) gave controllers whose closed-loop norm
    # moved by up to 50 % under relative perturbations of 1e-13 of their entries
    # (random plant 2: 1.5 % above the target at back-off 1e-4; 1e-8 in this form).
    E = np.eye(n) - (Y @ X) / g2
    Bb = (B2 + L12) @ Dh11 - L2
    G = -(C2 + F12)                                      # Dh21^-1 Ch2
    Ak, Bh1, Ch1, condZ = _descriptor_inverse(E, E @ (A + B @ F) + Bb @ G, Bb, F2 + Dh11 @ G, g)
    # back to the plant's own u and y: u = Tu u_n, y_n = Ty y
    Bk, Ck, Dk = Bh1 @ Ty, Tu @ Ch1, Tu @ Dh11 @ Ty
    Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, p.D22)
    info = {"cond_Z": condZ, "max_X": float(np.abs(X).max(initial=0.0)),
            "max_Y": float(np.abs(Y).max(initial=0.0))}
    return Ak, Bk, Ck, Dk, info


def _dh11(D11, p1, m1, nu, ny, g):
    r"""The central controller's :math:`\hat D_{11}` (:func:`central_controller`), after checking
    that :math:`\hat D_{12}, \hat D_{21}` exist (``g`` above the gains of the ``D11`` blocks
    the controller can act on; :math:`D_{11}` partitioned at ``p1`` rows, ``m1`` columns)."""
    g2 = g * g
    D1111, D1112, D1121, D1122 = D11[:p1, :m1], D11[:p1, m1:], D11[p1:, :m1], D11[p1:, m1:]
    if p1 and m1:
        Dh11 = -D1121 @ D1111.T @ np.linalg.solve(g2 * np.eye(p1) - D1111 @ D1111.T, D1112) - D1122
        M12 = np.eye(nu) - D1121 @ np.linalg.solve(g2 * np.eye(m1) - D1111.T @ D1111, D1121.T)
        M21 = np.eye(ny) - D1112.T @ np.linalg.solve(g2 * np.eye(p1) - D1111 @ D1111.T, D1112)
    else:  # z = z2 or w = w2: the D1111 terms are absent
        Dh11 = -D1122
        M12 = np.eye(nu) - D1121 @ D1121.T / g2
        M21 = np.eye(ny) - D1112.T @ D1112 / g2
    # Dh12, Dh21 (Cholesky factors of M12, M21) cancel from the central controller's
    # realisation; only their existence is needed
    try:
        np.linalg.cholesky(_sym(M12))
        np.linalg.cholesky(_sym(M21))
    except np.linalg.LinAlgError:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: gamma is below the gain of the "
                              "D11 blocks the controller can act on") from None
    return Dh11


def _descriptor_inverse(E, Ad, Bb, Ch1, g):
    """The controller ``E xk' = Ad xk + Bb y, u = Ch1 xk + ...`` in standard form, ``E``
    inverted once through its SVD ``E = U diag(s) V^T`` in the coordinates ``xk = V xt``.
    Returns ``A, B, C`` and the condition number of ``E``."""
    U, sE, Vt = np.linalg.svd(E)
    condZ = float(sE[0] / sE[-1]) if sE[-1] > 0 else np.inf
    if not condZ < 1e14:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: I - Y_inf X_inf / gamma^2 is singular "
                              f"(cond {condZ:.2g}); gamma is at the coupling limit rho(X_inf Y_inf) = gamma^2")
    return (U.T @ Ad @ Vt.T) / sE[:, None], (U.T @ Bb) / sE[:, None], Ch1 @ Vt.T, condZ


def _add_d22(Ak, Bk, Ck, Dk, D22):
    """Controller for the plant with feedthrough D22 from K0 designed with D22 = 0:
    K = K0 (I + D22 K0)^{-1}."""
    if not np.any(D22):
        return Ak, Bk, Ck, Dk
    E = np.eye(Dk.shape[0]) + Dk @ D22
    if np.linalg.cond(E) > 1e12:
        raise IllPosedError("I + DK*D22 is singular: the controller loop is not well posed with this D22")
    Z = np.linalg.inv(E)
    return (Ak - Bk @ D22 @ Z @ Ck, Bk @ (np.eye(D22.shape[0]) - D22 @ Z @ Dk), Z @ Ck, Z @ Dk)
