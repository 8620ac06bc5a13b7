r"""Where an identification starts, by either route: the true system (a measured FRF replaced
by its rational fit), the search grid, the shape of the error bound, the floor of :math:`W_z`
and the first :math:`W_z` (:func:`_start`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..response import FRF
from ._floor import WzFloor, spread_weight, wz_floor
from ._measured import _true_from_measured
from ._plant import MBIPlant, mbi_plant
from ._search import _first_wz, _open_loop_difference, _search_grid


@dataclass
class _Start:
    """Where the W_z search starts: the true system (a measured FRF's stand-in), the keyword
    arguments of :func:`mbi_plant` but ``Wz``, the grid, the shape of the bound, the floor,
    the first W_z and the notes so far."""
    true: object
    engineering: object
    kw: dict
    omega: np.ndarray
    shape: object
    floor: WzFloor
    Wz: float
    notes: list
    measured: object = None
    measured_fit: object = None

    def plant_at(self, Wz: float) -> MBIPlant:
        """The identification plant with the error bound ``Wz``."""
        return mbi_plant(self.true, self.engineering, Wz=Wz, **self.kw)


def _start(true, engineering, kw: dict, omega, Wz, weight: str, max_fit_residual, say) -> _Start:
    """The search's grid, shape, floor and first W_z, from the true system (fitted first if measured)."""
    excitation, measurement, Ww = kw["excitation"], kw["measurement"], kw["Ww"]
    measured, measured_fit = None, None
    if isinstance(true, FRF):
        measured = true
        true, measured_fit, omega = _true_from_measured(measured, engineering, omega, excitation, measurement,
                                                        max_fit_residual, say)
    probe = mbi_plant(true, engineering, Wz=1.0, **kw)
    omega = _search_grid(probe, omega)
    diff = _open_loop_difference(probe, omega, excitation, measurement, Ww)
    shape = None
    if weight == "spread":
        shape = spread_weight(true, excitation=excitation, measurement=measurement, omega=omega)
        say(f"error bound shaped by the spread of the true systems ({shape.order} poles; the cover is at most "
            f"{np.exp(shape.error):.2f} times the spread)")
    floor = wz_floor(true, excitation=excitation, measurement=measurement, Ww=Ww, omega=omega, shape=shape)
    Wz, notes = _first_wz(Wz, diff, floor)
    if shape is not None:
        S = np.abs(shape(omega))
        notes.append(f"error bound shaped by the spread of the true systems: W_z |S(jw)|, |S| from "
                     f"{S.min():.3g} to {S.max():.3g} on the grid "
                     f"(a cover of the spread, at most {np.exp(shape.error):.2f} times it)")
    if floor.value > 0:
        say(f"W_z floor {floor.value:.4g} (spread of {floor.samples} true systems at {floor.omega:.4g} rad/s)")
    return _Start(true, engineering, {**kw, "Wz_shape": shape}, omega, shape, floor, Wz, notes, measured,
                  measured_fit)
