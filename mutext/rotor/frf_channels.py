r"""Measured FRF channels resolved on a rotor model: input column, output DOF, spin speed, fitted points.

A measured :class:`mutext.response.FRF` names its input and output by station,
direction and quantity; :func:`_resolve_channel` finds the matching column of
the model's input matrix (an exciter port for a current input, a unit force
at a DOF for a force input) and the output DOF.  :func:`select_points` thins
a long sweep for a fit.  Shared by the tuning objective
(:mod:`mutext.rotor.tuning`), the sensitivities
(:mod:`mutext.rotor.sensitivity`) and the diagnosis.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import ModelError
from ..response import FRF

__all__ = ["select_points"]


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


def _groups(channels: Sequence[_Channel]) -> dict:
    g: dict[float, list] = {}
    for ch in channels:
        g.setdefault(ch.speed, []).append(2.0 * np.pi * ch.freq_hz)
    return {s: np.unique(np.concatenate(ws)) for s, ws in g.items()}
