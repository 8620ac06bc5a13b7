"""What a diagnosis returns: findings, the resonance comparison, the channels, the report."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._hypotheses import Hypothesis

@dataclass
class Finding:
    """One tested hypothesis with its fitted size and score.

    ``value`` is the size: the change of an existing value or the value of an
    added element (SI), the depth ratio of a crack, or the factor of a gain.
    ``std`` its standard uncertainty; ``score`` the information criterion
    (lower is better); ``delta_chi2`` the improvement over *none*;
    ``significant`` whether it passes the false-alarm test.
    """
    kind: str
    station: int | None
    element: str | None
    value: float
    unit: str
    std: float
    score: float
    delta_chi2: float
    description: str
    significant: bool = False
    refit: bool = False
    new_value: float | None = None
    hypothesis: Hypothesis | None = field(default=None, repr=False)

    def as_dict(self) -> dict:
        return {"kind": self.kind, "station": self.station, "element": self.element, "value": self.value,
                "unit": self.unit, "std": self.std, "score": self.score, "delta_chi2": self.delta_chi2,
                "description": self.description, "significant": self.significant, "refit": self.refit,
                "new_value": self.new_value}

    def sentence(self) -> str:
        if self.kind == "none":
            return "no effect beyond the noise"
        if self.unit == "1" and self.kind.endswith("gain"):
            return f"{self.description}: x{self.value:.4g} +/- {self.std:.2g}"
        if self.kind == "crack":
            return f"{self.description}: depth ratio a/D = {self.value:.4g} +/- {self.std:.2g}"
        return f"{self.description}: {self.value:+.4g} +/- {self.std:.2g} {self.unit}"


@dataclass
class ResonanceRow:
    """Measured against modelled resonance of one channel."""
    channel: str
    measured_hz: float
    measured_hz_std: float
    model_hz: float
    measured_damping: float
    measured_damping_std: float
    model_damping: float
    measured_peak: float
    model_peak: float

    @property
    def freq_error(self) -> float:
        """(model - measured) / measured."""
        return (self.model_hz - self.measured_hz) / self.measured_hz

    def as_dict(self) -> dict:
        d = dict(self.__dict__)
        d["freq_error"] = self.freq_error
        return d


@dataclass
class ChannelComparison:
    """Model against data in one channel (SI units)."""
    label: str
    source: str
    freq_hz: np.ndarray
    measured: np.ndarray
    before: np.ndarray
    after: np.ndarray | None = None
    role: str = "fit"            # "fit" or "validate"

    @property
    def residual_db(self) -> np.ndarray:
        """20 log10 |model/measured| before the fix [dB]."""
        return 20 * np.log10(np.abs(self.before / self.measured))

    @property
    def residual_deg(self) -> np.ndarray:
        return np.degrees(np.angle(self.before / self.measured))


@dataclass
class Diagnosis:
    """Result of :func:`diagnose` (see its docstring); ``as_dict()`` is the ``--json`` object."""
    model_name: str
    model_source: str | None
    noise: float
    findings: list
    verdict: Finding
    ambiguous_with: list
    separating_sensor: int | None
    error_before: dict
    error_after: dict
    gain: float
    held_out: str
    channels: list
    resonances: list
    summary: list
    threshold: float
    alpha: float
    n_hypotheses: int
    extended_model_text: str | None
    seconds: float
    notes: list = field(default_factory=list)
    n_residuals: int = 0          # real residuals of the fit (2 per complex point)
    extended_model: str | None = None
    mbi: dict | None = None
    sidebands: dict | None = None   # sideband evidence when the data were taken at speed (rotors)
    breathing: dict | None = None   # a crack that turns with the shaft, fitted when the sidebands call for it

    def as_dict(self) -> dict:
        return {
            "model": self.model_source or self.model_name,
            "findings": [f.as_dict() for f in self.findings],
            "verdict": self.verdict.as_dict(),
            "noise": self.noise,
            "error_before": self.error_before, "error_after": self.error_after, "gain": self.gain,
            "held_out": self.held_out,
            "ambiguous_with": [f.as_dict() for f in self.ambiguous_with],
            "separating_sensor": self.separating_sensor,
            "resonances": [r.as_dict() for r in self.resonances],
            "summary": self.summary,
            "threshold_delta_chi2": self.threshold, "alpha": self.alpha, "n_hypotheses": self.n_hypotheses,
            "n_residuals": self.n_residuals,
            "extended_model": self.extended_model,
            "mbi": self.mbi,
            "sidebands": self.sidebands,
            "breathing": self.breathing,
            "notes": self.notes,
            "seconds": self.seconds,
        }

    def misfit_left(self, finding: Finding) -> float:
        """The misfit after ``finding``, in units of what noise alone leaves (about 1 for the right model)."""
        none = next(f for f in self.findings if f.kind == "none")
        return (none.score - finding.delta_chi2) / max(self.n_residuals, 1)

    def report(self) -> str:
        """Plain-text report (what the command prints)."""
        out = [f"model: {self.model_source or self.model_name}",
               f"noise level estimated from the data: {100 * self.noise:.3g} % (relative, rms)", ""]
        if self.resonances:
            # one row per model resonance: the channel that measures it most precisely
            best: dict = {}
            for r in self.resonances:
                k = round(r.model_hz, 9)
                if not math.isfinite(r.measured_hz_std):
                    continue
                if k not in best or r.measured_hz_std < best[k].measured_hz_std:
                    best[k] = r
            out.append("resonances (measured from the data by vector fitting, +/- 1 std; the most precise "
                       "channel of each):")
            out.append(f"  {'channel':<10} {'measured Hz':>18} {'model Hz':>10} {'error':>8} "
                       f"{'zeta meas.':>16} {'zeta model':>10}")
            for _, r in sorted(best.items()):
                out.append(f"  {r.channel:<10} {r.measured_hz:>10.4g} +/-{r.measured_hz_std:<6.2g}"
                           f"{r.model_hz:>10.4g} {100 * r.freq_error:>+7.2f}% "
                           f"{r.measured_damping:>8.3g} +/-{r.measured_damping_std:<5.2g}{r.model_damping:>10.3g}")
            out.append("")
        out += [f"  {s}" for s in self.summary] + [""]
        out.append(f"hypotheses tested: {self.n_hypotheses} (accept if delta chi2 > {self.threshold:.1f}, "
                   f"false-alarm rate {100 * self.alpha:g} %; misfit left: after the hypothesis, in units of "
                   f"the noise's, about 1 when right)")
        out.append(f"  {'rank':<4} {'kind':<12} {'station':>7} {'element':<14} {'size':>24} {'delta chi2':>11} "
                   f"{'misfit left':>11}")
        for k, f in enumerate(self.findings[:8], start=1):
            size = "-" if f.kind == "none" else (f"x{f.value:.4g}" if f.kind.endswith("gain")
                                                 else f"a/D {f.value:.4g}" if f.kind == "crack"
                                                 else f"{f.value:+.4g} {f.unit}")
            sd = "" if f.kind == "none" else f" +/- {f.std:.2g}"
            out.append(f"  {k:<4} {f.kind:<12} {str(f.station or '-'):>7} {str(f.element or '-'):<14} "
                       f"{size + sd:>24} {f.delta_chi2:>11.1f} {self.misfit_left(f):>11.3g}")
        out.append("")
        out.append(f"verdict: {self.verdict.sentence()}")
        if self.breathing:
            b = self.breathing
            out.append(f"  at speed: the crack turns with the shaft and breathes ({b['law']} law), a/D = "
                       f"{b['depth_ratio']:.4g} +/- {b['depth_std']:.2g} (details below; the time-invariant "
                       "finding is its revolution average)")
        if self.ambiguous_with:
            names = "; ".join(f"{f.kind} at {f.station} ({f.element})" for f in self.ambiguous_with)
            out.append(f"  cannot be told apart from: {names}")
            if self.separating_sensor is not None:
                out.append(f"  a sensor at station {self.separating_sensor} would separate them best")
        eb, ea = self.error_before, self.error_after
        out.append(f"held-out data ({self.held_out}):")
        out.append(f"  before: {100 * eb['rel']:.3g} % rms complex error, {eb['db']:.3g} dB rms log-magnitude")
        out.append(f"  after:  {100 * ea['rel']:.3g} % rms complex error, {ea['db']:.3g} dB rms log-magnitude")
        out.append(f"  gain:   {self.gain:.3g}x  (noise level {100 * self.noise:.3g} %)")
        if self.mbi:
            m = self.mbi
            out.append(f"model-based identification (controller at {m.get('location')}): {m.get('reading')}")
            if m.get("agrees") is not None:
                out.append(f"  {m['compared']}: MBI {m['mbi_value']:+.4g} +/- {m['mbi_std']:.2g} against the "
                           f"diagnosis {m['diagnosis_value']:+.4g}: "
                           + ("they agree" if m["agrees"] else "they DISAGREE (beyond 3 standard uncertainties)")
                           + f" (mu {m['mu']:.3f}, {m['seconds']:.0f} s)")
        if self.sidebands:
            sb = self.sidebands
            found = [c for c in sb["candidates"] if c["found"]]
            out.append(f"sidebands (data taken at {sb['speed_hz']:.4g} Hz): {sb['verdict']}: {sb['meaning']}"
                       + ("" if not found else "; at " + ", ".join(
                           f"{c['freq_hz']:.1f} Hz (k={c['k']:+d})" for c in found[:6])))
        if self.breathing:
            b = self.breathing
            ti = b["time_invariant_crack"]
            line = (f"crack turning with the shaft ({b['law']} breathing) in the {b['element']}: a/D = "
                    f"{b['depth_ratio']:.4g} +/- {b['depth_std']:.2g} (time-invariant crack there: "
                    f"a/D {ti['depth_ratio']:.4g}); misfit left {b['misfit_left']:.3g}")
            if b["delta_chi2_vs_time_invariant"] is not None:
                line += f", delta chi2 {b['delta_chi2_vs_time_invariant']:.1f} over the time-invariant crack"
            out.append(line)
            he = b["held_out_error"]
            tie = ti.get("held_out_error")
            out.append(f"  held-out: {100 * he['rel']:.3g} % rms complex error"
                       + ("" if not tie else f" (time-invariant crack: {100 * tie['rel']:.3g} %)")
                       + f"; projection error of the reduced rotor {b['projection_error']:.1g}; {b['seconds']:.0f} s")
            out.append("  add to the model file: " + b["model_addition"].strip().replace("\n", "; "))
        if self.extended_model:
            out.append(f"extended model: {self.extended_model}")
        for n in self.notes:
            out.append(f"note: {n}")
        out.append(f"({self.seconds:.1f} s)")
        return "\n".join(out)
