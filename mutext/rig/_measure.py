"""The virtual rig: a sine-sweep measurement of one channel of a model (:func:`measure`), with noise
(:func:`with_noise`), on the thesis's sweep."""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from ..errors import ModelError
from ..response import FRF, sweep_frequencies
from ._noise import _active, _as_noise, _generator, _noisy

#: Thesis sine sweep: start, stop, step [Hz] ([Mad]_ sec. 4.3).
THESIS_SWEEP_HZ = (20.0, 1000.0, 0.5)
#: Band kept for the identification (noise above 225 Hz).
THESIS_ANALYSIS_BAND_HZ = (20.0, 225.0)
#: Exciter current amplitude of the sweeps [A].
THESIS_EXCITATION_A = 0.1
#: Running speed during the sweeps [Hz].
THESIS_SPEED_HZ = 10.0


def _port_index(spec, labels: Sequence[str], n: int, what: str) -> int:
    if isinstance(spec, (int, np.integer)):
        if not 0 <= spec < n:
            raise ModelError(f"measure: {what} index {spec} is outside 0..{n - 1}")
        return int(spec)
    if isinstance(spec, str):
        if spec not in labels:
            raise ModelError(f"measure: the system has no {what} named {spec!r}; "
                             f"{what}s are {list(labels)}")
        return list(labels).index(spec)
    raise ModelError(f"measure: {what} must be an index or a name, got {spec!r}")


def _response(system, in_port, out_port, omega) -> np.ndarray:
    """Frequency response of one channel at omega [rad/s]."""
    import control as ct

    if isinstance(system, (ct.StateSpace, ct.TransferFunction)) or (
            isinstance(system, tuple) and len(system) == 4):
        from ..lti import as_ss, freqresp
        sys = as_ss(system, "measure: system")
        i = _port_index(in_port, sys.input_labels, sys.ninputs, "input")
        o = _port_index(out_port, sys.output_labels, sys.noutputs, "output")
        return freqresp(sys, omega)[o, i, :]
    if callable(system):
        G = np.asarray(system(omega), dtype=complex)
        if G.shape == omega.shape:
            if in_port not in (0, None) or out_port not in (0, None):
                raise ModelError("measure: a callable returning one channel takes in_port=0, out_port=0")
            return G
        if G.ndim == 3 and G.shape[2] == omega.size:
            i = _port_index(in_port, [], G.shape[1], "input")
            o = _port_index(out_port, [], G.shape[0], "output")
            return G[o, i, :]
        raise ModelError(f"measure: the callable returned shape {G.shape}; expected "
                         f"({omega.size},) or (noutputs, ninputs, {omega.size})")
    if hasattr(system, "frequency_response"):      # other python-control LTI objects (FRD, ...)
        G = np.asarray(system.frequency_response(omega, squeeze=False).fresp, dtype=complex)
        i = _port_index(in_port, getattr(system, "input_labels", []), G.shape[1], "input")
        o = _port_index(out_port, getattr(system, "output_labels", []), G.shape[0], "output")
        return G[o, i, :]
    raise ModelError(f"measure: cannot compute a frequency response of a {type(system).__name__}; "
                     f"pass a control.StateSpace/TransferFunction, an (A, B, C, D) tuple or a "
                     f"callable omega[rad/s] -> response")


def measure(system, in_port=0, out_port=0, freq_hz=None, *, noise=None, rng=None,
            input_station: int | None = None, output_station: int | None = None,
            input_quantity: str = "force", output_quantity: str = "displacement",
            speed_hz: float | None = None, metadata: Mapping[str, str] | None = None,
            input_direction: str = "x", output_direction: str = "x") -> FRF:
    r"""Virtual sine-sweep measurement of one channel of a model.

    Parameters
    ----------
    system : control.StateSpace, control.TransferFunction, (A, B, C, D) or callable
        The "rig".  Its response must be in SI units (m/N or m/A).  A callable
        maps angular frequencies [rad/s] to the response, either of shape
        ``(n,)`` (one channel) or ``(noutputs, ninputs, n)``.
    in_port, out_port : int or str
        Channel: index or name (``input_labels`` / ``output_labels``).
    freq_hz : array_like, optional
        Frequencies [Hz]; default :func:`sweep_frequencies` (20-225 Hz,
        0.5 Hz steps, as the truncated thesis sweeps).
    noise : None, float, (relative, floor) or Noise
        Measurement noise (see :class:`Noise`); ``None`` or 0 for exact data.
    rng : numpy.random.Generator or int, optional
        Random generator or seed (for reproducible noise).
    input_station, output_station : int, optional
        Station numbers stored in the FRF (needed to write it to a file).
    input_quantity : {"force", "current"}
    output_quantity : {"displacement"}
    speed_hz : float, optional
        Running speed stored in the FRF [Hz].
    input_direction, output_direction : {"x", "y"}
        Directions stored in the FRF (the plane of a rotor).
    metadata : mapping, optional
        Extra metadata; ``noise_relative`` and ``noise_floor`` are added when
        noise is applied.

    Returns
    -------
    FRF
    """
    f = sweep_frequencies() if freq_hz is None else np.asarray(freq_hz, dtype=float).ravel()
    omega = 2.0 * np.pi * f
    G = _response(system, in_port, out_port, omega)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    nz = _as_noise(noise)
    if _active(nz):
        G = _noisy(G, nz.relative * np.abs(G) + nz.floor, _generator(rng))
        meta["noise_relative"] = repr(nz.relative)
        meta["noise_floor"] = repr(nz.floor)
    names = {}
    if isinstance(in_port, str):
        names["input_name"] = in_port
    if isinstance(out_port, str):
        names["output_name"] = out_port
    return FRF(freq_hz=f, response=G, input_station=input_station, output_station=output_station,
               input_quantity=input_quantity, output_quantity=output_quantity, speed_hz=speed_hz,
               metadata=meta, input_direction=input_direction, output_direction=output_direction, **names)


def with_noise(frf: FRF, noise=None, *, rng=None) -> FRF:
    """A copy of ``frf`` measured with ``noise`` (as in :func:`measure`: same generator, same
    metadata entries); stations, quantities, directions, names and speed are kept.

    Parameters
    ----------
    frf : FRF
        The exact response.
    noise : None, float, (relative, floor) or Noise
        As in :func:`measure`.
    rng : numpy.random.Generator or int, optional
        Random generator or seed.

    Returns
    -------
    FRF
    """
    out = measure(lambda w: frf.response, 0, 0, frf.freq_hz, noise=noise, rng=rng,
                  input_station=frf.input_station, output_station=frf.output_station,
                  input_quantity=frf.input_quantity, output_quantity=frf.output_quantity,
                  speed_hz=frf.speed_hz, metadata=frf.metadata, input_direction=frf.input_direction,
                  output_direction=frf.output_direction)
    out.input_name, out.output_name = frf.input_name, frf.output_name
    return out
