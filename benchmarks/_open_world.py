r"""Open-world data for the diagnosis benchmark: effects inside and outside the hypothesis library.

:mod:`mutext.hide` hides one effect that the diagnosis has a hypothesis for.
Real data also hold two effects at once, effects no single hypothesis
describes (damping spread over the whole structure, a sensor delay, a unit
slipped in one file, a nonlinear spring, an unmodelled absorber, ...), a
model that is wrong everywhere, or nothing at all.  :func:`make_case` makes
such data sets for the shipped lumped chains ``three_mass`` and
``four_story``, with the answer kept in ``Case.key``.

Written apart from the code under test
--------------------------------------
Nothing here comes from :mod:`mutext.diagnose`, :mod:`mutext.hide`,
:mod:`mutext.rotor` or :mod:`mutext.frfit` (checked by
``tests/test_open_world_generator.py``): the model file is read as plain
TOML (:func:`read_chain`), the mass, damping and stiffness matrices are
assembled with numpy, effects are applied to the matrices (or to the
measured responses), the responses come from a direct complex solve of
:math:`(K - \omega^2 M + j\omega C)\,x = b` per frequency, and the noise is
relative circular complex Gaussian from this module's own generator,
:math:`\hat H = H\,(1 + \sigma (n_1 + j n_2)/\sqrt 2)`.  Only the container
:class:`mutext.rig.FRF` is the package's.

Channels and grids are those of :mod:`mutext.hide` for lumped chains,
re-derived here: measured, the first ``[[force]]`` to every ``[[sensor]]``
on a grid from half the lowest to 1.4 times the highest natural frequency of
the model handed to the diagnosis, in an analyser's round steps (about 400
points, :func:`band_grid`); validation, the measured channels again on the
grid shifted by half a step (other frequencies, other noise), and the other
forces to the first two sensors.

Categories and kinds
--------------------
``in_library`` (:data:`IN_LIBRARY`)
    One effect the library has a hypothesis for: ``spring_change``,
    ``grounded_spring`` (added at a mass without one), ``mass``,
    ``damper_change``, ``grounded_damper`` (added at a mass without one; on a
    chain where every mass has one, e.g. ``three_mass``, the added damper is
    the same as a change of the existing one and the key names that
    element), ``sensor_gain`` (all channels of one sensor), ``exciter_gain``
    (all channels of the measured exciter), ``sensor_delay`` (one sensor's
    channels times :math:`e^{-j\omega\tau}`, :math:`\tau` from 0.05-0.5 ms,
    enlarged until detectable, at most the library's 10 ms; key: kind
    ``sensor_delay`` at the sensor's mass, element the sensor, value
    :math:`\tau` [s]) and ``unit_slip`` (one measured file scaled by 1e-3,
    1e-6, 25.4 or -1, its validation file right; key: kind ``channel_scale``
    at the file's output mass, element the channel ``"force->sensor"``, value
    the factor :math:`H_{\mathrm{data}}/H_{\mathrm{model}}`).  Sizes as in
    :mod:`mutext.hide`: log-uniform, changes 3-30 % of the value (either
    sign), dampers 10-100 % (a negative change at most 90 %), gains 2-20 %
    (either sign); an added spring relative to the mass's diagonal
    stiffness, an added damper relative to 10 % of
    :math:`\sqrt{K_{ii}M_{ii}}` (5 % of critical).
``two_effect`` (kind ``pair``, or ``A+B`` with two in-library kinds)
    Two in-library effects at different elements and different
    (kind, station), each detectable alone; a file's scale and the gain of
    its sensor are not drawn together when the sensor has only that measured
    channel (the same factor on the measured data).
``out_of_library`` (:data:`OUT_OF_LIBRARY`)
    ``rayleigh_damping`` (:math:`C \to (1 + a) C`, :math:`a` from 0.25-0.5,
    or :math:`C + bK` with 0.5-2 % of critical added at the highest mode),
    ``frequency_scale`` (every channel computed at :math:`f(1+\epsilon)`
    but labelled :math:`f`, :math:`|\epsilon|` from 0.1-0.3 %),
    ``roving_mass`` (each channel computed with an extra mass, 20 g to start,
    at its own output mass only: a different system per channel),
    ``cubic_spring`` (one spring with a cubic term, stepped sine at 1 N: see
    :func:`cubic_response`), ``tuned_absorber`` (an added mass-spring-damper
    DOF at one mass, 2-10 % of its mass, tuned within 10 % of a natural
    frequency), ``nonadjacent_spring`` (a spring between two masses not
    connected by one), ``wrong_model_parameters`` (the model handed to the
    diagnosis has every spring 15 % off, random signs, and two masses
    swapped; the data come from the shipped model),
    ``wrong_model_extra_mass`` (the data come from the chain with one more
    mass: a spring split in two springs of twice its stiffness with a mass
    between them) and ``stiffness_loss`` (every spring -8 %).
``none``
    No effect (the false-alarm check).

Detectable and distinct
-----------------------
Every effect is enlarged by factors of 1.5 (about its null value) until it is
**detectable**: the rms over the measured channels of
:math:`|\ln(H_{\mathrm{data}}/H_{\mathrm{model}})|` (noise-free) is at least
:data:`DETECTABLE` (5) times the noise level, as in :mod:`mutext.hide`.  An
out-of-library effect is further enlarged until it is **distinct** from the
library: the best fit of every single hypothesis of the library (a size per
hypothesis, within the library's bounds, fitted here by a scan and a bounded
1-D search on the noise-free data, :func:`single_fit`) still leaves an rms
misfit of at least :data:`DISTINCT` (1) times the noise, i.e. the
chi-square of the best single explanation at least doubles over that of the
noise.  A diagnosis that calls such data "explained" by one effect is then
wrong beyond doubt.  Effects of fixed size (``unit_slip``,
``wrong_model_parameters``) are redrawn when they fail either rule.  The
key records both measures (``change`` and ``single_fit["misfit"]``, in
units of the noise) for every case.  The library fitted here
(:func:`single_fit`) holds the diagnosis's local kinds: springs, dampers and
masses changed, grounded springs and dampers added, sensor and exciter gains
of either sign, a sensor's delay and one measured file's scale.  Kinds that
change the whole structure at once (all damping scaled, the frequency axis,
a mass moving with the sensor) are not fitted here: the out-of-library
effects they describe stay out of library, and an explanation by them is
judged by what it claims (below).

Equivalent explanations
-----------------------
Several library effects together may describe an out-of-library effect
exactly: :math:`C \to (1 + a) C` on a chain of discrete dampers is every
damper changed by the fraction :math:`a`, a stiffness loss every spring
changed by -8 %.  An explanation is therefore judged by the system it
claims: :func:`claimed_data` applies its effects to this module's matrices
and measurement chain, :func:`equivalence_error` compares the noise-free
responses with the true ones on the validation channels and the measured
files; below :data:`EQUIVALENT` (1/3) times the noise it is an equivalent
description, not a wrong cause.

Example
-------
>>> from _open_world import make_case
>>> case = make_case("three_mass", "in_library", "mass", seed=1, noise=0.01)
>>> case.key["effects"][0]["kind"], len(case.measured), len(case.validate)
('mass', 2, 4)
"""
from __future__ import annotations

import math
import tempfile
import tomllib
import zlib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar

from mutext.rig import FRF

__all__ = ["make_case", "Case", "Chain", "read_chain", "write_chain", "solve_response", "band_grid",
           "channels", "add_noise", "with_absorber", "cubic_response", "single_fit", "rms_log_change",
           "example_path", "EXAMPLES", "IN_LIBRARY", "OUT_OF_LIBRARY", "CATEGORIES", "DETECTABLE", "DISTINCT",
           "EQUIVALENT", "NotDetectable", "claimed_data", "equivalence_error"]

#: Shipped lumped chains: name -> file in mutext/data.
EXAMPLES = {"three_mass": "three_mass.toml", "four_story": "four_story.toml"}

IN_LIBRARY = ("spring_change", "grounded_spring", "mass", "damper_change", "grounded_damper", "sensor_gain",
              "exciter_gain", "sensor_delay", "unit_slip")
OUT_OF_LIBRARY = ("rayleigh_damping", "frequency_scale", "roving_mass", "cubic_spring", "tuned_absorber",
                  "nonadjacent_spring", "wrong_model_parameters", "wrong_model_extra_mass", "stiffness_loss")
CATEGORIES = {"in_library": IN_LIBRARY, "two_effect": ("pair",), "out_of_library": OUT_OF_LIBRARY,
              "none": ("none",)}

#: rms log change of the measured channels (noise-free) must reach this many times the noise.
DETECTABLE = 5.0
#: out of library: the best single library hypothesis must leave an rms misfit of this many times the noise.
DISTINCT = 1.0
#: enlargement factor of a size (about its null value)
ENLARGE = 1.5
#: force amplitude of the stepped sine on a cubic spring [N]
CUBIC_FORCE = 1.0
#: bounds of the magnitude of a sensor's or exciter's gain in the library (either sign)
GAIN_BOUNDS = (0.2, 5.0)
#: bounds of the magnitude of one measured file's scale in the library (either sign)
SCALE_BOUNDS = (1e-7, 1e7)
#: bounds of a sensor's delay in the library [s]
DELAY_BOUNDS = (-0.01, 0.01)
#: factors (data / model) of a unit slipped in one measured file
UNIT_SLIPS = (1e-3, 1e-6, 25.4, -1.0)
#: an explanation is equivalent to the truth when it reproduces the noise-free data within this many times the
#: noise (rms |ln(H_claimed / H_true)|, :func:`equivalence_error`)
EQUIVALENT = 1.0 / 3.0


class NotDetectable(Exception):
    """The effect drawn could not be made detectable (and distinct) within its limits."""


@dataclass
class Case:
    """A data set: the model handed to the diagnosis, the measured and validation FRFs, the answer.

    ``key``: ``category``, ``kind``, ``example``, ``seed``, ``noise``, ``effects`` (in-library and two-effect:
    dicts ``kind, station, element, value, unit`` named as :mod:`mutext.hide` names its answers; empty
    otherwise), ``description``, ``details`` (the sizes of an out-of-library effect), ``change`` (rms log
    change of the measured channels / noise), ``single_fit`` (best single library hypothesis on the
    noise-free data: ``kind, station, element, value, misfit`` with misfit / noise; None for ``none``),
    ``data_model`` (the file of the system measured when it differs from ``model_path``).
    ``clean``, ``clean_validate``: the noise-free responses of the measured and the validation channels
    (arrays, for checks and for :func:`equivalence_error`); ``channels``: ``(measured, validate)`` as lists of
    ``(force, sensor)`` names (:func:`channels`).
    """
    model_path: str
    measured: list
    validate: list
    key: dict = field(default_factory=dict)
    clean: list = field(default_factory=list, repr=False)
    clean_validate: list = field(default_factory=list, repr=False)
    channels: tuple = field(default=((), ()), repr=False)


def example_path(name: str) -> str:
    """Path of a shipped lumped chain (:data:`EXAMPLES`)."""
    return str(resources.files("mutext") / "data" / EXAMPLES[name])


# ----------------------------------------------------------------------------------------------
# the chain: plain TOML, plain matrices
# ----------------------------------------------------------------------------------------------

@dataclass
class Chain:
    """A lumped chain as its model file states it (SI).

    ``masses``: ``[(name, kg)]``; ``springs``, ``dampers``: ``[{"name", "between": (a, b), "value"}]`` with
    mass names or ``"ground"``; ``forces``, ``sensors``: ``{name: 0-based mass index}`` in file order.
    """
    name: str
    masses: list
    springs: list
    dampers: list
    forces: dict
    sensors: dict

    @property
    def names(self) -> list:
        return [m for m, _ in self.masses]

    def index(self, mass: str):
        return None if mass == "ground" else self.names.index(mass)

    def pattern(self, between) -> np.ndarray:
        """:math:`uu^T` with :math:`u = e_a - e_b` (ground: no entry)."""
        u = np.zeros(len(self.masses))
        a, b = (self.index(x) for x in between)
        if a is not None:
            u[a] = 1.0
        if b is not None:
            u[b] = -1.0
        return np.outer(u, u)

    def station(self, between) -> int:
        """1-based index of the first mass of an element (the station a hypothesis names)."""
        a, b = between
        return self.index(a if a != "ground" else b) + 1

    def matrices(self):
        """``(M, C, K)``."""
        M = np.diag([float(m) for _, m in self.masses])
        C = sum((d["value"] * self.pattern(d["between"]) for d in self.dampers), np.zeros_like(M))
        K = sum((s["value"] * self.pattern(s["between"]) for s in self.springs), np.zeros_like(M))
        return M, C, K

    def grounded(self, table: str) -> dict:
        """``{mass index: element}`` of the grounded springs (``table="springs"``) or dampers."""
        out = {}
        for e in getattr(self, table):
            if "ground" in e["between"]:
                out[self.station(e["between"]) - 1] = e
        return out


def read_chain(path) -> Chain:
    """A lumped-chain model file read with :mod:`tomllib` (SI, discrete dampers only)."""
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    if doc.get("units", "SI") != "SI" or "damping" in doc or "shaft" in doc or "station" in doc:
        raise ValueError(f"{path}: only SI lumped chains with discrete dampers are read here")
    masses = [(m["name"], float(m["mass"])) for m in doc["mass"]]
    el = lambda tbl, fld: [{"name": e["name"], "between": tuple(e["between"]), "value": float(e[fld])}
                           for e in doc.get(tbl, [])]
    names = [m for m, _ in masses]
    return Chain(str(doc.get("name", Path(path).stem)), masses, el("spring", "stiffness"), el("damper", "damping"),
                 {f["name"]: names.index(f["mass"]) for f in doc.get("force", [])},
                 {s["name"]: names.index(s["mass"]) for s in doc.get("sensor", [])})


def write_chain(chain: Chain, path) -> str:
    """Write ``chain`` as a model file (the format :func:`read_chain` reads)."""
    q = lambda s: '"' + str(s).replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines = [f"name = {q(chain.name)}", 'units = "SI"', ""]
    for n, m in chain.masses:
        lines += ["[[mass]]", f"name = {q(n)}", f"mass = {float(m)!r}", ""]
    for tbl, fld, els in (("spring", "stiffness", chain.springs), ("damper", "damping", chain.dampers)):
        for e in els:
            lines += [f"[[{tbl}]]", f"name = {q(e['name'])}", f"{fld} = {float(e['value'])!r}",
                      f"between = [{q(e['between'][0])}, {q(e['between'][1])}]", ""]
    for tbl, ports in (("force", chain.forces), ("sensor", chain.sensors)):
        for n, i in ports.items():
            lines += [f"[[{tbl}]]", f"name = {q(n)}", f"mass = {q(chain.names[i])}", ""]
    Path(path).write_text("\n".join(lines), encoding="utf-8")
    return str(path)


def solve_response(M, C, K, i_in: int, outs, f_hz) -> np.ndarray:
    r"""Receptances from a unit force at DOF ``i_in`` to DOFs ``outs``: shape ``(len(outs), len(f_hz))``.

    A direct complex solve of :math:`(K - \omega^2 M + j\omega C)\,x = e_{i_{in}}` at every frequency.
    """
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    b = np.zeros((w.size, M.shape[0], 1), complex)
    b[:, i_in, 0] = 1.0
    x = np.linalg.solve(Z, b)[:, :, 0]
    return x[:, list(outs)].T


def natural_frequencies(M, K) -> np.ndarray:
    """Undamped natural frequencies [Hz] (M diagonal, positive)."""
    d = 1.0 / np.sqrt(np.diag(M))
    lam = np.linalg.eigvalsh(d[:, None] * K * d[None, :])
    return np.sqrt(np.clip(lam, 0, None)) / (2 * np.pi)


def band_grid(M, K, n: int = 400) -> np.ndarray:
    """Half the lowest to 1.4 times the highest natural frequency [Hz], in round steps (one significant digit
    of the band / n) as a sine-sweep analyser steps."""
    f = natural_frequencies(M, K)
    f = f[f != 0]
    lo, hi = float(f.min() / 2.0), float(f.max() * 1.4)
    step = float(f"{(hi - lo) / n:.1g}")
    lo = math.floor(lo / step) * step
    return np.round(lo + step * np.arange(1, int((hi - lo) / step) + 1), 10)


def channels(chain: Chain):
    """``(measured, validate)``: lists of ``(force, sensor)`` names."""
    forces, sensors = list(chain.forces), list(chain.sensors)
    measured = [(forces[0], s) for s in sensors]
    return measured, measured + [(f, s) for f in forces[1:] for s in sensors[:2]]


def add_noise(H, sigma: float, rng: np.random.Generator) -> np.ndarray:
    r""":math:`H (1 + \sigma (n_1 + j n_2)/\sqrt 2)`, :math:`n_1, n_2` standard normal."""
    H = np.asarray(H, complex)
    n1, n2 = rng.standard_normal(H.size), rng.standard_normal(H.size)
    return H * (1.0 + sigma * (n1 + 1j * n2) / math.sqrt(2.0))


def rms_log_change(H, H0) -> float:
    """rms over all points of :math:`|\\ln(H/H_0)|` (lists of arrays)."""
    r = np.concatenate([np.log(np.asarray(h) / np.asarray(h0)) for h, h0 in zip(H, H0)])
    return float(np.sqrt(np.mean(np.abs(r) ** 2)))


def with_absorber(M, C, K, i: int, ma: float, ka: float, ca: float):
    """``(M, C, K)`` with one more DOF: mass ``ma`` tied to DOF ``i`` by spring ``ka`` and damper ``ca``."""
    n = M.shape[0]
    out = []
    for X, v in ((M, None), (C, ca), (K, ka)):
        Y = np.zeros((n + 1, n + 1))
        Y[:n, :n] = X
        if v is None:
            Y[n, n] = ma
        else:
            u = np.zeros(n + 1)
            u[i], u[n] = 1.0, -1.0
            Y += v * np.outer(u, u)
        out.append(Y)
    return tuple(out)


def cubic_response(M, C, K, between, k3: float, force: float, i_in: int, outs, f_hz) -> np.ndarray:
    r"""Stepped-sine receptances of a chain whose spring across ``between`` has a cubic term ``k3``.

    The spring's force is :math:`k\delta + k_3\delta^3` (:math:`\delta` its elongation); at force amplitude
    ``force`` [N] at DOF ``i_in``, single-harmonic balance (the describing function) replaces it by
    :math:`k_{\mathrm{eff}} = k + \tfrac34 k_3 |\delta|^2` at each frequency.  With
    :math:`Z_0 = K - \omega^2 M + j\omega C`, :math:`u = e_a - e_b`, the linear elongation
    :math:`\delta_0 = u^T Z_0^{-1} b\,F` and the spring's own compliance :math:`g = u^T Z_0^{-1} u`,
    Sherman-Morrison gives :math:`\delta = \delta_0/(1 + \Delta k\, g)` exactly, so the stiffness change
    :math:`\Delta k = \tfrac34 k_3|\delta|^2` solves the real cubic

    .. math::  |g|^2\Delta k^3 + 2\,\mathrm{Re}(g)\,\Delta k^2 + \Delta k - \tfrac34 k_3|\delta_0|^2 = 0 .

    Its real roots (three in a band where the response is bistable) are found per frequency
    (``numpy.roots``, polished by two Newton steps); as a stepped-sine analyser sweeping upwards follows its
    branch, the root nearest the previous frequency's is taken (at the first frequency, the one nearest 0).
    Roots that would leave the spring's effective stiffness below 5 % of ``k`` are discarded.  Returns
    ``x_out / F``, shape ``(len(outs), len(f_hz))``; as ``force`` -> 0 it tends to the linear receptance.
    """
    n = M.shape[0]
    u = np.zeros(n)
    a, b = between
    if a is not None:
        u[a] = 1.0
    if b is not None:
        u[b] = -1.0
    P = np.outer(u, u)
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z0 = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    e = np.zeros(n)
    e[i_in] = 1.0
    rhs = np.stack([e * force, u], axis=1).astype(complex)
    X = np.linalg.solve(Z0, np.broadcast_to(rhs, (w.size, n, 2)))
    d0 = X[:, :, 0] @ u
    g = X[:, :, 1] @ u
    k_el = _spring_between(K, between)
    dk_prev, dks = 0.0, np.zeros(w.size)
    for m in range(w.size):
        c = 0.75 * k3 * abs(d0[m]) ** 2
        coeffs = [abs(g[m]) ** 2, 2 * g[m].real, 1.0, -c]
        roots = np.roots(coeffs)
        real = roots[np.abs(roots.imag) <= 1e-7 * max(1.0, np.max(np.abs(roots)))].real
        cand = []
        for r in real:
            for _ in range(2):
                p = ((coeffs[0] * r + coeffs[1]) * r + coeffs[2]) * r + coeffs[3]
                dp = (3 * coeffs[0] * r + 2 * coeffs[1]) * r + coeffs[2]
                r = r - p / dp if dp != 0 else r
            if k_el + r > 0.05 * k_el:
                cand.append(r)
        if not cand:
            raise ValueError(f"cubic spring: no admissible harmonic-balance solution at {f_hz[m]} Hz")
        dk_prev = min(cand, key=lambda r: abs(r - dk_prev))
        dks[m] = dk_prev
    Z = Z0 + dks[:, None, None] * P[None]
    x = np.linalg.solve(Z, np.broadcast_to((e * force).astype(complex)[:, None], (w.size, n, 1)))[:, :, 0]
    return x[:, list(outs)].T / force


def _spring_between(K, between) -> float:
    """Stiffness of the spring(s) across ``between`` as seen in K (grounded: the diagonal less the others)."""
    a, b = between
    if a is not None and b is not None:
        return float(-K[a, b])
    i = a if a is not None else b
    return float(K[i, i] + sum(K[i, j] for j in range(K.shape[0]) if j != i))


# ----------------------------------------------------------------------------------------------
# the library, fitted one hypothesis at a time (the distinctness rule)
# ----------------------------------------------------------------------------------------------

def _library(chain: Chain, meas_ch):
    """Single hypotheses of the diagnosis's library on a chain, each ``(kind, station, element, matrix,
    pattern, lo, hi, scale)`` (structural: matrix "M", "C" or "K"), ``(kind, station, element, "gain",
    mask over the measured channels, lo, hi, 1)`` (a factor of either sign, its magnitude within
    ``lo``-``hi``: a sensor's gain, an exciter's gain, one measured file's scale) or ``(kind, station,
    element, "delay", mask, lo, hi, scale)`` (a sensor's delay)."""
    M, C, K = chain.matrices()
    n = len(chain.masses)
    hyps = []
    for i, (name, m) in enumerate(chain.masses):
        P = np.zeros((n, n))
        P[i, i] = 1.0
        hyps.append(("mass", i + 1, name, "M", P, -0.9 * m, 10 * m, m))
    for kind, mat, els in (("stiffness", "K", chain.springs), ("damping", "C", chain.dampers)):
        for e in els:
            v = e["value"]
            hyps.append((kind, chain.station(e["between"]), e["name"], mat, chain.pattern(e["between"]),
                         -0.95 * v, 10 * v, v))
    for kind, mat, table, pre in (("stiffness", "K", "springs", "k"), ("damping", "C", "dampers", "c")):
        have = chain.grounded(table)
        for i, (name, m) in enumerate(chain.masses):
            if i in have:
                continue
            scale = K[i, i] if kind == "stiffness" else 0.1 * math.sqrt(K[i, i] * M[i, i])
            P = np.zeros((n, n))
            P[i, i] = 1.0
            hyps.append((kind, i + 1, f"{pre}_{name}_ground", mat, P, 0.0, 10 * scale, scale))
    for s in dict.fromkeys(se for _, se in meas_ch):
        mask = np.array([se == s for _, se in meas_ch])
        hyps.append(("sensor_gain", chain.sensors[s] + 1, s, "gain", mask, *GAIN_BOUNDS, 1.0))
        hyps.append(("sensor_delay", chain.sensors[s] + 1, s, "delay", mask, *DELAY_BOUNDS, 1e-4))
    for fo in dict.fromkeys(fo for fo, _ in meas_ch):
        mask = np.array([f == fo for f, _ in meas_ch])
        hyps.append(("exciter_gain", chain.forces[fo] + 1, fo, "gain", mask, *GAIN_BOUNDS, 1.0))
    if len(meas_ch) > 1:            # with one channel a file's scale is the sensor's gain
        for k, (fo, se) in enumerate(meas_ch):
            mask = np.arange(len(meas_ch)) == k
            hyps.append(("channel_scale", chain.sensors[se] + 1, f"{fo}->{se}", "gain", mask, *SCALE_BOUNDS, 1.0))
    return hyps


def single_fit(chain: Chain, meas_ch, f_hz, H_data) -> dict:
    """The single library hypothesis that best explains noise-free data ``H_data`` (list over ``meas_ch``).

    Each hypothesis's size is fitted on the rms of :math:`|\\ln(H_{\\mathrm{model}}/H_{\\mathrm{data}})|`
    within the library's bounds (structural: a scan over decades and both signs, then a bounded 1-D
    search around the best point; factors: the magnitude in closed form, both signs tried; delays: a scan
    over the range and the closed form (the phase slope), then a bounded 1-D search).  Returns ``kind,
    station, element, value`` and ``misfit`` (the rms left) of the best, and ``none`` (the rms with no
    hypothesis).
    """
    M, C, K = chain.matrices()
    forces = {fo for fo, _ in meas_ch}
    Hd = np.array(H_data)
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z0 = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    fac = {"K": np.ones_like(w, complex), "C": 1j * w, "M": -(w ** 2) + 0j}
    rows = {fo: [k for k, (f, _) in enumerate(meas_ch) if f == fo] for fo in forces}
    outs = {fo: [chain.sensors[meas_ch[k][1]] for k in rows[fo]] for fo in forces}
    n = M.shape[0]

    def resp(Z):
        H = np.empty_like(Hd)
        for fo in forces:
            b = np.zeros((w.size, n, 1), complex)
            b[:, chain.forces[fo], 0] = 1.0
            x = np.linalg.solve(Z, b)[:, :, 0]
            H[rows[fo]] = x[:, outs[fo]].T
        return H

    ratio0 = resp(Z0) / Hd
    r0 = np.log(ratio0)
    npts = r0.size
    wk = np.broadcast_to(w, r0.shape)

    def rms(r):
        return float(np.sqrt(np.sum(np.abs(r) ** 2) / npts))

    best = {"kind": "none", "station": None, "element": None, "value": 0.0, "misfit": rms(r0)}
    for kind, station, element, mat, P, lo, hi, scale in _library(chain, meas_ch):
        if mat == "gain":
            lg = -float(np.mean(r0[P].real))
            g = math.exp(min(max(lg, math.log(lo)), math.log(hi)))
            val, mis = None, math.inf
            for v in (g, -g):
                r = r0.copy()
                r[P] = np.log(ratio0[P] * v)
                if rms(r) < mis:
                    val, mis = v, rms(r)
        elif mat == "delay":
            def cost(tau, P=P):
                r = r0.copy()
                r[P] = np.log(ratio0[P] * np.exp(-1j * wk[P] * tau))
                return rms(r)
            tau0 = float(np.sum(wk[P] * r0[P].imag) / np.sum(wk[P] ** 2))
            cand = sorted(set(list(np.linspace(lo, hi, 81)) + [0.0, min(max(tau0, lo), hi)]))
            vals = [cost(v) for v in cand]
            j = int(np.argmin(vals))
            val, mis = cand[j], vals[j]
            for a, b in ((cand[max(j - 1, 0)], cand[min(j + 1, len(cand) - 1)]),):
                if b > a:
                    res = minimize_scalar(cost, bounds=(a, b), method="bounded", options={"xatol": 1e-12})
                    if res.fun < mis:
                        val, mis = float(res.x), float(res.fun)
        else:
            D = fac[mat][:, None, None] * P[None]

            def cost(v, D=D):
                return rms(np.log(resp(Z0 + v * D) / Hd))
            cand = [0.0]
            if hi > 0:
                cand += list(scale * np.geomspace(1e-3, hi / scale, 31))
            if lo < 0:
                cand += list(-scale * np.geomspace(1e-3, -lo / scale, 31))
            cand = sorted(set(cand))
            vals = [cost(v) for v in cand]
            j = int(np.argmin(vals))
            a, b = cand[max(j - 1, 0)], cand[min(j + 1, len(cand) - 1)]
            val, mis = cand[j], vals[j]
            if b > a:
                res = minimize_scalar(cost, bounds=(a, b), method="bounded",
                                      options={"xatol": 1e-9 * max(abs(a), abs(b), scale)})
                if res.fun < mis:
                    val, mis = float(res.x), float(res.fun)
        if mis < best["misfit"]:
            best = {"kind": kind, "station": station, "element": element, "value": float(val), "misfit": mis}
    best["none"] = rms(r0)
    return best


# ----------------------------------------------------------------------------------------------
# systems measured: functions (channels, frequencies, role) -> list of noise-free responses
# ----------------------------------------------------------------------------------------------

@dataclass
class _State:
    """A linear chain as measured: matrices (possibly with extra DOFs after the chain's), the measurement
    chain: gains of exciters (``gin``) and sensors (``gout``), delays of sensors [s] (``delay``), and the
    scale of measured files (``scale``, ``{(force, sensor): factor}``: the measured file of that channel
    only, not its validation file)."""
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    gin: dict = field(default_factory=dict)
    gout: dict = field(default_factory=dict)
    delay: dict = field(default_factory=dict)
    scale: dict = field(default_factory=dict)
    eps: float = 0.0                 # the structure's response taken at f (1 + eps), labelled f
    sensor_mass: float = 0.0         # a mass at each channel's own output mass (moves with the sensor)


def _linear(chain: Chain, st: _State):
    def data(chans, f, role="measured"):
        out = []
        fs = np.asarray(f, float) * (1 + st.eps) if st.eps else f
        for fo, se in chans:
            j = chain.sensors[se]
            M = st.M
            if st.sensor_mass:
                M = M.copy()
                M[j, j] += st.sensor_mass
            h = solve_response(M, st.C, st.K, chain.forces[fo], [j], fs)[0]
            h = h * st.gin.get(fo, 1.0) * st.gout.get(se, 1.0)
            if st.delay.get(se, 0.0) != 0.0:
                h = h * np.exp(-2j * np.pi * np.asarray(f, float) * st.delay[se])
            if role == "measured":
                h = h * st.scale.get((fo, se), 1.0)
            out.append(h)
        return out
    return data


def _logu(rng, lo, hi) -> float:
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def _sign(rng) -> float:
    return 1.0 if rng.random() < 0.5 else -1.0


@dataclass
class _Effect:
    """An in-library effect: its answer (value filled when sized), first size, null, limits, and how it
    changes a state."""
    key: dict
    size: float
    null: float
    limit: tuple
    apply: object            # (state, value) -> state


def _draw_in_library(chain: Chain, kind: str, rng, taken=()) -> _Effect:
    """Draw an in-library effect of ``kind`` avoiding the (kind, station) pairs and elements in ``taken``."""
    M, C, K = chain.matrices()
    n = len(chain.masses)
    used_pairs = {(t[0], t[1]) for t in taken}
    used_el = {t[2] for t in taken}

    def free(k, station, element):
        return (k, station) not in used_pairs and element not in used_el

    def unit_p(i):
        P = np.zeros((n, n))
        P[i, i] = 1.0
        return P

    if kind in ("spring_change", "damper_change"):
        hk, mat, els, unit = (("stiffness", "K", chain.springs, "N/m") if kind == "spring_change"
                              else ("damping", "C", chain.dampers, "N s/m"))
        opts = [e for e in els if free(hk, chain.station(e["between"]), e["name"])]
        if not opts:
            raise NotDetectable(f"no free element for {kind}")
        e = opts[int(rng.integers(len(opts)))]
        v0 = e["value"]
        lo, hi = (0.03, 0.3) if kind == "spring_change" else (0.1, 1.0)
        sign = _sign(rng)
        rel = _logu(rng, lo, hi)
        if sign < 0:
            rel = min(rel, 0.9)
        P = chain.pattern(e["between"])
        key = {"kind": hk, "station": chain.station(e["between"]), "element": e["name"], "unit": unit,
               "description": f"{e['name']} changed"}
        return _Effect(key, sign * rel * v0, 0.0, (-0.9 * v0, 10 * v0),
                       lambda st, v, P=P, mat=mat: replace(st, **{mat: getattr(st, mat) + v * P}))
    if kind in ("grounded_spring", "grounded_damper"):
        hk, mat, table, pre, unit = (("stiffness", "K", "springs", "k", "N/m") if kind == "grounded_spring"
                                     else ("damping", "C", "dampers", "c", "N s/m"))
        have = chain.grounded(table)
        opts = [i for i in range(n) if i not in have
                and free(hk, i + 1, f"{pre}_{chain.names[i]}_ground")]
        if not opts:        # every mass has one: adding one is changing it (the key names that element)
            opts = [i for i in range(n) if free(hk, i + 1, have.get(i, {}).get("name"))]
        if not opts:
            raise NotDetectable(f"no free mass for {kind}")
        i = int(opts[int(rng.integers(len(opts)))])
        element = have[i]["name"] if i in have else f"{pre}_{chain.names[i]}_ground"
        what = "spring" if hk == "stiffness" else "damper"
        if hk == "stiffness":
            scale, rel = K[i, i], _logu(rng, 0.03, 0.3)
        else:
            scale, rel = 0.1 * math.sqrt(K[i, i] * M[i, i]), _logu(rng, 0.1, 1.0)
        key = {"kind": hk, "station": i + 1, "element": element, "unit": unit,
               "description": f"grounded {what} added at {chain.names[i]}"
                              + (f" (the same as a change of {element})" if i in have else "")}
        return _Effect(key, rel * scale, 0.0, (0.0, 10 * scale),
                       lambda st, v, P=unit_p(i), mat=mat: replace(st, **{mat: getattr(st, mat) + v * P}))
    if kind == "mass":
        opts = [i for i in range(n) if free("mass", i + 1, chain.names[i])]
        if not opts:
            raise NotDetectable("no free mass")
        i = int(opts[int(rng.integers(len(opts)))])
        m0 = M[i, i]
        key = {"kind": "mass", "station": i + 1, "element": chain.names[i], "unit": "kg",
               "description": f"mass {chain.names[i]} changed"}
        return _Effect(key, _sign(rng) * _logu(rng, 0.03, 0.3) * m0, 0.0, (-0.9 * m0, 10 * m0),
                       lambda st, v, P=unit_p(i): replace(st, M=st.M + v * P))
    if kind == "sensor_gain":
        meas_ch, _ = channels(chain)
        alone = {s for s in chain.sensors if sum(x == s for _, x in meas_ch) == 1}
        opts = [s for s in chain.sensors if free("sensor_gain", chain.sensors[s] + 1, s)
                and not (s in alone and ("channel_scale", chain.sensors[s] + 1) in used_pairs)]
        if not opts:
            raise NotDetectable("no free sensor")
        s = opts[int(rng.integers(len(opts)))]
        key = {"kind": kind, "station": chain.sensors[s] + 1, "element": s, "unit": "1",
               "description": f"gain of sensor {s}"}
        return _Effect(key, 1.0 + _sign(rng) * _logu(rng, 0.02, 0.2), 1.0, GAIN_BOUNDS,
                       lambda st, v, s=s: replace(st, gout={**st.gout, s: st.gout.get(s, 1.0) * v}))
    if kind == "sensor_delay":
        opts = [s for s in chain.sensors if free("sensor_delay", chain.sensors[s] + 1, s)]
        if not opts:
            raise NotDetectable("no free sensor")
        s = opts[int(rng.integers(len(opts)))]
        key = {"kind": "sensor_delay", "station": chain.sensors[s] + 1, "element": s, "unit": "s",
               "description": f"delay of sensor {s}"}
        return _Effect(key, _logu(rng, 5e-5, 5e-4), 0.0, (0.0, DELAY_BOUNDS[1]),
                       lambda st, v, s=s: replace(st, delay={**st.delay, s: st.delay.get(s, 0.0) + v}))
    if kind == "unit_slip":
        meas_ch, _ = channels(chain)

        def open_file(fo, se):
            station = chain.sensors[se] + 1
            # with one measured channel of its sensor, the file's scale is that sensor's gain on the measured
            # data (only the validation files tell them apart): not drawn together
            alone = sum(x == se for _, x in meas_ch) == 1
            return free("channel_scale", station, f"{fo}->{se}") and not (alone and ("sensor_gain", station)
                                                                          in used_pairs)
        opts = [c for c in meas_ch if open_file(*c)]
        if not opts:
            raise NotDetectable("no free measured file")
        fo, se = opts[int(rng.integers(len(opts)))]
        factor = UNIT_SLIPS[int(rng.integers(len(UNIT_SLIPS)))]
        key = {"kind": "channel_scale", "station": chain.sensors[se] + 1, "element": f"{fo}->{se}", "unit": "1",
               "description": f"unit slip in the measured file {fo}->{se} (factor {factor:g}; its validation "
                              f"file is right)"}
        return _Effect(key, factor, 1.0, (factor, factor),
                       lambda st, v, c=(fo, se): replace(st, scale={**st.scale, c: st.scale.get(c, 1.0) * v}))
    if kind == "exciter_gain":
        fo = list(chain.forces)[0]          # the exciter of the measured channels
        if not free("exciter_gain", chain.forces[fo] + 1, fo):
            raise NotDetectable("exciter taken")
        key = {"kind": kind, "station": chain.forces[fo] + 1, "element": fo, "unit": "1",
               "description": f"gain of force input {fo}"}
        return _Effect(key, 1.0 + _sign(rng) * _logu(rng, 0.02, 0.2), 1.0, GAIN_BOUNDS,
                       lambda st, v, fo=fo: replace(st, gin={**st.gin, fo: st.gin.get(fo, 1.0) * v}))
    raise ValueError(f"unknown in-library kind {kind!r}; kinds: {', '.join(IN_LIBRARY)}")


def _grow(data_of, base, meas_ch, f, size, null, limit, noise, distinct=None, tries=40):
    """Enlarge ``size`` about ``null`` by :data:`ENLARGE` until ``data_of(size)`` is detectable (and, with
    ``distinct=(chain, )``, distinct from every single library hypothesis).  Returns (size, change, fit)."""
    for _ in range(tries):
        H = data_of(size)(meas_ch, f, "measured")
        change = rms_log_change(H, base)
        if change >= DETECTABLE * noise:
            fit = single_fit(distinct, meas_ch, f, H) if distinct is not None else None
            if fit is None or fit["misfit"] >= DISTINCT * noise:
                return size, change, fit
        new = null + ENLARGE * (size - null)
        if not limit[0] <= new <= limit[1]:
            break
        size = new
    raise NotDetectable(f"not detectable{' and distinct' if distinct is not None else ''} within {limit}")


# ----------------------------------------------------------------------------------------------
# out-of-library effects: (details, size, null, limit, size -> data function, model chain)
# ----------------------------------------------------------------------------------------------

def _draw_open(chain: Chain, kind: str, rng, workdir: Path, tag: str):
    """Returns ``(details, size, null, limit, data_of, model_chain, data_model_path, fixed)``."""
    M, C, K = chain.matrices()
    n = len(chain.masses)
    base = _State(M, C, K)
    meas_ch, _ = channels(chain)
    fn = natural_frequencies(M, K)
    if kind == "rayleigh_damping":
        if rng.random() < 0.5:
            a = rng.uniform(0.25, 0.5)
            det = {"form": "C -> (1 + a) C", "parameter": "a"}
            return (det, a, 0.0, (0.0, 4.0), lambda v: _linear(chain, replace(base, C=(1 + v) * C)),
                    chain, None, False)
        wmax = 2 * np.pi * float(fn.max())
        b = 2 * rng.uniform(0.005, 0.02) / wmax
        det = {"form": "C -> C + b K", "parameter": "b [s]"}
        return (det, b, 0.0, (0.0, 2 * 0.5 / wmax), lambda v: _linear(chain, replace(base, C=C + v * K)),
                chain, None, False)
    if kind == "frequency_scale":
        lin = _linear(chain, base)

        def data_of(eps):
            return lambda chans, f, role="measured": lin(chans, np.asarray(f) * (1 + eps), role)
        det = {"form": "data at f (1 + eps) labelled f", "parameter": "eps"}
        return det, _sign(rng) * rng.uniform(0.001, 0.003), 0.0, (-0.1, 0.1), data_of, chain, None, False
    if kind == "roving_mass":
        def data_of(mr):
            def data(chans, f, role="measured"):
                out = []
                for fo, se in chans:
                    j = chain.sensors[se]
                    Mx = M.copy()
                    Mx[j, j] += mr
                    out.append(solve_response(Mx, C, K, chain.forces[fo], [j], f)[0])
                return out
            return data
        det = {"form": "each channel with an extra mass at its own output mass", "parameter": "mass [kg]"}
        return det, 0.02, 0.0, (0.0, 0.5 * float(np.min(np.diag(M)))), data_of, chain, None, False
    if kind == "cubic_spring":
        e = chain.springs[int(rng.integers(len(chain.springs)))]
        between = tuple(chain.index(x) for x in e["between"])
        sign = _sign(rng)
        f0 = band_grid(M, K)
        u = np.zeros(n)
        for x, sg in zip(between, (1.0, -1.0)):
            if x is not None:
                u[x] = sg
        X = solve_response(M, C, K, chain.forces[list(chain.forces)[0]], list(range(n)), f0)
        dmax = float(np.max(np.abs(u @ X))) * CUBIC_FORCE
        k_el = e["value"]
        # size: r = 3/4 k3 max|delta_lin|^2 / k, the relative stiffness change at the largest linear elongation
        to_k3 = k_el / (0.75 * dmax ** 2)

        def data_of(r, between=between):
            def data(chans, f, role="measured"):
                out, by_force = [], {}
                for fo, se in chans:
                    if fo not in by_force:
                        by_force[fo] = cubic_response(M, C, K, between, r * to_k3, CUBIC_FORCE, chain.forces[fo],
                                                      list(range(n)), f)
                    out.append(by_force[fo][chain.sensors[se]])
                return out
            return data
        det = {"spring": e["name"], "force_N": CUBIC_FORCE, "parameter": "r = 3/4 k3 max|delta_lin|^2 / k",
               "k3_per_r [N/m^3]": to_k3}
        limit = (0.0, 1.0) if sign > 0 else (-0.5, 0.0)
        return det, sign * _logu(rng, 0.02, 0.1), 0.0, limit, data_of, chain, None, False
    if kind == "tuned_absorber":
        i = int(rng.integers(n))
        mode = int(rng.integers(fn.size))
        ft = float(fn[mode]) * rng.uniform(0.9, 1.1)
        zeta = rng.uniform(0.02, 0.1)
        mi = M[i, i]

        def data_of(ma, i=i):
            ka = ma * (2 * np.pi * ft) ** 2
            ca = 2 * zeta * math.sqrt(ka * ma)
            return _linear(chain, _State(*with_absorber(M, C, K, i, ma, ka, ca)))
        det = {"mass": chain.names[i], "station": i + 1, "tuned_hz": ft, "zeta": zeta, "mode": mode + 1,
               "parameter": "absorber mass [kg]"}
        return det, rng.uniform(0.02, 0.1) * mi, 0.0, (0.0, 0.5 * mi), data_of, chain, None, False
    if kind == "nonadjacent_spring":
        linked = {frozenset(chain.index(x) for x in s["between"]) for s in chain.springs}
        pairs = [(a, b) for a in range(n) for b in range(a + 1, n) if frozenset((a, b)) not in linked]
        a, b = pairs[int(rng.integers(len(pairs)))]
        P = chain.pattern((chain.names[a], chain.names[b]))
        kref = float(np.mean([s["value"] for s in chain.springs]))
        det = {"between": [chain.names[a], chain.names[b]], "station": a + 1,
               "element": f"k_{chain.names[a]}_{chain.names[b]}", "parameter": "stiffness [N/m]"}
        return (det, _logu(rng, 0.03, 0.3) * kref, 0.0, (0.0, 10 * kref),
                lambda v: _linear(chain, replace(base, K=K + v * P)), chain, None, False)
    if kind == "wrong_model_parameters":
        signs = [_sign(rng) for _ in chain.springs]
        pairs = [(a, b) for a in range(n) for b in range(a + 1, n)
                 if abs(chain.masses[a][1] - chain.masses[b][1]) > 1e-9 * chain.masses[a][1]]
        a, b = pairs[int(rng.integers(len(pairs)))]
        masses = list(chain.masses)
        masses[a], masses[b] = (masses[a][0], chain.masses[b][1]), (masses[b][0], chain.masses[a][1])
        springs = [{**s, "value": s["value"] * (1 + 0.15 * sg)} for s, sg in zip(chain.springs, signs)]
        wrong = replace(chain, name=chain.name + " (wrong parameters)", masses=masses, springs=springs)
        path = write_chain(wrong, workdir / f"{tag}_model.toml")
        det = {"springs": {s["name"]: 0.15 * sg for s, sg in zip(chain.springs, signs)},
               "masses_swapped": [chain.names[a], chain.names[b]], "model": path,
               "parameter": "fixed size (every spring 15 % off, two masses swapped)"}
        return det, 1.0, 0.0, (1.0, 1.0), lambda v: _linear(chain, base), wrong, None, True
    if kind == "wrong_model_extra_mass":
        j = int(rng.integers(len(chain.springs)))
        s = chain.springs[j]
        mean_m = float(np.mean(np.diag(M)))

        def true_chain(mx):
            new = [dict(x) for x in chain.springs]
            new[j] = {"name": s["name"] + "a", "between": (s["between"][0], "mx"), "value": 2 * s["value"]}
            new.insert(j + 1, {"name": s["name"] + "b", "between": ("mx", s["between"][1]), "value": 2 * s["value"]})
            return replace(chain, name=chain.name + " (one more mass)", masses=chain.masses + [("mx", mx)],
                           springs=new)

        def data_of(mx):
            return _linear(chain, _State(*true_chain(mx).matrices()))
        det = {"split_spring": s["name"], "parameter": "extra mass [kg]",
               "form": f"{s['name']} split in two springs of twice its stiffness with a mass between them"}
        return det, rng.uniform(0.2, 1.0) * mean_m, 0.0, (0.0, 5 * mean_m), data_of, chain, true_chain, False
    if kind == "stiffness_loss":
        det = {"form": "every spring times (1 - d)", "parameter": "d"}
        return det, 0.08, 0.0, (0.0, 0.6), lambda v: _linear(chain, replace(base, K=(1 - v) * K)), chain, None, False
    raise ValueError(f"unknown out-of-library kind {kind!r}; kinds: {', '.join(OUT_OF_LIBRARY)}")


# ----------------------------------------------------------------------------------------------
# an explanation judged by what it claims: the system it describes against the true one
# ----------------------------------------------------------------------------------------------

def claimed_data(chain: Chain, effects):
    """The system an explanation describes: ``chain`` (the model handed to the diagnosis) with ``effects``
    applied, as a data function ``(channels, f, role) -> responses``.

    ``effects``: dicts (or objects) with ``kind, station, element, value`` as the library names them:
    ``stiffness`` / ``damping`` (``element`` a spring or damper of the chain: its value changed by
    ``value``; otherwise a grounded one added at mass ``station`` of size ``value``), ``mass`` (mass
    ``element``, or the mass at ``station``, changed by ``value``), ``sensor_gain`` / ``exciter_gain``
    (every channel of the sensor / force input ``element`` times ``value``), ``channel_scale`` (the measured
    file ``element`` = ``"force->sensor"`` times ``value``; not its validation file), ``sensor_delay``
    (every channel of sensor ``element`` times :math:`e^{-j\\omega\\tau}`, ``value`` = :math:`\\tau` [s]); kinds
    of the whole structure: ``damping_scale`` (the chain's own damping times :math:`1 + a`, ``value`` =
    :math:`a`; elements changed or added by other effects are not scaled), ``frequency_scale`` (the structure's
    response at :math:`f(1 + \\epsilon)` labelled :math:`f`, ``value`` = :math:`\\epsilon`) and ``sensor_mass``
    (a mass ``value`` [kg] at each channel's own output mass); kinds with an added degree of freedom or a run:
    ``absorber`` (``values`` = m_a, k_a, c_a: :func:`with_absorber` at mass ``station``), ``pedestal``
    (``values`` = m_p, k_p: the grounded spring ``element`` moved onto a mass m_p, held by k_p to ground)
    and ``distributed_stiffness`` (every spring named in ``run`` times 1 + ``value``).
    """
    M, C, K = chain.matrices()
    st = _State(M, C, K)
    n = len(chain.masses)
    get = (lambda e, k: e[k]) if all(isinstance(e, dict) for e in effects) else (lambda e, k: getattr(e, k))
    for e in effects:
        kind, station, element, v = get(e, "kind"), get(e, "station"), get(e, "element"), float(get(e, "value"))
        if kind in ("stiffness", "damping"):
            mat, els = ("K", chain.springs) if kind == "stiffness" else ("C", chain.dampers)
            el = next((x for x in els if x["name"] == element), None)
            P = np.zeros(st.M.shape)    # (with the DOFs other effects added after the chain's)
            if el is not None:
                P[:n, :n] = chain.pattern(el["between"])
            else:                       # an added grounded element at the mass ``station``
                P[int(station) - 1, int(station) - 1] = 1.0
            st = replace(st, **{mat: getattr(st, mat) + v * P})
        elif kind == "mass":
            i = chain.names.index(element) if element in chain.names else int(station) - 1
            Mx = st.M.copy()
            Mx[i, i] += v
            st = replace(st, M=Mx)
        elif kind == "sensor_gain":
            s = element if element in chain.sensors else _port_at(chain.sensors, station)
            st = replace(st, gout={**st.gout, s: st.gout.get(s, 1.0) * v})
        elif kind == "exciter_gain":
            fo = element if element in chain.forces else _port_at(chain.forces, station)
            st = replace(st, gin={**st.gin, fo: st.gin.get(fo, 1.0) * v})
        elif kind == "sensor_delay":
            s = element if element in chain.sensors else _port_at(chain.sensors, station)
            st = replace(st, delay={**st.delay, s: st.delay.get(s, 0.0) + v})
        elif kind == "channel_scale":
            fo, se = str(element).split("->")
            st = replace(st, scale={**st.scale, (fo, se): st.scale.get((fo, se), 1.0) * v})
        elif kind == "damping_scale":
            Cx = st.C.copy()
            Cx[:n, :n] += v * C
            st = replace(st, C=Cx)
        elif kind == "frequency_scale":
            st = replace(st, eps=st.eps + v)
        elif kind == "sensor_mass":
            st = replace(st, sensor_mass=st.sensor_mass + v)
        elif kind == "absorber":        # one more DOF: mass m_a tied to the mass ``station`` by k_a and c_a
            ma, ka, ca = (float(x) for x in get(e, "values"))
            st = replace(st, **dict(zip("MCK", with_absorber(st.M, st.C, st.K, int(station) - 1, ma, ka, ca))))
        elif kind == "pedestal":        # the grounded spring ``element`` ends on a mass m_p held by k_p
            mp, kp = (float(x) for x in get(e, "values"))
            el = next(x for x in chain.springs if x["name"] == element)
            i = chain.index(next(b for b in el["between"] if b != "ground"))
            Mx, Cx, Kx = with_absorber(st.M, st.C, st.K, i, mp, el["value"], 0.0)
            Kx[i, i] -= el["value"]
            Kx[-1, -1] += kp
            st = replace(st, M=Mx, C=Cx, K=Kx)
        elif kind == "distributed_stiffness":    # every spring of the run ``run`` times (1 + value)
            Kx = st.K.copy()
            for name in get(e, "run"):
                el = next(x for x in chain.springs if x["name"] == name)
                P = np.zeros_like(Kx)
                P[:n, :n] = chain.pattern(el["between"])
                Kx += v * el["value"] * P
            st = replace(st, K=Kx)
        else:
            raise ValueError(f"claimed_data: no physics here for an effect of kind {kind!r}")
    return _linear(chain, st)


def _port_at(ports: dict, station) -> str:
    return next(p for p, i in ports.items() if i + 1 == int(station))


def equivalence_error(case: Case, effects) -> dict:
    r"""How far the system an explanation claims is from the true one, on noise-free responses.

    The model handed to the diagnosis (``case.model_path``) with ``effects`` applied (:func:`claimed_data`)
    against the true noise-free data: rms over points of :math:`|\ln(H_{\mathrm{claimed}}/H_{\mathrm{true}})|`
    on the validation channels (``validate``: other frequencies, other exciters) and on the measured files
    (``measured``: where an effect on one file, a channel's scale, shows), and ``error``, the larger.
    An explanation with ``error`` below :data:`EQUIVALENT` times the noise reproduces the true system well
    below the noise on every channel: an equivalent description of the data (e.g. every damper changed by
    the same fraction for proportional damping :math:`C \to (1 + a) C`), not a wrong cause.
    """
    chain = read_chain(case.model_path)
    data = claimed_data(chain, effects)
    meas_ch, val_ch = case.channels
    f_meas, f_val = case.measured[0].freq_hz, case.validate[0].freq_hz
    out = {"measured": rms_log_change(data(list(meas_ch), f_meas, "measured"), case.clean),
           "validate": rms_log_change(data(list(val_ch), f_val, "validate"), case.clean_validate)}
    out["error"] = max(out["measured"], out["validate"])
    return out


# ----------------------------------------------------------------------------------------------
# the entry point
# ----------------------------------------------------------------------------------------------

def _rngs(example, category, kind, seed):
    ss = np.random.SeedSequence([int(seed), zlib.crc32(f"{example}/{category}/{kind}".encode())])
    a, b = ss.spawn(2)
    return np.random.default_rng(a), np.random.default_rng(b)


def _frfs(chain, data, chans, f, noise, rng, role):
    out = []
    for (fo, se), h in zip(chans, data(chans, f, role)):
        out.append(FRF(np.asarray(f, float), add_noise(h, noise, rng), input_station=chain.forces[fo] + 1,
                       output_station=chain.sensors[se] + 1, input_quantity="force",
                       output_quantity="displacement", input_direction="x", output_direction="x",
                       metadata={"noise_relative": repr(float(noise)), "noise_floor": "0.0",
                                 "generator": "benchmarks/_open_world.py"}))
    return out


def make_case(example: str, category: str, kind: str, seed: int, noise: float, workdir=None) -> Case:
    """A data set of ``category`` and ``kind`` (see the module docstring) on a shipped chain.

    Parameters
    ----------
    example : {"three_mass", "four_story"}
    category : {"in_library", "two_effect", "out_of_library", "none"}
    kind : str
        An entry of :data:`CATEGORIES` ``[category]``; for ``two_effect`` also ``"A+B"`` with two in-library
        kinds; for ``none``, ``"none"``.
    seed : int
        Seeds the draw of place and size and, separately, the noise (same draw at every noise level).
    noise : float
        Relative noise level (0.01 = 1 %).
    workdir : path, optional
        Where model files are written when the case needs them (``wrong_model_*``); default a new
        temporary directory.

    Returns
    -------
    Case
    """
    if example not in EXAMPLES:
        raise ValueError(f"unknown example {example!r}; examples: {', '.join(EXAMPLES)}")
    if category not in CATEGORIES:
        raise ValueError(f"unknown category {category!r}; categories: {', '.join(CATEGORIES)}")
    if not (0 < noise <= 0.2):
        raise ValueError(f"noise must be in (0, 0.2], got {noise!r}")
    path = example_path(example)
    chain = read_chain(path)
    M, C, K = chain.matrices()
    meas_ch, val_ch = channels(chain)
    draw, noise_rng = _rngs(example, category, kind, seed)
    key = {"category": category, "kind": kind, "example": example, "seed": int(seed), "noise": float(noise),
           "effects": [], "description": "", "details": {}, "change": 0.0, "single_fit": None,
           "data_model": None,
           "detectable_rule": f"rms |ln(H_data/H_model)| >= {DETECTABLE:g} x noise (measured channels)"}
    model_path, model_chain = path, chain

    if category == "none":
        if kind != "none":
            raise ValueError("category 'none' has kind 'none'")
        data = _linear(chain, _State(M, C, K))
        key["description"] = "no effect"
    elif category in ("in_library", "two_effect"):
        if category == "in_library":
            if kind not in IN_LIBRARY:
                raise ValueError(f"unknown in-library kind {kind!r}; kinds: {', '.join(IN_LIBRARY)}")
            kinds = [kind]
        elif kind == "pair":
            kinds = None
        else:
            kinds = kind.split("+")
            if len(kinds) != 2 or any(k not in IN_LIBRARY for k in kinds):
                raise ValueError(f"two_effect kind must be 'pair' or 'A+B' with A, B in {IN_LIBRARY}")
        f = band_grid(M, K)
        base_state = _State(M, C, K)
        base = _linear(chain, base_state)(meas_ch, f)
        for _attempt in range(30):
            ks = kinds or [IN_LIBRARY[int(draw.integers(len(IN_LIBRARY)))] for _ in range(2)]
            try:
                effects, taken = [], []
                for k in ks:
                    eff = _draw_in_library(chain, k, draw, taken)
                    size, _, _ = _grow(lambda v, eff=eff: _linear(chain, eff.apply(base_state, v)), base, meas_ch,
                                       f, eff.size, eff.null, eff.limit, noise)
                    effects.append((eff, size))
                    taken.append((eff.key["kind"], eff.key["station"], eff.key["element"]))
                break
            except NotDetectable:
                continue
        else:
            raise NotDetectable(f"{example} {category} {kind}: no detectable draw in 30 tries at noise {noise}")
        st = base_state
        for eff, size in effects:
            st = eff.apply(st, size)
        data = _linear(chain, st)
        key["effects"] = [{"kind": e.key["kind"], "station": e.key["station"], "element": e.key["element"],
                           "value": float(v), "unit": e.key["unit"]} for e, v in effects]
        key["description"] = "; ".join(e.key["description"] for e, _ in effects)
        key["details"] = {"kinds": [k for k in ks]}
    else:
        if kind not in OUT_OF_LIBRARY:
            raise ValueError(f"unknown out-of-library kind {kind!r}; kinds: {', '.join(OUT_OF_LIBRARY)}")
        wd = Path(workdir) if workdir is not None else None
        tag = f"{example}_{kind}_s{seed}_n{noise:g}"
        for _attempt in range(20):
            if wd is None and kind.startswith("wrong_model"):
                wd = Path(tempfile.mkdtemp(prefix="open-world-"))
            if wd is not None:
                wd.mkdir(parents=True, exist_ok=True)
            det, size, null, limit, data_of, model_chain, true_chain, fixed = _draw_open(chain, kind, draw, wd, tag)
            Mm, Cm, Km = model_chain.matrices()
            f = band_grid(Mm, Km)
            base = _linear(model_chain, _State(Mm, Cm, Km))(meas_ch, f)
            try:
                size, change, fit = _grow(data_of, base, meas_ch, f, size, null, limit, noise, distinct=model_chain)
                break
            except NotDetectable:
                continue
        else:
            raise NotDetectable(f"{example} {kind}: no detectable and distinct draw in 20 tries at noise {noise}")
        data = data_of(size)
        if model_chain is not chain:
            model_path = det["model"]
        if true_chain is not None:
            key["data_model"] = write_chain(true_chain(size), wd / f"{tag}_data_model.toml")
        det = {**det, "value": float(size), "fixed_size": fixed}
        key["details"] = det
        rest = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in det.items()
                         if k not in ("parameter", "value", "fixed_size", "model"))
        key["description"] = f"{kind} ({det['parameter']}: {size:.4g}; {rest})"
        key["distinct_rule"] = (f"best single library hypothesis leaves rms |ln ratio| >= {DISTINCT:g} x noise "
                                f"(noise-free data)")

    # the measurement, on the grid of the model handed to the diagnosis
    Mm, Cm, Km = model_chain.matrices()
    f = band_grid(Mm, Km)
    f_val = f + 0.5 * (f[1] - f[0])
    Hm = data(meas_ch, f, "measured")
    base = _linear(model_chain, _State(Mm, Cm, Km))(meas_ch, f)
    key["change"] = rms_log_change(Hm, base) / noise
    if category != "none":
        if category != "out_of_library":
            fit = single_fit(model_chain, meas_ch, f, Hm)       # (out of library: the fit that sized it)
        key["single_fit"] = {**fit, "misfit": fit["misfit"] / noise, "none": fit["none"] / noise}
    measured = _frfs(chain, data, meas_ch, f, noise, noise_rng, "measured")
    validate = _frfs(chain, data, val_ch, f_val, noise, noise_rng, "validate")
    Hv = data(val_ch, f_val, "validate")
    return Case(str(model_path), measured, validate, key, [np.asarray(h) for h in Hm],
                [np.asarray(h) for h in Hv], (list(meas_ch), list(val_ch)))
