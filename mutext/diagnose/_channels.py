"""The measured channels of a diagnosis, resolved against the model: ports, stations, names."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..response import FRF
from ..rotor.frf_channels import _Inputs, _resolve_channel


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
