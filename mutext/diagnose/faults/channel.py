r"""Effects on the measurement chain: a factor multiplies every channel it acts on.

=================  =============================  ==============================================
kind               factor on a channel            acts on
=================  =============================  ==============================================
``sensor_gain``    :math:`g`                      every channel of one sensor (fitted and held out)
``exciter_gain``   :math:`g`                      every channel of one exciter or force input
``channel_scale``  :math:`g`                      one fitted file only (a unit slip or reversed
                                                  polarity in that file: other files are right)
``sensor_delay``   :math:`e^{-j\omega\tau}`       every channel of one sensor
``sensor_mass``    :math:`1/(1 - m\omega^2 R_{oo})` every channel, at its own output: a mass that
                                                  moves with the sensor (a roving accelerometer)
=================  =============================  ==============================================

A gain may be negative (a reversed polarity: the phase of data over model
near :math:`\pm\pi`).  Sensor and exciter gains range over 0.2-5 in
magnitude (a calibration error); a channel's scale over
:math:`10^{-7}`-:math:`10^{7}` (unit slips: :data:`mutext.diagnose._result.UNIT_SLIPS`).

With the log residual :math:`r = \ln(H/\hat H)`, all four enter linearly and
are fitted in closed form: :math:`\ln|g| = -\overline{\mathrm{Re}\,r_0}` over the
channels hit (both signs tried), :math:`\tau = \sum\omega\,\mathrm{Im}\,r_0/\sum\omega^2`.
"""
from __future__ import annotations

import numpy as np

from ._base import Hypothesis

KINDS = ("sensor_gain", "exciter_gain", "channel_scale", "sensor_delay", "sensor_mass")

#: Magnitude range of a sensor's or exciter's gain, and of a channel's scale.
GAIN_RANGE = (0.2, 5.0)
SCALE_RANGE = (1e-7, 1e7)
#: Range of a sensor's delay [s].
DELAY_RANGE = (-0.01, 0.01)


def is_log_sized(h: Hypothesis) -> bool:
    """Whether the size is a factor (compared in log terms), not a delay or a mass.

    Parameters
    ----------
    h : Hypothesis
        A measurement-chain hypothesis (``h.gain`` set).
    """
    return h.gain is not None and h.gain[0] not in ("delay", "sensor_mass")


def hits(h: Hypothesis, ch) -> bool:
    """Whether the effect acts on channel ``ch``.

    Parameters
    ----------
    h : Hypothesis
        A measurement-chain hypothesis (``h.gain`` set).

    ch : channel
        A resolved measured channel (its ``out_dof``, ``in_spec``, ``frf``).
    """
    what, key = h.gain
    if what == "sensor_mass":
        return True
    if what in ("sensor", "delay"):
        return ch.out_dof == key
    if what == "exciter":
        return ch.in_spec == key
    return ch.frf is key                     # "channel": one file's data


def factor(h: Hypothesis, ch, f_hz, theta: float, Roo=None):
    """The factor on channel ``ch`` at ``f_hz``, and its derivative in ``theta`` (None, None if not hit).

    ``Roo``: the engineering model's direct receptance at the channel's output (a sensor's mass only).

    Parameters
    ----------
    h : Hypothesis
        A measurement-chain hypothesis (``h.gain`` set).

    ch : channel
        A resolved measured channel.
    f_hz : array_like
        Frequencies [Hz].
    theta : float
        Size of the effect (a factor, a delay [s] or a mass [kg]).
    Roo : array_like, optional
        Direct receptance [m/N] of the model at the channel's output (a sensor's mass only).
    """
    if not hits(h, ch):
        return None, None
    if h.gain[0] == "sensor_mass":
        # Z + theta (-w^2) e_o e_o^T: H / (1 - theta w^2 R_oo) (Sherman-Morrison)
        q = (2 * np.pi * np.asarray(f_hz, float)) ** 2 * Roo
        d = 1.0 / (1.0 - theta * q)
        return d, q * d * d
    if h.gain[0] == "delay":
        w = 2 * np.pi * np.asarray(f_hz, float)
        e = np.exp(-1j * w * theta)
        return e, -1j * w * e
    one = np.ones(np.shape(f_hz))
    return theta * one, one


def fit(h: Hypothesis, chans, H0s, meas, freqs):
    """Closed-form size: a list of candidate sizes (the best by the caller's residual).

    Parameters
    ----------
    h : Hypothesis
        A measurement-chain hypothesis (``h.gain`` set).

    chans : sequence of channel
        The resolved measured channels.
    H0s : sequence of complex ndarray
        The engineering model's response per channel.
    meas : sequence of complex ndarray
        The measured response per channel.
    freqs : sequence of ndarray
        Frequencies [Hz] per channel.
    """
    r, w = [], []
    for ch, H0, m, f in zip(chans, H0s, meas, freqs):
        if hits(h, ch):
            r.append(np.log(H0 / m))
            w.append(2 * np.pi * np.asarray(f, float))
    if h.gain[0] == "sensor_mass":
        return None                          # not linear in the log residual: the caller scans
    if not r:
        return [1.0 if is_log_sized(h) else 0.0]
    r, w = np.concatenate(r), np.concatenate(w)
    if h.gain[0] == "delay":
        # the phase of data over model, unwrapped per channel would be better; near 0 it is linear
        tau = float(np.sum(w * r.imag) / np.sum(w * w))
        return [min(max(tau, h.lower), h.upper)]
    g = min(max(float(np.exp(-np.mean(r.real))), h.lower), h.upper)
    return [g, -g]


def candidates(model, channels) -> list[Hypothesis]:
    """Every measurement-chain hypothesis for the measured ``channels``.

    Parameters
    ----------
    model : Structure or Rotor
        The engineering model.
    channels : sequence of channel
        The resolved measured channels.
    """
    out = []
    seen_out, seen_in = set(), set()
    for ch in channels:
        if ch.out_dof not in seen_out:
            seen_out.add(ch.out_dof)
            out.append(Hypothesis("sensor_gain", ch.out_station, ch.out_name, f"gain of sensor {ch.out_name}",
                                  "1", False, GAIN_RANGE[0], GAIN_RANGE[1], 1.0, gain=("sensor", ch.out_dof),
                                  nominal=1.0))
            out.append(Hypothesis("sensor_delay", ch.out_station, ch.out_name, f"delay of sensor {ch.out_name}",
                                  "s", False, DELAY_RANGE[0], DELAY_RANGE[1], 1e-4, gain=("delay", ch.out_dof),
                                  nominal=0.0))
        if ch.in_spec not in seen_in:
            seen_in.add(ch.in_spec)
            what = "exciter" if ch.in_spec[0] == "port" else "force input"
            out.append(Hypothesis("exciter_gain", ch.in_station, ch.in_name, f"gain of {what} {ch.in_name}",
                                  "1", False, GAIN_RANGE[0], GAIN_RANGE[1], 1.0, gain=("exciter", ch.in_spec),
                                  nominal=1.0))
    outs = {ch.out_dof for ch in channels}
    if len(outs) > 1:              # one output: a mass there is the same (mutext.diagnose, point masses)
        M = model.matrices()[0]
        total = float(np.sum(M[0::4, 0::4])) if model.layout.kind == "rotor" else float(np.trace(M))
        out.append(Hypothesis("sensor_mass", None, "sensor", "a mass that moves with the sensor (at each "
                              "channel's output)", "kg", True, 0.0, 0.2 * total, 1e-3 * total,
                              gain=("sensor_mass", None)))
    if len(channels) > 1:          # with one channel a file's scale is the sensor's gain
        for ch in channels:
            src = str(ch.frf.source) if ch.frf.source else ch.label
            out.append(Hypothesis("channel_scale", ch.out_station, ch.label,
                                  f"scale of channel {ch.label} ({src})", "1", False, SCALE_RANGE[0],
                                  SCALE_RANGE[1], 1.0, gain=("channel", ch.frf), nominal=1.0))
    return out
