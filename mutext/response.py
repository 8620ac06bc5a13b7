r"""Frequency responses: one type for measured and modelled channels, and the frequency grids.

:class:`FRF` is one input-output channel in SI units with what identifies it
in a model -- stations, directions, port names, quantities, running speed --
so that a measured file (:func:`mutext.rig.read_frf`), a virtual measurement
(:func:`mutext.rig.measure`) and a model's response
(:meth:`FRFMatrix.channel`) are the same kind of object and can be compared,
fitted (:func:`mutext.rotor.tuning.tune`), identified from
(:func:`mutext.mbi.identify`) and diagnosed (:func:`mutext.diagnose.diagnose`)
alike.  :class:`FRFMatrix` is a model's responses between named ports
(:func:`mutext.rotor.analysis.frf`).  Frequencies are in Hz (``omega`` gives
rad/s).  :func:`frequency_grid` builds the frequency grids of the package
(a band, densified at resonances or kept clear of them), :func:`sweep_frequencies`
a sine sweep's; :class:`FRFFileError` is what a malformed FRF file raises.

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

from ._validation import Integer, Options, Real, validate_params
from .errors import ModelError

__all__ = ["FRF", "FRFFileError", "FRFMatrix", "sweep_frequencies", "frequency_grid", "resonance_points",
           "local_extrema", "INPUT_UNITS", "OUTPUT_UNITS", "DIRECTIONS"]

#: Allowed input quantities and their unit (the SI unit; factor to SI is 1).
INPUT_UNITS: dict[str, dict[str, float]] = {"force": {"N": 1.0}, "current": {"A": 1.0}}

#: Allowed output quantities and units, with the factor that converts to metres.
OUTPUT_UNITS: dict[str, dict[str, float]] = {
    "displacement": {"m": 1.0, "mm": 1e-3, "um": 1e-6, "in": 0.0254},
}

#: Directions of a force or a sensor in the plane of a rotor.
DIRECTIONS = ("x", "y")


class FRFFileError(ModelError):
    """A malformed FRF file; the message names the file, the line and the field.

    Parameters
    ----------
    path : str
        The file.
    line : int or None
        1-based line number, or None for whole-file problems.
    field : str or None
        Header key or column concerned.
    problem : str
        What is wrong, in words (the end of the message).
    dataset : int or None, optional
        For a Universal File: the 1-based position of the data set.

    Attributes
    ----------
    path : str
    line : int or None
        1-based line number, or None for whole-file problems.
    field : str or None
        Header key or CSV column concerned (for a Universal File: the data set
        58 field, e.g. ``ord_data_type``, ``rsp_dir``).
    dataset : int or None
        For a Universal File (:mod:`mutext.uff`): the 1-based position of the
        data set in the file, or None for whole-file problems.
    """

    def __init__(self, path, line, field, problem, *, dataset=None):
        self.path = str(path)
        self.line = line
        self.field = field
        self.problem = problem
        self.dataset = dataset
        where = self.path if line is None else f"{self.path}, line {line}"
        if dataset is not None:
            where += f", data set {dataset}"
        what = f" [{field}]" if field else ""
        super().__init__(f"{where}{what}: {problem}")


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
    metadata : dict
        Any other header entries (str -> str).  The file readers add
        ``notes`` (a list of str: what the reader did that the user should
        know, e.g. a 0 Hz line dropped) and ``conversion`` (a str: how the
        file's values became m/N or m/A), see :mod:`mutext.rig`.
    source : pathlib.Path or None
        File the FRF was read from.
    input_direction, output_direction : {"x", "y"}
        Direction of the force (or exciter) and of the sensor in the plane of a
        rotor (``x`` also for a lumped chain).  For compatibility, metadata
        entries ``input_direction`` / ``output_direction`` set them.
    input_name, output_name : str or None
        Port names of the model (``"i12"``, ``"x13"``), when known.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.response import FRF
    >>> h = FRF(np.array([10.0, 20.0]), np.array([1e-3, 2e-3 + 1e-3j]), input_station=1, output_station=3)
    >>> h.label, h.unit
    ('F1->x3', 'm/N')
    >>> h.band(15.0, 25.0).freq_hz
    array([20.])
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
        """The response expressed in ``output_unit`` per SI input unit (e.g. ``um`` -> um/A).

        Parameters
        ----------
        output_unit : str
            A unit of the FRF's output quantity, e.g. ``"m"``, ``"mm"``, ``"um"`` for a displacement.
        """
        units = OUTPUT_UNITS[self.output_quantity]
        if output_unit not in units:
            raise ModelError(f"unknown {self.output_quantity} unit {output_unit!r}; "
                             f"allowed: {', '.join(units)}")
        return self.response / units[output_unit]

    def band(self, fmin: float, fmax: float) -> "FRF":
        """The part of the FRF with ``fmin <= f <= fmax`` [Hz] (e.g. the 20-225 Hz analysis band).

        Parameters
        ----------
        fmin, fmax : float
            The band's edges in Hz (inclusive).
        """
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

    Attributes
    ----------
    freqs_hz : (N,) ndarray
        Frequencies in Hz.
    H : (n_outputs, n_inputs, N) complex ndarray
        The responses, output unit per input unit.
    inputs, outputs : list of str
        Port names of the columns and rows of ``H``.
    speed : float
        Rotor speed in rad/s at which the responses were computed (0 for a standing rotor).
    ports : dict
        Port name -> ``(station, direction, quantity)``.
    """
    freqs_hz: np.ndarray
    H: np.ndarray
    inputs: list
    outputs: list
    speed: float
    ports: dict = field(default_factory=dict)

    def __call__(self, out_port: str, in_port: str) -> np.ndarray:
        """The response from ``in_port`` to ``out_port`` (complex, one per frequency)."""
        try:
            return self.H[self.outputs.index(out_port), self.inputs.index(in_port)]
        except ValueError:
            raise ModelError(f"FRF has inputs {self.inputs} and outputs {self.outputs}; "
                             f"asked for {in_port} -> {out_port}") from None

    def channel(self, out_port: str, in_port: str) -> FRF:
        """One channel as a :class:`FRF` (stations, directions, names, quantities and speed set).

        Parameters
        ----------
        out_port : str
            Name of the output port (a row of ``H``).
        in_port : str
            Name of the input port (a column of ``H``).
        """
        H = self(out_port, in_port)
        si, di, qi = self.ports.get(in_port, (None, "x", "force"))
        so, do, qo = self.ports.get(out_port, (None, "x", "displacement"))
        if qi not in INPUT_UNITS or qo not in OUTPUT_UNITS:
            raise ModelError(f"channel {in_port} -> {out_port}: only force/current inputs and displacement "
                             f"outputs make an FRF channel (got {qi} -> {qo})")
        return FRF(self.freqs_hz, H, input_station=si, output_station=so, input_quantity=qi,
                   output_quantity=qo, speed_hz=self.speed / (2 * math.pi) if self.speed else None,
                   input_direction=di, output_direction=do, input_name=in_port, output_name=out_port)

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
    sampled, ends excluded): ``(maxima, minima)``.

    Parameters
    ----------
    freq_hz : (N,) array_like
        Frequencies in Hz.
    magnitude : (N,) array_like
        The magnitude at each frequency (any unit; dB works as well).

    Examples
    --------
    >>> from mutext.response import local_extrema
    >>> local_extrema([1, 2, 3, 4, 5], [1.0, 3.0, 2.0, 0.5, 1.0])
    (array([2]), array([4]))
    """
    f, mag = np.asarray(freq_hz), np.asarray(magnitude)
    i = np.arange(1, mag.size - 1)
    mx = i[(mag[i] > mag[i - 1]) & (mag[i] >= mag[i + 1])]
    mn = i[(mag[i] < mag[i - 1]) & (mag[i] <= mag[i + 1])]
    return f[mx], f[mn]


@validate_params({"start": Real(lo=0, closed="neither"), "stop": Real(lo=0, closed="neither"),
                  "step": Real(lo=0, closed="neither")})
def sweep_frequencies(start: float = 20.0, stop: float = 225.0, step: float = 0.5) -> np.ndarray:
    """Linear sine-sweep frequencies [Hz]: ``start, start+step, ...`` up to ``stop`` inclusive.

    The defaults give the thesis analysis band (20-225 Hz in 0.5 Hz steps,
    411 points); ``sweep_frequencies(*THESIS_SWEEP_HZ)`` the full 20-1000 Hz
    sweep.  The grid is computed as ``start + k*step`` (no accumulated
    rounding) and rounded to 12 significant digits of the largest frequency,
    so that a decimal grid is written as decimals (``0.3``, not the
    ``0.30000000000000004`` of ``0.2 + 5 * 0.02``); ``stop`` is included
    when it lies on the grid to 1e-9 steps.

    Parameters
    ----------
    start : float, optional
        First frequency in Hz (positive).
    stop : float, optional
        Last frequency in Hz (included when it lies on the grid).
    step : float, optional
        Spacing in Hz (positive).

    Examples
    --------
    >>> from mutext.response import sweep_frequencies
    >>> f = sweep_frequencies()            # the thesis analysis band
    >>> f.size, float(f[0]), float(f[-1])
    (411, 20.0, 225.0)
    >>> sweep_frequencies(0.1, 0.3, 0.1)
    array([0.1, 0.2, 0.3])
    """
    start, stop, step = float(start), float(stop), float(step)
    if stop < start:
        raise ModelError(f"sweep_frequencies: need 0 < start <= stop and step > 0 [Hz], got "
                         f"start={start}, stop={stop}, step={step}")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    f = start + step * np.arange(n)
    return np.round(f, max(0, 11 - int(math.floor(math.log10(f[-1])))))


@validate_params({"n": Integer(lo=1), "spacing": Options(("log", "linear", "step")), "avoid": Real(lo=0)})
def frequency_grid(band=None, n: int = 400, *, poles=(), margin=(10.0, 10.0), spacing: str = "log",
                   resonance_offsets=None, avoid: float = 0.0) -> np.ndarray:
    r"""Frequencies at which to evaluate a response: a grid over a band, densified at resonances
    or kept clear of them.

    The package's frequency grids are built here; the unit is the caller's
    (rad/s or Hz), the same for ``band`` and ``poles``.

    Parameters
    ----------
    band : (float, float), optional
        ``(lo, hi)``.  Default: the magnitudes of the nonzero ``poles``,
        ``margin[0]`` times below the smallest and ``margin[1]`` times above
        the largest (``(1e-2, 1e2)`` when there is none).
    n : int
        Number of grid points (for ``spacing="step"``: about that many).
    poles : array_like
        Poles (complex) or natural frequencies (real, non-negative) of the
        system to be sampled.
    margin : (float, float)
        Factors that widen the pole span into the default band (10, 10 = a
        decade each side).
    spacing : {"log", "linear", "step"}
        ``"log"``: ``n`` log-spaced points (a band starting at 0 is sampled
        from ``1e-6 hi`` and 0 is added); ``"linear"``: ``n`` equally spaced
        points; ``"step"``: the multiples of a round step (one significant
        digit of ``(hi - lo) / n``) above ``lo`` up to ``hi``, rounded to 10
        decimals, as a sine-sweep analyser would step.
    resonance_offsets : sequence of float, optional
        Densify at resonances: each oscillating pole :math:`p` adds
        :math:`|\Im p| + k |\Re p|` for each ``k`` (:math:`|\Re p|` is the
        half-power half-width, so ``(-1, 0, 1)`` brackets the peak); an
        undamped pole adds :math:`|\Im p|(1 \pm 10^{-3})` instead, its gain
        being infinite at :math:`|\Im p|`.  Points outside the band are dropped.
    avoid : float
        Drop grid points within this relative distance of any nonzero
        :math:`|p|` (comparing undamped models next to their poles would
        compare rounding errors).

    Returns
    -------
    ndarray
        Sorted, without repeats.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.response import frequency_grid
    >>> frequency_grid((1.0, 100.0), 3)
    array([  1.,  10., 100.])
    >>> p = np.array([-0.1 + 10j, -0.1 - 10j])          # a resonance at 10 rad/s, half-width 0.1
    >>> w = frequency_grid(n=50, poles=p, resonance_offsets=(-1, 0, 1))
    >>> round(float(w[0]), 3), round(float(w[-1]), 2), bool(np.isin([9.9, 10.0, 10.1], w).all())
    (1.0, 100.0, True)
    """
    poles = np.atleast_1d(np.asarray(poles, complex))
    lo, hi = _grid_band(band, poles, margin)
    if spacing == "log":
        # only a band that starts at 0 is cut (six decades below its top): a positive lower end is
        # kept however far down it lies (a weight's poles at 1e-6 rad/s; a grid cut at 1e-2 missed
        # what a controller does below them)
        w = np.logspace(np.log10(lo if lo > 0 else 1e-6 * hi), np.log10(hi), n)
        if lo == 0.0:
            w = np.concatenate([[0.0], w])
    elif spacing == "linear":
        w = np.linspace(lo, hi, n)
    else:                                  # "step"
        step = float(f"{(hi - lo) / n:.1g}")
        lo = math.floor(lo / step) * step
        w = np.round(lo + step * np.arange(1, int((hi - lo) / step) + 1), 10)
    if avoid > 0:
        for m in np.abs(poles[poles != 0]):
            w = w[np.abs(w / m - 1.0) > avoid]
    if resonance_offsets is not None:
        w = np.concatenate([w, resonance_points(poles, resonance_offsets, (lo, hi))])
    return np.unique(w)


def _grid_band(band, poles, margin):
    if band is None:
        mags = np.abs(poles[poles != 0])
        if not mags.size:
            return 1e-2, 1e2
        return float(mags.min() / margin[0]), float(mags.max() * margin[1])
    lo, hi = float(band[0]), float(band[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise ModelError(f"frequency_grid: band must be (lo, hi) with 0 <= lo < hi, got {band!r}")
    return lo, hi


def resonance_points(poles, offsets=(-1.0, 0.0, 1.0), band=None) -> np.ndarray:
    r"""Frequencies that bracket the resonances of ``poles``.

    Each oscillating pole :math:`p` gives :math:`|\Im p| + k |\Re p|` for each
    ``k`` in ``offsets`` (:math:`|\Re p|` is the half-power half-width, so a
    resonance cannot fall between the points of ``(-1, 0, 1)``); an undamped
    pole gives :math:`|\Im p|(1 \pm 10^{-3})` instead, its gain being
    infinite at :math:`|\Im p|`.

    Parameters
    ----------
    poles : array_like
        Poles (complex); real ones add nothing.
    offsets : sequence of float
        Multiples of the half-width either side of each damped resonance.
    band : (float, float), optional
        Keep only the points in ``[lo, hi]`` (default: every point above 0).

    Returns
    -------
    ndarray
        The points, unsorted, possibly repeated.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.response import resonance_points
    >>> resonance_points(np.array([-0.1 + 10j, -0.1 - 10j]), (-1, 0, 1)).round(6)
    array([ 9.9, 10. , 10.1,  9.9, 10. , 10.1])
    """
    poles = np.atleast_1d(np.asarray(poles, complex))
    osc = poles[poles.imag != 0]
    undamped = np.abs(osc.real) <= 1e-12 * np.abs(osc)
    w0 = np.abs(osc.imag[undamped])
    damped = osc[~undamped]
    k = np.asarray(offsets, float)
    w = np.concatenate([(np.abs(damped.imag)[:, None] + np.abs(damped.real)[:, None] * k).ravel(),
                        w0 * (1 - 1e-3), w0 * (1 + 1e-3)])
    lo, hi = (0.0, np.inf) if band is None else (float(band[0]), float(band[1]))
    return w[(w > 0) & (w >= lo) & (w <= hi)]
