"""Hypotheses of the form *kind at location*: assembled from the kinds' own modules in
:mod:`mutext.diagnose.faults` (each kind's candidates, change of dynamic stiffness, description and
model-file writing live there)."""
from __future__ import annotations

import os

from ..rotor.model import load_model
from ._channels import _resolve
from .faults import absorber as _absorber
from .faults import bearing_cross as _bearing_cross
from .faults import channel as _channel
from .faults import crack as _crack
from .faults import distributed as _distributed
from .faults import lumped as _lumped
from .faults import pedestal as _pedestal
from .faults import rotor as _rotor
from .faults import structure as _structure
from .faults._base import Hypothesis

__all__ = ["KINDS", "Hypothesis", "hypotheses", "write_finding"]

#: Kinds of finding (the ``kind`` field of :class:`~mutext.diagnose.Finding`).
KINDS = (("stiffness", "mass", "damping", "crack", "bearing") + _bearing_cross.KINDS + _absorber.KINDS
         + _distributed.KINDS + _pedestal.KINDS + _channel.KINDS + _structure.KINDS + ("none",))


def hypotheses(model, frfs=None, *, stations=None) -> list[Hypothesis]:
    """The hypotheses :func:`diagnose` tests on ``model`` (given the measured channels ``frfs``).

    Parameters
    ----------
    model : Structure, Rotor or str
        The engineering model, or the path of its model file.
    frfs : sequence of mutext.response.FRF, optional
        The measured channels (adds the measurement-chain hypotheses).
    stations : sequence of int, optional
        Stations at which rotor and crack hypotheses are formed (default: all).
    """
    if isinstance(model, (str, os.PathLike)):
        model = load_model(model)
    if model.layout.kind == "lumped":
        hyps = (_lumped.candidates(model) + _distributed.candidates(model) + _absorber.candidates(model)
                + _pedestal.candidates(model))
    else:
        hyps = (_rotor.candidates(model, stations) + _bearing_cross.candidates(model, stations)
                + _crack.candidates(model, stations))
    if frfs is not None:
        chans, _ = _resolve(model, list(frfs), "FRF")
        hyps += _channel.candidates(model, chans)
    return hyps


def write_finding(mf, finding, model, note: str) -> None:
    """Write a structural ``finding`` into the model file ``mf`` through its kind's module."""
    h = finding.hypothesis
    if h.kind == "absorber":
        home = _absorber
    elif h.kind == "cross_coupling":
        home = _bearing_cross
    elif h.kind == "distributed_stiffness":
        home = _distributed
    elif h.kind == "pedestal":
        home = _pedestal
    elif model.layout.kind == "lumped":
        home = _lumped
    else:
        home = _crack if h.kind == "crack" else _rotor
    home.write(mf, finding, model, note)
