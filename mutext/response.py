r"""Frequency responses: one type for measured and modelled channels, and the sweep grid.

:class:`FRF` is one input-output channel in SI units with what identifies it
in a model -- stations, directions, port names, quantities, running speed --
so that a measured file (:func:`mutext.rig.read_frf`), a virtual measurement
(:func:`mutext.rig.measure`) and a model's response
(:meth:`FRFMatrix.channel`) are the same kind of object and can be compared,
fitted (:func:`mutext.rotor.tuning.tune`), identified from
(:func:`mutext.mbi.identify`) and diagnosed (:func:`mutext.diagnose.diagnose`)
alike.  :class:`FRFMatrix` is a model's responses between named ports
(:func:`mutext.rotor.analysis.frf`).  Frequencies are in Hz (``omega`` gives
rad/s).

Examples
--------
>>> import numpy as np
>>> from mutext.response import FRF
>>> w0 = 2 * np.pi * 3.0                              # a 3 Hz oscillator, 1 kg
>>> f = np.array([1.0, 2.0, 3.0])
>>> h = FRF(f, 1 / (w0**2 - (2 * np.pi * f)**2 + 0.1j * 2 * np.pi * f), input_station=1, output_station=1,
...         input_name="f1", output_name="x1")
>>> h.label, h.unit
('f1->x1', 'm/N')
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .errors import ModelError

__all__ = ["FRF", "FRFMatrix", "sweep_frequencies", "local_extrema", "INPUT_UNITS", "OUTPUT_UNITS",
           "DIRECTIONS"]

#: Allowed input quantities and their unit (the SI unit; factor to SI is 1).
INPUT_UNITS: dict[str, dict[str, float]] = {"force": {"N": 1.0}, "current": {"A": 1.0}}

#: Allowed output quantities and units, with the factor that converts to metres.
OUTPUT_UNITS: dict[str, dict[str, float]] = {
    "displacement": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "in": 0.0254},
}

#: Directions of a force or a sensor in the plane of a rotor.
DIRECTIONS = ("x", "y")


@dataclass
class FRF:
    r"""One measured or simulated frequency-response channel, in SI units.

    Attributes
    ----------
    freq_hz : ndarray, shape (n,)
        Frequencies [Hz], positive and strictly increasing.
    response : ndarray of complex, shape (n,)
        :math:`G(j\omega)` in m/N (force input) or m/A (current input).
    input_station, output_station : int or None
        Station numbers (as in the rotor station table; masses 1..n of a
        lumped chain).  Required to write a file.
    input_quantity : {"force", "current"}
    output_quantity : {"displacement"}
    speed_hz : float or None
        Running speed during the measurement [Hz].
    metadata : dict of str -> str
        Any other header entries.
    source : pathlib.Path or None
        File the FRF was read from.
    input_direction, output_direction : {"x", "y"}
        Direction of the force (or exciter) and of the sensor in the plane of a
        rotor (``x`` also for a lumped chain).  For compatibility, metadata
        entries ``input_direction`` / ``output_direction`` set them.
    input_name, output_name : str or None
        Port names of the model (``"i12"``, ``"x13"``), when known.
    """
    freq_hz: np.ndarray
    response: np.ndarray
    input_station: int | None = None
    output_station: int | None = None
    input_quantity: str = "force"
    output_quantity: str = "displacement"
    speed_hz: float | None = None
    metadata: dict = field(default_factory=dict)
    source: Path | None = None
    input_direction: str = "x"
    output_direction: str = "x"
    input_name: str | None = None
    output_name: str | None = None

    def __post_init__(self):
        for which in ("input", "output"):
            key = f"{which}_direction"
            if key in self.metadata:            # older files and callers kept it as metadata
                setattr(self, key, str(self.metadata.pop(key)))
            if getattr(self, key) not in DIRECTIONS:
                raise ModelError(f"FRF: {key} must be one of {DIRECTIONS}, got {getattr(self, key)!r}")
        self.freq_hz = np.asarray(self.freq_hz, dtype=float).ravel()
        self.response = np.asarray(self.response, dtype=complex).ravel()
        if self.freq_hz.shape != self.response.shape:
            raise ModelError(f"FRF: {self.freq_hz.size} frequencies but {self.response.size} "
                             f"response values")
        if self.freq_hz.size == 0:
            raise ModelError("FRF: no frequencies")
        if not np.all(np.isfinite(self.freq_hz)) or np.any(self.freq_hz <= 0):
            raise ModelError("FRF: frequencies must be finite and positive [Hz]")
        if np.any(np.diff(self.freq_hz) <= 0):
            k = int(np.argmax(np.diff(self.freq_hz) <= 0))
            raise ModelError(f"FRF: frequencies must be strictly increasing; "
                             f"{self.freq_hz[k + 1]} Hz follows {self.freq_hz[k]} Hz")
        if not np.all(np.isfinite(self.response)):
            k = int(np.argmax(~np.isfinite(self.response)))
            raise ModelError(f"FRF: non-finite response at {self.freq_hz[k]} Hz")
        if self.input_quantity not in INPUT_UNITS:
            raise ModelError(f"FRF: input_quantity must be one of {sorted(INPUT_UNITS)}, "
                             f"got {self.input_quantity!r}")
        if self.output_quantity not in OUTPUT_UNITS:
            raise ModelError(f"FRF: output_quantity must be one of {sorted(OUTPUT_UNITS)}, "
                             f"got {self.output_quantity!r}")

    @property
    def omega(self) -> np.ndarray:
        """Frequencies in rad/s."""
        return 2.0 * np.pi * self.freq_hz

    @property
    def input_unit(self) -> str:
        """SI unit of the input (``N`` or ``A``)."""
        return next(iter(INPUT_UNITS[self.input_quantity]))

    @property
    def output_unit(self) -> str:
        """SI unit of the output (``m``)."""
        return "m"

    @property
    def unit(self) -> str:
        """Unit of :attr:`response`, e.g. ``m/A``."""
        return f"{self.output_unit}/{self.input_unit}"

    def response_in(self, output_unit: str) -> np.ndarray:
        """The response expressed in ``output_unit`` per SI input unit (e.g. ``um`` -> um/A)."""
        units = OUTPUT_UNITS[self.output_quantity]
        if output_unit not in units:
            raise ModelError(f"unknown {self.output_quantity} unit {output_unit!r}; "
                             f"allowed: {', '.join(units)}")
        return self.response / units[output_unit]

    def band(self, fmin: float, fmax: float) -> "FRF":
        """The part of the FRF with ``fmin <= f <= fmax`` [Hz] (e.g. the 20-225 Hz analysis band)."""
        keep = (self.freq_hz >= fmin) & (self.freq_hz <= fmax)
        if not np.any(keep):
            raise ModelError(f"FRF has no frequency in [{fmin}, {fmax}] Hz "
                             f"(it covers {self.freq_hz[0]}-{self.freq_hz[-1]} Hz)")
        return replace(self, freq_hz=self.freq_hz[keep], response=self.response[keep],
                       metadata=dict(self.metadata))

    @property
    def label(self) -> str:
        """``input -> output`` by port names where known, else by stations and directions."""
        i = self.input_name or f"{'I' if self.input_quantity == 'current' else 'F'}{self.input_station}" \
            + ("y" if self.input_direction == "y" else "")
        o = self.output_name or f"{self.output_direction}{self.output_station}"
        return f"{i}->{o}"


@dataclass
class FRFMatrix:
    """A model's frequency responses ``H[i, j, k]``: output ``i`` per unit input ``j`` at ``freqs_hz[k]``.

    Units: output unit (m or rad) per input unit (N, N m or A).  ``ports``
    maps port names to ``(station, direction, quantity)`` (quantity
    ``"force"``, ``"current"``, ``"displacement"``, or ``None`` for moments
    and rotations), so that :meth:`channel` returns a :class:`FRF` that
    knows where it was taken.
    """
    freqs_hz: np.ndarray
    H: np.ndarray
    inputs: list
    outputs: list
    speed: float
    ports: dict = field(default_factory=dict)

    def __call__(self, output: str, input: str) -> np.ndarray:
        """The response from ``input`` to ``output`` (complex, one per frequency)."""
        try:
            return self.H[self.outputs.index(output), self.inputs.index(input)]
        except ValueError:
            raise ModelError(f"FRF has inputs {self.inputs} and outputs {self.outputs}; "
                             f"asked for {input} -> {output}") from None

    def channel(self, output: str, input: str) -> FRF:
        """One channel as a :class:`FRF` (stations, directions, names, quantities and speed set)."""
        H = self(output, input)
        si, di, qi = self.ports.get(input, (None, "x", "force"))
        so, do, qo = self.ports.get(output, (None, "x", "displacement"))
        if qi not in INPUT_UNITS or qo not in OUTPUT_UNITS:
            raise ModelError(f"channel {input} -> {output}: only force/current inputs and displacement "
                             f"outputs make an FRF channel (got {qi} -> {qo})")
        return FRF(self.freqs_hz, H, input_station=si, output_station=so, input_quantity=qi,
                   output_quantity=qo, speed_hz=self.speed / (2 * math.pi) if self.speed else None,
                   input_direction=di, output_direction=do, input_name=input, output_name=output)

    def channels(self) -> list:
        """Every force/current -> displacement channel as a :class:`FRF`, outputs first."""
        out = []
        for o in self.outputs:
            for i in self.inputs:
                if self.ports.get(i, (None, "x", "force"))[2] in INPUT_UNITS and \
                        self.ports.get(o, (None, "x", "displacement"))[2] in OUTPUT_UNITS:
                    out.append(self.channel(o, i))
        return out


def local_extrema(freq_hz, magnitude):
    """Frequencies of the local maxima and minima of a sampled magnitude (peaks and notches as
    sampled, ends excluded): ``(maxima, minima)``."""
    f, mag = np.asarray(freq_hz), np.asarray(magnitude)
    i = np.arange(1, mag.size - 1)
    mx = i[(mag[i] > mag[i - 1]) & (mag[i] >= mag[i + 1])]
    mn = i[(mag[i] < mag[i - 1]) & (mag[i] <= mag[i + 1])]
    return f[mx], f[mn]


def sweep_frequencies(start: float = 20.0, stop: float = 225.0, step: float = 0.5) -> np.ndarray:
    """Linear sine-sweep frequencies [Hz]: ``start, start+step, ...`` up to ``stop`` inclusive.

    The defaults give the thesis analysis band (20-225 Hz in 0.5 Hz steps,
    411 points); ``sweep_frequencies(*THESIS_SWEEP_HZ)`` the full 20-1000 Hz
    sweep.  The grid is computed as ``start + k*step`` (no accumulated
    rounding) and rounded to 12 significant digits of the largest frequency,
    so that a decimal grid is written as decimals (``0.3``, not the
    ``0.30000000000000004`` of ``0.2 + 5 * 0.02``); ``stop`` is included
    when it lies on the grid to 1e-9 steps.
    """
    start, stop, step = float(start), float(stop), float(step)
    if not (math.isfinite(start) and math.isfinite(stop) and math.isfinite(step)):
        raise ModelError("sweep_frequencies: start, stop and step must be finite")
    if start <= 0 or step <= 0 or stop < start:
        raise ModelError(f"sweep_frequencies: need 0 < start <= stop and step > 0 [Hz], got "
                         f"start={start}, stop={stop}, step={step}")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    f = start + step * np.arange(n)
    return np.round(f, max(0, 11 - int(math.floor(math.log10(f[-1])))))
