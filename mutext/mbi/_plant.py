r"""The identification plant (thesis fig. 3.3): the true and engineering systems side by side,
the normalised error output, the regularisation, and the engineering model with the
identified dynamics attached."""
from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from ..errors import IllPosedError, ModelError
from ..frfit import MagnitudeFit
from ..lti import as_ss, check_finite, freqresp, is_real_number, is_stable, lft_lower, ss
from ..mu import Block, BlockStructure
from ..response import frequency_grid


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
    from ..uncertain import UncertainModel
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
    _check_weights(Ww, Wz, regularization, Wz_shape)
    E = as_ss(engineering, "engineering model")
    check_finite(E, "engineering model")
    Pt, blocks, nunc = _true_parts(true, excitation, measurement)
    ports = _Ports(*(_index(E, name, kind, "engineering model") for name, kind in (
        (excitation, "input"), (control_input, "input"), (measurement, "output"), (control_output, "output"))))
    _check_systems(Pt, E, ports)
    eps_u, eps_y = _regularisation(E, ports, Ww, Wz, regularization)
    reg = bool(regularization)
    A, B, C, D = _matrices(Pt, E, nunc, ports, Ww, Wz, eps_u, eps_y, reg)
    inputs, outputs = _labels(true, nunc, reg)
    P = ss(A, B, C, D, inputs=inputs, outputs=outputs)
    if Wz_shape is not None:
        P = _shape_output(P, nunc, Wz_shape.inverse())
    nperf = 2 if reg else 1
    structure = BlockStructure(blocks + [Block.full(nperf, nperf, "performance")])
    return MBIPlant(P, structure, nunc, float(Ww), float(Wz), eps_u, eps_y, true, E,
                    {"excitation": excitation, "measurement": measurement,
                     "control_input": control_input, "control_output": control_output}, Wz_shape)


@dataclass(frozen=True)
class _Ports:
    """Indices into the engineering model: the excitation ``ie`` and control ``iu`` inputs,
    the measured ``oe`` and control ``oy`` outputs."""
    ie: int
    iu: int
    oe: int
    oy: int


def _check_weights(Ww, Wz, regularization, Wz_shape) -> None:
    """The weights and the regularisation of :func:`mbi_plant`, checked."""
    for name, v in (("Ww", Ww), ("Wz", Wz)):
        if not is_real_number(v) or not np.isfinite(v) or v <= 0:
            raise ModelError(f"{name} must be positive and finite, got {v!r}")
    if regularization is not None and (
            not is_real_number(regularization) or not np.isfinite(regularization) or regularization < 0):
        raise ModelError(f"regularization must be a finite number >= 0 (or None for none), got {regularization!r}")
    if Wz_shape is not None and not isinstance(Wz_shape, MagnitudeFit):
        raise ModelError("Wz_shape must be a mutext.frfit.MagnitudeFit (e.g. from spread_weight), "
                         f"got {type(Wz_shape).__name__}")


def _check_systems(Pt: ct.StateSpace, E: ct.StateSpace, ports: _Ports) -> None:
    """Both systems stable; the engineering model's control and measured outputs displacements."""
    for what, sysm in (("true system", Pt), ("engineering model", E)):
        if sysm.nstates and not is_stable(sysm):
            poles = np.linalg.eigvals(np.asarray(sysm.A, float))
            raise IllPosedError(f"the {what} is unstable (pole at {poles[np.argmax(poles.real)]:.4g}); "
                                "model-based identification compares steady frequency responses")
    De = np.asarray(E.D, float)
    if abs(De[ports.oy, ports.iu]) > 0 or abs(De[ports.oe, ports.iu]) > 0 or abs(De[ports.oy, ports.ie]) > 0:
        raise ModelError("engineering model: the control and measured outputs must be displacements "
                         "(no direct feedthrough from the inputs)")


def _regularisation(E: ct.StateSpace, ports: _Ports, Ww: float, Wz: float, regularization):
    """``(eps_u, eps_y)``: the control penalty and the sensor noise (both 0 without regularisation).

    The penalty is scaled to the plant: the error per unit control force and the size of
    ``y`` per unit excitation, both at the engineering model's static gain and at its
    largest resonance on a coarse grid."""
    if not regularization:
        return 0.0, 0.0
    Ae = np.asarray(E.A, float)
    w = np.logspace(-2, 2, 200) * max(1.0, float(np.max(np.abs(np.linalg.eigvals(Ae)))) / 10)
    H = freqresp(E, w)
    g_zu = np.max(np.abs(H[:, ports.oe, ports.iu])) / Wz
    g_yw = np.max(np.abs(H[:, ports.oy, ports.ie])) * Ww
    return float(regularization) * g_zu, float(regularization) * g_yw


def _matrices(Pt: ct.StateSpace, E: ct.StateSpace, nunc: int, ports: _Ports, Ww: float, Wz: float,
              eps_u: float, eps_y: float, reg: bool):
    """``(A, B, C, D)`` of the plant, inputs ``[w_unc (nunc), w, (n), u]`` and outputs
    ``[z_unc (nunc), z, (z_u), y]``."""
    At, Bt, Ct, Dt = (np.asarray(X, float) for X in (Pt.A, Pt.B, Pt.C, Pt.D))
    Ae, Be, Ce, De = (np.asarray(X, float) for X in (E.A, E.B, E.C, E.D))
    ie, iu, oe, oy = ports.ie, ports.iu, ports.oe, ports.oy
    nt, ne = At.shape[0], Ae.shape[0]
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
    if reg:
        D[oyy, nunc + 1] = eps_y
        D[nunc + 1, iuu] = eps_u
    return A, B, C, D


def _labels(true, nunc: int, reg: bool):
    """Input and output names of the plant (the true model's names for its uncertainty channels)."""
    inputs = [f"w_unc{i + 1}" for i in range(nunc)] + ["w"]
    outputs = [f"z_unc{i + 1}" for i in range(nunc)] + ["z"]
    if true is not None and nunc:
        inputs[:nunc] = list(true.P.input_labels[:nunc])
        outputs[:nunc] = list(true.P.output_labels[:nunc])
    if reg:
        inputs.append("n")
        outputs.append("z_u")
    inputs.append("u")
    outputs.append("y")
    return inputs, outputs


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


def _default_omega(plant: MBIPlant, n: int = 300):
    """A decade either side of the plant's poles."""
    return frequency_grid(n=n, poles=np.linalg.eigvals(np.asarray(plant.P.A, float)))
