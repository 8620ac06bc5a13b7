r"""Model-based identification by mu-synthesis (thesis ch. 3).

A *true* system (measured, or a model standing for the measurement, with its
uncertainty) and an *engineering* model of it are excited by the same input
``w``.  The engineering model gets an extra force input ``u`` and an extra
displacement output ``y`` where it is believed to be wrong; a controller
``u = K y`` is synthesised so that the engineering model's response follows the
true one for every true system in the uncertainty set.  The controller is then
the missing dynamics: with the force applied as :math:`-u`,

.. math::
    K(s) \approx D_u(s) = D_t(s) - D_e(s),

the difference of the local dynamic stiffnesses of the two systems (thesis
eqs. 3.7-3.9; for a mass, damper and spring, :math:`D_u = \Delta m\,s^2 +
\Delta c\,s + \Delta k`).

The generalized plant (thesis fig. 3.3) has inputs ``[w_Delta; w; u]`` and
outputs ``[z_Delta; z; y]``:

.. math::
    A = \begin{bmatrix} A_t & 0\\ 0 & A_e\end{bmatrix},\
    B_1 = \begin{bmatrix} B_t\\ B_{e1}\end{bmatrix} W_w,\
    B_2 = \begin{bmatrix} 0\\ -B_{e2}\end{bmatrix},\
    C_1 = W_z^{-1}\begin{bmatrix} C_t & -C_{e1}\end{bmatrix},\
    C_2 = \begin{bmatrix} 0 & C_{e2}\end{bmatrix},

plus the uncertainty channels ``w_Delta``/``z_Delta`` of the true system's
LFT.  Robust performance (mu at most 1 for the real parameter blocks and a
full complex performance block) means: for every true system in the set,
:math:`|x_t - x_e| \le W_z` for unit excitation :math:`|w| \le W_w`.

The thesis plant has no control penalty and no sensor noise, so ``D12 = 0``
and ``D21 = 0``: a singular H-infinity problem.  Here a small control penalty
:math:`\varepsilon_u u` and sensor noise :math:`\varepsilon_y n` are added
(``regularization``), scaled to the plant so that they change the controller by
far less than the identification error; :func:`identify` reports it and
``tests/test_mbi.py`` measures the effect by halving it.

References
----------
.. [M] R. J. Madden, *Identification of unmodeled dynamics in rotor systems using
   mu-synthesis approach*, M.S. thesis, Cleveland State University, ch. 3.
.. [WPM] Y. Wang, B. Pettinato and E. Maslen, "Model-based identification of
   unmodeled dynamics", 2009 (cited in [M]_).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import control as ct
import numpy as np

from .errors import IllPosedError, InfeasibleError, ModelError, SolverError
from .frfit import MagnitudeFit, fit_envelope
from .lti import as_ss, check_finite, freqresp, is_real_number, is_stable, lft_lower, ss
from .mu import Block, BlockStructure
from .response import FRF, frequency_grid

__all__ = ["MBIPlant", "mbi_plant", "ImpedanceFit", "fit_impedance", "WzTry", "MBIResult", "identify",
           "WzFloor", "wz_floor", "true_spread", "spread_weight", "true_from_frf", "required_impedance"]


def _index(sys, name, kind, what):
    labels = list(sys.input_labels if kind == "input" else sys.output_labels)
    if name not in labels:
        raise ModelError(f"{what}: no {kind} named {name!r}; its {kind}s are {labels}")
    return labels.index(name)


@dataclass
class MBIPlant:
    r"""The model-based identification plant and what it was built from.

    Attributes
    ----------
    P : control.StateSpace
        Inputs ``[w_Delta (nunc); w; (n_y if regularised); u]``, outputs
        ``[z_Delta (nunc); z; (z_u if regularised); y]``.
    structure : BlockStructure
        The real blocks of the true system followed by the full complex
        performance block.
    nunc : int
        Number of uncertainty channels.
    Ww, Wz : float
        Excitation size (unit of the input) and allowed error (unit of the output).
    eps_u, eps_y : float
        Regularisation (control penalty, sensor noise); zero when none.
    Wz_shape : mutext.frfit.MagnitudeFit or None
        The frequency shape of the allowed error: the bound at
        :math:`\omega` is :math:`W_z|S(j\omega)|` (None: flat, :math:`W_z`).
    true : control.StateSpace or mutext.uncertain.UncertainModel
        The true system the plant was built from.
    engineering : control.StateSpace
        The engineering model.
    ports : dict
        Names of the ports: ``excitation``, ``measurement``, ``control_input``, ``control_output``.
    """
    P: ct.StateSpace
    structure: BlockStructure
    nunc: int
    Ww: float
    Wz: float
    eps_u: float
    eps_y: float
    true: object
    engineering: ct.StateSpace
    ports: dict
    Wz_shape: object = None

    nmeas = 1
    ncon = 1

    def bound(self, omega) -> np.ndarray:
        r"""The allowed error at the frequencies ``omega`` (rad/s): :math:`W_z|S(j\omega)|`.

        Parameters
        ----------
        omega : float or array_like
            Frequencies in rad/s.
        """
        omega = np.asarray(omega, float)
        if self.Wz_shape is None:
            return np.full(omega.shape, self.Wz)
        return self.Wz * np.abs(self.Wz_shape(omega))


def _true_parts(true, excitation, measurement):
    """(P_true restricted to [w_unc; excitation] -> [z_unc; measurement], structure blocks, nunc)."""
    from .uncertain import UncertainModel
    if isinstance(true, UncertainModel):
        P = true.P
        nunc = true.nunc
        blocks = list(true.structure.blocks)
    else:
        P = as_ss(true, "true system")
        nunc = 0
        blocks = []
    check_finite(P, "true system")
    i = _index(P, excitation, "input", "true system")
    o = _index(P, measurement, "output", "true system")
    if i < nunc or o < nunc:
        raise ModelError("true system: the excitation/measurement ports must not be uncertainty channels")
    cols = list(range(nunc)) + [i]
    rows = list(range(nunc)) + [o]
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    return ss(A, B[:, cols], C[rows], D[np.ix_(rows, cols)]), blocks, nunc


def mbi_plant(true, engineering, *, excitation: str, measurement: str, control_input: str,
              control_output: str, Ww: float = 1.0, Wz: float = 1e-3,
              regularization: float | None = 1e-4, Wz_shape=None) -> MBIPlant:
    r"""Assemble the mu-controlled model-based identification plant (thesis fig. 3.3).

    Parameters
    ----------
    true : control.StateSpace or mutext.uncertain.UncertainModel
        The true system.  An :class:`~mutext.uncertain.UncertainModel` brings its
        real parameter blocks into the structure.  Must be stable.
    engineering : control.StateSpace
        The engineering model; must have the inputs ``excitation`` and
        ``control_input`` and the outputs ``measurement`` and ``control_output``.
    excitation, measurement : str
        Names of the shared excitation input and measured output (same units in
        both systems, e.g. N and m).
    control_input, control_output : str
        Where the engineering model is unsure: a force input and a displacement
        output at the same place.  The plant applies ``-u`` there, so that
        ``K`` approximates the missing dynamic stiffness :math:`D_u`.
    Ww : float
        Size of the excitation (input unit, e.g. N).
    Wz : float
        Allowed error of the measured output (output unit, e.g. m).
    regularization : float or None
        Relative size of the control penalty and sensor noise that make the
        H-infinity problem regular (None or 0: the singular plant as in the
        thesis).  ``eps_u`` is this times ``Ww``-scaled error per unit force,
        ``eps_y`` this times the typical size of ``y``, both measured on the
        engineering model's static and peak gains.
    Wz_shape : mutext.frfit.MagnitudeFit, optional
        A frequency shape :math:`S` of the allowed error (stable, minimum phase,
        biproper, e.g. :func:`spread_weight`): the error output becomes
        :math:`z = S^{-1}(x_t - x_e)/W_z`, so the bound at :math:`\omega` is
        :math:`W_z|S(j\omega)|`.

    Returns
    -------
    MBIPlant

    Raises
    ------
    ModelError
        Port names that do not exist, non-finite matrices, non-positive weights.
    IllPosedError
        An unstable true or engineering system (the identification compares
        responses, which must exist).
    """
    for name, v in (("Ww", Ww), ("Wz", Wz)):
        if not is_real_number(v) or not np.isfinite(v) or v <= 0:
            raise ModelError(f"{name} must be positive and finite, got {v!r}")
    if regularization is not None and (
            not is_real_number(regularization) or not np.isfinite(regularization) or regularization < 0):
        raise ModelError(f"regularization must be a finite number >= 0 (or None for none), got {regularization!r}")
    if Wz_shape is not None and not isinstance(Wz_shape, MagnitudeFit):
        raise ModelError("Wz_shape must be a mutext.frfit.MagnitudeFit (e.g. from spread_weight), "
                         f"got {type(Wz_shape).__name__}")
    E = as_ss(engineering, "engineering model")
    check_finite(E, "engineering model")
    Pt, blocks, nunc = _true_parts(true, excitation, measurement)
    ie = _index(E, excitation, "input", "engineering model")
    iu = _index(E, control_input, "input", "engineering model")
    oe = _index(E, measurement, "output", "engineering model")
    oy = _index(E, control_output, "output", "engineering model")
    for what, sysm in (("true system", Pt), ("engineering model", E)):
        if sysm.nstates and not is_stable(sysm):
            poles = np.linalg.eigvals(np.asarray(sysm.A, float))
            raise IllPosedError(f"the {what} is unstable (pole at {poles[np.argmax(poles.real)]:.4g}); "
                                "model-based identification compares steady frequency responses")
    At, Bt, Ct, Dt = (np.asarray(X, float) for X in (Pt.A, Pt.B, Pt.C, Pt.D))
    Ae, Be, Ce, De = (np.asarray(X, float) for X in (E.A, E.B, E.C, E.D))
    if abs(De[oy, iu]) > 0 or abs(De[oe, iu]) > 0 or abs(De[oy, ie]) > 0:
        raise ModelError("engineering model: the control and measured outputs must be displacements "
                         "(no direct feedthrough from the inputs)")
    nt, ne = At.shape[0], Ae.shape[0]
    eps_u = eps_y = 0.0
    if regularization:
        # scale the penalty to the plant: the error per unit control force and the
        # size of y per unit excitation, both at the engineering model's static gain
        # and at its largest resonance on a coarse grid
        w = np.logspace(-2, 2, 200) * max(1.0, float(np.max(np.abs(np.linalg.eigvals(Ae)))) / 10)
        H = freqresp(E, w)
        g_zu = np.max(np.abs(H[:, oe, iu])) / Wz
        g_yw = np.max(np.abs(H[:, oy, ie])) * Ww
        eps_u = float(regularization) * g_zu
        eps_y = float(regularization) * g_yw
    reg = bool(regularization)
    # inputs [w_unc (nunc), w, (n), u]; outputs [z_unc (nunc), z, (z_u), y]
    nin = nunc + 1 + (1 if reg else 0) + 1
    nout = nunc + 1 + (1 if reg else 0) + 1
    A = np.block([[At, np.zeros((nt, ne))], [np.zeros((ne, nt)), Ae]])
    B = np.zeros((nt + ne, nin))
    C = np.zeros((nout, nt + ne))
    D = np.zeros((nout, nin))
    iw, iuu = nunc, nin - 1
    oz, oyy = nunc, nout - 1
    B[:nt, :nunc] = Bt[:, :nunc]
    B[:nt, iw] = Bt[:, nunc] * Ww
    B[nt:, iw] = Be[:, ie] * Ww
    B[nt:, iuu] = -Be[:, iu]
    C[:nunc, :nt] = Ct[:nunc]
    D[:nunc, :nunc] = Dt[:nunc, :nunc]
    D[:nunc, iw] = Dt[:nunc, nunc] * Ww
    C[oz, :nt] = Ct[nunc] / Wz
    C[oz, nt:] = -Ce[oe] / Wz
    D[oz, :nunc] = Dt[nunc, :nunc] / Wz
    D[oz, iw] = (Dt[nunc, nunc] - De[oe, ie]) * Ww / Wz
    C[oyy, nt:] = Ce[oy]
    D[oyy, iw] = De[oy, ie] * Ww
    inputs = [f"w_unc{i + 1}" for i in range(nunc)] + ["w"]
    outputs = [f"z_unc{i + 1}" for i in range(nunc)] + ["z"]
    if true is not None and nunc:
        inputs[:nunc] = list(true.P.input_labels[:nunc])
        outputs[:nunc] = list(true.P.output_labels[:nunc])
    if reg:
        D[oyy, nunc + 1] = eps_y
        D[nunc + 1, iuu] = eps_u
        inputs.append("n")
        outputs.append("z_u")
    inputs.append("u")
    outputs.append("y")
    P = ss(A, B, C, D, inputs=inputs, outputs=outputs)
    if Wz_shape is not None:
        P = _shape_output(P, oz, Wz_shape.inverse())
    nperf = 2 if reg else 1
    structure = BlockStructure(blocks + [Block.full(nperf, nperf, "performance")])
    return MBIPlant(P, structure, nunc, float(Ww), float(Wz), eps_u, eps_y, true, E,
                    {"excitation": excitation, "measurement": measurement,
                     "control_input": control_input, "control_output": control_output}, Wz_shape)


def _shape_output(P: ct.StateSpace, row: int, F: ct.StateSpace) -> ct.StateSpace:
    """``P`` with its output ``row`` passed through the SISO filter ``F`` (states of ``F`` appended)."""
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    Af, Bf, Cf, Df = (np.asarray(X, float) for X in (F.A, F.B, F.C, F.D))
    n, nf = A.shape[0], Af.shape[0]
    A2 = np.block([[A, np.zeros((n, nf))], [Bf @ C[row:row + 1], Af]])
    B2 = np.vstack([B, Bf @ D[row:row + 1]])
    C2 = np.hstack([C, np.zeros((C.shape[0], nf))])
    D2 = D.copy()
    C2[row] = np.concatenate([Df[0, 0] * C[row], Cf[0]])
    D2[row] = Df[0, 0] * D[row]
    return ss(A2, B2, C2, D2, inputs=list(P.input_labels), outputs=list(P.output_labels))


def controlled_engineering(plant: MBIPlant, K) -> ct.StateSpace:
    """The engineering model with the identified dynamics attached: input
    ``excitation``, output ``measurement`` (the 'controlled engsys' of the thesis)."""
    E = plant.engineering
    pr = plant.ports
    ie, iu = (list(E.input_labels).index(pr[k]) for k in ("excitation", "control_input"))
    oe, oy = (list(E.output_labels).index(pr[k]) for k in ("measurement", "control_output"))
    A, B, C, D = (np.asarray(X, float) for X in (E.A, E.B, E.C, E.D))
    G = ss(A, np.column_stack([B[:, ie], -B[:, iu]]), C[[oe, oy]], D[np.ix_([oe, oy], [ie, iu])],
           inputs=[pr["excitation"], "u"], outputs=[pr["measurement"], "y"])
    return lft_lower(G, K, 1, 1)


def _channels(plant: MBIPlant, omega):
    """Frequency responses of the nominal performance channels: z<-w, z<-u, y<-w, y<-u."""
    H = freqresp(plant.P, omega)   # (nout, nin, nw)
    n = plant.nunc
    return H[n, n], H[n, -1], H[-1, n], H[-1, -1]


@dataclass
class ImpedanceFit:
    r"""Least-squares reading of a controller as a mass, damper and spring.

    :math:`K(j\omega) \approx dk + j\omega\,dc - \omega^2 dm` on ``band``
    (rad/s), each frequency weighted by how much the measured output depends on
    ``K`` there (see :func:`fit_impedance`).

    Attributes
    ----------
    dm, dc, dk : float
        Added mass (kg), damping (N s/m) and stiffness (N/m).
    residual : float
        Weighted relative residual :math:`\|w(K - \hat K)\| / \|w K\|` (0 = perfect).
    band : tuple of float
        Lowest and highest frequency (rad/s) of the identifiable band.
    fits : bool
        ``residual <= tol``: the mass-damper-spring form describes ``K``.
    description : str
    sigma : tuple of float
        Standard uncertainty of ``(dm, dc, dk)``: with the identification
        weights :math:`|s(\omega)|`, the spread that changes the normalised error
        by about one, i.e. what the measurement cannot tell apart.
    omega : ndarray
        The frequencies (rad/s) of the fit.
    weight : ndarray
        The weight :math:`|s(\omega)|` of each frequency.
    """
    dm: float
    dc: float
    dk: float
    residual: float
    band: tuple
    fits: bool
    description: str
    omega: np.ndarray = field(repr=False, default=None)
    weight: np.ndarray = field(repr=False, default=None)
    sigma: tuple = (np.nan, np.nan, np.nan)

    def response(self, omega) -> np.ndarray:
        """:math:`dk + j\\omega dc - \\omega^2 dm`.

        Parameters
        ----------
        omega : float or array_like
            Frequencies in rad/s.
        """
        w = np.asarray(omega, float)
        return self.dk + 1j * w * self.dc - w ** 2 * self.dm


def identifiable_band(plant: MBIPlant, K, omega):
    r"""Sensitivity of the normalised error to the controller, and the band where it matters.

    A change :math:`\delta K` changes the normalised error by
    :math:`\delta z = s(\omega)\,\delta K` with
    :math:`s = P_{zu}P_{yw}/(1 - P_{yu}K)^2` (nominal channels).  ``K`` is
    pinned down where a 100 % error in it would exceed the allowed error:
    :math:`|s(\omega)\,K(j\omega)| \ge 1`.

    Returns
    -------
    sensitivity : ndarray
        :math:`|s(\omega)|` on ``omega``.
    mask : ndarray of bool
        Frequencies inside the identifiable band.
    """
    omega = np.asarray(omega, float)
    _, Pzu, Pyw, Pyu = _channels(plant, omega)
    Kj = freqresp(as_ss(K), omega)[0, 0]
    s = np.abs(Pzu * Pyw / (1 - Pyu * Kj) ** 2)
    return s, s * np.abs(Kj) >= 1.0


def fit_impedance(K, omega, weight=None, tol: float = 0.1) -> ImpedanceFit:
    r"""Fit :math:`K(j\omega) \approx dk + j\omega dc - \omega^2 dm` by weighted least squares.

    Parameters
    ----------
    K : control.StateSpace or array_like of complex
        The controller, or its frequency response on ``omega``.
    omega : array_like
        Frequencies (rad/s) of the band to fit.
    weight : array_like, optional
        Non-negative weight per frequency (default 1).
    tol : float
        Largest weighted relative residual for which the form is accepted.

    Returns
    -------
    ImpedanceFit
    """
    omega = np.asarray(omega, float).ravel()
    if omega.size < 3:
        raise ModelError(f"fit_impedance needs at least 3 frequencies in the band, got {omega.size}")
    Kj = freqresp(as_ss(K), omega)[0, 0] if isinstance(K, (ct.StateSpace, ct.TransferFunction)) \
        else np.asarray(K, complex).ravel()
    if Kj.shape != omega.shape:
        raise ModelError(f"K has {Kj.size} response values for {omega.size} frequencies")
    if not np.all(np.isfinite(omega)) or np.any(omega <= 0) or omega.max() > 1e100:
        raise ModelError("fit_impedance: omega must hold positive, finite frequencies (rad/s, at most 1e100)")
    if not np.all(np.isfinite(Kj)):
        raise ModelError("fit_impedance: K has non-finite response values on omega")
    if weight is None:
        wgt = np.ones_like(omega)
    else:
        try:
            wgt = np.asarray(weight, float).ravel()
        except (TypeError, ValueError):
            raise ModelError(f"fit_impedance: weight must be an array of real numbers, got {weight!r}") from None
        if wgt.size == 1:
            wgt = np.full(omega.size, float(wgt[0]))
        if wgt.shape != omega.shape:
            raise ModelError(f"fit_impedance: weight has {wgt.size} values for {omega.size} frequencies")
        if not np.all(np.isfinite(wgt)):
            i = int(np.flatnonzero(~np.isfinite(wgt))[0])
            raise ModelError(f"fit_impedance: weight[{i}] is {wgt[i]} (weights must be finite)")
        if np.any(wgt < 0):
            i = int(np.flatnonzero(wgt < 0)[0])
            raise ModelError(f"fit_impedance: weight[{i}] = {wgt[i]:g} is negative (weights must be >= 0)")
        if np.count_nonzero(wgt) < 2:
            raise ModelError(f"fit_impedance: only {np.count_nonzero(wgt)} of the {wgt.size} weights are "
                             "positive; at least 2 frequencies must count to determine mass, damper and spring")
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol >= 0):
        raise ModelError(f"fit_impedance: tol must be a non-negative finite number, got {tol!r}")
    # real part: dk - w^2 dm; imaginary part: w dc; scale the columns for conditioning
    A = np.zeros((2 * omega.size, 3))
    A[:omega.size, 0] = -omega ** 2
    A[:omega.size, 2] = 1.0
    A[omega.size:, 1] = omega
    b = np.concatenate([Kj.real, Kj.imag])
    # only relative weights shape the fit: normalise them (a weight of 1e152 overflowed)
    wscale = float(wgt.max())
    wn = wgt / wscale
    W = np.concatenate([wn, wn])
    col = np.linalg.norm(A * W[:, None], axis=0)
    col[col == 0] = 1.0
    Aw = A * W[:, None] / col
    x, *_ = np.linalg.lstsq(Aw, b * W, rcond=None)
    dm, dc, dk = x / col
    fit = dk + 1j * omega * dc - omega ** 2 * dm
    res = float(np.linalg.norm(wn * (Kj - fit)) / max(np.linalg.norm(wn * Kj), 1e-300))
    # standard uncertainty: the weights are read as inverse standard deviations of K
    # (for the identification weights 1/|s|: the change of K that moves the
    # normalised error by one); without weights, from the residual variance
    cov = np.linalg.pinv(Aw.T @ Aw) / np.outer(col, col) / wscale ** 2
    if weight is None:
        dof = max(2 * omega.size - 3, 1)
        cov *= float(np.sum(np.abs(Kj - fit) ** 2)) / dof
    sigma = np.sqrt(np.maximum(np.diag(cov), 0.0))
    ok = res <= tol
    terms = []
    for val, sd, unit, what in zip((dm, dc, dk), sigma, ("kg", "N s/m", "N/m"), ("mass", "damper", "spring")):
        terms.append(f"{what} {val:+.4g} +/- {sd:.2g} {unit}")
    if ok:
        desc = f"added {', '.join(terms)} (residual {res:.2%})"
    else:
        desc = (f"not a mass-damper-spring: best such fit ({', '.join(terms)}) leaves {res:.0%} of K "
                "unexplained; look at K's shape (resonances, phase) instead")
    return ImpedanceFit(float(dm), float(dc), float(dk), res, (float(omega.min()), float(omega.max())),
                        bool(ok), desc, omega, wgt, tuple(float(v) for v in sigma))


@dataclass
class WzTry:
    """One D-K run of the W_z search.

    Attributes
    ----------
    Wz : float
        The error bound tried (output unit).
    mu_upper : float
        Upper bound of mu of the run's final controller (the branch-and-bound bound where that was run).
    mu_lower : float
        Lower bound of mu of the run's final controller.
    controller_order : int
        Number of states of the controller.
    seconds : float
        Wall time of the run.
    iterations : int
        Number of D-K iterations.
    mu_dg : float
        The D-G upper bound (before branch and bound).
    """
    Wz: float
    mu_upper: float
    mu_lower: float
    controller_order: int
    seconds: float
    iterations: int
    #: the D-G bound (``mu_upper`` is the branch-and-bound bound where that was run)
    mu_dg: float = float("nan")


@dataclass
class MBIResult:
    r"""Result of :func:`identify`.

    Attributes
    ----------
    K : control.StateSpace
        The identified dynamics (force per displacement, applied as :math:`-u`):
        :math:`K \approx D_u`.
    Wz : float
        The accepted error bound (output unit).
    mu_upper, mu_lower : float
        Certified robust-performance bounds of the final controller at ``Wz``.
    tries : list of WzTry
        Every W_z tried, in order.
    plant : MBIPlant
        The plant at the accepted ``Wz``.
    fit : ImpedanceFit
        Mass-damper-spring reading of ``K`` on its identifiable band.
    controlled : control.StateSpace
        The engineering model with ``K`` attached.
    dk : mutext.dk.DKResult
        The final D-K run.
    seconds : float
    notes : list of str
    floor : WzFloor
        The certified lower bound on any achievable ``Wz`` (:func:`wz_floor`).
    measured_fit : mutext.frfit.RationalFit or None
        When the true system was a measured FRF: the rational model that stood in
        for it, with its residual.
    omega : ndarray
        The frequency grid (rad/s) of the search.
    """
    K: ct.StateSpace
    Wz: float
    mu_upper: float
    mu_lower: float
    tries: list
    plant: MBIPlant
    fit: ImpedanceFit
    controlled: ct.StateSpace
    dk: object
    seconds: float
    omega: np.ndarray = field(repr=False, default=None)
    notes: list = field(default_factory=list)
    floor: WzFloor | None = None
    measured_fit: object = None

    def bound(self, omega=None) -> np.ndarray:
        r"""The certified error bound at ``omega`` (default: the search grid): ``Wz``, or
        :math:`W_z|S(j\omega)|` with a shaped bound (``weight="spread"``).

        Parameters
        ----------
        omega : array_like, optional
            Frequencies in rad/s (default: the search grid ``omega``).
        """
        return self.plant.bound(self.omega if omega is None else omega)

    def error(self, true_system, omega=None) -> np.ndarray:
        """|x_true - x_controlled| (output unit per input unit) of a true system over ``omega``.

        Parameters
        ----------
        true_system : control.StateSpace
            A true system with the ports ``excitation`` and ``measurement``.
        omega : array_like, optional
            Frequencies in rad/s (default: the search grid ``omega``).
        """
        omega = self.omega if omega is None else np.asarray(omega, float)
        pr = self.plant.ports
        T = as_ss(true_system)
        i = list(T.input_labels).index(pr["excitation"])
        o = list(T.output_labels).index(pr["measurement"])
        return np.abs(freqresp(T, omega)[o, i] - freqresp(self.controlled, omega)[0, 0])


@dataclass
class WzFloor:
    r"""A certified lower bound on the achievable :math:`W_z` (:func:`wz_floor`).

    Attributes
    ----------
    value : float
        No controller can certify robust performance (:math:`\mu \le 1`) with a
        smaller :math:`W_z` (output unit).
    omega : float
        Frequency (rad/s) where the true systems spread most.
    deltas : tuple of numpy.ndarray
        The two normalised perturbations whose responses are farthest apart there.
    samples : int
        Number of true systems compared.
    """
    value: float
    omega: float
    deltas: tuple
    samples: int


def _delta_samples(m: int, rng=0) -> np.ndarray:
    """Perturbations covering the box [-1, 1]^m: a full grid for few parameters, else
    all vertices (up to 2^8) plus random interior points."""
    if m == 0:
        return np.zeros((1, 0))
    if m <= 5:
        levels = np.linspace(-1.0, 1.0, 5 if m <= 3 else 3)
        return np.array(np.meshgrid(*[levels] * m, indexing="ij")).reshape(m, -1).T
    r = np.random.default_rng(rng)
    verts = (r.choice((-1.0, 1.0), size=(256, m)) if m > 8
             else np.array(np.meshgrid(*[[-1.0, 1.0]] * m, indexing="ij")).reshape(m, -1).T)
    return np.vstack([np.zeros((1, m)), verts, r.uniform(-1.0, 1.0, size=(64, m))])


def _true_systems(true, excitation, measurement, who: str, rng=0):
    """The true systems on a grid of the uncertainty box, closed once: ``(systems, deltas, i, o)``."""
    from .uncertain import UncertainModel
    if not isinstance(true, UncertainModel):
        raise ModelError(f"{who}: the spread of the true systems needs an uncertain true model "
                         f"(mutext.uncertain.UncertainModel), got {type(true).__name__}")
    nom = true.nominal()
    i = _index(nom, excitation, "input", "true system")
    o = _index(nom, measurement, "output", "true system")
    deltas = _delta_samples(len(true.params), rng)
    return [true.close(d) for d in deltas], deltas, i, o


def _half_gaps(systems, i, o, omega):
    """Half the widest gap between the systems' responses at each frequency, and the pair
    that makes it: ``(half (nw,), pair (2, nw) indices into systems)``."""
    R = np.array([freqresp(S, omega)[o, i] for S in systems])      # (samples, nw)
    # widest pair per frequency, one sample against all at a time (memory: samples x nw)
    best, pair = np.zeros(omega.size), np.zeros((2, omega.size), dtype=int)
    for a in range(len(systems)):
        d = np.abs(R - R[a])
        b = np.argmax(d, axis=0)
        da = d[b, np.arange(omega.size)]
        better = da > best
        best[better], pair[0, better], pair[1, better] = da[better], a, b[better]
    return best / 2, pair


def true_spread(true, *, excitation: str, measurement: str, omega=None, rng=0):
    r"""Half the widest gap between the true systems' responses at each frequency.

    .. math::
        r(\omega) = \tfrac12 \max_{\delta_1, \delta_2} |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|,

    over a grid of the uncertainty box (all vertices and interior points for up
    to five parameters): no single controlled response can be closer than
    :math:`r(\omega)` to all of them (:func:`wz_floor` is its maximum,
    :func:`spread_weight` its cover).

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel or control.StateSpace
        The true system (set).
    excitation, measurement : str
        Names of its input and output ports.
    omega : array_like, optional
        Frequencies in rad/s (default: a grid around the nominal poles).
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    (omega, r) : tuple of numpy.ndarray
        The grid (rad/s; default as :func:`wz_floor`) and :math:`r` on it (output unit per input unit).
    """
    return _true_spread(true, excitation, measurement, omega, rng, "true_spread")


def _true_spread(true, excitation, measurement, omega, rng, who):
    systems, _, i, o = _true_systems(true, excitation, measurement, who, rng)
    omega = _floor_grid(true, omega, who)
    return omega, _half_gaps(systems, i, o, omega)[0]


def _floor_grid(true, omega, who: str):
    if omega is None:
        omega = frequency_grid(n=400, poles=np.linalg.eigvals(np.asarray(true.nominal().A, float)))
    omega = np.asarray(omega, float)
    if omega.size == 0:
        raise ModelError(f"{who}: the frequency grid is empty")
    return omega


def wz_floor(true, *, excitation: str, measurement: str, Ww: float = 1.0, omega=None,
             rng=0, shape=None) -> WzFloor:
    r"""The smallest :math:`W_z` that any identification can certify, from the spread of the true set.

    Robust performance at :math:`W_z` means that one controlled response
    :math:`x_c(j\omega)` is within :math:`W_z/W_w` of the response
    :math:`x_t(\delta, j\omega)` of every true system in the uncertainty set.
    Two true systems :math:`\delta_1, \delta_2` whose responses differ by
    :math:`d` therefore force :math:`W_z \ge W_w d/2`, whatever the controller:

    .. math::
        W_z \ge W_w \max_\omega \tfrac12 \max_{\delta_1, \delta_2}
        |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|.

    With a shaped bound :math:`W_z|S(j\omega)|` (``shape``) the same argument
    holds at each frequency, and the floor is the largest of the half-gaps
    divided by :math:`|S(j\omega)|`.  Any finite set of samples and
    frequencies gives a valid (lower) bound; the grid is refined around the
    widest spread.  A true system without uncertainty gives 0.

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel or control.StateSpace
    excitation, measurement : str
        The shared input and measured output.
    Ww : float
        Size of the excitation.
    omega : array_like, optional
        Frequencies (rad/s); default: two decades around the true system's poles.
    shape : mutext.frfit.MagnitudeFit, optional
        The frequency shape of the bound (:func:`spread_weight`); default flat.
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    WzFloor
    """
    from .uncertain import UncertainModel
    if not isinstance(true, UncertainModel):
        return WzFloor(0.0, float("nan"), (), 1)
    omega = _floor_grid(true, omega, "wz_floor")
    systems, deltas, i, o = _true_systems(true, excitation, measurement, "wz_floor", rng)

    def spread(w):
        half, pair = _half_gaps(systems, i, o, w)
        if shape is not None:
            half = half / np.abs(shape(w))
        k = int(np.argmax(half))
        return half[k], w[k], (deltas[pair[0, k]], deltas[pair[1, k]])

    half, wk, pair = spread(omega)
    for _ in range(2):       # lightly damped resonances: zoom in around the widest spread
        h2, w2, p2 = spread(wk * np.logspace(-0.02, 0.02, 81))
        if h2 > half:
            half, wk, pair = h2, w2, p2
    return WzFloor(float(Ww * half), float(wk), pair, len(systems))


def spread_weight(true, *, excitation: str, measurement: str, omega=None, floor: float = 0.02,
                  max_sections: int = 4, rng=0) -> MagnitudeFit:
    r"""The frequency shape of the error bound that follows the spread of the true set.

    A flat bound :math:`W_z` can be no tighter than the spread of the true
    systems where they differ most (:func:`wz_floor`), usually at a resonance;
    everywhere else it is loose, and there the identification leaves ``K``
    free.  Shaped by the spread itself, :math:`W_z|S(j\omega)|` with

    .. math::
        |S(j\omega)| \ge \frac{\tfrac12 \max_{\delta_1, \delta_2}
        |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|}{\max_\omega(\ldots)},

    the bound asks at every frequency for as much as the uncertainty allows,
    and ``K`` is pinned down over the whole band where the true systems' spread
    is resolved.  :math:`S` is the stable, minimum-phase cover of the half-gaps
    on the grid by :func:`mutext.frfit.fit_envelope` (one peaking section per
    resonance of the spread), normalised to a peak of about 1, so that
    :math:`W_z` keeps its meaning at the widest spread.

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel
        The uncertain true system.
    excitation, measurement : str
        The shared input and measured output.
    omega : array_like, optional
        Frequencies (rad/s); default as :func:`wz_floor`.
    floor : float
        Relative level below which the spread is not followed (beyond the last
        resonance it falls to zero, which no proper weight can follow).
    max_sections : int
        Peaking sections of the cover (two poles each; they add to the
        plant's and the controller's order).
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    mutext.frfit.MagnitudeFit
        ``error``: how loose the cover is where it is loosest (log).

    Raises
    ------
    ModelError
        A true system without uncertainty (no spread to follow), a bad grid.
    """
    omega, half = _true_spread(true, excitation, measurement, omega, rng, "spread_weight")
    if not half.max() > 0:
        raise ModelError("spread_weight: the true systems do not spread on this grid: no shape to follow")
    return fit_envelope(omega, half / half.max(), floor=floor, max_sections=max_sections)


def _default_omega(plant: MBIPlant, n: int = 300):
    """A decade either side of the plant's poles."""
    return frequency_grid(n=n, poles=np.linalg.eigvals(np.asarray(plant.P.A, float)))


def true_from_frf(frf, engineering, *, excitation: str, measurement: str, tol: float = 0.02,
                  max_order: int = 24, max_residual: float = 0.2):
    r"""A state-space stand-in for a measured FRF, to serve as the true system.

    The measured response (:class:`mutext.rig.FRF`, SI units, the excitation
    and measurement of the engineering model) is fitted by a stable rational
    model (:func:`mutext.frfit.fit_frf_auto`); its inputs and outputs are
    named ``excitation`` and ``measurement``.

    Parameters
    ----------
    frf : mutext.rig.FRF
        The measured response (SI units).
    engineering : control.StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The engineering model; its modes must lie in the measured band.
    excitation, measurement : str
        Names given to the stand-in's input and output (those of the engineering model).
    tol : float, optional
        Residual at which :func:`mutext.frfit.fit_frf_auto` stops raising the order.
    max_order : int, optional
        Highest order of the rational fit.
    max_residual : float, optional
        Largest RMS relative residual of the fit that is accepted.

    Raises
    ------
    ModelError
        No frequency overlap: none of the engineering model's modes lies in the
        measured band (the identification would compare the two where neither
        says anything about the other), unusable data, or data that no stable
        rational model up to ``max_order`` fits to an RMS relative residual of
        ``max_residual`` (noise, or not a frequency response): identifying
        against such a stand-in would only fit the fit's errors.

    Returns
    -------
    (control.StateSpace, mutext.frfit.RationalFit)
    """
    from .frfit import fit_frf_auto
    E = as_ss(engineering, "engineering model")
    f = np.asarray(frf.freq_hz, float)
    if f.size < 4:
        raise ModelError(f"measured FRF{_source(frf)}: need at least 4 frequencies, got {f.size}")
    modes = np.abs(np.linalg.eigvals(np.asarray(E.A, float))) / (2 * np.pi) if E.nstates else np.zeros(0)
    modes = np.unique(np.round(modes[modes > 0], 9))
    if modes.size and not np.any((modes >= f.min()) & (modes <= f.max())):
        raise ModelError(f"measured FRF{_source(frf)}: no frequency overlap: it covers {f.min():.4g}-{f.max():.4g} Hz, "
                         f"the engineering model's modes lie at {', '.join(f'{m:.4g}' for m in modes[:6])} Hz")
    if not (isinstance(max_residual, (int, float, np.integer, np.floating)) and max_residual > 0):
        raise ModelError(f"max_residual must be a positive number, got {max_residual!r}")
    fit = fit_frf_auto(2 * np.pi * f, frf.response, tol=tol, max_order=max_order)
    over = [n for n in fit.notes if n.startswith("over-fitted")]
    if not fit.residual <= max_residual or over:
        why = over[0] if over else (f"the best stable rational fit (order {fit.order}) leaves an RMS relative "
                                    f"residual of {fit.residual:.3g} > max_residual={max_residual:g}")
        raise ModelError(f"measured FRF{_source(frf)}: cannot serve as the true system: {why}; the data look "
                         "like noise or not like the response of a linear system (check the channel, the "
                         "units and the coherence), or raise max_order / max_residual knowingly")
    sys = ss(fit.system.A, fit.system.B, fit.system.C, fit.system.D, inputs=[excitation], outputs=[measurement])
    return sys, fit


def _source(frf) -> str:
    src = getattr(frf, "source", None)
    return f" {src}" if src else ""


def identify(true, engineering, *, excitation: str, measurement: str, control_input: str,
             control_output: str, Ww: float = 1.0, Wz: float | None = None, tol: float = 0.05,
             max_tries: int = 8, regularization: float | None = 1e-4, omega=None,
             dk_options: dict | None = None, out=None, time_limit: float | None = None,
             max_fit_residual: float = 0.2, progress: Callable[[str, float], None] | None = None,
             real: bool = False, branch: bool = False, weight: str = "flat") -> MBIResult:
    r"""Identify the unmodeled dynamics of ``engineering`` by mu-synthesis (thesis sec. 3.5).

    Runs D-K iteration on the plant of :func:`mbi_plant` and tunes :math:`W_z`
    by the thesis's step-7 rule, automated: :math:`\mu > 1` means the bound is
    too tight (raise :math:`W_z`), :math:`\mu < 1 - \text{tol}` too loose (lower
    it).  Each new value comes from the log-log secant through the last two tries
    (:math:`\mu` scales roughly like :math:`W_z^{-1}`), kept inside the bracket
    once one is known.  Accepted: :math:`1 - \text{tol} \le \mu \le 1`.  No try goes
    below the floor of :func:`wz_floor`, under which :math:`\mu > 1` for every
    controller.

    Parameters
    ----------
    true : control.StateSpace, mutext.uncertain.UncertainModel or mutext.rig.FRF
        As in :func:`mbi_plant`, or a measured FRF from the excitation to the
        measurement (SI units), which :func:`true_from_frf` fits by a stable
        rational model; the grid is then the measured frequencies.
    engineering, excitation, measurement, control_input, control_output, Ww, regularization
        As in :func:`mbi_plant`.
    Wz : float, optional
        First value to try (default: 1 % of the peak open-loop error
        :math:`W_w|x_t - x_e|`, or 1.1 times the floor if that is larger; a
        value at or below the floor is raised to it, with a note).
    tol : float
        Accepted distance of mu below 1.
    max_tries : int
        Largest number of D-K runs.
    omega : array_like, optional
        Frequency grid (rad/s) for the D steps, the identifiable band and the fit.
    dk_options : dict, optional
        Passed to :func:`mutext.dk.dk_iteration` (or :func:`mutext.dk.dgk_iteration`).
    out : file or None
        A log of the search (one line per try, and the D-K tables); default
        None: silent.
    progress : callable(stage: str, fraction: float), optional
        Called during the W_z search (e.g. :class:`mutext.progress.ProgressLine`):
        the D-K stage of each try (passed on to :func:`mutext.dk.dk_iteration`
        unless ``dk_options`` gives its own ``progress``) and the try's
        :math:`W_z`, with the fraction of ``max_tries`` spent; the fraction
        reaches 1 at the end.
    time_limit : float, optional
        Budget in seconds: no new D-K run is started once it is spent (a run
        under way is finished).  The notes of the result report the budget and
        what was used.
    max_fit_residual : float
        For a measured FRF: largest RMS relative residual of its rational fit
        (:func:`true_from_frf`) for which identification goes on.
    real : bool
        Design each try's controller with the uncertain parameters kept real
        (:func:`mutext.dk.dgk_iteration`) instead of plain D-K.  On trial 5
        (10 % uncertainty) it accepts the same :math:`W_z` (4.86 mm), in seven
        times the time: there D-K keeps its first, H-infinity, loop, whose
        D-G bound the later iterations only raise.
    branch : bool
        Judge each try whose D-G bound could decide it (above ``1 - tol``) by
        branch and bound on the real parameters (:func:`mutext.dk.branch_mu`),
        a certified bound that closes the D-G bound's gap to :math:`\mu` where
        the ranges are wide.  On trial 5 (10 % uncertainty) the search then
        accepts 4.72 mm at :math:`\mu` = 0.993, where the D-G bound reads 1.003
        (against 4.86 mm judged by D-G): it can accept values the D-G bound
        rejects.  Each judged try costs some seconds more.
    weight : {"flat", "spread"}
        The frequency shape of the error bound.  ``"flat"`` (the thesis's):
        the error may reach :math:`W_z` at every frequency.  ``"spread"``: the
        bound :math:`W_z|S(j\omega)|` follows the spread of the true systems
        (:func:`spread_weight`; needs an uncertain true model), so that ``K``
        is held wherever the true set is narrow, not only where it is widest.
        With wide uncertainty this is what lets ``K`` be read: on trial 5
        (10 %) a flat bound holds ``K`` on 4.5-7.1 rad/s only (the spring read
        to +/-85 N/m), the shaped one over 0.5-32 rad/s (+/-5 N/m).  :math:`W_z` is then the bound
        at the widest spread, and the floor is the floor of the shaped bound.

    Raises
    ------
    ModelError
        ``max_tries`` not a positive integer, ``time_limit`` not positive,
        a measured FRF that cannot be fitted (see :func:`true_from_frf`), no
        frequency overlap, a bad grid.

    Returns
    -------
    MBIResult
        If no try reached the accepted window, the best try with mu <= 1 (or the
        lowest mu) is returned with a note saying so.

    Examples
    --------
    Trial 1a of the thesis: the engineering model's spring ``k3`` is 200 N/m,
    the rig's 386 N/m.  One D-K run (a few seconds) finds the difference:

    >>> from mutext.examples import three_mass as tm
    >>> from mutext.mbi import identify
    >>> trial = tm.TRIALS["1a"]
    >>> r = identify(**tm.mbi_arguments(trial), max_tries=1, dk_options={"max_iter": 1})
    >>> round(r.fit.dk), trial.Du["dk"]                # the spring K stands for [N/m]
    (186, 186.0)
    >>> bool(r.mu_upper <= 1)                           # the error bound W_z is certified
    True
    """
    t0 = time.perf_counter()
    _check_search_arguments(max_tries, time_limit, tol, real)
    if not isinstance(branch, (bool, np.bool_)):
        raise ModelError(f"identify: branch must be True or False, got {branch!r}")
    if weight not in ("flat", "spread"):
        raise ModelError(f"identify: weight must be 'flat' or 'spread', got {weight!r}")
    if weight == "spread" and isinstance(true, FRF):
        raise ModelError("identify: weight='spread' follows the spread of an uncertain true model; a measured "
                         "FRF has none (use weight='flat')")
    say = _logger(out)
    measured, measured_fit = None, None
    if isinstance(true, FRF):
        measured = true
        true, measured_fit, omega = _true_from_measured(measured, engineering, omega, excitation, measurement,
                                                        max_fit_residual, say)
    kw = dict(excitation=excitation, measurement=measurement, control_input=control_input,
              control_output=control_output, Ww=Ww, regularization=regularization)
    probe = mbi_plant(true, engineering, Wz=1.0, **kw)
    omega = _search_grid(probe, omega)
    diff = _open_loop_difference(probe, omega, excitation, measurement, Ww)
    shape = None
    if weight == "spread":
        shape = spread_weight(true, excitation=excitation, measurement=measurement, omega=omega)
        say(f"error bound shaped by the spread of the true systems ({shape.order} poles; the cover is at most "
            f"{np.exp(shape.error):.2f} times the spread)")
    floor = wz_floor(true, excitation=excitation, measurement=measurement, Ww=Ww, omega=omega, shape=shape)
    Wz, notes = _first_wz(Wz, diff, floor)
    if shape is not None:
        S = np.abs(shape(omega))
        notes.append(f"error bound shaped by the spread of the true systems: W_z |S(jw)|, |S| from "
                     f"{S.min():.3g} to {S.max():.3g} on the grid "
                     f"(a cover of the spread, at most {np.exp(shape.error):.2f} times it)")
    if floor.value > 0:
        say(f"W_z floor {floor.value:.4g} (spread of {floor.samples} true systems at {floor.omega:.4g} rad/s)")
    opts = {"max_iter": 4, "out": None if out is None else out}
    if dk_options is not None and not isinstance(dk_options, dict):
        raise ModelError(f"dk_options must be a dict of dk_iteration's keyword arguments, got "
                         f"{type(dk_options).__name__}")
    import inspect

    from .dk import dgk_iteration, dk_iteration
    # the options go to dk_iteration, or to dgk_iteration when real parameters are kept real
    known = (set(inspect.signature(dk_iteration).parameters) | set(inspect.signature(dgk_iteration).parameters)) \
        - {"P", "structure", "nmeas", "ncon"}
    unknown = sorted(set(dk_options or {}) - known)
    if unknown:
        raise ModelError(f"dk_options: unknown option(s) {', '.join(map(repr, unknown))}; dk_iteration and "
                         f"dgk_iteration take {', '.join(sorted(known))}")
    opts.update(dk_options or {})
    kw["Wz_shape"] = shape
    search = _search_wz(lambda w: mbi_plant(true, engineering, Wz=w, **kw), Wz, floor, omega, opts, tol,
                        max_tries, time_limit, t0, say, progress, real, branch)
    best = _best_try(search.tries)
    plant, res = search.runs[best]
    if search.failed:
        notes.append(f"the K step failed at {len(search.failed)} W_z value(s) ("
                     + ", ".join(f"{w:.4g}" for w, _ in search.failed) + "); the search moved on to looser ones")
    if measured_fit is not None:
        notes += _measured_notes(plant, res, measured, measured_fit)
    notes += _search_notes(search, best, tol, max_tries, time_limit, t0)
    judged = [t for t in search.tries if t.mu_upper < t.mu_dg]
    if judged:
        notes.append(f"branch and bound on the real parameters judged {len(judged)} of {len(search.tries)} "
                     f"tries below their D-G bound (accepted W_z: mu {search.tries[best].mu_upper:.4f}, "
                     f"D-G {search.tries[best].mu_dg:.4f})")
    if plant.eps_u or plant.eps_y:
        notes.append(f"regularised: control penalty {plant.eps_u:.3g} per unit u, sensor noise "
                     f"{plant.eps_y:.3g} (the thesis plant is singular)")
    fit = _fit_on_identifiable_band(plant, res.K, omega, notes)
    if progress is not None:
        progress(f"W_z search done: W_z = {search.tries[best].Wz:.4g}, mu <= {search.tries[best].mu_upper:.4f}",
                 1.0)
    tries = search.tries
    return MBIResult(res.K, tries[best].Wz, tries[best].mu_upper, tries[best].mu_lower, tries, plant, fit,
                     controlled_engineering(plant, res.K), res, time.perf_counter() - t0, omega, notes, floor,
                     measured_fit)


def _logger(out):
    """``say(text)``: a line ``[mbi] text`` on ``out`` (nothing for ``None``)."""
    def say(text):
        if out is not None:
            print(f"[mbi] {text}", file=out, flush=True)
    return say


def _check_search_arguments(max_tries, time_limit, tol, real) -> None:
    if isinstance(max_tries, (bool, np.bool_)) or not isinstance(max_tries, (int, np.integer)) or max_tries < 1:
        raise ModelError(f"identify: max_tries must be a positive integer (the number of D-K runs allowed), "
                         f"got {max_tries!r}")
    if time_limit is not None and (isinstance(time_limit, (bool, np.bool_))
                                   or not isinstance(time_limit, (int, float, np.integer, np.floating))
                                   or not time_limit > 0):
        raise ModelError(f"identify: time_limit must be a positive number of seconds or None, got {time_limit!r}")
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and 0 < tol < 1):
        raise ModelError(f"identify: tol must lie in (0, 1), got {tol!r}")
    if not isinstance(real, (bool, np.bool_)):
        raise ModelError(f"identify: real must be True or False, got {real!r}")


def _true_from_measured(measured, engineering, omega, excitation, measurement, max_fit_residual, say):
    """The true system fitted to a measured FRF, and the grid cut to the measured band (default: its points)."""
    true, measured_fit = true_from_frf(measured, engineering, excitation=excitation, measurement=measurement,
                                       max_residual=max_fit_residual)
    band = 2 * np.pi * np.asarray(measured.freq_hz, float)
    if omega is None:
        omega = band
    else:
        omega = np.asarray(omega, float)
        omega = omega[(omega >= band.min()) & (omega <= band.max())]
        if omega.size == 0:
            raise ModelError(f"identify: no frequency overlap between the grid and the measured FRF "
                             f"({band.min():.4g}-{band.max():.4g} rad/s)")
    say(f"measured FRF: {measured.freq_hz.size} frequencies, "
        f"{measured.freq_hz.min():.4g}-{measured.freq_hz.max():.4g} Hz; fitted by a stable "
        f"model of order {measured_fit.order} (relative residual {measured_fit.residual:.3g})")
    return true, measured_fit, omega


def _search_grid(probe: MBIPlant, omega) -> np.ndarray:
    """The grid of the search (default :func:`_default_omega`), checked to cover the systems' modes."""
    omega = _default_omega(probe) if omega is None else np.asarray(omega, float)
    if omega.size == 0:
        raise ModelError("identify: the frequency grid is empty")
    if not np.all(np.isfinite(omega)) or omega.min() <= 0:
        raise ModelError("identify: the frequency grid must hold positive, finite frequencies (rad/s)")
    modes = np.abs(np.linalg.eigvals(np.asarray(probe.P.A, float)))
    modes = modes[modes > 0]
    if modes.size and (omega.max() < modes.min() / 10 or omega.min() > modes.max() * 10):
        raise ModelError(f"identify: no frequency overlap: the grid spans {omega.min():.4g}-{omega.max():.4g} "
                         f"rad/s, the systems' modes lie at {modes.min():.4g}-{modes.max():.4g} rad/s "
                         "(a decade either side is needed to compare their responses)")
    return omega


def _open_loop_difference(probe: MBIPlant, omega, excitation, measurement, Ww) -> float:
    """Peak open-loop error :math:`|x_t - x_e|` on the grid; an error if the two responses agree."""
    diff = float(np.max(np.abs(freqresp(probe.P, omega)[probe.nunc, probe.nunc])))
    E = probe.engineering
    ref = float(np.max(np.abs(freqresp(E, omega)[list(E.output_labels).index(measurement),
                                                 list(E.input_labels).index(excitation)]))) * Ww
    if diff <= 1e-9 * ref:
        raise IllPosedError("the true and engineering responses are identical on the grid "
                            f"(largest difference {diff:.3g} against {ref:.3g}): there is nothing to identify")
    return diff


def _first_wz(Wz, diff: float, floor: WzFloor):
    """The first W_z of the search (default 1 % of the open-loop error), kept above the floor; and notes."""
    notes = []
    if Wz is None:
        Wz = max(0.01 * diff, 1.1 * floor.value)
    elif Wz <= floor.value:
        notes.append(f"the first W_z {Wz:.4g} is below the floor {floor.value:.4g} set by the "
                     f"spread of the true systems at {floor.omega:.4g} rad/s (no controller can "
                     f"reach it); the search started at {1.1 * floor.value:.4g}")
        Wz = 1.1 * floor.value
    return Wz, notes


@dataclass
class _WzSearch:
    """What the W_z search did: the tries, their (plant, D-K result), the failed K steps, why it stopped."""
    tries: list = field(default_factory=list)
    runs: list = field(default_factory=list)
    failed: list = field(default_factory=list)
    stopped_by_time: bool = False


def _next_wz(tries, Wz: float, mu: float, lo, hi, target: float) -> float:
    """The log-log secant step toward ``mu = target`` (slope -1 on the first try), kept in ``(lo, hi)``."""
    if len(tries) >= 2 and tries[-1].Wz != tries[-2].Wz and tries[-1].mu_upper > 0 and tries[-2].mu_upper > 0:
        a, b = tries[-2], tries[-1]
        slope = (np.log(b.mu_upper) - np.log(a.mu_upper)) / (np.log(b.Wz) - np.log(a.Wz))
        slope = slope if slope < -0.05 else -1.0
    else:
        slope = -1.0
    new = Wz * np.exp((np.log(target) - np.log(max(mu, 1e-12))) / slope)
    if lo is not None and hi is not None:
        if not lo < new < hi:
            new = np.sqrt(lo * hi)
    elif lo is not None and new <= lo:
        new = lo * 1.1
    return float(new)


def _try_progress(progress, k: int, max_tries: int, Wz: float):
    """``progress`` for the D-K run of try ``k`` (0-based): its stages, within the try's share of the bar."""
    def report(stage, fraction):
        progress(f"{stage} (W_z try {k + 1}/{max_tries}, W_z = {Wz:.4g})", (k + fraction) / max_tries)
    return report


def _search_wz(plant_at, Wz: float, floor: WzFloor, omega, opts: dict, tol: float, max_tries: int,
               time_limit, t0: float, say, progress, real: bool = False, branch: bool = False) -> _WzSearch:
    r"""D-K runs at successive :math:`W_z` until :math:`1 - \text{tol} \le \mu \le 1` (see :func:`identify`)."""
    from .dk import branch_mu, dgk_iteration, dk_iteration
    s = _WzSearch()
    lo = floor.value or None    # Wz with mu > 1 (too tight; the floor is one) / mu <= 1
    hi = None
    target = 1.0 - tol / 2
    for k in range(max_tries):
        if time_limit is not None and k > 0 and time.perf_counter() - t0 > time_limit:
            s.stopped_by_time = True
            break
        plant = plant_at(Wz)
        say(f"try {k + 1}: Wz = {Wz:.4g}")
        run_opts = opts
        if progress is not None:
            progress(f"W_z try {k + 1}/{max_tries}: W_z = {Wz:.4g}", k / max_tries)
            if "progress" not in opts:
                run_opts = {**opts, "progress": _try_progress(progress, k, max_tries, Wz)}
        ti = time.perf_counter()
        try:
            synth = dgk_iteration if real and plant.structure.has_real else dk_iteration
            res = synth(plant.P, plant.structure, 1, 1, omega=omega, **run_opts)
        except (SolverError, InfeasibleError) as exc:
            # the controller construction is numerically erratic on some badly scaled plants: a
            # slightly looser W_z is a differently scaled plant, and the search goes on
            s.failed.append((Wz, str(exc)))
            say(f"       the K step failed at this W_z ({str(exc)[:90]}...); trying 7 % looser")
            Wz = float(Wz * 1.07)
            continue
        mu = float(max(res.mu_upper_dg, 0.0)) if np.isfinite(res.mu_upper_dg) else float(res.mu_upper)
        mu_dg = mu
        if branch and plant.structure.has_real and mu > 1.0 - tol:
            if progress is not None:
                progress(f"W_z try {k + 1}/{max_tries}: branch and bound on the real parameters",
                         (k + 0.95) / max_tries)
            mu = min(mu, branch_mu(res, plant.structure).value)
        s.tries.append(WzTry(Wz, mu, float(res.mu_lower), res.controller_order, time.perf_counter() - ti,
                             len(res.history), mu_dg))
        s.runs.append((plant, res))
        say(f"       mu <= {mu:.4f} (lower {res.mu_lower:.4f})"
            + (f"; D-G bound {mu_dg:.4f}" if mu < mu_dg else ""))
        if 1.0 - tol <= mu <= 1.0:
            break
        if mu > 1.0:
            lo = Wz if lo is None else max(lo, Wz)
        else:
            hi = Wz if hi is None else min(hi, Wz)
        Wz = _next_wz(s.tries, Wz, mu, lo, hi, target)
    if not s.runs:
        raise SolverError(f"identify: every D-K run failed ({len(s.failed)} W_z values from {s.failed[0][0]:.4g} "
                          f"to {s.failed[-1][0]:.4g}); the last: {s.failed[-1][1]}")
    return s


def _best_try(tries) -> int:
    """The smallest W_z with mu <= 1, else the lowest mu."""
    ok = [i for i, t in enumerate(tries) if t.mu_upper <= 1.0]
    return min(ok, key=lambda i: tries[i].Wz) if ok else int(np.argmin([t.mu_upper for t in tries]))


def _measured_notes(plant: MBIPlant, res, measured, measured_fit) -> list:
    """How far the controlled model is from the measured data, and how the data were fitted."""
    Gm = np.asarray(measured.response, complex)
    xc = freqresp(controlled_engineering(plant, res.K), 2 * np.pi * np.asarray(measured.freq_hz, float))[0, 0]
    rel = float(np.sqrt(np.mean(np.abs(xc - Gm) ** 2 / np.abs(Gm) ** 2)))
    return [(f"against the measured data themselves the controlled model is off by {rel:.3g} "
             f"(RMS relative; the fit of the data alone leaves {measured_fit.residual:.3g})"),
            (f"true system: the measured FRF fitted by a stable model of order {measured_fit.order} "
             f"(relative residual {measured_fit.residual:.3g})"
             + (f"; {measured_fit.notes[0]}" if measured_fit.notes else ""))]


def _search_notes(search: _WzSearch, best: int, tol: float, max_tries: int, time_limit, t0: float) -> list:
    """A search that stopped outside the accepted window, and the budget used."""
    tries, notes = search.tries, []
    if not 1.0 - tol <= tries[best].mu_upper <= 1.0:
        ok = any(t.mu_upper <= 1.0 for t in tries)
        why = (f"the time limit of {time_limit:g} s was spent" if search.stopped_by_time
               else f"max_tries={max_tries} was reached")
        notes.append(f"W_z search stopped after {len(tries)} tries ({why}) without mu in [{1 - tol:.3g}, 1]; "
                     f"returning the try with {'the smallest W_z at mu <= 1' if ok else 'the lowest mu (> 1)'}")
    limit = "none" if time_limit is None else f"{time_limit:g} s"
    notes.append(f"budget: max_tries {max_tries}, time_limit {limit}; used {len(tries)} D-K run(s) in "
                 f"{time.perf_counter() - t0:.1f} s")
    return notes


def _fit_on_identifiable_band(plant: MBIPlant, K, omega, notes: list) -> ImpedanceFit:
    """The impedance fit of ``K`` on its identifiable band (the whole grid if that band is too thin)."""
    sens, band = identifiable_band(plant, K, omega)
    if band.sum() < 3:
        notes.append("K has almost no identifiable band (|s K| >= 1 at fewer than 3 frequencies); "
                     "the fit uses the whole grid")
        band = np.ones_like(band)
    return fit_impedance(K, omega[band], weight=sens[band])


def impedance_response(coeffs: dict, omega) -> np.ndarray:
    """:math:`dk + j\\omega dc - \\omega^2 dm` for ``coeffs = {"dm", "dc", "dk"}`` (missing keys are 0).

    Parameters
    ----------
    coeffs : dict
        ``{"dm": kg, "dc": N s/m, "dk": N/m}``; a missing key counts as 0.
    omega : float or array_like
        Frequencies in rad/s.

    Examples
    --------
    >>> from mutext.mbi import impedance_response
    >>> impedance_response({"dk": 100.0, "dm": 1.0}, [0.0, 10.0])     # a spring and a mass cancel at 10 rad/s
    array([100.+0.j,   0.+0.j])
    """
    w = np.asarray(omega, float)
    return coeffs.get("dk", 0.0) + 1j * w * coeffs.get("dc", 0.0) - w ** 2 * coeffs.get("dm", 0.0)


def relative_error(K, reference, omega, weight=None) -> float:
    r"""Weighted RMS over ``omega`` of :math:`|K(j\omega) - D(j\omega)| / |D(j\omega)|`, with
    ``K`` a system or a response array on ``omega`` and ``reference`` a dict
    ``{"dm", "dc", "dk"}`` or a response array on ``omega``.

    With ``weight`` the sensitivity :math:`|s(\omega)|` of :func:`identifiable_band`
    (as :attr:`ImpedanceFit.weight` holds it), frequencies count by how strongly the
    measurement constrains ``K`` there; without, equally.

    Parameters
    ----------
    K : StateSpace or (N,) complex array_like
        The identified dynamic stiffness (N/m): a SISO system, or its response on ``omega``.
    reference : dict or (N,) complex array_like
        The reference: ``{"dm", "dc", "dk"}`` (see :func:`impedance_response`) or a response on ``omega``.
    omega : (N,) array_like
        Frequencies in rad/s.
    weight : (N,) array_like, optional
        Sensitivity weight per frequency (:attr:`ImpedanceFit.weight`); equal weights if omitted.
    """
    omega = np.asarray(omega, float)
    D = impedance_response(reference, omega) if isinstance(reference, dict) else np.asarray(reference, complex)
    Kj = np.asarray(K, complex) if isinstance(K, np.ndarray) else freqresp(as_ss(K), omega)[0, 0]
    w2 = np.ones_like(omega) if weight is None else np.asarray(weight, float) ** 2
    for name, arr in (("K", Kj), ("reference", D), ("weight", w2)):
        if np.shape(arr) != omega.shape:
            raise ModelError(f"relative_error: {name} has shape {np.shape(arr)}; it must have one value per "
                             f"frequency ({omega.shape})")
    return float(np.sqrt(np.sum(w2 * np.abs(Kj - D) ** 2 / np.abs(D) ** 2) / np.sum(w2)))


def required_impedance(engineering, frf, *, excitation: str, measurement: str, control_input: str,
                       control_output: str) -> np.ndarray:
    r"""The dynamic stiffness a controller at one port must realise to reproduce a measured FRF exactly.

    With the engineering responses :math:`a = H_{me}`, :math:`b = H_{mu}`,
    :math:`c = H_{ye}`, :math:`e = H_{yu}` (measurement/control output per
    excitation/control input) and a dynamic stiffness :math:`D` added at the
    control port (force :math:`-D\,y`), the measured response is
    :math:`H = a - D\,bc/(1 + De)`, so

    .. math::
        D(\omega) = \frac{a - H}{He - ae + bc}.

    This is the :math:`D_u` that :func:`identify`'s controller approximates
    (:math:`K \approx D_u`), frequency by frequency, without any fit.  Where
    :math:`bc - (a - H)e` vanishes (the port does not move in the mode that
    changed) no finite :math:`D` exists and the value grows without bound:
    the port cannot explain the data there.

    Parameters
    ----------
    engineering : control.StateSpace
        With the four named ports.
    frf : mutext.rig.FRF
        The measured response from ``excitation`` to ``measurement`` (SI).
    excitation, measurement : str
        Names of the engineering model's input and output of the measured FRF.
    control_input, control_output : str
        Names of the force input and displacement output of the port where ``D`` acts.

    Returns
    -------
    ndarray (complex)
        :math:`D` [N/m] at ``frf.freq_hz``.
    """
    E = as_ss(engineering, "engineering model")
    ie = _index(E, excitation, "input", "engineering model")
    iu = _index(E, control_input, "input", "engineering model")
    oe = _index(E, measurement, "output", "engineering model")
    oy = _index(E, control_output, "output", "engineering model")
    H = np.asarray(frf.response, complex)
    G = freqresp(E, 2 * np.pi * np.asarray(frf.freq_hz, float))
    a, b, c, e = G[oe, ie], G[oe, iu], G[oy, ie], G[oy, iu]
    return (a - H) / (H * e - a * e + b * c)
