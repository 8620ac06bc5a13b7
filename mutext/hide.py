r"""Data sets with a hidden effect: the exercise material and the test bench of :mod:`mutext.diagnose`.

:func:`hidden_effect_data` takes a shipped model (the three-mass rig, a
four-storey shear frame, the thesis rotor), hides one effect of random kind,
location and size in it, and "measures" the changed system with noise on the
virtual rig.  The engineering model handed out is the unchanged one; the
answer is kept apart (``answer_key.json``), so an instructor can hand out the
rest.  ``mutext rig hide`` is the command-line front end.

Where the data come from
------------------------
For the lumped chains the measured system is **not** built by the code that
is diagnosed: the model file is read as plain TOML and the mass, damping and
stiffness matrices are assembled here directly (a few lines of numpy), the
effect applied to those matrices, and the response computed by a direct
complex solve.  For the rotor, the effect is written into the model file (as
the extended model of a diagnosis would be) and the finite-element model of
:mod:`mutext.rotor` computes the response; the test suite checks the rotor
case against a separately written beam model.

Kinds and sizes
---------------
``stiffness`` (a spring changed, or a grounded spring added at a mass or a
station), ``mass``, ``damping``, ``bearing`` (a bearing's stiffness, rotor),
``crack`` (an open crack in a shaft element, rotor), ``exciter_gain``,
``sensor_gain`` and ``none`` (about one case in six).  The size is drawn
log-uniformly (changes: 3-30 % of the value, either sign; dampers 10-100 %;
gains 2-20 %; crack depth ratio 0.1-0.45) and then enlarged by factors of 1.5
until the effect is **detectable**: the rms over the measured channels of
:math:`|\ln(H_{\mathrm{changed}}/H_{\mathrm{model}})|` is at least
:data:`DETECTABLE` (5) times the relative noise level.

Noise is relative circular complex Gaussian (:class:`mutext.rig.Noise`).

Examples
--------
>>> from mutext.hide import hidden_effect_data
>>> case = hidden_effect_data("three_mass", seed=1, kind="mass", noise=0.01)
>>> case.key["kind"], case.key["unit"]
('mass', 'kg')
>>> len(case.measured) >= 1 and len(case.validate) >= 1
True
"""
from __future__ import annotations

import json
import math
import os
import re
import shutil
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from ._validation import Integer, validate_params
from .errors import ModelError
from .response import frequency_grid
from .rig import Noise, measure, write_frf

__all__ = ["hidden_effect_data", "HiddenCase", "EXAMPLES", "DETECTABLE", "plain_chain", "example_path"]

#: Shipped models that can hide an effect: name -> model file in mutext/data.
EXAMPLES = {"three_mass": "three_mass.toml", "four_story": "four_story.toml", "rotor": "rotor.toml"}

#: An effect is drawn so that it changes the noise-free FRF by at least this many times the noise rms.
DETECTABLE = 5.0

_LUMPED_KINDS = ("stiffness", "mass", "damping", "sensor_gain", "exciter_gain")
_ROTOR_KINDS = ("stiffness", "mass", "bearing", "crack", "sensor_gain", "exciter_gain")

# measured and validation channels of the rotor: exciter current at 12 to these sensors
_ROTOR_MEASURED = ("x13", "x6", "x24")
_ROTOR_VALIDATE = ("x13", "x15", "y13")


@dataclass
class HiddenCase:
    """A data set with a hidden effect.

    Attributes
    ----------
    model : str
        The engineering model (without the effect): a model-file path.
    measured, validate : list of FRF
        Channels to diagnose and channels held back for validation.
    key : dict
        The answer: ``kind``, ``station``, ``element``, ``value``, ``unit``,
        ``noise``, ``description`` (and ``example``, ``seed``).
    files : dict
        Paths written (with ``out_dir``).
    """
    model: str
    measured: list
    validate: list
    key: dict
    files: dict = field(default_factory=dict)


def example_path(name: str) -> str:
    """Path of a shipped example model (:data:`EXAMPLES`).

    Parameters
    ----------
    name : str
        A key of :data:`EXAMPLES`.
    """
    if name not in EXAMPLES:
        raise ModelError(f"unknown example '{name}'; available: {', '.join(EXAMPLES)}")
    return str(resources.files("mutext") / "data" / EXAMPLES[name])


# ----------------------------------------------------------------------------
# lumped chains: a plain assembly, written apart from mutext.rotor
# ----------------------------------------------------------------------------

def plain_chain(doc: dict):
    """``(M, C, K, forces, sensors, names)`` of a lumped-chain model file's TOML tables.

    ``forces`` and ``sensors`` map port names to 0-based mass indices.  Only
    the ``[[mass]]``, ``[[spring]]``, ``[[damper]]``, ``[[force]]`` and
    ``[[sensor]]`` tables in SI are read (what the shipped chains use).

    Parameters
    ----------
    doc : dict
        The parsed TOML document of a lumped-chain model file.
    """
    if doc.get("units", "SI") != "SI" or "damping" in doc:
        raise ModelError("plain_chain reads SI chains with discrete dampers only")
    names = [m["name"] for m in doc["mass"]]
    n = len(names)
    M = np.diag([float(m["mass"]) for m in doc["mass"]])
    C, K = np.zeros((n, n)), np.zeros((n, n))
    for tbl, X, key in (("spring", K, "stiffness"), ("damper", C, "damping")):
        for e in doc.get(tbl, []):
            a, b = e["between"]
            v = float(e[key])
            ia = None if a == "ground" else names.index(a)
            ib = None if b == "ground" else names.index(b)
            for i in (ia, ib):
                if i is not None:
                    X[i, i] += v
            if ia is not None and ib is not None:
                X[ia, ib] -= v
                X[ib, ia] -= v
    forces = {f["name"]: names.index(f["mass"]) for f in doc.get("force", [])}
    sensors = {s["name"]: names.index(s["mass"]) for s in doc.get("sensor", [])}
    return M, C, K, forces, sensors, names


def _chain_response(M, C, K, i_in, i_out, f_hz, gain_in=1.0, gain_out=1.0):
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    b = np.zeros(M.shape[0])
    b[i_in] = 1.0
    x = np.linalg.solve(Z, np.broadcast_to(b, (w.size, b.size))[:, :, None])[:, :, 0]
    return gain_in * gain_out * x[:, i_out]


def _first_mass(e):
    a, b = e["between"]
    return a if a != "ground" else b


def _lumped_effect(doc, kind, rng):
    """Draw an effect: returns (key without value, apply(value) -> (M, C, K, gains), size sampler)."""
    M, C, K, forces, sensors, names = plain_chain(doc)
    n = len(names)
    if kind in ("stiffness", "damping"):
        tbl, key, unit = ("spring", "stiffness", "N/m") if kind == "stiffness" else ("damper", "damping", "N s/m")
        grounded = {_first_mass(e) for e in doc.get(tbl, []) if "ground" in e["between"]}
        options = [("change", e) for e in doc.get(tbl, [])] + \
                  [("add", m) for m in names if m not in grounded]
        what, obj = options[rng.integers(len(options))]
        lo, hi = (0.03, 0.3) if kind == "stiffness" else (0.1, 1.0)
        rel = math.exp(rng.uniform(math.log(lo), math.log(hi)))
        if what == "change":
            v0 = float(obj[key])
            sign = 1.0 if rng.random() < 0.5 else -1.0
            a, b = obj["between"]
            ia = None if a == "ground" else names.index(a)
            ib = None if b == "ground" else names.index(b)
            u = np.zeros(n)
            if ia is not None:
                u[ia] = 1.0
            if ib is not None:
                u[ib] = -1.0
            P = np.outer(u, u)
            key_ = {"kind": kind, "station": names.index(_first_mass(obj)) + 1, "element": obj["name"],
                    "unit": unit, "description": f"{obj['name']} changed"}
            size0 = sign * rel * v0
            limit = (-0.9 * v0, 10 * v0)
        else:
            i = names.index(obj)
            P = np.zeros((n, n))
            P[i, i] = 1.0
            scale = K[i, i] if kind == "stiffness" else 0.05 * 2 * math.sqrt(K[i, i] * M[i, i])
            key_ = {"kind": kind, "station": i + 1,
                    "element": f"{'k' if kind == 'stiffness' else 'c'}_{obj}_ground", "unit": unit,
                    "description": f"grounded {'spring' if kind == 'stiffness' else 'damper'} added at {obj}"}
            size0 = rel * scale
            limit = (0.0, 10 * scale)

        def apply(v, P=P):
            return (M, C + v * P, K, 1.0, 1.0) if kind == "damping" else (M, C, K + v * P, 1.0, 1.0)
        return key_, apply, size0, limit
    if kind == "mass":
        i = int(rng.integers(n))
        m0 = M[i, i]
        rel = math.exp(rng.uniform(math.log(0.03), math.log(0.3))) * (1.0 if rng.random() < 0.5 else -1.0)
        P = np.zeros((n, n))
        P[i, i] = 1.0
        key_ = {"kind": "mass", "station": i + 1, "element": names[i], "unit": "kg",
                "description": f"mass {names[i]} changed"}
        return key_, (lambda v: (M + v * P, C, K, 1.0, 1.0)), rel * m0, (-0.9 * m0, 10 * m0)
    # gains
    rel = math.exp(rng.uniform(math.log(0.02), math.log(0.2))) * (1.0 if rng.random() < 0.5 else -1.0)
    if kind == "sensor_gain":
        name = list(sensors)[rng.integers(len(sensors))]
        key_ = {"kind": kind, "station": sensors[name] + 1, "element": name, "unit": "1",
                "description": f"gain of sensor {name}"}
        return key_, (lambda v: (M, C, K, 1.0, {name: v})), 1.0 + rel, (0.2, 5.0)
    name = list(forces)[0]     # the exciter of the measured channels
    key_ = {"kind": kind, "station": forces[name] + 1, "element": name, "unit": "1",
            "description": f"gain of force input {name}"}
    return key_, (lambda v: (M, C, K, {name: v}, 1.0)), 1.0 + rel, (0.2, 5.0)


def _lumped_channels(doc):
    """(measured, validate): lists of (force, sensor) names."""
    forces = [f["name"] for f in doc.get("force", [])]
    sensors = [s["name"] for s in doc.get("sensor", [])]
    if not forces or not sensors:
        raise ModelError("the model needs at least one [[force]] and one [[sensor]]")
    measured = [(forces[0], s) for s in sensors]
    # a second sweep of the measured channels (other frequencies, other noise) and the other exciters
    validate = measured + [(f, s) for f in forces[1:] for s in sensors[:2]]
    return measured, validate


def _lumped_grid(M, K, C):
    import scipy.linalg as sla
    lam = sla.eigh(K, M, eigvals_only=True)
    f = np.sqrt(np.clip(lam, 0, None)) / (2 * np.pi)
    # half the lowest to 1.4 times the highest natural frequency, in an analyser's round steps
    return frequency_grid(n=400, poles=f, margin=(2.0, 1.4), spacing="step")


def _case_lumped(path, seed, kind, noise, rng):
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    M, C, K, forces, sensors, names = plain_chain(doc)
    meas_ch, val_ch = _lumped_channels(doc)
    f_hz = _lumped_grid(M, K, C)
    # validation sweep: the same band, offset by half a step (other frequencies, other noise)
    f_val = f_hz + 0.5 * (f_hz[1] - f_hz[0])

    def responses(state, chans, f):
        Mx, Cx, Kx, gin, gout = state
        out = []
        for fo, se in chans:
            gi = gin.get(fo, 1.0) if isinstance(gin, dict) else gin
            go = gout.get(se, 1.0) if isinstance(gout, dict) else gout
            out.append(_chain_response(Mx, Cx, Kx, forces[fo], sensors[se], f, gi, go))
        return out

    base = responses((M, C, K, 1.0, 1.0), meas_ch, f_hz)
    if kind == "none":
        key = {"kind": "none", "station": None, "element": None, "value": 0.0, "unit": "",
               "description": "no effect"}
        state = (M, C, K, 1.0, 1.0)
    else:
        key, apply, size, limit = _lumped_effect(doc, kind, rng)
        size = _detectable(lambda v: responses(apply(v), meas_ch, f_hz), base, size, limit, noise,
                           gain=kind.endswith("gain"))
        key["value"] = float(size)
        state = apply(size)
    meas = []
    for (fo, se), H in zip(meas_ch, responses(state, meas_ch, f_hz)):
        meas.append(_frf(H, f_hz, forces[fo] + 1, sensors[se] + 1, noise, rng, "force"))
    val = []
    for (fo, se), H in zip(val_ch, responses(state, val_ch, f_val)):
        val.append(_frf(H, f_val, forces[fo] + 1, sensors[se] + 1, noise, rng, "force"))
    return key, meas, val


def _frf(H, f_hz, s_in, s_out, noise, rng, quantity, speed_hz=None, direction=None):
    return measure(lambda w, H=H: H, 0, 0, f_hz, noise=Noise(relative=noise), rng=rng, input_station=s_in,
                   output_station=s_out, input_quantity=quantity, speed_hz=speed_hz,
                   output_direction=direction or "x")


def _detectable(resp, base, size, limit, noise, gain=False, tries=12):
    """Enlarge ``size`` (about the null value) by 1.5x until the effect is DETECTABLE times the noise."""
    null = 1.0 if gain else 0.0
    for _ in range(tries):
        H = resp(size)
        r = np.concatenate([np.abs(np.log(h / b)) for h, b in zip(H, base)])
        if math.sqrt(float(np.mean(r ** 2))) >= DETECTABLE * noise:
            return size
        new = null + 1.5 * (size - null)
        if not limit[0] <= new <= limit[1]:
            break
        size = new
    raise _NotDetectable()


class _NotDetectable(Exception):
    pass


# ----------------------------------------------------------------------------
# the rotor: the effect written into the model file
# ----------------------------------------------------------------------------

def _set_bearing_stiffness(text: str, station: int, value: float) -> str:
    """Model-file text with the stiffness of the ``[[bearing]]`` at ``station`` set to ``value``."""
    blocks = re.split(r"(?m)^(?=\s*\[)", text)
    for k, b in enumerate(blocks):
        if b.strip().startswith("[[bearing]]") and re.search(rf"(?m)^\s*station\s*=\s*{station}\b", b):
            blocks[k] = re.sub(r"(?m)^(\s*stiffness\s*=\s*)[^#\n]*", rf"\g<1>{value!r} ", b, count=1)
            return "".join(blocks)
    raise ModelError(f"no [[bearing]] at station {station} in the model file")

def _case_rotor(path, seed, kind, noise, rng):
    from .rotor.analysis import frf as model_frf
    from .rotor.elements import BearingElement
    from .rotor.model import load_model, loads_model
    from .rig import sweep_frequencies
    eng = load_model(path)
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    base_dir = os.path.dirname(os.path.abspath(path))
    speed_hz = eng.speed / (2 * math.pi)
    f_hz = sweep_frequencies()                          # thesis band 20-225 Hz, 0.5 Hz
    f_val = f_hz[:-1] + 0.25
    exc = next(p for p in eng.inputs if p.gain is not None)
    outs = list(_ROTOR_MEASURED) + list(_ROTOR_VALIDATE)

    def responses(model, gain_in=1.0, gain_out=None):
        Hm = model_frf(model, f_hz, inputs=[exc.name], outputs=outs)
        Hv = model_frf(model, f_val, inputs=[exc.name], outputs=outs)
        go = gain_out or {}
        meas = [Hm(o, exc.name) * gain_in * go.get(o, 1.0) for o in _ROTOR_MEASURED]
        val = [Hv(o, exc.name) * gain_in * go.get(o, 1.0) for o in _ROTOR_VALIDATE]
        return meas, val

    base, _ = responses(eng)
    bearings = [el for el in eng.elements if isinstance(el, BearingElement)]
    bstations = {el.nodes[0] for el in bearings}
    shaft_ok = [el.nodes[0] for el in eng.elements if type(el).__name__ == "ShaftElement"
                and el.nominal("di") == 0.0]
    n = eng.layout.n_nodes
    M, _, K, _ = eng.matrices()
    rotor_mass = float(np.sum(M[0::4, 0::4]))     # consistent mass: the whole x-x block

    def ext_model(extra_text):
        return loads_model(text.rstrip("\n") + "\n\n" + extra_text, source=f"{path} (hidden effect)",
                           base_dir=base_dir)

    if kind == "none":
        key = {"kind": "none", "station": None, "element": None, "value": 0.0, "unit": "",
               "description": "no effect"}
        meas, val = responses(eng)
    else:
        free = [s for s in range(2, n) if s not in bstations]
        if kind == "stiffness":
            s = int(rng.choice(free))
            kb = min(el.nominal("k") for el in bearings)
            kss = kb
            size = kb * math.exp(rng.uniform(math.log(1e-3), math.log(3e-2)))
            key = {"kind": kind, "station": s, "element": f"k_s{s}", "unit": "N/m",
                   "description": f"grounded spring added at station {s}"}
            make = lambda v, s=s: ext_model(f"[[bearing]]\nname = \"k_s{s}\"\nstation = {s}\nstiffness = {v!r}\n")
            limit = (0.0, 10 * kss)
            null = 0.0
        elif kind == "mass":
            s = int(rng.choice(free))
            size = rotor_mass * math.exp(rng.uniform(math.log(0.005), math.log(0.05)))
            key = {"kind": kind, "station": s, "element": f"m_s{s}", "unit": "kg",
                   "description": f"point mass added at station {s}"}
            make = lambda v, s=s: ext_model(f"[[disk]]\nname = \"m_s{s}\"\nstation = {s}\nmass = {v!r}\n")
            limit = (0.0, rotor_mass)
            null = 0.0
        elif kind == "bearing":
            el = bearings[int(rng.integers(len(bearings)))]
            s, kb = el.nodes[0], el.nominal("k")
            size = -kb * math.exp(rng.uniform(math.log(0.1), math.log(0.7)))
            key = {"kind": kind, "station": s, "element": el.name, "unit": "N/m",
                   "description": f"stiffness of {el.name} changed"}
            def make(v, s=s, kb=kb):
                return loads_model(_set_bearing_stiffness(text, s, kb + v), source=f"{path} (hidden effect)",
                                   base_dir=base_dir)
            limit = (-0.95 * kb, 10 * kb)
            null = 0.0
        elif kind == "crack":
            s = int(rng.choice([x for x in shaft_ok if 3 <= x <= n - 3]))
            size = float(rng.uniform(0.1, 0.45))
            key = {"kind": kind, "station": s, "element": f"crack{s}", "unit": "1",
                   "description": f"open crack in the shaft element {s}-{s + 1}"}
            make = lambda v, s=s: ext_model(f"[[crack]]\nstation = {s}\ndepth_ratio = {v!r}\n")
            limit = (0.0, 0.5)
            null = 0.0
        elif kind in ("sensor_gain", "exciter_gain"):
            rel = math.exp(rng.uniform(math.log(0.02), math.log(0.2))) * (1.0 if rng.random() < 0.5 else -1.0)
            size = 1.0 + rel
            if kind == "sensor_gain":
                o = _ROTOR_MEASURED[int(rng.integers(len(_ROTOR_MEASURED)))]
                port = eng.outputs[eng.output_names.index(o)]
                key = {"kind": kind, "station": port.node, "element": o, "unit": "1",
                       "description": f"gain of sensor {o}"}
                make = ("gain", lambda v, o=o: responses(eng, 1.0, {o: v}))
            else:
                key = {"kind": kind, "station": exc.node, "element": exc.name, "unit": "1",
                       "description": f"gain of exciter {exc.name}"}
                make = ("gain", lambda v: responses(eng, v))
            limit = (0.2, 5.0)
            null = 1.0
        else:
            raise ModelError(f"unknown kind '{kind}' for the rotor; kinds: {', '.join(_ROTOR_KINDS)}, none")

        def resp(v):
            if isinstance(make, tuple):
                return make[1](v)
            return responses(make(v))
        size = _detectable(lambda v: resp(v)[0], base, size, limit, noise, gain=(null == 1.0))
        if kind == "crack":
            size = min(size, 0.5)
        key["value"] = float(size)
        meas, val = resp(size)
    ms = []
    for o, H in zip(_ROTOR_MEASURED, meas):
        port = eng.outputs[eng.output_names.index(o)]
        ms.append(_frf(H, f_hz, exc.node, port.node, noise, rng, "current", speed_hz,
                       "y" if port.direction == "v" else None))
    vs = []
    for o, H in zip(_ROTOR_VALIDATE, val):
        port = eng.outputs[eng.output_names.index(o)]
        vs.append(_frf(H, f_val, exc.node, port.node, noise, rng, "current", speed_hz,
                       "y" if port.direction == "v" else None))
    return key, ms, vs


# ----------------------------------------------------------------------------
# the entry point
# ----------------------------------------------------------------------------

@validate_params({"seed": Integer(lo=0)})
def hidden_effect_data(example: str = "three_mass", seed: int = 0, *, kind: str | None = None,
                       noise: float = 0.01, out_dir=None) -> HiddenCase:
    """A data set with a hidden effect (see the module docstring).

    Parameters
    ----------
    example : str or path
        A shipped example (:data:`EXAMPLES`: ``three_mass``, ``four_story``,
        ``rotor``) or a lumped-chain model file.
    seed : int
        Seed of the random kind, location, size and noise.
    kind : str, optional
        Force the kind (``stiffness``, ``mass``, ``damping``, ``bearing``,
        ``crack``, ``sensor_gain``, ``exciter_gain``, ``none``); default random,
        with ``none`` about one time in six.
    noise : float
        Relative noise level (0.01 = 1 %); must be in (0, 0.2].
    out_dir : path, optional
        Write ``model.toml`` (the engineering model), ``measured/*.csv``,
        ``validate/*.csv`` and ``answer_key.json`` there.

    Returns
    -------
    HiddenCase
    """
    path = example_path(example) if example in EXAMPLES else os.fspath(example)
    if not os.path.exists(path):
        raise ModelError(f"hide: no example or model file '{example}' (examples: {', '.join(EXAMPLES)})")
    if not (isinstance(noise, (int, float)) and 0 < noise <= 0.2):
        raise ModelError(f"hide: noise must be a relative level in (0, 0.2], got {noise!r}")
    try:
        with open(path, "rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{path}: not a valid TOML file ({exc})") from None
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the model file ({exc.strerror or exc})") from None
    rotor = "shaft" in doc or "station" in doc
    if not rotor:
        # the model parser names the file, table and key of a malformed chain before the plain assembly reads it
        from .rotor import load_model
        load_model(path)
    kinds = _ROTOR_KINDS if rotor else _LUMPED_KINDS
    if kind is not None and kind not in kinds + ("none",):
        raise ModelError(f"hide: kind '{kind}' is not available for this model; kinds: {', '.join(kinds)}, none")
    rng = np.random.default_rng(seed)
    for attempt in range(20):
        k = kind
        if k is None:
            k = "none" if rng.random() < 1 / 6 else kinds[int(rng.integers(len(kinds)))]
        try:
            key, meas, val = (_case_rotor if rotor else _case_lumped)(path, seed, k, float(noise), rng)
            break
        except _NotDetectable:
            continue
    else:
        raise ModelError(f"hide: no detectable effect of kind {kind} found in 20 draws at noise {noise}")
    key.update({"noise": float(noise), "example": str(example), "seed": int(seed),
                "detectable_rule": f"rms |ln(H_changed/H_model)| >= {DETECTABLE:g} x noise"})
    case = HiddenCase(path, meas, val, key)
    if out_dir is not None:
        _write(case, path, doc, Path(out_dir))
    return case


def _write(case: HiddenCase, path, doc, out: Path):
    out.mkdir(parents=True, exist_ok=True)
    (out / "measured").mkdir(exist_ok=True)
    (out / "validate").mkdir(exist_ok=True)
    model_out = out / "model.toml"
    shutil.copyfile(path, model_out)
    table = doc.get("shaft", {}).get("station_table")
    if table:
        src = table if os.path.isabs(table) else os.path.join(os.path.dirname(path), table)
        shutil.copyfile(src, out / os.path.basename(table))
        if os.path.basename(table) != table:
            t = model_out.read_text(encoding="utf-8").replace(f'"{table}"', f'"{os.path.basename(table)}"')
            model_out.write_text(t, encoding="utf-8")
    files = {"model": str(model_out), "measured": [], "validate": []}
    for role, frfs in (("measured", case.measured), ("validate", case.validate)):
        for frf in frfs:
            d = frf.output_direction
            name = f"in{frf.input_station}_out{frf.output_station}{'' if d == 'x' else d}.csv"
            p = write_frf(out / role / name, frf, output_unit="um" if frf.input_quantity == "current" else "m")
            files[role].append(str(p))
            frf.source = p
    with open(out / "answer_key.json", "w", encoding="utf-8") as fh:
        json.dump(case.key, fh, indent=2)
    files["answer_key"] = str(out / "answer_key.json")
    case.model = str(model_out)
    case.files = files
