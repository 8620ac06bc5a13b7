"""Finite-element rotor models with symbolic (CasADi) parameters.

Modules
-------
units
    Conversion of inch-pound files to SI (pound read as pound-mass).
table
    Station tables in the thesis appendix format.
elements
    Timoshenko shaft, disk, bearing and exciter elements (and lumped masses,
    springs, dampers), each matrix a CasADi expression of named parameters;
    gathers one module per part: ``element`` (parameters, DOF layout, ports,
    the :class:`Element` interface), ``shaft_element``, ``disk_element``,
    ``bearing_element``, ``exciter_element``, ``lumped_elements``.
crack
    Open-crack compliance (fracture mechanics), breathing laws and the
    :class:`~mutext.rotor.crack.Crack` element.
assembly
    :class:`Structure` / :class:`Rotor`: assembled ``M(p), C(p), K(p), G(p)``
    as ``casadi.Function`` objects, numeric matrices, the crack hook.
model
    TOML model files for rotors and lumped chains.
analysis
    Natural frequencies, mode shapes, whirl, Campbell data, FRFs, state space.
campbell_diagram
    :func:`campbell`: whirl frequencies, forward/backward, log decrement and the
    critical speeds where the 1x, 2x, 3x lines cross the modes.
modal
    :func:`mode_shapes`: the modes at a speed along the shaft, with log decrement and whirl.
unbalance
    :func:`unbalance_response`: steady 1x response to unbalance at probes (Bode, polar), run-up.
transient
    :func:`transient_run_up`: run-up or coast-down through the critical speeds at a finite
    acceleration, the response in time and its envelope against speed.
sparse_modal
    :func:`sparse_modes`: the lowest modes at speed by shift-invert Arnoldi (fine meshes).
periodic_orbit
    :func:`periodic_unbalance_response`: weight and unbalance on a rotor with a breathing
    crack, every order of the steady response (the 2x inner loop of the orbit).
orbits
    :func:`orbit`: the x-y path of a station from harmonic components; forward/backward ellipses.
analytic
    Closed-form beam frequencies (references for the finite elements).
reduction
    Modal truncation with static correction and balanced truncation, with
    the measured error (H-infinity norm, band error) and the a-priori bound.
periodic
    A breathing crack at speed: the time-periodic rotor, harmonic transfer
    functions, the analyzer's FRF and a brute-force time integration.
simulate
    Time simulation of a Jeffcott rotor with a breathing crack.
frf_channels
    Measured FRFs as channels of a model (input column, output DOF, speed);
    the x-y port pair of a planar FRF (:func:`~mutext.rotor.frf_channels.planar_ports`).
directional
    :class:`PlanarFRF` (the 2x2 x-y FRF matrix) and :func:`directional_frf`: forward and backward
    whirl dFRFs (Lee 1993), :func:`whirl_peaks`.
sensitivity
    FRFs and their exact parameter derivatives (adjoint, Daleckii-Krein).
tuning
    Fitting parameters to measured FRFs: :func:`tune` chains the objective
    (``_tune_objective``: unknowns, channels, log residuals) and the IPOPT
    driver (``_ipopt``); uncertainties.

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
from .campbell_diagram import CampbellDiagram, Crossing, campbell
from .modal import ModeShapes, mode_shapes
from .orbits import Ellipse, Orbit, ellipse, orbit
from .unbalance import UnbalanceResponse, run_up, unbalance_response
from .transient import TransientRunUp, transient_run_up
from .periodic_orbit import PeriodicResponse, periodic_unbalance_response
from .sparse_modal import sparse_modes
from .directional import DirectionalFRF, PlanarFRF, WhirlPeak, directional_frf, planar_rotor, whirl_peaks
from .units import rad_s_to_rpm, rpm_to_rad_s
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
    "CampbellDiagram", "Crossing", "campbell", "ModeShapes", "mode_shapes", "Ellipse", "Orbit", "ellipse", "orbit",
    "UnbalanceResponse", "run_up", "unbalance_response", "rpm_to_rad_s", "rad_s_to_rpm",
    "TransientRunUp", "transient_run_up",
    "PeriodicResponse", "periodic_unbalance_response", "sparse_modes",
    "DirectionalFRF", "PlanarFRF", "WhirlPeak", "directional_frf", "planar_rotor", "whirl_peaks",
]


def data_path(name: str) -> str:
    """Path of a file shipped in ``mutext/data`` (e.g. ``"rotor.toml"``, ``"rotor_healthy.txt"``).

    Parameters
    ----------
    name : str
        File name inside ``mutext/data``.

    Examples
    --------
    >>> import os
    >>> from mutext.rotor import data_path
    >>> os.path.basename(data_path("rotor.toml")), os.path.exists(data_path("rotor.toml"))
    ('rotor.toml', True)
    """
    return os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", name)
