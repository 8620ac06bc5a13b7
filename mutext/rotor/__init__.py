"""Finite-element rotor models with symbolic (CasADi) parameters.

Modules
-------
units
    Conversion of inch-pound files to SI (pound read as pound-mass).
table
    Station tables in the thesis appendix format.
elements
    Timoshenko shaft, disk, bearing and exciter elements (and lumped masses,
    springs, dampers), each matrix a CasADi expression of named parameters.
assembly
    :class:`Structure` / :class:`Rotor`: assembled ``M(p), C(p), K(p), G(p)``
    as ``casadi.Function`` objects, numeric matrices, the crack hook.
model
    TOML model files for rotors and lumped chains.
analysis
    Natural frequencies, mode shapes, whirl, Campbell data, FRFs, state space.
reduction
    Modal truncation with static correction and balanced truncation, with
    the measured error (H-infinity norm, band error) and the a-priori bound.
periodic
    A breathing crack at speed: the time-periodic rotor, harmonic transfer
    functions, the analyzer's FRF and a brute-force time integration.
tuning
    Fitting parameters to measured FRFs (IPOPT through CasADi, exact
    sensitivities, uncertainties).
demo
    ``mutext demo rotor``.

Example
-------
>>> from mutext.rotor import load_model, data_path
>>> rotor = load_model(data_path("rotor.toml"))
>>> f = rotor.natural_frequencies(n=4)          # Hz, at the file's 600 rpm
"""
from __future__ import annotations

import os

from .assembly import (Matrices, ModalDamping, ProportionalDamping, Rotor, ShaftFlexibility, Structure,
                       shaft_stiffness_with_compliance)
from .elements import (BearingElement, Damper, DiskElement, Element, ExciterElement, InputPort, Layout,
                       OutputPort, Param, PointMass, ShaftElement, Spring)
from .model import load_model, loads_model, rotor_from_table
from .reduction import Reduction, balanced_truncation, hankel_singular_values, modal_truncation, reduction_error
from .tuning import FRFSensitivity, TuneResult, frf_sensitivity, model_response, tune
from .table import Station, StationTable, parse_station_table, read_station_table

__all__ = [
    "Matrices", "ModalDamping", "ProportionalDamping", "Rotor", "ShaftFlexibility", "Structure",
    "shaft_stiffness_with_compliance", "BearingElement", "Damper", "DiskElement", "Element",
    "ExciterElement", "InputPort", "Layout", "OutputPort", "Param", "PointMass", "ShaftElement", "Spring",
    "load_model", "loads_model", "rotor_from_table", "Station", "StationTable", "parse_station_table",
    "read_station_table", "data_path",
    "Reduction", "balanced_truncation", "hankel_singular_values", "modal_truncation", "reduction_error",
    "FRFSensitivity", "TuneResult", "frf_sensitivity", "model_response", "tune",
]


def data_path(name: str) -> str:
    """Path of a file shipped in ``mutext/data`` (e.g. ``"rotor.toml"``, ``"rotor_healthy.txt"``)."""
    return os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", name)
