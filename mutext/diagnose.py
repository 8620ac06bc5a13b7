r"""Diagnosis: what a model gets wrong against measured FRFs, its cause, the fix and the gain.

:func:`diagnose` takes an engineering model (a lumped chain or a rotor, see
:mod:`mutext.rotor.model`) and measured frequency responses
(:class:`mutext.rig.FRF`, e.g. read with :func:`mutext.rig.read_frf`) and

1. compares model and data channel by channel (the residual over frequency
   and the measured against modelled resonances);
2. tests hypotheses of the form *kind at location* -- a change of a spring,
   mass or damper, a grounded spring, mass or damper added at a mass or a
   station, a bearing's stiffness or damping, a crack in a shaft element, the
   exciter's force per ampere, a sensor's gain -- and **none**, fits the size
   of each, and ranks them;
3. writes the extended model (the original plus the identified element) and
   measures the gain on data that the fit did not use.

Residual and noise
------------------
The residual of channel :math:`c` at frequency :math:`\omega_i` is the complex
log ratio of model and measurement (as in :mod:`mutext.rotor.tuning`),

.. math::
    r_{ci}(\theta) = \ln\frac{H_c(j\omega_i;\theta)}{\hat H_c(j\omega_i)},\qquad
    \mathrm{RSS}(\theta) = \sum_{c,i} (\mathrm{Re}\,r_{ci})^2 + (\mathrm{Im}\,r_{ci})^2 .

For relative circular complex noise of standard deviation :math:`\sigma` (the
virtual rig's :class:`~mutext.rig.Noise`) each real component of :math:`r`
has variance :math:`\sigma^2/2`.  :math:`\sigma` is estimated from the data
alone, before any model is fitted (:func:`mutext.frfit.noise_level`: robust
fourth differences of the log response along frequency), so the tests below do not depend on the
hypotheses being right.

Hypotheses and their fit
------------------------
Every structural hypothesis changes the dynamic stiffness
:math:`Z(\omega) = K - \omega^2 M + j\omega (C + \Omega G)` by a matrix
:math:`\theta D(\omega)` on a few degrees of freedom :math:`U` (a spring:
:math:`D = S`, a damper :math:`j\omega S`, a mass :math:`-\omega^2 S`, with
:math:`S` the element's pattern, e.g. :math:`e_ie_i^T` to ground or
:math:`(e_i-e_j)(e_i-e_j)^T` between two masses).  With the receptance of the
engineering model :math:`R = Z^{-1}` (one inverse per frequency, shared by all
hypotheses) the response of the changed model is exact for any size
(Woodbury identity):

.. math::
    H_c(\theta) = H_c(0) - \theta\, R_{oU}\, D\,u,\qquad
    (I + \theta R_{UU} D)\,u = R_{U:}\,b_c ,

    \frac{\partial H_c}{\partial \theta} = -R_{oU}\,(I + \theta D R_{UU})^{-1} D\,u ,

with :math:`o` the output DOF and :math:`b_c` the input vector of the
channel.  A crack is the same with :math:`\theta D` replaced by the exact
cracked-minus-intact stiffness of its shaft element
(:class:`mutext.rotor.crack.Crack`), a function of the depth ratio.  A sensor
or exciter gain :math:`g` multiplies the channels of that sensor or
exciter: :math:`\ln g` enters the residual linearly.  The damping matrix of
the engineering model (modal damping included) is held fixed in this screen.

Each size is fitted by weighted (log) least squares: a scan of the size over
several decades and both signs (where physical) picks the start, Gauss-Newton
steps with the exact derivative above refine it.  The best few hypotheses are
then refitted on the *extended model* itself -- the model file with the new
element, loaded and tuned with :func:`mutext.rotor.tuning.tune` (IPOPT, exact
sensitivities, modal damping recomputed) -- so the reported size is that of
the model file the user receives.

Ranking and the "none" verdict
------------------------------
With :math:`s^2 = \hat\sigma^2/2`, hypothesis :math:`h` (one parameter)
improves the fit by :math:`\Delta\chi^2_h = (\mathrm{RSS}_0 -
\mathrm{RSS}_h)/s^2`.  Under the null hypothesis (model right, residual
noise) :math:`\Delta\chi^2` of one fitted parameter is :math:`\chi^2_1`
distributed; with :math:`m` hypotheses tested, the best is accepted only if

.. math::
    \Delta\chi^2_h > \chi^2_{1}\!\left(1 - \alpha/m\right)

(Bonferroni), so the false-alarm rate is at most :math:`\alpha` (default
1 %) when the model and noise level are right.  Hypotheses are ranked by
:math:`\mathrm{RSS}_h/s^2 + k_h\ln N` (the Bayesian information criterion,
:math:`k_h` = 1 fitted size, 0 for *none*, :math:`N` real residuals).  Others
whose :math:`\mathrm{RSS}` lies within :math:`\chi^2_1(0.95)\,s^2 = 3.84\,s^2`
of the best cannot be told apart from it with the channels measured: they are
reported as ``ambiguous_with``, with the sensor station whose response would
separate them best.

Gain on held-out data
---------------------
Two metrics, before (engineering model) and after (extended model), on data
the fit did not use (``validate`` FRFs; or, when none are given, every
fifth frequency of each fitted channel, held out of the fit):

.. math::
    e_{\mathrm{rel}} = \sqrt{\operatorname{mean}\frac{|H - \hat H|^2}{|\hat H|^2}},\qquad
    e_{\mathrm{dB}} = \sqrt{\operatorname{mean}\left(20\log_{10}\frac{|H|}{|\hat H|}\right)^2},

and the gain :math:`e_{\mathrm{rel}}^{\mathrm{before}}/e_{\mathrm{rel}}^{\mathrm{after}}`.
A well-diagnosed model reaches the noise level after the fix.

Examples
--------
>>> from mutext.diagnose import diagnose
>>> from mutext.hide import hidden_effect_data
>>> case = hidden_effect_data("three_mass", seed=3, kind="stiffness", noise=0.01)
>>> d = diagnose(case.model, case.measured, validate=case.validate)
>>> d.findings[0].kind == case.key["kind"], d.findings[0].station == case.key["station"]
(True, True)
>>> d.gain > 3
True

References
----------
.. [FM95] M. I. Friswell and J. E. Mottershead, *Finite Element Model Updating
   in Structural Dynamics*, Kluwer, 1995 (sensitivity-based updating and error
   localisation).
.. [Sch78] G. Schwarz, "Estimating the dimension of a model", *Ann. Statist.*
   6 (1978) 461-464 (BIC).
.. [PS12] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012 (noise on FRFs).
"""
from __future__ import annotations

import logging
import math
import os
import re
import time
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
import scipy.stats as sst

from .errors import ModelError
from .frfit import noise_level, resonances
from .rig import FRF, read_frf
from .rotor.tuning import DB_PER_NEPER

__all__ = ["diagnose", "Diagnosis", "Finding", "Hypothesis", "ChannelComparison", "ResonanceRow",
           "hypotheses", "KINDS", "HOLDOUT_EVERY"]

log = logging.getLogger(__name__)

#: Kinds of finding (the ``kind`` field of :class:`Finding`).
KINDS = ("stiffness", "mass", "damping", "crack", "bearing", "exciter_gain", "sensor_gain", "none")

#: Without validation files, every this many-th frequency of each channel is held out of the fit.
HOLDOUT_EVERY = 5

_ORDER = {"stiffness": 0, "damping": 1, "mass": 2}      # D(w) = S * (1, j w, -w^2)[order]


# ----------------------------------------------------------------------------
# hypotheses
# ----------------------------------------------------------------------------

@dataclass
class Hypothesis:
    """One candidate cause: a *kind* at a *location*, with a size to fit.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    station : int or None
        1-based station (rotor) or mass index (lumped chain), as numbered in the model file.
    element : str or None
        The model element changed (``"k1"``, ``"bearing2"``) or the name of the added one.
    description : str
        Plain-language description, e.g. ``"grounded spring added at m2"``.
    unit : str
        Unit of the size (``N/m``, ``kg``, ``N s/m``, ``1`` for a depth ratio or a gain).
    added : bool
        True when the hypothesis adds an element (size 0 = no effect), False
        when it changes an existing value (the size is the change).
    lower, upper : float
        Bounds of the size (SI).
    scale : float
        Typical size (for the scan and the reporting of relative sizes).
    dofs : list of int
        DOFs U touched (0-based).
    pattern : ndarray
        The real matrix S on U (structural hypotheses).
    order : int
        0 stiffness, 1 damping, 2 mass (D = S, j w S, -w^2 S).
    gain : tuple or None
        ``("sensor", out_dof)`` or ``("exciter", input column spec)`` for gain hypotheses.
    parameter : str or None
        Parameter of the *extended* model that holds the size (for the full fit).
    nominal : float
        Value of the existing parameter (changes) or 0 (added elements); the
        new value is ``nominal + size`` (gains: ``nominal * size``).
    """
    kind: str
    station: int | None
    element: str | None
    description: str
    unit: str
    added: bool
    lower: float
    upper: float
    scale: float
    dofs: list = field(default_factory=list)
    pattern: np.ndarray | None = None
    order: int = 0
    gain: tuple | None = None
    parameter: str | None = None
    nominal: float = 0.0
    crack: object = None          # callable depth -> dK on dofs (crack hypotheses)

    @property
    def label(self) -> str:
        return f"{self.kind} at {self.station}" + (f" ({self.element})" if self.element else "")


def _lumped_hypotheses(model) -> list[Hypothesis]:
    from .rotor.elements import Damper, PointMass, Spring
    lay = model.layout
    n = lay.n_nodes
    names = lay.node_names
    M, C, K, _ = model.matrices()
    out: list[Hypothesis] = []
    grounded = {"stiffness": set(), "damping": set()}
    for el in model.elements:
        if isinstance(el, PointMass):
            i = el.nodes[0]
            m = el.nominal("m")
            out.append(Hypothesis("mass", i, el.name, f"mass {el.name} changed", "kg", False, -0.9 * m, 10 * m,
                                  m, [i - 1], np.ones((1, 1)), 2, parameter=el.param_name("m"), nominal=m))
        elif isinstance(el, (Spring, Damper)):
            kind = "stiffness" if isinstance(el, Spring) else "damping"
            fld = "k" if kind == "stiffness" else "c"
            v = el.nominal(fld)
            unit = "N/m" if kind == "stiffness" else "N s/m"
            what = "spring" if kind == "stiffness" else "damper"
            if len(el.nodes) == 1:
                i = el.nodes[0]
                grounded[kind].add(i)
                dofs, S = [i - 1], np.ones((1, 1))
                where = f"{names[i - 1]}-ground"
            else:
                i, j = el.nodes
                dofs, S = [i - 1, j - 1], np.array([[1.0, -1.0], [-1.0, 1.0]])
                where = f"{names[i - 1]}-{names[j - 1]}"
            scale = v if v > 0 else (float(K[i - 1, i - 1]) if kind == "stiffness"
                                     else 2.0 * math.sqrt(K[i - 1, i - 1] * M[i - 1, i - 1]) * 0.05)
            out.append(Hypothesis(kind, i, el.name, f"{what} {el.name} ({where}) changed", unit, False,
                                  -0.95 * v, 10 * max(v, scale), scale, dofs, S, _ORDER[kind],
                                  parameter=el.param_name(fld), nominal=v))
    for i in range(1, n + 1):
        kii, mii = float(K[i - 1, i - 1]), float(M[i - 1, i - 1])
        for kind, unit, scale in (("stiffness", "N/m", kii),
                                  ("damping", "N s/m", 2.0 * math.sqrt(max(kii, 1e-300) * mii) * 0.05)):
            if i in grounded[kind]:
                continue            # the same effect as changing the existing grounded element
            what = "spring" if kind == "stiffness" else "damper"
            name = f"{'k' if kind == 'stiffness' else 'c'}_{names[i - 1]}_ground"
            out.append(Hypothesis(kind, i, name, f"grounded {what} added at {names[i - 1]}", unit, True,
                                  0.0, 10 * scale, scale, [i - 1], np.ones((1, 1)), _ORDER[kind],
                                  parameter=f"{name}", nominal=0.0))
    return out


def _rotor_hypotheses(model, stations=None) -> list[Hypothesis]:
    from .rotor.elements import BearingElement
    lay = model.layout
    M, C, K, _ = model.matrices()
    out: list[Hypothesis] = []
    bearings = {el.nodes[0]: el for el in model.elements if isinstance(el, BearingElement)}
    total_mass = float(np.sum(M[0::4, 0::4]))     # consistent mass: the whole x-x block
    # reference stiffness and damping: the softest bearing (or 1e-3 of the shaft's local stiffness),
    # and 2 % of critical at the first natural frequency
    k_ref = min((el.nominal("k") for el in bearings.values()), default=1e-3 * float(np.max(np.diag(K))))
    w1 = 2 * np.pi * float(model.natural_frequencies(n=1)[0])
    c_ref = 0.02 * k_ref / w1
    stations = range(1, lay.n_nodes + 1) if stations is None else stations
    two = lay.kind == "rotor"
    for s in stations:
        dofs = [lay.dof(s, "u")] + ([lay.dof(s, "v")] if two else [])
        S = np.eye(len(dofs))
        if s in bearings:
            el = bearings[s]
            kb, cb = el.nominal("k"), el.nominal("c")
            out.append(Hypothesis("bearing", s, el.name, f"stiffness of {el.name} changed", "N/m", False,
                                  -0.95 * kb, 10 * kb, kb, dofs, S, 0, parameter=el.param_name("k"), nominal=kb))
            out.append(Hypothesis("bearing", s, el.name, f"damping of {el.name} changed", "N s/m",
                                  cb == 0.0, -0.95 * cb if cb > 0 else 0.0, 1000 * c_ref, max(cb, c_ref), dofs, S,
                                  1, parameter=el.param_name("c"), nominal=cb))
            continue
        out.append(Hypothesis("stiffness", s, f"k_s{s}", f"grounded spring added at station {s}", "N/m", True,
                              0.0, 100 * k_ref, k_ref, dofs, S, 0, parameter=f"k_s{s}.k"))
        out.append(Hypothesis("mass", s, f"m_s{s}", f"point mass added at station {s}", "kg", True,
                              0.0, total_mass, 0.1 * total_mass, dofs, S, 2, parameter=f"m_s{s}.m"))
        out.append(Hypothesis("damping", s, f"c_s{s}", f"grounded damper added at station {s}", "N s/m", True,
                              0.0, 1000 * c_ref, c_ref, dofs, S, 1, parameter=f"c_s{s}.c"))
    return out


def _gain_hypotheses(model, channels) -> list[Hypothesis]:
    out = []
    seen_out, seen_in = set(), set()
    for ch in channels:
        if ch.out_dof not in seen_out:
            seen_out.add(ch.out_dof)
            out.append(Hypothesis("sensor_gain", ch.out_station, ch.out_name, f"gain of sensor {ch.out_name}",
                                  "1", False, 0.2, 5.0, 1.0, gain=("sensor", ch.out_dof), nominal=1.0))
        if ch.in_spec not in seen_in:
            seen_in.add(ch.in_spec)
            what = "exciter" if ch.in_spec[0] == "port" else "force input"
            out.append(Hypothesis("exciter_gain", ch.in_station, ch.in_name, f"gain of {what} {ch.in_name}",
                                  "1", False, 0.2, 5.0, 1.0, gain=("exciter", ch.in_spec), nominal=1.0))
    return out


def hypotheses(model, frfs=None, *, stations=None) -> list[Hypothesis]:
    """The hypotheses :func:`diagnose` tests on ``model`` (given the measured channels ``frfs``)."""
    from .rotor.model import load_model
    if isinstance(model, (str, os.PathLike)):
        model = load_model(model)
    kind = model.layout.kind
    hyps = _lumped_hypotheses(model) if kind == "lumped" else _rotor_hypotheses(model, stations)
    if kind != "lumped":
        hyps += _crack_hypotheses(model, stations)
    if frfs is not None:
        chans, _ = _resolve(model, list(frfs), "FRF")
        hyps += _gain_hypotheses(model, chans)
    return hyps


def _crack_hypotheses(model, stations=None) -> list[Hypothesis]:
    """A crack in shaft element s (between stations s and s+1), depth ratio in [0, 0.5]."""
    try:
        from .rotor.crack import Crack
    except ImportError:  # pragma: no cover
        return []
    import casadi as ca
    from .rotor.elements import ParameterSet
    lay = model.layout
    out = []
    shafts = {el.nodes[0]: el for el in model.elements if type(el).__name__ == "ShaftElement"}
    stations = range(1, lay.n_nodes) if stations is None else [s for s in stations if s < lay.n_nodes]
    p = model.p
    pnames = model.parameter_names
    for s in stations:
        if s not in shafts:
            continue
        cr = Crack(station=s, depth_ratio=0.0, name=f"crack{s}")
        # the crack's stiffness change, as a function of the model's parameters and its depth
        try:
            cr.bind(model)
            cr.declare(ParameterSet())
            a = ca.SX.sym("a")
            syms = {n: p[i] for i, n in enumerate(pnames)}
            syms[cr.param_name("depth_ratio")] = a
            dK = cr.stiffness_matrix(syms, lay)
        except Exception as exc:  # pragma: no cover - reported, not fatal
            log.debug("no crack hypothesis at station %s: %s", s, exc)
            continue
        dofs = cr.dofs(lay)
        fun = ca.Function(f"dK_crack{s}", [p, a], [dK])
        v0 = model.values()
        out.append(Hypothesis("crack", s, f"crack{s}", f"open crack in the shaft element {s}-{s + 1}", "1", True,
                              0.0, 0.5, 0.1, list(dofs), None, 0, parameter=f"crack{s}.depth_ratio",
                              crack=lambda depth, f=fun, v=v0: np.asarray(f(v, depth).full())))
    return out


# ----------------------------------------------------------------------------
# channels
# ----------------------------------------------------------------------------

@dataclass
class _Chan:
    frf: FRF
    label: str
    in_spec: tuple
    in_col: int
    in_name: str
    in_station: int
    out_dof: int
    out_name: str
    out_station: int
    speed: float


def _resolve(model, frfs: list, what: str):
    from .rotor.tuning import _Inputs, _resolve_channel
    inputs = _Inputs(model)
    chans = []
    for k, frf in enumerate(frfs, start=1):
        if not isinstance(frf, FRF):
            raise ModelError(f"{what} #{k}: expected a mutext.rig.FRF, got {type(frf).__name__}")
        try:
            col, od, label, speed = _resolve_channel(model, frf, k, inputs)
        except ModelError as exc:
            src = f"{frf.source}: " if frf.source else ""
            raise ModelError(f"{src}{exc}") from None
        if np.any(frf.response == 0):
            raise ModelError(f"{_src(frf, k)}: zero response at {frf.freq_hz[np.argmax(frf.response == 0)]:g} Hz "
                             "(a log-ratio residual needs a nonzero response)")
        in_name, out_name = _port_names(model, inputs.specs[col], od, label)
        label = f"{in_name}->{out_name}"
        chans.append(_Chan(frf, label, inputs.specs[col], col, in_name, int(frf.input_station), od, out_name,
                           int(frf.output_station), speed))
    return chans, inputs


def _port_names(model, in_spec, out_dof, label):
    """Names of the model's ports for a channel (the file's stations otherwise)."""
    in_name, out_name = label.split("->")
    if in_spec[0] == "port":
        in_name = model.input_names[in_spec[1]]
    else:
        lay = model.layout
        for q in model.inputs:
            if q.gain is None and lay.dof(q.node, q.direction) == in_spec[1]:
                in_name = q.name
                break
    if out_dof in model.output_dofs:
        out_name = model.output_names[model.output_dofs.index(out_dof)]
    return in_name, out_name


def _src(frf, k):
    return str(frf.source) if frf.source else f"FRF #{k}"


# ----------------------------------------------------------------------------
# the receptance engine
# ----------------------------------------------------------------------------

class _Receptance:
    """Receptance R = Z^-1 of the engineering model at a set of frequencies, and channel pieces."""

    def __init__(self, model, values, speed, omega, chunk_bytes=64_000_000):
        M, C, K, G = model.matrices(values)
        self.B = model.input_matrix(values)
        self.omega = np.asarray(omega, float)
        n = M.shape[0]
        D = C + speed * G
        R = np.empty((self.omega.size, n, n), complex)
        chunk = max(1, int(chunk_bytes // (16 * n * n)))
        for k0 in range(0, self.omega.size, chunk):
            w = self.omega[k0:k0 + chunk, None, None]
            Z = K[None] - w * w * M[None] + 1j * w * D[None]
            R[k0:k0 + chunk] = np.linalg.inv(Z)
        self.R = R
        self.M, self.K = M, K

    def input_vector(self, spec) -> np.ndarray:
        kind, j = spec
        if kind == "port":
            return self.B[:, j]
        b = np.zeros(self.B.shape[0])
        b[j] = 1.0
        return b


@dataclass
class _Data:
    """Stacked channel data for one set of frequencies (fit or held-out)."""
    chans: list
    idx: list            # per channel: indices into the receptance frequency grid
    meas: list           # per channel: measured response at those points
    H0: list             # per channel: engineering-model response
    b: list              # per channel: input vector
    freq_hz: list = None  # per channel: the frequencies [Hz]
    _cols: dict = None

    @property
    def n_points(self) -> int:
        return sum(len(i) for i in self.idx)

    def columns(self, rec, k):
        """``(R b, R_o:)`` of channel k at its frequencies (computed once, shared by all hypotheses)."""
        if self._cols is None:
            self._cols = {}
        if k not in self._cols:
            idx = self.idx[k]
            Ro = rec.R[idx, self.chans[k].out_dof, :]
            Rb = np.einsum("kij,j->ki", rec.R[idx], self.b[k])
            self._cols[k] = (Rb, Ro)
        return self._cols[k]


class _Evaluator:
    """Responses of the channels of a data set under one hypothesis, exactly for any size."""

    def __init__(self, rec: _Receptance, data: _Data, hyp: Hypothesis):
        self.hyp, self.data = hyp, data
        self.pieces = []
        U = hyp.dofs
        for k, (ch, idx) in enumerate(zip(data.chans, data.idx)):
            if hyp.gain is not None:
                self.pieces.append(None)
                continue
            Rb, Ro = data.columns(rec, k)
            y = Rb[:, U]                              # R_U: b   (nf, |U|)
            z = Ro[:, U]                              # R_oU     (nf, |U|)
            RUU = rec.R[np.ix_(idx, U, U)]            # (nf, |U|, |U|)
            w = rec.omega[idx]
            self.pieces.append((y, z, RUU, w))

    def _D(self, w, theta):
        h = self.hyp
        if h.crack is not None:
            dK = h.crack(theta)
            return np.broadcast_to(dK, (w.size,) + dK.shape).astype(complex)
        s = (np.ones_like(w), 1j * w, -w * w)[h.order]
        return s[:, None, None] * h.pattern[None]

    def responses(self, theta: float, derivative: bool = False):
        """Per channel ``H(theta)`` (and ``dH/dtheta`` when asked; for gains d/d ln g)."""
        h = self.hyp
        Hs, dHs = [], []
        for ch, H0, piece in zip(self.data.chans, self.data.H0, self.pieces):
            if h.gain is not None:
                hit = (h.gain[0] == "sensor" and ch.out_dof == h.gain[1]) or \
                      (h.gain[0] == "exciter" and ch.in_spec == h.gain[1])
                g = theta if hit else 1.0
                Hs.append(H0 * g)
                dHs.append(H0 / theta if hit else np.zeros_like(H0))
                continue
            y, z, RUU, w = piece
            nU = len(h.dofs)
            if h.crack is not None:
                Dt = self._D(w, theta)            # already scaled by the depth
                scale = 1.0
            else:
                Dt = self._D(w, 1.0)
                scale = theta
            A = np.eye(nU)[None] + scale * RUU @ Dt            # I + theta R D
            u = np.linalg.solve(A, y[:, :, None])[:, :, 0]
            Du = (Dt @ u[:, :, None])[:, :, 0]
            H = H0 - scale * np.einsum("ku,ku->k", z, Du)
            Hs.append(H)
            if derivative:
                if h.crack is not None:
                    dHs.append(None)
                else:
                    A2 = np.eye(nU)[None] + theta * Dt @ RUU       # I + theta D R
                    t = np.linalg.solve(A2, Du[:, :, None])[:, :, 0]
                    dHs.append(-np.einsum("ku,ku->k", z, t))
        return (Hs, dHs) if derivative else Hs


def _rss(Hs, meas) -> float:
    r = np.concatenate([np.log(h / m) for h, m in zip(Hs, meas)])
    return float(np.sum(r.real ** 2 + r.imag ** 2))


def _fit_size(ev: _Evaluator, n_scan: int = 25, gn_iter: int = 30):
    """Least-squares size of one hypothesis: scan for a start, then Gauss-Newton (or golden section)."""
    h = ev.hyp
    meas = ev.data.meas

    def rss(t):
        try:
            Hs = ev.responses(t)
        except np.linalg.LinAlgError:
            return math.inf
        with np.errstate(all="ignore"):
            v = _rss(Hs, meas)
        return v if math.isfinite(v) else math.inf

    if h.gain is not None:
        # ln g enters linearly: closed form over the affected channels
        r = []
        for ch, H0, m in zip(ev.data.chans, ev.data.H0, meas):
            hit = (h.gain[0] == "sensor" and ch.out_dof == h.gain[1]) or \
                  (h.gain[0] == "exciter" and ch.in_spec == h.gain[1])
            if hit:
                r.append(np.log(H0 / m).real)
        g = float(np.exp(-np.mean(np.concatenate(r))))
        g = min(max(g, h.lower), h.upper)
        return g, rss(g)

    # scan: the null size, and sizes over four decades either side of the typical scale
    mags = h.scale * np.logspace(-3, 1, n_scan)
    grid = [0.0] + [m for m in mags if h.lower <= m <= h.upper] + [-m for m in mags if h.lower <= -m <= h.upper]
    vals = [rss(t) for t in grid]
    k = int(np.argmin(vals))
    t, best = grid[k], vals[k]
    if h.crack is not None:
        # one-dimensional and smooth: golden-section refinement between the scan neighbours
        srt = sorted(grid)
        j = srt.index(t)
        a, b = srt[max(j - 1, 0)], srt[min(j + 1, len(srt) - 1)]
        import scipy.optimize as so
        res = so.minimize_scalar(rss, bounds=(a, b), method="bounded", options={"xatol": 1e-6})
        if res.fun < best:
            t, best = float(res.x), float(res.fun)
        return t, best
    for _ in range(gn_iter):
        Hs, dHs = ev.responses(t, derivative=True)
        r = np.concatenate([np.log(hh / m) for hh, m in zip(Hs, meas)])
        J = np.concatenate([d / hh for d, hh in zip(dHs, Hs)])
        den = float(np.sum(np.abs(J) ** 2))
        if not den > 0:
            break
        step = -float(np.sum((np.conj(J) * r).real)) / den
        lam = 1.0
        improved = False
        while lam > 1e-4:
            tn = min(max(t + lam * step, h.lower), h.upper)
            vn = rss(tn)
            if vn < best:
                improved = True
                break
            lam *= 0.5
        if not improved:
            break
        rel = abs(tn - t) / max(abs(t), 1e-12 * h.scale)
        t, best = tn, vn
        if rel < 1e-9:
            break
    return t, best


def _jacobian_std(ev: _Evaluator, theta: float, s2: float) -> float:
    """Linearised standard uncertainty of the size: s * (J^T J)^{-1/2} (J from a central difference)."""
    h = ev.hyp
    if h.gain is not None:
        Hs, dHs = ev.responses(theta, derivative=True)
    elif h.crack is None:
        Hs, dHs = ev.responses(theta, derivative=True)
    else:
        d = max(1e-4, 1e-3 * abs(theta))
        lo, hi = max(theta - d, 0.0), theta + d
        Hl, Hh = ev.responses(lo), ev.responses(hi)
        Hs = ev.responses(theta)
        dHs = [(b - a) / (hi - lo) for a, b in zip(Hl, Hh)]
    J = np.concatenate([d / hh for d, hh in zip(dHs, Hs)])
    den = float(np.sum(np.abs(J) ** 2))
    return math.sqrt(s2 / den) if den > 0 else math.inf


# ----------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------

@dataclass
class Finding:
    """One tested hypothesis with its fitted size and score.

    ``value`` is the size: the change of an existing value or the value of an
    added element (SI), the depth ratio of a crack, or the factor of a gain.
    ``std`` its standard uncertainty; ``score`` the information criterion
    (lower is better); ``delta_chi2`` the improvement over *none*;
    ``significant`` whether it passes the false-alarm test.
    """
    kind: str
    station: int | None
    element: str | None
    value: float
    unit: str
    std: float
    score: float
    delta_chi2: float
    description: str
    significant: bool = False
    refit: bool = False
    new_value: float | None = None
    hypothesis: Hypothesis | None = field(default=None, repr=False)

    def as_dict(self) -> dict:
        return {"kind": self.kind, "station": self.station, "element": self.element, "value": self.value,
                "unit": self.unit, "std": self.std, "score": self.score, "delta_chi2": self.delta_chi2,
                "description": self.description, "significant": self.significant, "refit": self.refit,
                "new_value": self.new_value}

    def sentence(self) -> str:
        if self.kind == "none":
            return "no effect beyond the noise"
        if self.unit == "1" and self.kind.endswith("gain"):
            return f"{self.description}: x{self.value:.4g} +/- {self.std:.2g}"
        if self.kind == "crack":
            return f"{self.description}: depth ratio a/D = {self.value:.4g} +/- {self.std:.2g}"
        return f"{self.description}: {self.value:+.4g} +/- {self.std:.2g} {self.unit}"


@dataclass
class ResonanceRow:
    """Measured against modelled resonance of one channel."""
    channel: str
    measured_hz: float
    measured_hz_std: float
    model_hz: float
    measured_damping: float
    measured_damping_std: float
    model_damping: float
    measured_peak: float
    model_peak: float

    @property
    def freq_error(self) -> float:
        """(model - measured) / measured."""
        return (self.model_hz - self.measured_hz) / self.measured_hz

    def as_dict(self) -> dict:
        d = dict(self.__dict__)
        d["freq_error"] = self.freq_error
        return d


@dataclass
class ChannelComparison:
    """Model against data in one channel (SI units)."""
    label: str
    source: str
    freq_hz: np.ndarray
    measured: np.ndarray
    before: np.ndarray
    after: np.ndarray | None = None
    role: str = "fit"            # "fit" or "validate"

    @property
    def residual_db(self) -> np.ndarray:
        """20 log10 |model/measured| before the fix [dB]."""
        return 20 * np.log10(np.abs(self.before / self.measured))

    @property
    def residual_deg(self) -> np.ndarray:
        return np.degrees(np.angle(self.before / self.measured))


@dataclass
class Diagnosis:
    """Result of :func:`diagnose` (see its docstring); ``as_dict()`` is the ``--json`` object."""
    model_name: str
    model_source: str | None
    noise: float
    findings: list
    verdict: Finding
    ambiguous_with: list
    separating_sensor: int | None
    error_before: dict
    error_after: dict
    gain: float
    held_out: str
    channels: list
    resonances: list
    summary: list
    threshold: float
    alpha: float
    n_hypotheses: int
    extended_model_text: str | None
    seconds: float
    notes: list = field(default_factory=list)
    n_residuals: int = 0          # real residuals of the fit (2 per complex point)
    extended_model: str | None = None
    mbi: dict | None = None

    def as_dict(self) -> dict:
        return {
            "model": self.model_source or self.model_name,
            "findings": [f.as_dict() for f in self.findings],
            "verdict": self.verdict.as_dict(),
            "noise": self.noise,
            "error_before": self.error_before, "error_after": self.error_after, "gain": self.gain,
            "held_out": self.held_out,
            "ambiguous_with": [f.as_dict() for f in self.ambiguous_with],
            "separating_sensor": self.separating_sensor,
            "resonances": [r.as_dict() for r in self.resonances],
            "summary": self.summary,
            "threshold_delta_chi2": self.threshold, "alpha": self.alpha, "n_hypotheses": self.n_hypotheses,
            "n_residuals": self.n_residuals,
            "extended_model": self.extended_model,
            "mbi": self.mbi,
            "notes": self.notes,
            "seconds": self.seconds,
        }

    def misfit_left(self, finding: Finding) -> float:
        """The misfit after ``finding``, in units of what noise alone leaves (about 1 for the right model)."""
        none = next(f for f in self.findings if f.kind == "none")
        return (none.score - finding.delta_chi2) / max(self.n_residuals, 1)

    def report(self) -> str:
        """Plain-text report (what the command prints)."""
        out = [f"model: {self.model_source or self.model_name}",
               f"noise level estimated from the data: {100 * self.noise:.3g} % (relative, rms)", ""]
        if self.resonances:
            # one row per model resonance: the channel that measures it most precisely
            best: dict = {}
            for r in self.resonances:
                k = round(r.model_hz, 9)
                if not math.isfinite(r.measured_hz_std):
                    continue
                if k not in best or r.measured_hz_std < best[k].measured_hz_std:
                    best[k] = r
            out.append("resonances (measured from the data by vector fitting, +/- 1 std; the most precise "
                       "channel of each):")
            out.append(f"  {'channel':<10} {'measured Hz':>18} {'model Hz':>10} {'error':>8} "
                       f"{'zeta meas.':>16} {'zeta model':>10}")
            for _, r in sorted(best.items()):
                out.append(f"  {r.channel:<10} {r.measured_hz:>10.4g} +/-{r.measured_hz_std:<6.2g}"
                           f"{r.model_hz:>10.4g} {100 * r.freq_error:>+7.2f}% "
                           f"{r.measured_damping:>8.3g} +/-{r.measured_damping_std:<5.2g}{r.model_damping:>10.3g}")
            out.append("")
        out += [f"  {s}" for s in self.summary] + [""]
        out.append(f"hypotheses tested: {self.n_hypotheses} (accept if delta chi2 > {self.threshold:.1f}, "
                   f"false-alarm rate {100 * self.alpha:g} %; misfit left: after the hypothesis, in units of "
                   f"the noise's, about 1 when right)")
        out.append(f"  {'rank':<4} {'kind':<12} {'station':>7} {'element':<14} {'size':>24} {'delta chi2':>11} "
                   f"{'misfit left':>11}")
        for k, f in enumerate(self.findings[:8], start=1):
            size = "-" if f.kind == "none" else (f"x{f.value:.4g}" if f.kind.endswith("gain")
                                                 else f"a/D {f.value:.4g}" if f.kind == "crack"
                                                 else f"{f.value:+.4g} {f.unit}")
            sd = "" if f.kind == "none" else f" +/- {f.std:.2g}"
            out.append(f"  {k:<4} {f.kind:<12} {str(f.station or '-'):>7} {str(f.element or '-'):<14} "
                       f"{size + sd:>24} {f.delta_chi2:>11.1f} {self.misfit_left(f):>11.3g}")
        out.append("")
        out.append(f"verdict: {self.verdict.sentence()}")
        if self.ambiguous_with:
            names = "; ".join(f"{f.kind} at {f.station} ({f.element})" for f in self.ambiguous_with)
            out.append(f"  cannot be told apart from: {names}")
            if self.separating_sensor is not None:
                out.append(f"  a sensor at station {self.separating_sensor} would separate them best")
        eb, ea = self.error_before, self.error_after
        out.append(f"held-out data ({self.held_out}):")
        out.append(f"  before: {100 * eb['rel']:.3g} % rms complex error, {eb['db']:.3g} dB rms log-magnitude")
        out.append(f"  after:  {100 * ea['rel']:.3g} % rms complex error, {ea['db']:.3g} dB rms log-magnitude")
        out.append(f"  gain:   {self.gain:.3g}x  (noise level {100 * self.noise:.3g} %)")
        if self.mbi:
            m = self.mbi
            out.append(f"model-based identification (controller at {m.get('location')}): {m.get('reading')}")
            if m.get("agrees") is not None:
                out.append(f"  {m['compared']}: MBI {m['mbi_value']:+.4g} +/- {m['mbi_std']:.2g} against the "
                           f"diagnosis {m['diagnosis_value']:+.4g}: "
                           + ("they agree" if m["agrees"] else "they DISAGREE (beyond 3 standard uncertainties)")
                           + f" (mu {m['mu']:.3f}, {m['seconds']:.0f} s)")
        if self.extended_model:
            out.append(f"extended model: {self.extended_model}")
        for n in self.notes:
            out.append(f"note: {n}")
        out.append(f"({self.seconds:.1f} s)")
        return "\n".join(out)


# ----------------------------------------------------------------------------
# the extended model file
# ----------------------------------------------------------------------------

def _toml_number(x: float) -> str:
    return f"{x:.8g}" if "e" not in f"{x:.8g}" else f"{x:.8e}"


def _replace_value(text: str, table: str, match: Callable[[dict], bool], doc_tables: list, key: str,
                   value: float, comment: str) -> str:
    """Set ``key = value`` in the k-th ``[[table]]`` of TOML text (the one ``match`` selects)."""
    k = next((i for i, t in enumerate(doc_tables) if match(t)), None)
    if k is None:
        raise ModelError(f"cannot find the [[{table}]] entry to change in the model file")
    lines = text.splitlines()
    count, start = -1, None
    for i, ln in enumerate(lines):
        if re.match(rf"^\s*\[\[\s*{re.escape(table)}\s*\]\]", ln):
            count += 1
            if count == k:
                start = i
                break
    if start is None:
        raise ModelError(f"cannot locate [[{table}]] #{k + 1} in the model text")
    for i in range(start + 1, len(lines)):
        if re.match(r"^\s*\[", lines[i]):
            break
        m = re.match(rf"^(\s*{re.escape(key)}\s*=\s*)([^#]*?)(\s*(#.*)?)$", lines[i])
        if m:
            lines[i] = f"{m.group(1)}{_toml_number(value)}   # {comment} (was {m.group(2).strip()})"
            return "\n".join(lines) + "\n"
    # key absent: insert after the header
    lines.insert(start + 1, f"{key} = {_toml_number(value)}   # {comment}")
    return "\n".join(lines) + "\n"


def extended_model_text(model_text: str, finding: Finding, model) -> str:
    """The model file's text with the finding built in (a comment names the finding)."""
    import tomllib
    doc = tomllib.loads(model_text)
    h = finding.hypothesis
    note = f"mutext diagnose: {finding.sentence()}"
    header = f"# Extended by mutext diagnose: {finding.sentence()}\n"
    lay = model.layout
    if h is None or finding.kind == "none":
        return model_text
    if finding.kind == "sensor_gain":
        return header + "# (a sensor calibration: the model itself is unchanged)\n" + model_text
    if lay.kind == "lumped":
        names = lay.node_names
        if h.added:
            tbl = "spring" if h.kind == "stiffness" else "damper"
            key = "stiffness" if h.kind == "stiffness" else "damping"
            return (header + model_text.rstrip("\n") + f"\n\n# {note}\n[[{tbl}]]\nname = \"{h.element}\"\n"
                    f"{key} = {_toml_number(finding.value)}\nbetween = [\"{names[h.station - 1]}\", \"ground\"]\n")
        if h.kind == "exciter_gain":
            return header + "# (the force input's gain: the model itself is unchanged)\n" + model_text
        tbl, key = {"mass": ("mass", "mass"), "stiffness": ("spring", "stiffness"),
                    "damping": ("damper", "damping")}[h.kind]
        new = finding.new_value
        return header + _replace_value(model_text, tbl, lambda t: t.get("name") == h.element,
                                       doc.get(tbl, []), key, new, note)
    # rotors
    if h.kind == "bearing":
        key = "stiffness" if h.order == 0 else "damping"
        return header + _replace_value(model_text, "bearing", lambda t: t.get("station") == h.station,
                                       doc.get("bearing", []), key, finding.new_value, note)
    if h.kind == "exciter_gain":
        st = h.gain[1]
        port = model.inputs[st[1]] if st[0] == "port" else None
        if port is None:
            return header + "# (the force input's gain: the model itself is unchanged)\n" + model_text
        ki = float(model.parameter(port.gain).value) * finding.value
        return header + _replace_value(model_text, "exciter", lambda t: t.get("station") == port.node,
                                       doc.get("exciter", []), "force_per_ampere", ki, note)
    add = {"stiffness": f"[[bearing]]\nname = \"{h.element}\"\nstation = {h.station}\n"
                        f"stiffness = {_toml_number(finding.value)}\ndamping = 0.0\n",
           "damping": f"[[bearing]]\nname = \"{h.element}\"\nstation = {h.station}\nstiffness = 0.0\n"
                      f"damping = {_toml_number(finding.value)}\n",
           "mass": f"[[disk]]\nname = \"{h.element}\"\nstation = {h.station}\nmass = {_toml_number(finding.value)}\n",
           "crack": f"[[crack]]\nstation = {h.station}\ndepth_ratio = {_toml_number(finding.value)}\n"}[h.kind]
    return header + model_text.rstrip("\n") + f"\n\n# {note}\n" + add


# ----------------------------------------------------------------------------
# comparison helpers
# ----------------------------------------------------------------------------

def _errors(Hs, meas) -> dict:
    num = np.concatenate([np.abs(h - m) ** 2 / np.abs(m) ** 2 for h, m in zip(Hs, meas)])
    db = np.concatenate([20 * np.log10(np.abs(h / m)) for h, m in zip(Hs, meas)])
    return {"rel": float(np.sqrt(np.mean(num))), "db": float(np.sqrt(np.mean(db ** 2)))}


def _model_modes(model, speed):
    md = model.modes(speed=speed)
    f = np.abs(md.eigenvalues) / (2 * np.pi)        # undamped natural frequency, as the data's poles
    z = np.asarray(md.damping_ratio, float)
    return f, z


#: Smallest relative frequency difference the summary calls a mismatch: vector fitting of noisy data is
#: biased by up to about 0.1-0.2 % (beyond its bootstrap standard deviation), so less is not claimed.
FREQ_RESOLUTION = 0.003


def _model_resonances(fm, zm, band):
    """Model resonances inside ``band`` [Hz], modes closer than zeta f merged (e.g. the whirl pair of a
    nearly isotropic rotor, which one sensor sees as one resonance)."""
    out = []
    for k in np.argsort(fm):
        if not band[0] <= fm[k] <= band[1]:
            continue
        if out and fm[k] - out[-1][0][-1] <= max(zm[k], 1e-3) * fm[k]:
            out[-1][0].append(fm[k])
            out[-1][1].append(zm[k])
        else:
            out.append(([fm[k]], [zm[k]]))
    return [(float(np.mean(f)), float(np.mean(z))) for f, z in out]


def _resonance_table(chans, before, model, speed, noise) -> list[ResonanceRow]:
    """Measured resonances matched one to one to the model's (nearest in log frequency, within 50 %)."""
    from scipy.optimize import linear_sum_assignment
    rows = []
    try:
        fm, zm = _model_modes(model, speed)
    except Exception as exc:  # pragma: no cover
        log.debug("model modes failed: %s", exc)
        return rows
    for ch, Hb in zip(chans, before):
        f = ch.frf.freq_hz
        try:
            res = resonances(f, ch.frf.response, noise=noise)
        except ModelError as exc:
            log.debug("no resonances for %s: %s", ch.label, exc)
            continue
        mods = _model_resonances(fm, zm, (f[0], f[-1]))
        if not res or not mods:
            continue
        cost = np.abs(np.log(np.array([r.freq_hz for r in res])[:, None] / np.array([m[0] for m in mods])[None]))
        for i, j in zip(*linear_sum_assignment(cost)):
            if cost[i, j] > math.log(1.5):
                continue
            r, (fmod, zmod) = res[i], mods[j]
            peak_model = float(np.interp(fmod, f, np.abs(Hb)))
            rows.append(ResonanceRow(ch.label, r.freq_hz, r.freq_std, fmod, r.damping_ratio, r.damping_std, zmod,
                                     r.peak, peak_model))
    return rows


def _ordinal(k: int) -> str:
    return {1: "first", 2: "second", 3: "third", 4: "fourth", 5: "fifth"}.get(k, f"{k}th")


def _summary(rows: list[ResonanceRow], chans, before) -> list[str]:
    out = []
    by_mode: dict[float, list] = {}
    for r in rows:
        if not math.isfinite(r.measured_hz_std):     # not found in most bootstrap refits: not reliable
            continue
        by_mode.setdefault(round(r.model_hz, 6), []).append(r)
    for k, (fmod, rs) in enumerate(sorted(by_mode.items()), start=1):
        r = min(rs, key=lambda x: x.measured_hz_std)
        err = r.freq_error
        sd = r.measured_hz_std / r.measured_hz
        if abs(err) <= max(3 * sd, FREQ_RESOLUTION):
            out.append(f"the model's {_ordinal(k)} resonance ({r.model_hz:.4g} Hz) is right within the "
                       f"measurement's resolution ({100 * err:+.2f} %; resolution "
                       f"{100 * max(3 * sd, FREQ_RESOLUTION):.2g} %)")
        else:
            hl = "high" if err > 0 else "low"
            out.append(f"the model's {_ordinal(k)} resonance ({r.model_hz:.4g} Hz) is {100 * abs(err):.2f} % {hl} "
                       f"(measured {r.measured_hz:.4g} +/- {r.measured_hz_std:.2g} Hz)")
    for ch, Hb in zip(chans, before):
        db = 20 * np.log10(np.abs(Hb / ch.frf.response))
        k = int(np.argmax(np.abs(db)))
        out.append(f"{ch.label}: rms error {np.sqrt(np.mean(db ** 2)):.3g} dB, largest {db[k]:+.3g} dB at "
                   f"{ch.frf.freq_hz[k]:.4g} Hz")
    return out


# ----------------------------------------------------------------------------
# the entry point
# ----------------------------------------------------------------------------

def _as_frfs(frfs, what) -> list[FRF]:
    if frfs is None:
        return []
    if isinstance(frfs, (FRF, str, os.PathLike)):
        frfs = [frfs]
    out = [f if isinstance(f, FRF) else read_frf(f) for f in frfs]
    return out


def _same_data(a: FRF, b: FRF) -> bool:
    return (a.freq_hz.shape == b.freq_hz.shape and np.array_equal(a.freq_hz, b.freq_hz)
            and np.array_equal(a.response, b.response))


def diagnose(model, frfs, validate=None, *, alpha: float = 0.01, refit: int = 3, noise: float | None = None,
             out_dir=None, progress: Callable[[str, float], None] | None = None,
             only: Callable[[Hypothesis], bool] | None = None, mbi: bool = False) -> Diagnosis:
    r"""Find what ``model`` gets wrong against measured FRFs, name the cause, extend the model, measure the gain.

    See the module docstring for the method and the statistics.

    Parameters
    ----------
    model : str or os.PathLike
        Model file (TOML, :mod:`mutext.rotor.model`): a lumped chain or a rotor.
        (A path is needed to write the extended model next to it.)
    frfs : sequence of FRF or paths
        Measured channels used for the fit.  Stations as numbered in the model
        file (masses 1..n of a chain); directions ``input_direction`` /
        ``output_direction`` (default x).
    validate : sequence of FRF or paths, optional
        Channels held out of the fit, on which the gain is measured.  Default:
        every :data:`HOLDOUT_EVERY`-th frequency of each fitted channel.
    alpha : float
        False-alarm rate of the *none* verdict (Bonferroni over the hypotheses).
    refit : int
        Number of best hypotheses refitted on the extended model with
        :func:`mutext.rotor.tuning.tune`.
    noise : float, optional
        Relative noise level; default estimated from the data
        (:func:`mutext.frfit.noise_level`).
    out_dir : path, optional
        Write ``model_extended.toml`` there (see also :func:`write_outputs`).
    progress : callable(stage: str, fraction: float), optional
        Called as the work proceeds (the command line draws a progress line).
    mbi : bool
        Also read the top finding the thesis's way (lumped chains): model-based
        identification (:func:`mutext.mbi.identify`, D-K iteration) with the
        controller at the finding's mass, K read as mass, damper and spring,
        compared with the diagnosis (``Diagnosis.mbi``).  Takes 5-60 s more.
    only : callable(Hypothesis) -> bool, optional
        Test only the hypotheses it accepts (e.g. a fit told the kind and the
        location: ``only=lambda h: (h.kind, h.station) == ("mass", 3)``); the
        Bonferroni threshold counts the hypotheses actually tested.

    Returns
    -------
    Diagnosis
    """
    from .rotor.model import load_model, loads_model
    from .rotor.tuning import model_response
    t0 = time.perf_counter()

    def tell(stage, frac):
        log.info("%s (%.0f %%)", stage, 100 * frac)
        if progress is not None:
            progress(stage, frac)

    if not isinstance(model, (str, os.PathLike)):
        raise ModelError("diagnose: give the model as a model file path (TOML); the extended model is "
                         "written from it")
    path = os.fspath(model)
    eng = load_model(path)
    with open(path, encoding="utf-8") as fh:
        model_text = fh.read()
    if not 0 < alpha < 1:
        raise ModelError(f"diagnose: alpha must be in (0, 1), got {alpha}")
    fit_frfs = _as_frfs(frfs, "data")
    if not fit_frfs:
        raise ModelError("diagnose: no measured FRF given")
    val_frfs = _as_frfs(validate, "validation")
    for v in val_frfs:
        for f in fit_frfs:
            if _same_data(v, f):
                raise ModelError(f"validation file {_src(v, 0)} holds the same data as the fitted "
                                 f"{_src(f, 0)}: held-out data must not be used in the fit")
    chans, _ = _resolve(eng, fit_frfs, "data")
    vchans, _ = _resolve(eng, val_frfs, "validation") if val_frfs else ([], None)
    speeds = {c.speed for c in chans + vchans}
    if len(speeds) > 1:
        raise ModelError(f"diagnose: the FRFs were measured at different running speeds "
                         f"({sorted(s / (2 * math.pi) for s in speeds)} Hz); diagnose one speed at a time")
    speed = speeds.pop()
    # frequency overlap with the model's modes: at least one model resonance within the data band
    fmin = min(c.frf.freq_hz[0] for c in chans)
    fmax = max(c.frf.freq_hz[-1] for c in chans)
    fmodes, _ = _model_modes(eng, speed)
    if not np.any((fmodes >= fmin) & (fmodes <= fmax)):
        raise ModelError(f"diagnose: the data cover {fmin:g}-{fmax:g} Hz but the model has no resonance there "
                         f"(model resonances: {', '.join(f'{x:.4g}' for x in fmodes[:6])} Hz): check the units of "
                         f"the frequency column and that the file belongs to this model")

    # noise level from the data alone
    if noise is None:
        lv = [noise_level(c.frf.freq_hz, c.frf.response) for c in chans]
        npts = [c.frf.freq_hz.size for c in chans]
        noise = float(math.sqrt(np.average(np.square(lv), weights=npts)))
    elif not (isinstance(noise, (int, float)) and math.isfinite(noise) and 0 < noise < 1):
        raise ModelError(f"diagnose: noise must be a relative level in (0, 1), e.g. 0.01 for 1 %; got {noise!r}")
    noise = max(float(noise), 1e-6)
    s2 = noise ** 2 / 2.0
    tell("engineering model's receptance", 0.02)

    # one frequency grid for every channel
    allf = np.unique(np.concatenate([c.frf.freq_hz for c in chans + vchans]))
    omega = 2 * np.pi * allf
    rec = _Receptance(eng, None, speed, omega)

    def data_for(cs, keep):
        idx, meas, H0, b, fs = [], [], [], [], []
        for c, kp in zip(cs, keep):
            pos = np.searchsorted(allf, c.frf.freq_hz[kp])
            bb = rec.input_vector(c.in_spec)
            idx.append(pos)
            meas.append(c.frf.response[kp])
            H0.append(rec.R[pos][:, c.out_dof, :] @ bb)
            b.append(bb)
            fs.append(c.frf.freq_hz[kp])
        return _Data(list(cs), idx, meas, H0, b, fs)

    if vchans:
        fit = data_for(chans, [np.arange(c.frf.freq_hz.size) for c in chans])
        held = data_for(vchans, [np.arange(c.frf.freq_hz.size) for c in vchans])
        held_desc = f"{len(vchans)} validation channel(s): " + ", ".join(_src(c.frf, k) for k, c in
                                                                             enumerate(vchans, 1))
    else:
        keep_fit, keep_out = [], []
        for c in chans:
            k = np.arange(c.frf.freq_hz.size)
            keep_out.append(k[k % HOLDOUT_EVERY == HOLDOUT_EVERY // 2])
            keep_fit.append(k[k % HOLDOUT_EVERY != HOLDOUT_EVERY // 2])
        fit, held = data_for(chans, keep_fit), data_for(chans, keep_out)
        held_desc = (f"every {HOLDOUT_EVERY}th frequency of the fitted channels, held out of the fit "
                     f"(no validation files given; neighbouring frequencies are not independent data)")
    all_fit = data_for(chans, [np.arange(c.frf.freq_hz.size) for c in chans])

    # 1. what the simulation gets wrong
    before = all_fit.H0
    rows = _resonance_table(chans, before, eng, speed, noise)
    summary = _summary(rows, chans, before)

    # 2. hypotheses
    hyps = hypotheses(eng) + _gain_hypotheses(eng, chans)
    if only is not None:
        hyps = [h for h in hyps if only(h)]
        if not hyps:
            raise ModelError("diagnose: no hypothesis passes the 'only' filter")
    N = 2 * fit.n_points
    rss0 = _rss(fit.H0, fit.meas)
    nh = len(hyps)
    threshold = float(sst.chi2.isf(alpha / nh, 1))
    scored = []
    for k, h in enumerate(hyps):
        if k % max(1, nh // 20) == 0:
            tell(f"screening hypotheses {k + 1}/{nh}", 0.05 + 0.6 * k / nh)
        ev = _Evaluator(rec, fit, h)
        theta, rss = _fit_size(ev)
        scored.append((h, theta, rss, ev))
    findings = []
    for h, theta, rss, ev in scored:
        std = _jacobian_std(ev, theta, s2) if rss < rss0 else math.inf
        findings.append(_finding(h, theta, std, rss, rss0, s2, N, threshold))
    none = Finding("none", None, None, 0.0, "", 0.0, rss0 / s2, 0.0, "no effect beyond the noise")
    findings.sort(key=lambda f: f.score)

    # refit the best few on the extended model file itself (with modal damping, the damping matrix
    # follows the changed stiffness and mass there, unlike in the screen)
    notes = []
    n_ref = 0
    for f in findings:
        if n_ref >= refit:
            break
        if f.delta_chi2 <= 0.5 * threshold:      # cannot become significant: no need to refit
            continue
        h = f.hypothesis
        if h.gain is not None or h.parameter is None:
            continue
        n_ref += 1
        tell(f"refitting {f.kind} at {f.station} on the extended model", 0.7 + 0.2 * n_ref / max(refit, 1))
        try:
            _refit(f, model_text, path, eng, fit, s2, N, rss0, threshold)
        except Exception as exc:   # the screen's value stands; say why
            notes.append(f"refit of {f.kind} at station {f.station} failed ({exc}); the screen's value is shown")
    findings.sort(key=lambda f: f.score)
    findings.insert(next((i for i, f in enumerate(findings) if f.score > none.score), len(findings)), none)

    best = next(f for f in findings if f.kind != "none")
    verdict = best if best.significant else none
    if verdict is none and best.delta_chi2 > 0:
        notes.append(f"best hypothesis ({best.description}) improves the fit by delta chi2 = "
                     f"{best.delta_chi2:.1f}, below the threshold {threshold:.1f}")
    ambiguous, sensor = [], None
    if verdict is not none:
        ambiguous = [f for f in findings if f is not verdict and f.kind != "none" and f.significant
                     and (f.score - verdict.score) < float(sst.chi2.isf(0.05, 1))]
        if ambiguous:
            sensor = _separating_station(rec, fit, [verdict] + ambiguous, eng)
        fit_rss_after = verdict.score - math.log(N)
        if fit_rss_after > 2 * N + 6 * math.sqrt(2 * N):
            notes.append(f"after the best hypothesis the residual is still {math.sqrt(fit_rss_after / N):.2g} "
                         f"times the noise: part of the misfit lies beyond the hypotheses tested")

    # 3. the gain on held-out data
    tell("held-out gain", 0.95)
    err_before = _errors(held.H0, held.meas)
    after_held = held.H0
    after_all = None
    text = extended_model_text(model_text, verdict, eng) if verdict is not none else None
    if verdict is not none and verdict.hypothesis.gain is None:
        # the extended model file itself, loaded as a user would load it
        ext = loads_model(text, source=f"{path} (extended)", base_dir=os.path.dirname(os.path.abspath(path)))
        after_held = [model_response(ext, c.frf, freq_hz=fs) for c, fs in zip(held.chans, held.freq_hz)]
        after_all = [model_response(ext, c.frf) for c in chans]
    elif verdict is not none:
        after_held = _Evaluator(rec, held, verdict.hypothesis).responses(verdict.value)
        after_all = _Evaluator(rec, all_fit, verdict.hypothesis).responses(verdict.value)
    err_after = _errors(after_held, held.meas)
    gain = err_before["rel"] / err_after["rel"] if err_after["rel"] > 0 else math.inf

    comps = []
    for k, c in enumerate(chans):
        comps.append(ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response, before[k],
                                       None if after_all is None else after_all[k], "fit"))
    if vchans:
        for k, c in enumerate(vchans):
            comps.append(ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response,
                                           held.H0[k], after_held[k] if verdict is not none else None,
                                           "validate"))
    result = Diagnosis(eng.name, path, noise, findings, verdict, ambiguous, sensor, err_before, err_after, gain,
                       held_desc, comps, rows, summary, threshold, alpha, nh, text,
                       time.perf_counter() - t0, notes, N)
    if mbi and verdict is not none:
        tell("model-based identification at the finding (D-K iteration)", 0.97)
        try:
            result.mbi = mbi_reading(model_text, path, verdict, chans[0].frf, chans[0].in_name,
                                     chans[0].out_name)
        except ModelError as exc:
            result.mbi = {"location": None, "reading": f"not run: {exc}", "agrees": None}
        result.seconds = time.perf_counter() - t0
    if out_dir is not None:
        write_model(result, out_dir)
    tell("done", 1.0)
    return result


def mbi_reading(model_text: str, path: str, finding: Finding, frf: FRF, excitation: str,
                measurement: str) -> dict:
    r"""The thesis's route to the same finding: a mu-controller at the finding's mass absorbs the effect.

    The engineering model gets a force input and a displacement output at the
    finding's mass; :func:`mutext.mbi.identify` tunes a controller there so that
    the model follows the measured channel ``frf`` (``excitation`` to
    ``measurement``), and reads it as an added mass, damper and spring
    (:func:`mutext.mbi.fit_impedance`).  The quantity of the finding's kind is
    compared with the diagnosis: they agree when they differ by at most three
    combined standard uncertainties (the MBI one from its impedance fit:
    the larger of the coefficient's standard error and the fit's relative
    residual times the coefficient).

    Only lumped chains and findings at one mass (a mass, a grounded spring or
    damper) have a single controller location; other findings raise ModelError.
    """
    import tomllib
    from .mbi import identify
    from .rotor.model import loads_model
    h = finding.hypothesis
    doc = tomllib.loads(model_text)
    if "mass" not in doc:
        raise ModelError("model-based identification is run on lumped chains only (a rotor needs a reduced "
                         "model and minutes of D-K iteration)")
    if h is None or h.gain is not None or len(h.dofs) != 1:
        raise ModelError(f"a {finding.kind} finding between two masses or on a gain has no single controller "
                         "location")
    mass = doc["mass"][h.station - 1]["name"]
    text = model_text + (f'\n[[force]]\nname = "u_mbi"\nmass = "{mass}"\n'
                         f'[[sensor]]\nname = "y_mbi"\nmass = "{mass}"\n')
    ext = loads_model(text, source=f"{path} (controller at {mass})",
                      base_dir=os.path.dirname(os.path.abspath(path)))
    E = ext.state_space(inputs=[excitation, "u_mbi"], outputs=[measurement, "y_mbi"])
    t0 = time.perf_counter()
    res = identify(frf, E, excitation=excitation, measurement=measurement, control_input="u_mbi",
                   control_output="y_mbi", out=None)
    fit = res.fit
    coef = {"mass": ("dm", 0), "damping": ("dc", 1), "stiffness": ("dk", 2)}[finding.kind]
    v = float(getattr(fit, coef[0]))
    sd = max(float(fit.sigma[coef[1]]), float(fit.residual) * abs(v))
    comb = math.sqrt(sd ** 2 + finding.std ** 2)
    return {"location": mass, "reading": fit.description, "mu": float(res.mu_upper), "Wz": float(res.Wz),
            "dm": float(fit.dm), "dc": float(fit.dc), "dk": float(fit.dk),
            "sigma": [float(x) for x in fit.sigma], "residual": float(fit.residual),
            "compared": coef[0], "mbi_value": v, "mbi_std": sd, "diagnosis_value": finding.value,
            "agrees": bool(abs(v - finding.value) <= 3 * comb), "seconds": time.perf_counter() - t0}


def _finding(h, theta, std, rss, rss0, s2, N, threshold) -> Finding:
    dchi = (rss0 - rss) / s2
    new = None
    if h.gain is None and not h.added:
        new = h.nominal + theta
    return Finding(h.kind, h.station, h.element, float(theta), h.unit, float(std), rss / s2 + math.log(N),
                   float(dchi), h.description, bool(dchi > threshold), False, new, h)


def _refit(f: Finding, model_text, path, eng, fit: _Data, s2, N, rss0, threshold):
    """Fit the size again with tune() on the extended model; update the finding in place."""
    from .rotor.model import loads_model
    from .rotor.tuning import tune
    h = f.hypothesis
    start = f.value if not h.added else max(f.value, 1e-3 * h.scale)
    trial = Finding(**{**f.__dict__, "value": start,
                       "new_value": None if h.added else h.nominal + start})
    text = extended_model_text(model_text, trial, eng)
    ext = loads_model(text, source=f"{path} (extended)", base_dir=os.path.dirname(os.path.abspath(path)))
    name = h.parameter
    lo = 1e-9 * h.scale if h.added else h.nominal + h.lower
    hi = h.upper if h.added else h.nominal + h.upper
    frfs = [replace(c.frf, freq_hz=fs, response=m, metadata=dict(c.frf.metadata))
            for c, fs, m in zip(fit.chans, fit.freq_hz, fit.meas)]
    x0 = min(max(float(ext.values()[ext.parameter_names.index(name)]), lo), hi)
    res = tune(ext, frfs, [name], bounds={name: (lo, hi)}, start={name: x0}, max_iter=60)
    v = res.values[name]
    rms = (res.residual_rms_db / DB_PER_NEPER) ** 2 + math.radians(res.residual_rms_deg) ** 2
    rss = res.n_points * rms
    f.value = float(v - h.nominal)
    f.new_value = None if h.added else float(v)
    f.std = float(res.std[name]) * math.sqrt(s2) / max(res.sigma, 1e-300)
    f.delta_chi2 = float((rss0 - rss) / s2)
    f.score = rss / s2 + math.log(N)
    f.significant = bool(f.delta_chi2 > threshold)
    f.refit = True


def _separating_station(rec: _Receptance, fit: _Data, cands: list, model) -> int | None:
    """Station whose (translational) response would best separate the candidates' fitted models."""
    lay = model.layout
    best, best_station = -1.0, None
    for s in range(1, lay.n_nodes + 1):
        d = lay.dof(s, "x" if lay.kind == "lumped" else "u")
        resp = []
        for f in cands:
            h = f.hypothesis
            hs = []
            for ch, idx, b in zip(fit.chans, fit.idx, fit.b):
                probe = _Chan(ch.frf, ch.label, ch.in_spec, ch.in_col, ch.in_name, ch.in_station, d, "probe", s,
                              ch.speed)
                Rk = rec.R[idx]
                H0 = Rk[:, d, :] @ b
                data = _Data([probe], [idx], [H0], [H0], [b])
                hs.append(_Evaluator(rec, data, h).responses(f.value)[0])
            resp.append(np.concatenate(hs))
        sep = min(float(np.sqrt(np.mean(np.abs(np.log(resp[i] / resp[j])) ** 2)))
                  for i in range(len(resp)) for j in range(i + 1, len(resp)))
        if sep > best:
            best, best_station = sep, s
    return best_station


def write_model(result: Diagnosis, out_dir) -> str | None:
    """Write the extended model to ``out_dir/model_extended.toml`` (copying a station table it names)."""
    if result.extended_model_text is None:
        return None
    import shutil
    import tomllib
    os.makedirs(out_dir, exist_ok=True)
    text = result.extended_model_text
    doc = tomllib.loads(text)
    table = doc.get("shaft", {}).get("station_table")
    if table and result.model_source:
        src = table if os.path.isabs(table) else os.path.join(os.path.dirname(os.path.abspath(
            result.model_source)), table)
        dst = os.path.join(out_dir, os.path.basename(table))
        if os.path.abspath(src) != os.path.abspath(dst):
            shutil.copyfile(src, dst)
        text = text.replace(f'"{table}"', f'"{os.path.basename(table)}"')
    out = os.path.join(out_dir, "model_extended.toml")
    with open(out, "w", encoding="utf-8") as fh:
        fh.write(text)
    result.extended_model = out
    return out
