r"""Measured FRF channels resolved on a rotor model: input column, output DOF, spin speed, fitted points.

A measured :class:`mutext.response.FRF` names its input and output by station,
direction and quantity; :func:`_resolve_channel` finds the matching column of
the model's input matrix (an exciter port for a current input, a unit force
at a DOF for a force input) and the output DOF.  :func:`select_points` thins
a long sweep for a fit.  Shared by the tuning objective
(:mod:`mutext.rotor.tuning`), the sensitivities
(:mod:`mutext.rotor.sensitivity`) and the diagnosis.

:func:`planar_ports` resolves a two-plane channel pair (excitation in x and
y at one station, displacement in x and y at another) for the planar FRF
matrix that the virtual rig records (:func:`mutext.rig.measure_rotor` with
``planes="xy"``) and the directional FRFs
(:mod:`mutext.rotor.directional`) are made of.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .._validation import Integer
from ..errors import ModelError
from ..response import FRF

__all__ = ["select_points", "PlanarPorts", "planar_ports"]


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
    if not Integer(1, n).is_satisfied_by(s):
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
        # the force's direction named as the displacement's (x12, y12): F12 along x, F12y along y
        in_name = f"F{s_in}" + ("" if d_in in ("u", "x") else "y" if d_in == "v" else d_in)
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

    Parameters
    ----------
    freq_hz : array_like (n,)
        Frequencies [Hz], increasing.
    response : array_like (n,)
        The FRF at them (complex).
    max_points : int or None
        About how many to keep (at least 4); None keeps all.

    Returns
    -------
    ndarray of int
        Sorted unique indices into ``freq_hz``.
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


def _groups(channels: Sequence[_Channel]) -> dict:
    g: dict[float, list] = {}
    for ch in channels:
        g.setdefault(ch.speed, []).append(2.0 * np.pi * ch.freq_hz)
    return {s: np.unique(np.concatenate(ws)) for s, ws in g.items()}


# ----------------------------------------------------------------------------
# two-plane channels
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class PlanarPorts:
    r"""Excitation in x and y at one station, displacement in x and y at another.

    Attributes
    ----------
    input_station, output_station : int
        Stations (1-based).
    input_quantity : {"force", "current"}
        Unit of the inputs: N for a force, A for an exciter current.
    B : ndarray, shape (ndof, 2)
        Input columns, x first: a unit force, or the exciter's force per
        ampere, on the station's :math:`u` and :math:`v` DOFs.
    Cy : ndarray, shape (2, ndof)
        Output rows, x first: the station's :math:`u` and :math:`v`.
    inputs, outputs : list of str
        Names ``[x, y]`` of the two inputs and the two outputs.
    ports : dict
        Name -> ``(station, direction, quantity)``, as
        :attr:`mutext.response.FRFMatrix.ports`.
    """
    input_station: int
    output_station: int
    input_quantity: str
    B: np.ndarray
    Cy: np.ndarray
    inputs: list
    outputs: list
    ports: dict


def _twin_name(ports, node, label, gain, base_name, base_label, kind):
    """Name of the port at ``node`` in plane ``label``: the model's own port there (same gain for an
    input) if it has one, else one made from the given port's name (``F12 -> F12y``, ``x13 -> y13``)."""
    if label == base_label:
        return base_name
    for q in ports:
        if q.node == node and q.direction in (label, {"u": "x", "v": "y"}[label]) and \
                (kind == "output" or q.gain == gain):
            return q.name
    if kind == "output":
        return ("x" if label == "u" else "y") + str(node)
    if label == "v":
        return base_name + "y"
    return base_name[:-1] if base_name.endswith("y") and len(base_name) > 1 else base_name + "x"


def planar_ports(model, in_port, out_port, *, values=None) -> PlanarPorts:
    r"""The two-plane input and output pair of a rotor for the planar FRF matrix.

    Parameters
    ----------
    model : mutext.rotor.Rotor
        A two-plane rotor (``planes = 2``).
    in_port : str or int
        An input port name (``"i12"``, ``"F2"``): excitation at its station,
        by the same means in both planes -- a force [N], or an exciter
        current [A] with the port's force per ampere in x and in y (an
        active magnetic bearing drives both axes; the model file declares
        one, and the other is taken to have the same gain) -- or a station
        number: a unit force there.
    out_port : str or int
        An output port name (``"x13"``) or a station number: the station's
        displacement in x and y.
    values : mapping or array, optional
        Parameter values (default: nominal), for an exciter's gain.

    Returns
    -------
    PlanarPorts

    Raises
    ------
    ModelError
        The model is not a two-plane rotor, a port name is unknown, a port
        is not a translational force/displacement (a moment, a rotation),
        or a station is outside the rotor.

    Examples
    --------
    >>> from mutext.rotor import load_model, data_path
    >>> from mutext.rotor.frf_channels import planar_ports
    >>> pp = planar_ports(load_model(data_path("rotor.toml")), "i12", 13)
    >>> pp.inputs, pp.outputs, pp.input_quantity
    (['i12', 'i12y'], ['x13', 'y13'], 'current')
    """
    model = _as_model(model)
    lay = model.layout
    if lay.kind != "rotor":
        raise ModelError(f"{model.name}: a planar (x-y) FRF needs a two-plane rotor (planes = 2); this "
                         f"model has the '{lay.kind}' layout")
    n = lay.ndof
    B = np.zeros((n, 2))
    Cy = np.zeros((2, n))
    if isinstance(in_port, str):
        if in_port not in model.input_names:
            raise ModelError(f"{model.name}: unknown input '{in_port}' (inputs: {', '.join(model.input_names)})")
        j = model.input_names.index(in_port)
        port = model.inputs[j]
        base = lay.label(port.direction)
        if base not in ("u", "v"):
            raise ModelError(f"{model.name}: input '{in_port}' acts on '{port.direction}' (a moment); a planar "
                             f"FRF needs a force or an exciter current in x or y")
        s_in, gain_name = port.node, port.gain
        b = float(np.asarray(model.input_matrix(values))[lay.dof(s_in, base), j])
        qty = "current" if gain_name is not None else "force"
        ins = [_twin_name(model.inputs, s_in, lab, gain_name, in_port, base, "input") for lab in ("u", "v")]
    else:
        s_in = lay.check_node(in_port if not isinstance(in_port, np.integer) else int(in_port), "in_port")
        b, qty, base = 1.0, "force", "u"
        ins = [f"F{s_in}", f"F{s_in}y"]
    if isinstance(out_port, str):
        if out_port not in model.output_names:
            raise ModelError(f"{model.name}: unknown output '{out_port}' (outputs: "
                             f"{', '.join(model.output_names)})")
        port = model.outputs[model.output_names.index(out_port)]
        obase = lay.label(port.direction)
        if obase not in ("u", "v"):
            raise ModelError(f"{model.name}: output '{out_port}' is the rotation '{port.direction}'; a planar "
                             f"FRF needs a displacement in x or y")
        s_out = port.node
        outs = [_twin_name(model.outputs, s_out, lab, None, out_port, obase, "output") for lab in ("u", "v")]
    else:
        s_out = lay.check_node(out_port if not isinstance(out_port, np.integer) else int(out_port), "out_port")
        outs = [f"x{s_out}", f"y{s_out}"]
    if len(set(ins)) != 2 or len(set(outs)) != 2:  # pragma: no cover - the naming keeps them apart
        raise ModelError(f"{model.name}: the x and y ports are not told apart ({ins}, {outs})")
    for k, lab in enumerate(("u", "v")):
        B[lay.dof(s_in, lab), k] = b
        Cy[k, lay.dof(s_out, lab)] = 1.0
    ports = {ins[0]: (s_in, "x", qty), ins[1]: (s_in, "y", qty),
             outs[0]: (s_out, "x", "displacement"), outs[1]: (s_out, "y", "displacement")}
    return PlanarPorts(s_in, s_out, qty, B, Cy, ins, outs, ports)
