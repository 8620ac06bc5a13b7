"""What the model gets wrong, before any hypothesis: errors, resonances matched to the model's, a summary."""
from __future__ import annotations

import logging
import math

import numpy as np

from ..errors import ModelError
from ..frfit import resonances
from ._result import ResonanceRow
from .faults._base import model_poles

log = logging.getLogger("mutext.diagnose")

def _errors(Hs, meas) -> dict:
    num = np.concatenate([np.abs(h - m) ** 2 / np.abs(m) ** 2 for h, m in zip(Hs, meas)])
    db = np.concatenate([20 * np.log10(np.abs(h / m)) for h, m in zip(Hs, meas)])
    return {"rel": float(np.sqrt(np.mean(num))), "db": float(np.sqrt(np.mean(db ** 2)))}


def _model_modes(model, speed):
    # undamped natural frequency, as the data's poles
    return model_poles(model, speed)


#: Smallest relative frequency difference the summary calls a mismatch: vector fitting of noisy data is
#: biased by up to about 0.1-0.2 % (beyond its bootstrap standard deviation), so less is not claimed.
FREQ_RESOLUTION = 0.003


def _model_resonances(fm, zm, band):
    """Model resonances inside ``band`` [Hz], modes closer than zeta f merged (e.g. the whirl pair of a
    nearly isotropic rotor, which one sensor sees as one resonance)."""
    out = []
    for k in np.argsort(fm):
        if not band[0] <= fm[k] <= band[1]:
            continue
        if out and fm[k] - out[-1][0][-1] <= max(zm[k], 1e-3) * fm[k]:
            out[-1][0].append(fm[k])
            out[-1][1].append(zm[k])
        else:
            out.append(([fm[k]], [zm[k]]))
    return [(float(np.mean(f)), float(np.mean(z))) for f, z in out]


def _resonance_table(chans, before, model, speed, noise, unmatched: dict | None = None) -> list[ResonanceRow]:
    """Measured resonances matched one to one to the model's (nearest in log frequency, within 50 %).

    ``unmatched``, when given, receives ``"measured"``: the resonances found in the data that no model
    resonance is matched to (reliable ones only: found in most bootstrap refits), and ``"model"``: the
    model's resonances outside the measured band."""
    from scipy.optimize import linear_sum_assignment
    rows = []
    try:
        fm, zm = _model_modes(model, speed)
    except Exception as exc:  # pragma: no cover
        log.debug("model modes failed: %s", exc)
        return rows
    if unmatched is not None:
        lo = min(c.frf.freq_hz[0] for c in chans)
        hi = max(c.frf.freq_hz[-1] for c in chans)
        unmatched["model"] = [float(f) for f, _ in _model_resonances(fm, zm, (0.0, np.inf)) if not lo <= f <= hi]
        unmatched["measured"] = []
    for ch, Hb in zip(chans, before):
        f = ch.frf.freq_hz
        try:
            # the mobility j w H has the receptance's poles without its rise towards 0 Hz (rigid-body
            # motion, a soft support), which a fit of the receptance can mistake for low resonances
            res = resonances(f, 2j * np.pi * f * ch.frf.response, noise=noise)
        except ModelError as exc:
            log.debug("no resonances for %s: %s", ch.label, exc)
            continue
        mods = _model_resonances(fm, zm, (f[0], f[-1]))
        matched = set()
        if res and mods:
            cost = np.abs(np.log(np.array([r.freq_hz for r in res])[:, None] / np.array([m[0] for m in mods])[None]))
            pairs = [(i, j) for i, j in zip(*linear_sum_assignment(cost)) if cost[i, j] <= math.log(1.5)]
        else:
            pairs = []
        if unmatched is not None:
            matched = {i for i, _ in pairs}
            unmatched["measured"] += [{"channel": ch.label, "freq_hz": r.freq_hz, "freq_std": r.freq_std,
                                       "damping_ratio": r.damping_ratio}
                                      for i, r in enumerate(res) if i not in matched and math.isfinite(r.freq_std)]
        for i, j in pairs:
            r, (fmod, zmod) = res[i], mods[j]
            peak_model = float(np.interp(fmod, f, np.abs(Hb)))
            peak = float(np.interp(r.freq_hz, f, np.abs(ch.frf.response)))      # of the receptance
            rows.append(ResonanceRow(ch.label, r.freq_hz, r.freq_std, fmod, r.damping_ratio, r.damping_std, zmod,
                                     peak, peak_model))
    return rows


def _ordinal(k: int) -> str:
    return {1: "first", 2: "second", 3: "third", 4: "fourth", 5: "fifth"}.get(k, f"{k}th")


def _summary(rows: list[ResonanceRow], chans, before) -> list[str]:
    out = []
    by_mode: dict[float, list] = {}
    for r in rows:
        if not math.isfinite(r.measured_hz_std):     # not found in most bootstrap refits: not reliable
            continue
        by_mode.setdefault(round(r.model_hz, 6), []).append(r)
    for k, (fmod, rs) in enumerate(sorted(by_mode.items()), start=1):
        r = min(rs, key=lambda x: x.measured_hz_std)
        err = r.freq_error
        sd = r.measured_hz_std / r.measured_hz
        if abs(err) <= max(3 * sd, FREQ_RESOLUTION):
            out.append(f"the model's {_ordinal(k)} resonance ({r.model_hz:.4g} Hz) is right within the "
                       f"measurement's resolution ({100 * err:+.2f} %; resolution "
                       f"{100 * max(3 * sd, FREQ_RESOLUTION):.2g} %)")
        else:
            hl = "high" if err > 0 else "low"
            out.append(f"the model's {_ordinal(k)} resonance ({r.model_hz:.4g} Hz) is {100 * abs(err):.2f} % {hl} "
                       f"(measured {r.measured_hz:.4g} +/- {r.measured_hz_std:.2g} Hz)")
    for ch, Hb in zip(chans, before):
        db = 20 * np.log10(np.abs(Hb / ch.frf.response))
        k = int(np.argmax(np.abs(db)))
        out.append(f"{ch.label}: rms error {np.sqrt(np.mean(db ** 2)):.3g} dB, largest {db[k]:+.3g} dB at "
                   f"{ch.frf.freq_hz[k]:.4g} Hz")
    return out
