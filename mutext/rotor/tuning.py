r"""Tuning model parameters to measured frequency responses (model updating).

The thesis tuned the density and the disk mass of its rotor model by hand
until the first two resonances of the sine sweeps matched.  :func:`tune`
does the same systematically: it fits any set of the model's symbolic
parameters (a station-table entry, a bearing stiffness, the exciter's force
per ampere, a crack depth ratio, ...) to measured FRFs
(:class:`mutext.rig.FRF`, several channels) by nonlinear least squares,
solved by IPOPT through CasADi, with exact first derivatives.

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

Objective
---------
The residual of channel :math:`c` at frequency :math:`\omega_i` is the
complex logarithm of the model/measurement ratio,

.. math::
    r_{ci} = \ln\frac{H_c(j\omega_i; p)}{\hat H_c(j\omega_i)}
      = \ln\frac{|H_c|}{|\hat H_c|} + j\,\angle\frac{H_c}{\hat H_c},
    \qquad f(p) = \tfrac12\sum_{c,i} w_c\left[(\mathrm{Re}\,r_{ci})^2 + (\mathrm{Im}\,r_{ci})^2\right],

i.e. the log-magnitude error (nepers; :math:`\times 20/\ln 10` for dB) and the
phase error (rad) weighted equally.  Taking the logarithm of the *ratio*
keeps the phase difference in :math:`(-\pi, \pi]` whatever the phase
unwrapping of model and data.  The relative measurement noise of a sine
sweep (:class:`mutext.rig.Noise`) is homoscedastic in this metric, and
resonances and anti-resonances weigh alike (on logarithmic least squares
for FRFs: Pintelon and Schoukens 2012).

The optimisation variables are the parameters divided by their start values
(*normalised* parameters, all of order one), with bounds.  IPOPT (Wächter and
Biegler 2006) gets the exact gradient :math:`J^Tr` and the Gauss-Newton
Hessian :math:`J^TJ` (:math:`J = \partial r/\partial\theta`, the standard
Hessian model for least squares).

Implementation
--------------
CasADi supplies the model (the compiled functions :math:`M(p), \dots, B(p)`
and their exact symbolic Jacobians) and the optimiser (``casadi.nlpsol``
with IPOPT); the residual and its Jacobian enter the NLP as a
``casadi.Callback`` that evaluates the formulas above with one complex LU
factorisation per frequency (reused for the adjoint solve).  A CasADi
expression graph of the solve itself (the real :math:`2n\times 2n` block
system, mapped over the frequencies, differentiated algorithmically) gives
the same numbers -- the tests compare the two on a small model -- but on the
thesis rotor it is one to two orders of magnitude slower: modal damping makes
the damping matrix dense, so the sparse solvers gain nothing, and the real
block system has eight times the flops of the complex one.  With the
callback, a fit of two or three parameters to two 411-point channels takes
a few seconds.

Uncertainty
-----------
At the optimum :math:`\hat\theta` with :math:`N` real residuals and
:math:`n` parameters (the usual linearised least-squares estimate: Friswell
and Mottershead 1995; Pintelon and Schoukens 2012),

.. math::
    \hat\sigma^2 = \frac{\|r\|^2}{N - n},\qquad
    \mathrm{cov}(\hat\theta) \approx \hat\sigma^2 (J^TJ)^{-1},

reported as standard uncertainties of the parameters (SI) and their
correlation matrix.  These are *statistical* uncertainties: they assume the
model structure is right and the residual is noise; a model error shows up
as a large residual and structured (not white) residuals over frequency.

References
----------
.. [FM95] M. I. Friswell and J. E. Mottershead, *Finite Element Model
   Updating in Structural Dynamics*, Kluwer, 1995 (sensitivity-based
   penalty methods, updating with frequency-response data, statistics of
   the estimates).
.. [WB06] A. Wächter and L. T. Biegler, "On the implementation of an
   interior-point filter line-search algorithm for large-scale nonlinear
   programming", *Math. Programming* 106 (2006) 25-57 (IPOPT).
.. [CasADi] J. A. E. Andersson, J. Gillis, G. Horn, J. B. Rawlings and M.
   Diehl, "CasADi: a software framework for nonlinear optimization and
   optimal control", *Math. Programming Computation* 11 (2019) 1-36.
.. [Hig08] N. J. Higham, *Functions of Matrices: Theory and Computation*,
   SIAM, 2008, ch. 3 (Fréchet derivative of a matrix function, Daleckii-Krein
   theorem).
.. [PS12] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012.
.. [Mad] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University,
   ch. 4 (hand tuning of density and disk mass).
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import casadi as ca
import numpy as np
import scipy.linalg as sla

from ..errors import ModelError, SolverError
from ..response import FRF
from .assembly import ModalDamping

__all__ = ["TuneResult", "FRFSensitivity", "tune", "frf_sensitivity", "model_response",
           "select_points", "DB_PER_NEPER"]

#: dB per neper of log-magnitude: 20 / ln(10).
DB_PER_NEPER = 20.0 / math.log(10.0)

_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


# ----------------------------------------------------------------------------
# parameters and channels
# ----------------------------------------------------------------------------

def _as_model(model):
    if isinstance(model, (str, os.PathLike)):
        from .model import load_model
        return load_model(model)
    if not (hasattr(model, "symbolic") and hasattr(model, "layout") and hasattr(model, "parameter_names")):
        raise ModelError(f"expected a Rotor/Structure or a model file path, got {type(model).__name__}")
    return model


def _lookup(model, name) -> int:
    if not isinstance(name, str):
        raise ModelError(f"parameter names must be strings, got {name!r}")
    if name not in model.parameter_names:
        import difflib
        close = difflib.get_close_matches(name, model.parameter_names, n=3, cutoff=0.5)
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        raise ModelError(f"{model.name}: unknown parameter '{name}'{hint} Valid parameter names: "
                         f"{', '.join(model.parameter_names)}")
    return model.parameter_names.index(name)


@dataclass
class _Channel:
    label: str
    freq_hz: np.ndarray
    measured: np.ndarray
    speed: float
    in_col: int          # column of the used-input matrix
    out_dof: int
    weight: float
    source: object


class _Inputs:
    """The input columns used by the channels: exciter/force ports (parameter-dependent) or unit DOF forces."""

    def __init__(self, model):
        self.model = model
        self.specs: list[tuple[str, int]] = []   # ("port", j) or ("dof", d)

    def add(self, spec) -> int:
        if spec not in self.specs:
            self.specs.append(spec)
        return self.specs.index(spec)

    def matrix(self, B_full: np.ndarray, derivative: bool = False) -> np.ndarray:
        """The used input columns from ``B_full`` (or, with ``derivative``, from its derivative
        ``dB``: a unit force at a DOF does not depend on the parameters, so its column is zero)."""
        n = self.model.ndof
        out = np.zeros((n, len(self.specs)))
        for k, (kind, j) in enumerate(self.specs):
            if kind == "port":
                out[:, k] = B_full[:, j]
            elif not derivative:
                out[j, k] = 1.0
        return out


def _station(model, frf, which, k):
    s = getattr(frf, f"{which}_station")
    src = f" ({frf.source})" if getattr(frf, "source", None) else ""
    if s is None:
        raise ModelError(f"FRF #{k}{src}: {which}_station is not set; a fitted channel needs its stations")
    n = model.layout.n_nodes
    if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or not 1 <= int(s) <= n:
        raise ModelError(f"FRF #{k}{src}: {which} station {s!r} is not in the model '{model.name}' "
                         f"(stations 1..{n})")
    return int(s)


def _direction(model, frf, which, k):
    d = getattr(frf, f"{which}_direction", "x")
    try:
        return model.layout.label(d)
    except ModelError as exc:
        raise ModelError(f"FRF #{k}: {which}_direction: {exc}") from None


def _resolve_channel(model, frf, k, inputs: _Inputs):
    if not isinstance(frf, FRF):
        raise ModelError(f"FRF #{k}: expected a mutext.rig.FRF, got {type(frf).__name__}")
    s_in, s_out = _station(model, frf, "input", k), _station(model, frf, "output", k)
    d_in, d_out = _direction(model, frf, "input", k), _direction(model, frf, "output", k)
    lay = model.layout
    if frf.input_quantity == "current":
        cands = [j for j, port in enumerate(model.inputs)
                 if port.gain is not None and port.node == s_in and lay.label(port.direction) == d_in]
        if not cands:
            have = [f"{p.name} (station {p.node})" for p in model.inputs if p.gain is not None]
            raise ModelError(f"FRF #{k}: current input at station {s_in}, but the model has no exciter "
                             f"there; current inputs: {', '.join(have) or 'none'}")
        col = inputs.add(("port", cands[0]))
        in_name = model.inputs[cands[0]].name
    elif frf.input_quantity == "force":
        col = inputs.add(("dof", lay.dof(s_in, d_in)))
        in_name = f"F{s_in}" + ("" if d_in in ("u", "x") else d_in)
    else:  # pragma: no cover - FRF validates its quantity
        raise ModelError(f"FRF #{k}: unsupported input quantity {frf.input_quantity!r}")
    if frf.output_quantity != "displacement":  # pragma: no cover
        raise ModelError(f"FRF #{k}: unsupported output quantity {frf.output_quantity!r}")
    out_dof = lay.dof(s_out, d_out)
    out_name = ("y" if d_out == "v" else "x") + str(s_out) if lay.kind != "lumped" else lay.node_names[s_out - 1]
    speed = float(getattr(model, "speed", 0.0)) if frf.speed_hz is None else 2.0 * math.pi * float(frf.speed_hz)
    if speed != 0.0 and lay.kind != "rotor":
        raise ModelError(f"FRF #{k}: measured at {speed / (2 * math.pi):g} Hz running speed, but the model "
                         f"'{model.name}' is not a two-plane rotor (no gyroscopic terms)")
    return col, out_dof, f"{in_name}->{out_name}", speed


def select_points(freq_hz, response, max_points: int) -> np.ndarray:
    """Indices of at most about ``max_points`` frequencies of one FRF for a fit.

    Half of them log-spaced over the band; the rest in windows around the
    largest local maxima (resonances) and the deepest local minima
    (anti-resonances) of :math:`|H|`, where the response changes fastest.
    Returns sorted unique indices.
    """
    f = np.asarray(freq_hz, float)
    n = f.size
    if max_points is None or n <= max_points:
        return np.arange(n)
    if max_points < 4:
        raise ModelError(f"max_points must be at least 4, got {max_points}")
    n_log = max_points // 2
    targets = np.geomspace(f[0], f[-1], n_log)
    idx = set(np.clip(np.searchsorted(f, targets), 0, n - 1).tolist())
    a = np.abs(np.asarray(response))
    inner = np.arange(1, n - 1)
    maxima = inner[(a[inner] >= a[inner - 1]) & (a[inner] >= a[inner + 1])]
    minima = inner[(a[inner] <= a[inner - 1]) & (a[inner] <= a[inner + 1])]
    maxima = maxima[np.argsort(-a[maxima])][:4]
    minima = minima[np.argsort(a[minima])][:4]
    extrema = list(maxima) + list(minima)
    if extrema:
        half = max(1, (max_points - len(idx)) // (2 * len(extrema)))
        for e in extrema:
            idx.update(range(max(0, e - half), min(n, e + half + 1)))
    return np.array(sorted(idx))


# ----------------------------------------------------------------------------
# the response and its exact derivatives
# ----------------------------------------------------------------------------

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


def _groups(channels: Sequence[_Channel]) -> dict:
    g: dict[float, list] = {}
    for ch in channels:
        g.setdefault(ch.speed, []).append(2.0 * np.pi * ch.freq_hz)
    return {s: np.unique(np.concatenate(ws)) for s, ws in g.items()}


# ----------------------------------------------------------------------------
# sensitivity (public)
# ----------------------------------------------------------------------------

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


# ----------------------------------------------------------------------------
# tuning
# ----------------------------------------------------------------------------

@dataclass
class TuneResult:
    r"""Result of :func:`tune`.

    Attributes
    ----------
    parameters : list of str
        Fitted quantities: a parameter name, or ``"a+b"`` for names tied
        together (then the value is that of the first name).
    values : dict
        Fitted value (SI) of each fitted quantity.
    start : dict
        Start values (SI).
    std : dict
        Standard uncertainty (SI), :math:`\hat\sigma\sqrt{[(J^TJ)^{-1}]_{kk}}`.
    units : dict
        SI unit of each fitted quantity.
    bounds : dict
        Bounds used (SI).
    covariance : ndarray (n, n)
        Covariance of the fitted values (SI).
    correlation : ndarray (n, n)
    member_values : dict
        Fitted value of every model parameter changed by the fit.
    parameter_vector : ndarray
        The full parameter vector of the model with the fitted values.
    residual_rms_db, residual_rms_deg : float
        RMS of the log-magnitude error [dB] and of the phase error [deg] at the optimum.
    start_rms_db, start_rms_deg : float
        The same at the start values.
    channel_rms : dict
        Per channel label: ``(rms dB, rms deg)`` at the optimum.
    sigma : float
        Estimated standard deviation of one real log residual (nepers / rad).
    n_points : int
        Complex data points fitted (all channels).
    status : str
        IPOPT's return status.
    iterations : int
    seconds : float
        Wall time of the solve (without building the problem).
    build_seconds : float
    history : list of float
        Objective at every IPOPT iteration.
    n_solves : int
        Complex LU factorisations of the dynamic stiffness performed.
    """
    parameters: list
    values: dict
    start: dict
    std: dict
    units: dict
    bounds: dict
    covariance: np.ndarray
    correlation: np.ndarray
    member_values: dict
    parameter_vector: np.ndarray
    residual_rms_db: float
    residual_rms_deg: float
    start_rms_db: float
    start_rms_deg: float
    channel_rms: dict
    sigma: float
    n_points: int
    status: str
    iterations: int
    seconds: float
    build_seconds: float
    history: list = field(default_factory=list)
    n_solves: int = 0

    def relative_std(self) -> dict:
        """Standard uncertainty relative to the fitted value."""
        return {k: (self.std[k] / abs(self.values[k]) if self.values[k] != 0 else float("inf"))
                for k in self.parameters}

    def summary(self) -> str:
        lines = [f"{'parameter':<24} {'start':>12} {'fitted':>12} {'std':>10} {'unit':<8}"]
        for k in self.parameters:
            lines.append(f"{k:<24} {self.start[k]:>12.5g} {self.values[k]:>12.5g} {self.std[k]:>10.2g} "
                         f"{self.units[k]:<8}")
        lines.append(f"residual RMS: {self.residual_rms_db:.3f} dB, {self.residual_rms_deg:.3f} deg "
                     f"(start: {self.start_rms_db:.3f} dB, {self.start_rms_deg:.3f} deg); "
                     f"{self.n_points} points")
        lines.append(f"IPOPT: {self.status}, {self.iterations} iterations, {self.seconds:.2f} s")
        if len(self.parameters) > 1:
            lines.append("correlation:")
            for k, row in zip(self.parameters, self.correlation):
                lines.append(f"  {k:<22} " + " ".join(f"{x:+.3f}" for x in row))
        return "\n".join(lines)

    __str__ = summary


def _entries(model, parameters):
    """Parse ``parameters`` into entries: (label, [member indices])."""
    if isinstance(parameters, str):
        parameters = [parameters]
    try:
        parameters = list(parameters)
    except TypeError:
        raise ModelError(f"parameters must be a list of names, got {parameters!r}") from None
    if not parameters:
        raise ModelError("no parameters to fit")
    entries, seen = [], set()
    for e in parameters:
        names = [e] if isinstance(e, str) else list(e)
        if not names:
            raise ModelError("an empty group in parameters")
        idx = [_lookup(model, nm) for nm in names]
        for nm in names:
            if nm in seen:
                raise ModelError(f"parameter '{nm}' is given twice")
            seen.add(nm)
        entries.append(("+".join(names), idx))
    return entries


def _default_bounds(name, x0):
    if name.endswith("depth_ratio"):
        from .crack import MAX_DEPTH_RATIO
        return (0.0, MAX_DEPTH_RATIO)
    if x0 > 0:
        return (x0 / 10.0, x0 * 10.0)
    if x0 < 0:
        return (x0 * 10.0, x0 / 10.0)
    raise ModelError(f"parameter '{name}' starts at 0: give bounds={{'{name}': (lo, hi)}} (or a nonzero "
                     f"start) so that it can be scaled")


def tune(model, frfs, parameters, bounds: Mapping | None = None, *, start: Mapping | None = None,
         values=None, band_hz=None, max_points: int | None = None, weights=None, verbose: bool = False,
         max_iter: int = 100, tol: float = 1e-8, hessian: str = "gauss-newton",
         ipopt_options: Mapping | None = None) -> TuneResult:
    r"""Fit model parameters to measured FRFs by IPOPT (see the module docstring).

    Parameters
    ----------
    model : Rotor, Structure or path of a model file
        The model with symbolic parameters.
    frfs : mutext.rig.FRF or sequence of them
        Measured channels (SI, with input/output stations and quantities; a
        ``current`` input needs an exciter at that station, a ``force`` input
        is a unit force on the station's x DOF).  ``speed_hz`` of an FRF sets
        the spin speed of its channel (default: the model's speed).
        ``input_direction`` / ``output_direction`` = ``"y"``
        select the y direction.
    parameters : sequence
        Names of the parameters to fit (``model.parameter_names``, e.g.
        ``"rho"``, ``"disk16.m"``, ``"bearing2.k"``, ``"exciter12.ki"``,
        ``"crack15.depth_ratio"``).  A tuple of names is fitted as one
        quantity: the names keep the ratios of their start values (e.g. two
        identical bearings ``("bearing2.k", "bearing29.k")``).
    bounds : mapping name -> (lo, hi), optional
        SI bounds (for a tuple, keyed by its first name or by the tuple).
        Default: a decade either side of the start value; ``[0, 0.5]`` for a
        crack depth ratio.  A parameter starting at 0 needs bounds.
    start : mapping name -> value, optional
        Start values (SI); default the model's values.
    values : mapping or array, optional
        Values of the *other* parameters (default nominal).
    band_hz : (float, float), optional
        Fit only the frequencies in this band [Hz] (e.g. the thesis band
        ``mutext.rig.THESIS_ANALYSIS_BAND_HZ``).
    max_points : int, optional
        Use at most about this many frequencies per channel
        (:func:`select_points`); default all.
    weights : sequence of float, optional
        Weight of each channel in the objective (default 1).
    verbose : bool
        Print the objective at every iteration.
    max_iter : int
        IPOPT iteration limit.
    tol : float
        IPOPT convergence tolerance (on the scaled optimality error).  The
        objective is only computed to about 1e-12 relative (one LU solve per
        frequency), so near the optimum IPOPT's line search can stall on
        round-off: the options ``acceptable_tol = max(tol, 1e-6)``,
        ``acceptable_iter = 2`` (stop as "Solved_To_Acceptable_Level") and
        ``accept_after_max_steps = 5`` (accept a trial point after five
        backtracking steps) are set unless ``ipopt_options`` overrides them.
    hessian : {"gauss-newton", "limited-memory"}
        Hessian model given to IPOPT.
    ipopt_options : mapping, optional
        Extra IPOPT options (``{"max_cpu_time": 60}``, ...).

    Returns
    -------
    TuneResult

    Raises
    ------
    ModelError
        Unknown parameter (the message lists the valid names), a parameter
        given twice, bounds with lo > hi or a start outside them, an FRF
        without stations, a station not in the model, a current input where
        the model has no exciter, no frequency inside ``band_hz``, or fewer
        data than parameters.
    SolverError
        If IPOPT does not converge (the message gives IPOPT's return status).
    """
    from .analysis import blas_single_thread
    t_build = time.perf_counter()
    model = _as_model(model)
    if isinstance(frfs, FRF):
        frfs = [frfs]
    frfs = list(frfs)
    if not frfs:
        raise ModelError("tune: no FRFs given")
    entries = _entries(model, parameters)
    v0 = model.values(values)
    if start:
        for k, x in start.items():
            v0[_lookup(model, k)] = float(x)
    bounds = dict(bounds or {})
    for k in bounds:
        keys = [k] if isinstance(k, str) else list(k)
        for nm in keys:
            _lookup(model, nm)
        if not any(k == lab or k == lab.split("+")[0] or (not isinstance(k, str) and "+".join(k) == lab)
                   for lab, _ in entries):
            raise ModelError(f"bounds given for '{k}', which is not fitted (fitted: "
                             f"{', '.join(lab for lab, _ in entries)})")

    # --- entries: scaling, bounds, tie matrix
    members = [i for _, idx in entries for i in idx]
    T = np.zeros((len(members), len(entries)))
    x0, lo, hi, scale, units = [], [], [], [], []
    row = 0
    for e, (lab, idx) in enumerate(entries):
        lead = idx[0]
        xl = float(v0[lead])
        if len(idx) > 1 and xl == 0.0:
            raise ModelError(f"tied parameters '{lab}': the first one starts at 0, so the ratios are undefined")
        for i in idx:
            T[row, e] = 1.0 if i == lead else float(v0[i]) / xl
            row += 1
        name = model.parameter_names[lead]
        b = bounds.get(lab, bounds.get(name, bounds.get(tuple(lab.split("+")))))
        if b is None:
            b = _default_bounds(name, xl)
        try:
            bl, bh = (float(b[0]), float(b[1]))
        except (TypeError, ValueError, IndexError):
            raise ModelError(f"bounds of '{lab}' must be a pair (lo, hi), got {b!r}") from None
        if math.isnan(bl) or math.isnan(bh) or bl > bh:
            raise ModelError(f"bounds of '{lab}': lo = {bl:g} > hi = {bh:g}")
        if not bl <= xl <= bh:
            raise ModelError(f"start value of '{lab}' ({xl:g}) is outside its bounds [{bl:g}, {bh:g}]")
        s = abs(xl) if xl != 0 else max(abs(bl) if math.isfinite(bl) else 0.0,
                                        abs(bh) if math.isfinite(bh) else 0.0)
        if not (s > 0 and math.isfinite(s)):
            raise ModelError(f"'{lab}' starts at 0 with unbounded or zero bounds: cannot scale it")
        x0.append(xl)
        lo.append(bl)
        hi.append(bh)
        scale.append(s)
        units.append(model.parameters[lead].unit)
    x0, lo, hi, scale = (np.array(a, float) for a in (x0, lo, hi, scale))

    # --- channels
    inp = _Inputs(model)
    if weights is not None:
        weights = [float(w) for w in weights]
        if len(weights) != len(frfs) or any(not (w > 0 and math.isfinite(w)) for w in weights):
            raise ModelError(f"weights must be {len(frfs)} positive numbers (one per FRF), got {weights}")
    out_dofs: list[int] = []
    chans: list[_Channel] = []
    for k, frf in enumerate(frfs, start=1):
        col, od, label, speed = _resolve_channel(model, frf, k, inp)
        f, Hm = frf.freq_hz, frf.response
        if band_hz is not None:
            bl_, bh_ = float(band_hz[0]), float(band_hz[1])
            if not bl_ < bh_:
                raise ModelError(f"band_hz must be (lo, hi) with lo < hi, got {band_hz!r}")
            keep = (f >= bl_) & (f <= bh_)
            if not np.any(keep):
                raise ModelError(f"FRF #{k} ({label}): no frequency inside the fitted band "
                                 f"{bl_:g}-{bh_:g} Hz (it covers {f[0]:g}-{f[-1]:g} Hz)")
            f, Hm = f[keep], Hm[keep]
        if np.any(Hm == 0):
            raise ModelError(f"FRF #{k} ({label}): zero response at {f[np.argmax(Hm == 0)]:g} Hz (the log "
                             "error is undefined)")
        sel = select_points(f, Hm, max_points) if max_points is not None else np.arange(f.size)
        if od not in out_dofs:
            out_dofs.append(od)
        chans.append(_Channel(label, f[sel], Hm[sel], speed, col, out_dofs.index(od),
                              1.0 if weights is None else weights[k - 1], frf))
    labels = [c.label for c in chans]
    for c in chans:
        if labels.count(c.label) > 1:
            c.label = f"{c.label}#{chans.index(c) + 1}"
    groups = _groups(chans)
    n_pts = sum(c.freq_hz.size for c in chans)
    if 2 * n_pts <= len(entries):
        raise ModelError(f"{n_pts} data points cannot determine {len(entries)} parameters")
    ev = _Evaluator(model, members, inp, out_dofs, groups)
    pos = [np.searchsorted(groups[c.speed], 2 * np.pi * c.freq_hz) for c in chans]
    sqw = np.concatenate([np.full(c.freq_hz.size, math.sqrt(c.weight)) for c in chans])

    def full_vector(x):
        v = v0.copy()
        v[members] = T @ x
        return v

    def residual(theta, jac: bool):
        x = scale * np.asarray(theta, float).ravel()
        res = ev.evaluate(full_vector(x), derivatives=jac)
        rs, Js = [], []
        for c, ps in zip(chans, pos):
            H, dH = res[c.speed]
            h = H[c.out_dof, c.in_col, ps]
            if np.any(h == 0) or not np.all(np.isfinite(h)):
                raise SolverError("the model response is zero or not finite at some frequency for parameters "
                                  f"{dict(zip([lab for lab, _ in entries], x))}")
            rs.append(np.log(h / c.measured))
            if jac:
                dh = dH[:, c.out_dof, c.in_col][:, ps]                   # (nmembers, npts)
                Js.append(((T * scale[None, :]).T @ dh / h[None, :]).T)  # (npts, nentries)
        r = np.concatenate(rs)
        rr = np.concatenate([r.real, r.imag]) * np.concatenate([sqw, sqw])
        if not jac:
            return rr, r
        J = np.concatenate(Js)
        JJ = np.vstack([J.real, J.imag]) * np.concatenate([sqw, sqw])[:, None]
        return rr, r, JJ

    nE = len(entries)
    nR = 2 * n_pts
    cache: dict = {}

    def cached(theta, jac):
        key = np.asarray(theta, float).tobytes()
        hit = cache.get(key)
        if hit is not None and (not jac or len(hit) == 3):
            return hit
        out = residual(theta, jac)
        cache.clear()
        cache[key] = out
        return out

    class _Jac(ca.Callback):
        def __init__(self, name, opts=None):
            ca.Callback.__init__(self)
            self.construct(name, opts or {})

        def get_n_in(self):
            return 2

        def get_n_out(self):
            return 1

        def get_sparsity_in(self, i):
            return ca.Sparsity.dense(nE, 1) if i == 0 else ca.Sparsity.dense(nR, 1)

        def get_sparsity_out(self, i):
            return ca.Sparsity.dense(nR, nE)

        def eval(self, arg):
            return [ca.DM(cached(np.array(arg[0]).ravel(), True)[2])]

    class _Res(ca.Callback):
        def __init__(self, name, opts=None):
            ca.Callback.__init__(self)
            self.construct(name, opts or {})

        def get_n_in(self):
            return 1

        def get_n_out(self):
            return 1

        def get_sparsity_in(self, i):
            return ca.Sparsity.dense(nE, 1)

        def get_sparsity_out(self, i):
            return ca.Sparsity.dense(nR, 1)

        def eval(self, arg):
            return [ca.DM(cached(np.array(arg[0]).ravel(), False)[0])]

        def has_jacobian(self):
            return True

        def get_jacobian(self, name, inames, onames, opts):
            self._jac = _Jac(name, opts)
            return self._jac

    history: list[float] = []
    names = [lab for lab, _ in entries]

    class _Progress(ca.Callback):
        def __init__(self, name, opts=None):
            ca.Callback.__init__(self)
            self.construct(name, opts or {})

        def get_n_in(self):
            return ca.nlpsol_n_out()

        def get_n_out(self):
            return 1

        def get_name_in(self, i):
            return ca.nlpsol_out(i)

        def get_name_out(self, i):
            return "ret"

        def get_sparsity_in(self, i):
            n = ca.nlpsol_out(i)
            if n == "f":
                return ca.Sparsity.scalar()
            if n in ("x", "lam_x"):
                return ca.Sparsity.dense(nE, 1)
            return ca.Sparsity(0, 0)

        def eval(self, arg):
            f = float(arg[1])
            history.append(f)
            if verbose:
                xs = scale * np.array(arg[0]).ravel()
                rms = math.sqrt(2.0 * f / nR)
                print(f"  iter {len(history) - 1:3d}  objective {f:.6e}  rms {rms * DB_PER_NEPER:.4f} dB / "
                      f"{math.degrees(rms):.4f} deg  " + "  ".join(f"{k}={x:.6g}" for k, x in zip(names, xs)),
                      flush=True)
            return [0]

    rcb = _Res("frf_log_residual")
    prog = _Progress("progress")
    th = ca.MX.sym("theta", nE)
    r_mx = rcb(th)
    f_mx = 0.5 * ca.sumsqr(r_mx)
    opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": int(max_iter),
            "ipopt.tol": float(tol), "ipopt.acceptable_tol": max(1e-6, float(tol)), "ipopt.acceptable_iter": 2,
            "ipopt.accept_after_max_steps": 5, "iteration_callback": prog}
    if hessian == "gauss-newton":
        J = ca.jacobian(r_mx, th)
        lam_f = ca.MX.sym("lam_f")
        hess = ca.Function("nlp_hess_l", [th, ca.MX.sym("p", 0), lam_f, ca.MX.sym("lam_g", 0)],
                           [ca.triu(lam_f * ca.mtimes(J.T, J))],
                           ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])
        opts["hess_lag"] = hess
    elif hessian == "limited-memory":
        opts["ipopt.hessian_approximation"] = "limited-memory"
    else:
        raise ModelError(f"hessian must be 'gauss-newton' or 'limited-memory', got {hessian!r}")
    for k, x in (ipopt_options or {}).items():
        opts[k if "." in k or k in ("print_time",) else f"ipopt.{k}"] = x
    solver = ca.nlpsol("tune", "ipopt", {"x": th, "f": f_mx}, opts)
    build_seconds = time.perf_counter() - t_build

    t0 = time.perf_counter()
    with blas_single_thread():
        _, r_start = cached(x0 / scale, False)
        sol = solver(x0=x0 / scale, lbx=lo / scale, ubx=hi / scale)
        stats = solver.stats()
        status = str(stats.get("return_status", "unknown"))
        iters = int(stats.get("iter_count", -1))
        if status not in _SUCCESS:
            raise SolverError(f"IPOPT did not converge: return status {status} after {iters} iterations "
                              f"(parameters {names}; last values "
                              f"{dict(zip(names, (scale * np.array(sol['x']).ravel()).tolist()))})")
        theta = np.array(sol["x"]).ravel()
        rr, r, JJ = cached(theta, True)
    seconds = time.perf_counter() - t0

    # --- statistics
    xopt = scale * theta
    dof = max(nR - nE, 1)
    sigma2 = float(rr @ rr) / dof
    JtJ = JJ.T @ JJ
    try:
        cov_theta = sigma2 * np.linalg.inv(JtJ)
    except np.linalg.LinAlgError:
        cov_theta = np.full((nE, nE), np.inf)
    cov = cov_theta * np.outer(scale, scale)
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(sd, sd)
    vfit = full_vector(xopt)
    ch_rms, off = {}, 0
    for c in chans:
        rc = r[off:off + c.freq_hz.size]
        off += c.freq_hz.size
        ch_rms[c.label] = (float(np.sqrt(np.mean(rc.real ** 2)) * DB_PER_NEPER),
                           float(np.degrees(np.sqrt(np.mean(rc.imag ** 2)))))
    return TuneResult(
        parameters=names,
        values=dict(zip(names, xopt.tolist())),
        start=dict(zip(names, x0.tolist())),
        std=dict(zip(names, sd.tolist())),
        units=dict(zip(names, units)),
        bounds={k: (a, b) for k, a, b in zip(names, lo.tolist(), hi.tolist())},
        covariance=cov, correlation=corr,
        member_values={model.parameter_names[i]: float(vfit[i]) for i in members},
        parameter_vector=vfit,
        residual_rms_db=float(np.sqrt(np.mean(r.real ** 2)) * DB_PER_NEPER),
        residual_rms_deg=float(np.degrees(np.sqrt(np.mean(r.imag ** 2)))),
        start_rms_db=float(np.sqrt(np.mean(r_start.real ** 2)) * DB_PER_NEPER),
        start_rms_deg=float(np.degrees(np.sqrt(np.mean(r_start.imag ** 2)))),
        channel_rms=ch_rms, sigma=math.sqrt(sigma2), n_points=n_pts, status=status, iterations=iters,
        seconds=seconds, build_seconds=build_seconds, history=history, n_solves=ev.n_solves)
