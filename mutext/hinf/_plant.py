r"""The generalized plant's partition and the checks of the synthesis assumptions."""
from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from ..errors import IllPosedError, ModelError
from ..lti import as_ss, balance_states, check_finite, ss


@dataclass
class PlantParts:
    r"""The blocks of a generalized plant (all 2-D float arrays).

    With ``n`` states, ``nw`` exogenous inputs ``w``, ``nu`` controls ``u``,
    ``nz`` performance outputs ``z`` and ``ny`` measurements ``y``:
    :math:`\dot x = Ax + B_1w + B_2u`, :math:`z = C_1x + D_{11}w + D_{12}u`,
    :math:`y = C_2x + D_{21}w + D_{22}u`.

    Attributes
    ----------
    A : ndarray, shape (n, n)
        State matrix.
    B1 : ndarray, shape (n, nw)
        Input matrix of ``w``.
    B2 : ndarray, shape (n, nu)
        Input matrix of ``u``.
    C1 : ndarray, shape (nz, n)
        Output matrix of ``z``.
    C2 : ndarray, shape (ny, n)
        Output matrix of ``y``.
    D11 : ndarray, shape (nz, nw)
        Feedthrough from ``w`` to ``z``.
    D12 : ndarray, shape (nz, nu)
        Feedthrough from ``u`` to ``z``.
    D21 : ndarray, shape (ny, nw)
        Feedthrough from ``w`` to ``y``.
    D22 : ndarray, shape (ny, nu)
        Feedthrough from ``u`` to ``y``.
    """
    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    C2: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray
    D22: np.ndarray

    @property
    def n(self):
        return self.A.shape[0]

    @property
    def sizes(self):
        """(n, nw, nu, nz, ny)."""
        return self.A.shape[0], self.B1.shape[1], self.B2.shape[1], self.C1.shape[0], self.C2.shape[0]


def _partition(P: ct.StateSpace, nmeas: int, ncon: int) -> PlantParts:
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    nw, nz = P.ninputs - ncon, P.noutputs - nmeas
    return PlantParts(A, B[:, :nw], B[:, nw:], C[:nz], C[nz:],
                      D[:nz, :nw], D[:nz, nw:], D[nz:, :nw], D[nz:, nw:])


def _uncontrollable_modes(A, B, tol=1e-9):
    """Eigenvalues of A in the closed right half plane that (A, B) cannot move (PBH test).

    Scale-invariant: the columns of B are normalised and A - lam I is divided by
    the norm of A, so multiplying A, B or single inputs by a constant does not
    change the answer (an absolute tolerance declared a plant with B scaled by
    1e-8 not stabilizable)."""
    n = A.shape[0]
    normA = float(np.linalg.norm(A, 2)) if A.size else 0.0
    sa = normA if normA > 0 else 1.0
    cb = np.linalg.norm(B, axis=0) if B.size else np.zeros(B.shape[1] if B.ndim == 2 else 0)
    Bn = B[:, cb > 0] / cb[cb > 0] if B.size else B
    bad = []
    for lam in np.linalg.eigvals(A):
        if lam.real < -1e-9 * max(abs(lam), 1e-3 * sa):
            continue
        M = np.hstack([(A - lam * np.eye(n)) / sa, Bn])
        smin = np.linalg.svd(M, compute_uv=False)[-1] if M.size else 0.0
        if smin < tol:
            bad.append(lam)
    return bad


def _axis_rank_losses(parts: PlantParts, tol: float = 1e-9) -> list[tuple[str, str]]:
    r"""Where the Riccati route's rank conditions fail on the imaginary axis.

    The central controller needs :math:`[A - j\omega I,\ B_2;\ C_1,\ D_{12}]` of full column
    rank and :math:`[A - j\omega I,\ B_1;\ C_2,\ D_{21}]` of full row rank at every
    :math:`\omega` (Zhou, Doyle and Glover 1996, sec. 17.1).  Checked at the frequencies where
    they can fail: the imaginary-axis eigenvalues of :math:`A` and, for square invertible
    :math:`D_{12}` or :math:`D_{21}`, those of :math:`A - B_2 D_{12}^{-1} C_1` or
    :math:`A - B_1 D_{21}^{-1} C_2` (the invariant zeros).  A mode on the axis that w cannot
    reach while it reaches y (``B1 = 0`` on that mode) is the common case."""
    A, n = parts.A, parts.A.shape[0]
    if n == 0:
        return []
    sa = max(float(np.linalg.norm(A, 2)), 1.0)

    def axis(M):
        ev = np.linalg.eigvals(M) if M.size else np.zeros(0)
        return [lam for lam in ev if abs(lam.real) <= 1e-9 * max(abs(lam), 1e-3 * sa)]
    out = []
    for what, B, C, D, col in (("[A - jwI, B2; C1, D12]", parts.B2, parts.C1, parts.D12, True),
                               ("[A - jwI, B1; C2, D21]", parts.B1, parts.C2, parts.D21, False)):
        cands = axis(A)
        if D.shape[0] == D.shape[1] and D.size and np.linalg.cond(D) < 1e12:
            with np.errstate(all="ignore"):
                Az = A - B @ np.linalg.solve(D, C)
            # a D of subnormal entries is well conditioned yet its inverse overflows: the
            # invariant zeros are then beyond any frequency, none of them on the axis
            if np.all(np.isfinite(Az)):
                cands += axis(Az)
        bad = []
        for lam in sorted({complex(round(c.real, 12), round(c.imag, 9)) for c in cands}, key=lambda c: c.imag):
            M = np.block([[(A - lam * np.eye(n)) / sa, B], [C, D]])
            sv = np.linalg.svd(M, compute_uv=False)
            need = M.shape[1] if col else M.shape[0]
            if need > min(M.shape) or sv[need - 1] < tol * max(sv[0], 1e-300):
                bad.append(lam)
        if bad:
            out.append((what, ", ".join(f"s = {b.imag:+.6g}j" for b in bad)))
    return out


def _labels(P, kind):
    try:
        return list(P.input_labels if kind == "in" else P.output_labels)
    except AttributeError:  # pragma: no cover
        return []


def check_plant(P, nmeas: int, ncon: int) -> tuple[ct.StateSpace, PlantParts, list[str]]:
    """Validate a generalized plant for H-infinity synthesis.

    Parameters
    ----------
    P : control.StateSpace or control.TransferFunction
        Generalized plant with inputs ``[w; u]`` and outputs ``[z; y]``
        (continuous time).
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``; at least 1,
        fewer than the outputs).
    ncon : int
        Number of control inputs ``u`` (the last inputs of ``P``; at least 1,
        fewer than the inputs).

    Returns
    -------
    P : control.StateSpace
        The plant as a state space.
    parts : PlantParts
        Its blocks.
    notes : list of str
        Properties that are allowed but worth knowing (singular ``D12`` or
        ``D21``, rank loss of the plant's pencils on the imaginary axis).

    Raises
    ------
    ModelError
        Malformed input: port counts, non-finite entries, a control input or
        measurement that is not connected.
    IllPosedError
        No stabilizing controller can exist (``(A, B2)`` not stabilizable or
        ``(C2, A)`` not detectable).
    """
    for name, v in (("nmeas", nmeas), ("ncon", ncon)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"{name} must be a positive integer, got {v!r}")
    P = as_ss(P, "P")
    check_finite(P, "P")
    if ncon >= P.ninputs:
        raise ModelError(f"ncon={ncon} but P has only {P.ninputs} inputs: "
                         "at least one exogenous input w must remain")
    if nmeas >= P.noutputs:
        raise ModelError(f"nmeas={nmeas} but P has only {P.noutputs} outputs: "
                         "at least one performance output z must remain")
    parts = _partition(P, nmeas, ncon)
    notes = []
    # a control input that moves neither the state nor z, or a measurement that
    # sees neither the state nor w, means the port counts are wrong (a different
    # problem would be solved silently)
    ins, outs = _labels(P, "in"), _labels(P, "out")
    Bu = np.vstack([parts.B2, parts.D12])
    Cy = np.hstack([parts.C2, parts.D21])
    ref_in = max(float(np.abs(np.vstack([np.hstack([parts.B1, parts.B2]),
                                          np.hstack([parts.D11, parts.D12])])).max(initial=0.0)), 1e-300)
    ref_out = max(float(np.abs(np.hstack([np.vstack([parts.C1, parts.C2]),
                                          np.vstack([parts.D11, parts.D21])])).max(initial=0.0)), 1e-300)
    for j in range(ncon):
        if np.abs(Bu[:, j]).max(initial=0.0) <= 1e-14 * ref_in:
            k = P.ninputs - ncon + j
            lab = f" ('{ins[k]}')" if k < len(ins) else ""
            raise ModelError(f"ncon={ncon}: control input {k + 1}{lab} of P moves neither the state nor a "
                             f"performance output (its columns of B2 and D12 are zero); the last ncon inputs "
                             f"of P are taken as controls -- is ncon right? (inputs: {', '.join(ins)})")
    for i in range(nmeas):
        if np.abs(Cy[i]).max(initial=0.0) <= 1e-14 * ref_out:
            k = P.noutputs - nmeas + i
            lab = f" ('{outs[k]}')" if k < len(outs) else ""
            raise ModelError(f"nmeas={nmeas}: measurement {k + 1}{lab} of P sees neither the state nor an "
                             f"exogenous input (its rows of C2 and D21 are zero); the last nmeas outputs of P "
                             f"are taken as measurements -- is nmeas right? (outputs: {', '.join(outs)})")
    if parts.n:
        # PBH tests in state coordinates balanced for (A, B2, C2): the test is then
        # invariant to the units of the states (states scaled by 1e-5..1e5 made
        # well-controllable modes look uncontrollable to the fixed tolerance)
        bal, _ = balance_states(ss(parts.A, parts.B2, parts.C2, parts.D22))
        Ab, B2b, C2b = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
        bad = _uncontrollable_modes(Ab, B2b)
        if bad:
            raise IllPosedError(
                "(A, B2) is not stabilizable: the mode(s) at s = "
                + ", ".join(f"{b:.6g}" for b in bad)
                + " are unstable (or on the imaginary axis) and cannot be moved by the control input u")
        bad = _uncontrollable_modes(Ab.T, C2b.T)
        if bad:
            raise IllPosedError(
                "(C2, A) is not detectable: the mode(s) at s = "
                + ", ".join(f"{b:.6g}" for b in bad)
                + " are unstable (or on the imaginary axis) and invisible in the measurement y")
    for what, axis in _axis_rank_losses(parts):
        notes.append(f"{what} loses rank on the imaginary axis at {axis}: outside the Riccati method's "
                     "assumptions; solved by the LMI route. The optimal level may only be approached.")
    r12 = np.linalg.matrix_rank(parts.D12, tol=1e-12 * max(1.0, np.abs(parts.D12).max(initial=0)))
    r21 = np.linalg.matrix_rank(parts.D21, tol=1e-12 * max(1.0, np.abs(parts.D21).max(initial=0)))
    if r12 < ncon:
        notes.append(f"D12 does not have full column rank (rank {r12} < ncon={ncon}): singular problem, "
                     "outside the Riccati method's assumptions; solved by the LMI route. The optimal "
                     "level may only be approached, with controller gains that grow as gamma nears it.")
    if r21 < nmeas:
        notes.append(f"D21 does not have full row rank (rank {r21} < nmeas={nmeas}): singular problem, "
                     "outside the Riccati method's assumptions; solved by the LMI route. The optimal "
                     "level may only be approached, with controller gains that grow as gamma nears it.")
    return P, parts, notes


def _sym(E):
    return 0.5 * (E + E.T)
