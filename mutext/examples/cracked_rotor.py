"""The thesis rotor with a breathing crack, spinning at 10 Hz (thesis ch. 4; rig of Pesch 2008).

Factories reused by ``mutext demo crack``, the book, the exercises and the
tests.  The healthy rotor is ``mutext/data/rotor.toml`` (station table,
ball bearings, exciter current input at station 12, sensor at station 13,
10 Hz); the cracked one adds a crack element at station 15 (mid-span,
40 % of the 0.625 in diameter) that breathes under the shaft's weight.

The thesis's own "cracked" model is a different thing: its cracked station
table (density and disk mass tuned by hand to the cracked sweep, no crack
element), available as :func:`thesis_cracked_table_rotor`.
"""
from __future__ import annotations

import os

from ..rotor import data_path, load_model, loads_model
from ..rotor.crack import RIG_CRACK_DEPTH_RATIO, RIG_CRACK_STATION

__all__ = ["healthy_rotor", "cracked_rotor", "thesis_cracked_table_rotor", "EXCITATION", "MEASUREMENT",
           "CONTROL_INPUT", "CONTROL_OUTPUT", "SPEED_HZ", "THESIS"]

#: Ports of the sweep and of the controller at the crack station (thesis fig. 4.8).
EXCITATION, MEASUREMENT = "i12", "x13"
CONTROL_INPUT, CONTROL_OUTPUT = f"F{RIG_CRACK_STATION}", f"x{RIG_CRACK_STATION}"
#: Running speed of the sweeps [Hz].
SPEED_HZ = 10.0
#: What the thesis reports for its chapter-4 identification (sec. 4.5).
THESIS = {"mu": 0.9576, "Wz": 1.1e-6, "K_resonances_hz": (162.0, 205.0), "Ww": 0.1}


def healthy_rotor():
    """The healthy rotor at 10 Hz (``mutext/data/rotor.toml``)."""
    return load_model(data_path("rotor.toml"))


def cracked_rotor(depth_ratio: float = RIG_CRACK_DEPTH_RATIO, *, breathing: str | None = "mayes",
                  station: int = RIG_CRACK_STATION, orientation: float = 0.0, model_path=None):
    """The healthy rotor with a crack element (default: the rig's, breathing by the Mayes law).

    ``breathing=None`` gives an open crack facing ``orientation`` (time-invariant).

    Parameters
    ----------
    depth_ratio : float, optional
        Crack depth over shaft diameter, a/D.
    breathing : str or None, optional
        Breathing law (``"mayes"``, ``"gasch"``, ``"gaping"``); None: an open crack at a fixed angle.
    station : int, optional
        Station where the cracked shaft element starts (1-based, the thesis's numbering).
    orientation : float, optional
        Angle [rad] of the open crack's normal from x (``breathing=None`` only).
    model_path : str or path-like, optional
        The healthy rotor's model file (default: ``mutext/data/rotor.toml``).
    """
    extra = f"\n[[crack]]\nstation = {int(station)}\ndepth_ratio = {float(depth_ratio)!r}\n" \
            f"orientation = {float(orientation)!r}\n"
    if breathing is not None:
        extra += f"breathing = {breathing!r}\n"
    path = os.fspath(model_path) if model_path is not None else data_path("rotor.toml")
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return loads_model(text + extra, source=f"{path} + crack at station {station}",
                       base_dir=os.path.dirname(os.path.abspath(path)))


def thesis_cracked_table_rotor():
    """The thesis's cracked model: its cracked station table (density 0.29 lb/in^3, disk 5.21 lb)."""
    return load_model(data_path("rotor.toml"), station_table=data_path("rotor_cracked.txt"))
