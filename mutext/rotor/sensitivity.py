r"""Frequency responses of a rotor model and their exact parameter sensitivities.

Model response
--------------
For a channel from input :math:`j` (a force [N] at a DOF, or an exciter
current [A] entering through the force per ampere) to the displacement
:math:`y = c^Tq` of a DOF, at spin speed :math:`\Omega`,

.. math::
    H(j\omega; p) = c^T Z(\omega; p)^{-1} b(p),\qquad
    Z = K(p) - \omega^2 M(p) + j\omega\,(C(p) + \Omega G(p)) ,

one complex LU factorisation of the dynamic stiffness per frequency (the
matrices are evaluated once per parameter vector by the model's CasADi
functions).

Sensitivities (exact)
---------------------
With :math:`x = Z^{-1}b` and the adjoint solution :math:`w = Z^{-T}c` (same
factorisation), the derivative with respect to a parameter :math:`p_k` is

.. math::
    \frac{\partial H}{\partial p_k} = w^T\left(\frac{\partial b}{\partial p_k}
      - \frac{\partial Z}{\partial p_k}x\right),\qquad
    \frac{\partial Z}{\partial p_k} = \frac{\partial K}{\partial p_k}
      - \omega^2\frac{\partial M}{\partial p_k}
      + j\omega\Big(\frac{\partial C}{\partial p_k} + \Omega\frac{\partial G}{\partial p_k}\Big)

(Friswell and Mottershead 1995: sensitivity-based updating, also with
frequency-response data).  The matrix derivatives are the exact symbolic
Jacobians of the assembled CasADi expressions :math:`M(p), C(p), K(p), G(p), B(p)`.
Modal damping (:class:`~mutext.rotor.assembly.ModalDamping`,
:math:`C_m = M\Phi g(\Lambda)\Phi^TM` with :math:`g(\lambda) = 2\zeta\sqrt\lambda`)
depends on the eigenvectors and is not a CasADi expression; it is the
matrix function :math:`C_m = M\,g(M^{-1}K)`, whose exact derivative follows
from the Daleckii-Krein formula in the modal basis (Higham 2008, ch. 3):

.. math::
    \mathrm dC_m = \mathrm dM\,\Phi g\Phi^TM
      + M\Phi\left[\Gamma\circ(\Phi^T\mathrm dK\Phi - \Phi^T\mathrm dM\Phi\,\Lambda)\right]\Phi^TM,
    \qquad \Gamma_{rs} = \frac{g(\lambda_r)-g(\lambda_s)}{\lambda_r-\lambda_s}
      = \frac{2\zeta}{\sqrt{\lambda_r}+\sqrt{\lambda_s}} ,

which stays finite for the repeated eigenvalues of an isotropic rotor.
:func:`frf_sensitivity` exposes :math:`H` and :math:`\partial H/\partial p`
for diagnosis.

Layout: :class:`_Evaluator` factorises the dynamic stiffness once per
frequency and returns :math:`H` and :math:`\partial H/\partial p` for a set of
channels (the tuning objective of :mod:`mutext.rotor.tuning` calls it at
every IPOPT step); :func:`frf_sensitivity` and :func:`model_response` are the
public entry points.

References
----------
.. [FM95] M. I. Friswell and J. E. Mottershead, *Finite Element Model
   Updating in Structural Dynamics*, Kluwer, 1995 (sensitivity-based
   updating, also with frequency-response data).
.. [Hig08] N. J. Higham, *Functions of Matrices: Theory and Computation*,
   SIAM, 2008, ch. 3 (Fréchet derivative of a matrix function, Daleckii-Krein
   theorem).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import casadi as ca
import numpy as np
import scipy.linalg as sla

from ..errors import ModelError
from .assembly import ModalDamping
from .frf_channels import _as_model, _Inputs, _lookup, _resolve_channel

__all__ = ["FRFSensitivity", "frf_sensitivity", "model_response"]


def _modal_damping(M, K, ratio, dMs, dKs):
    """Modal damping matrix and its exact derivatives (see the module docstring)."""
    lam, Phi = sla.eigh(0.5 * (K + K.T), M)
    lam_max = max(float(np.max(np.abs(lam))), 1e-300)
    flex = lam > 1e-12 * lam_max            # same threshold as modal_damping_matrix
    s = np.sqrt(np.where(flex, lam, 0.0))
    g = np.where(flex, 2.0 * ratio * s, 0.0)
    MPhi = M @ Phi
    Cm = (MPhi * g[None, :]) @ MPhi.T
    if not dMs:
        return Cm, []
    den = lam[:, None] - lam[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        dd = np.where(den != 0.0, (g[:, None] - g[None, :]) / den, 0.0)
        both = flex[:, None] & flex[None, :]
        dd = np.where(both, 2.0 * ratio / (s[:, None] + s[None, :]), dd)
    dd = np.nan_to_num(dd, nan=0.0, posinf=0.0, neginf=0.0)
    Pg = Phi * g[None, :]
    out = []
    for dM, dK in zip(dMs, dKs):
        E = Phi.T @ (0.5 * (dK + dK.T)) @ Phi
        F = Phi.T @ dM @ Phi
        X = dd * (E - F * lam[None, :])
        dC = dM @ Pg @ MPhi.T + MPhi @ X @ MPhi.T
        out.append(0.5 * (dC + dC.T))
    return Cm, out


class _Evaluator:
    """Responses of a set of channels and their derivatives with respect to chosen parameters."""

    def __init__(self, model, member_idx: Sequence[int], inputs: _Inputs, out_dofs: Sequence[int],
                 groups: dict):
        self.model = model
        self.idx = list(member_idx)
        self.inputs = inputs
        self.out_dofs = list(out_dofs)
        self.groups = groups            # speed -> sorted unique omegas
        p = model.p
        sel = ca.vertcat(*[p[i] for i in self.idx]) if self.idx else ca.SX(0, 1)
        sym = model.symbolic
        self._dfun = ca.Function("dMCKGB", [p], [ca.jacobian(ca.vec(sym[k]), sel) for k in "MCKGB"])
        self.n_solves = 0

    def matrices(self, v, derivatives: bool):
        model = self.model
        M, C, K, G, B = (np.asarray(x.full()) for x in model._all(v))
        n = model.ndof
        npar = len(self.idx)
        d = None
        if derivatives and npar:
            outs = [np.asarray(x.full()) for x in self._dfun(v)]
            dM, dC, dK, dG = ([o[:, j].reshape(n, n, order="F") for j in range(npar)] for o in outs[:4])
            nb = B.shape[1]
            dB = [outs[4][:, j].reshape(n, nb, order="F") for j in range(npar)]
            d = dict(M=dM, C=dC, K=dK, G=dG, B=dB)
        damp = model.damping
        if isinstance(damp, ModalDamping) and damp.ratio > 0:
            Cm, dCm = _modal_damping(M, K, damp.ratio, d["M"] if d else [], d["K"] if d else [])
            C = C + Cm
            if d:
                d["C"] = [a + b for a, b in zip(d["C"], dCm)]
        return (M, C, K, G, B), d

    def evaluate(self, v, derivatives: bool = True):
        """``H[speed] (nout, nin, nf)`` and ``dH[speed] (npar, nout, nin, nf)`` for every speed group."""
        (M, C, K, G, B), d = self.matrices(v, derivatives)
        Bu = self.inputs.matrix(B)
        nin, nout = Bu.shape[1], len(self.out_dofs)
        npar = len(self.idx)
        res = {}
        for speed, w in self.groups.items():
            D = C + speed * G
            nf = w.size
            H = np.empty((nout, nin, nf), complex)
            X = np.empty((self.model.ndof, nin, nf), complex)
            W = np.empty((self.model.ndof, nout, nf), complex)
            E = np.zeros((self.model.ndof, nout))
            E[self.out_dofs, np.arange(nout)] = 1.0
            for k in range(nf):
                Z = K - w[k] ** 2 * M + 1j * w[k] * D
                lu = sla.lu_factor(Z, check_finite=False)
                X[:, :, k] = sla.lu_solve(lu, Bu, check_finite=False)
                if derivatives and npar:
                    W[:, :, k] = sla.lu_solve(lu, E, trans=1, check_finite=False)
            self.n_solves += nf
            H[:] = X[self.out_dofs]
            dH = None
            if derivatives and npar:
                dH = np.empty((npar, nout, nin, nf), complex)
                Xf = X.reshape(self.model.ndof, nin * nf)
                wcol = np.repeat(w[None, :], nin, axis=0).reshape(nin * nf)   # omega of each column
                for j in range(npar):
                    dBu = self.inputs.matrix(d["B"][j], derivative=True)
                    dD = d["C"][j] + speed * d["G"][j]
                    dZX = d["K"][j] @ Xf - (wcol ** 2)[None, :] * (d["M"][j] @ Xf) \
                        + (1j * wcol)[None, :] * (dD @ Xf)
                    rhs = dBu[:, :, None] - dZX.reshape(self.model.ndof, nin, nf)
                    dH[j] = np.einsum("aok,aik->oik", W, rhs)
            res[speed] = (H, dH)
        return res


@dataclass
class FRFSensitivity:
    r"""Frequency responses and their exact parameter derivatives.

    Attributes
    ----------
    freqs_hz : ndarray (nf,)
    H : complex ndarray (nout, nin, nf)
        Response [output unit per input unit].
    dH : complex ndarray (npar, nout, nin, nf)
        :math:`\partial H/\partial p_k` [response unit per parameter unit (SI)].
    parameters : list of str
    values : ndarray (npar,)
        Parameter values (SI) at which the derivatives were taken.
    inputs, outputs : list of str
    speed : float
        Spin speed [rad/s].
    """
    freqs_hz: np.ndarray
    H: np.ndarray
    dH: np.ndarray
    parameters: list
    values: np.ndarray
    inputs: list
    outputs: list
    speed: float

    def relative(self) -> np.ndarray:
        r""":math:`p_k\,\partial\ln H/\partial p_k` (npar, nout, nin, nf), dimensionless.

        Real part: change of :math:`\ln|H|` (nepers) per relative change of
        :math:`p_k`; imaginary part: change of the phase (rad).
        """
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.values[:, None, None, None] * self.dH / self.H[None]

    def __call__(self, out_port: str, in_port: str, parameter: str | None = None) -> np.ndarray:
        """One channel: ``H`` (``parameter=None``) or ``dH/dp`` for the named parameter."""
        try:
            o, i = self.outputs.index(out_port), self.inputs.index(in_port)
        except ValueError:
            raise ModelError(f"sensitivity has inputs {self.inputs} and outputs {self.outputs}; asked "
                             f"for {in_port} -> {out_port}") from None
        if parameter is None:
            return self.H[o, i]
        if parameter not in self.parameters:
            raise ModelError(f"sensitivity has parameters {self.parameters}; asked for '{parameter}'")
        return self.dH[self.parameters.index(parameter), o, i]


def frf_sensitivity(model, freqs_hz, parameters: Sequence[str], *, inputs: Sequence[str] | None = None,
                    outputs: Sequence[str] | None = None, speed: float | None = None,
                    values=None) -> FRFSensitivity:
    r"""FRFs between named ports and their exact derivatives with respect to ``parameters``.

    See the module docstring for the adjoint formula.  Modal damping is
    differentiated exactly (Daleckii-Krein formula).

    Parameters
    ----------
    model : Structure, Rotor or path of a model file
    freqs_hz : array_like
        Frequencies [Hz] (positive).
    parameters : sequence of str
        Parameter names (``model.parameter_names``).
    inputs, outputs : sequence of str, optional
        Port names (default: all ports of the model).
    speed : float, optional
        Spin speed [rad/s] (default: the model's).
    values : mapping or array, optional
        Parameter values (see :meth:`Structure.values`); default nominal.

    Returns
    -------
    FRFSensitivity
    """
    from .analysis import _ports, _speed, blas_single_thread
    model = _as_model(model)
    speed = _speed(model, speed)
    ins, outs = _ports(model, inputs, outputs)
    idx = [_lookup(model, p) for p in parameters]
    if len(set(idx)) != len(idx):
        raise ModelError(f"parameters repeat a name: {list(parameters)}")
    f = np.atleast_1d(np.asarray(freqs_hz, float))
    if f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ModelError("freqs_hz must be finite positive frequencies [Hz]")
    v = model.values(values)
    inp = _Inputs(model)
    for q in ins:
        inp.add(("port", model.input_names.index(q)))
    out_dofs = [model.output_dofs[model.output_names.index(q)] for q in outs]
    w = 2 * np.pi * f
    ev = _Evaluator(model, idx, inp, out_dofs, {speed: np.unique(w)})
    with blas_single_thread():
        H, dH = ev.evaluate(v, derivatives=True)[speed]
    pos = np.searchsorted(np.unique(w), w)
    dH = dH[..., pos] if dH is not None else np.zeros((0, len(outs), len(ins), f.size), complex)
    return FRFSensitivity(f, H[..., pos], dH, list(parameters), v[idx], ins, outs, speed)


def model_response(model, frf, values=None, freq_hz=None) -> np.ndarray:
    """The model's response in the channel of ``frf`` (stations, quantities, speed) [SI].

    Parameters
    ----------
    model : Structure, Rotor or path
    frf : mutext.rig.FRF
        Gives the channel (input/output station and quantity, speed, and
        ``input_direction``/``output_direction``, default x).
    values : mapping or array, optional
        Parameter values (default nominal).
    freq_hz : array_like, optional
        Frequencies [Hz]; default those of ``frf``.
    """
    from .analysis import blas_single_thread
    model = _as_model(model)
    inp = _Inputs(model)
    col, out_dof, _, speed = _resolve_channel(model, frf, 1, inp)
    f = frf.freq_hz if freq_hz is None else np.atleast_1d(np.asarray(freq_hz, float))
    w = 2 * np.pi * f
    ev = _Evaluator(model, [], inp, [out_dof], {speed: np.unique(w)})
    with blas_single_thread():
        H, _ = ev.evaluate(model.values(values), derivatives=False)[speed]
    return H[0, col, np.searchsorted(np.unique(w), w)]
