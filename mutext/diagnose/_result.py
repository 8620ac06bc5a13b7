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
    ``significant`` whether it passes the false-alarm test (never when the size
    sits at a bound of its range: ``at_bound``).

    Attributes
    ----------
    kind : str
        Kind of the hypothesis (see :data:`KINDS`), or ``"none"``.
    station : int or None
        1-based station or mass index.
    element : str or None
        Element changed or added.
    value : float
        The fitted size (SI, a depth ratio or a factor).
    unit : str
        Unit of ``value``.
    std : float
        Standard uncertainty of ``value``.
    score : float
        Information criterion (lower is better).
    delta_chi2 : float
        Improvement of :math:`\\chi^2` over *none*.
    description : str
        The hypothesis in words.
    significant : bool
        Passes the false-alarm test.
    refit : bool
        Size refitted on the extended model file itself.
    new_value : float or None
        The element's value in the extended model (an existing element changed).
    hypothesis : Hypothesis or None
        The hypothesis fitted.
    at_bound : bool
        The size sits at a bound of its range.
    values : tuple or None
        The fitted vector of a k-parameter hypothesis.
    stds : tuple or None
        The standard uncertainty of each of ``values``.
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
    at_bound: bool = False
    values: tuple | None = None        # k > 1 parameters (Hypothesis.params): the fitted vector ...
    stds: tuple | None = None          # ... and the standard uncertainty of each

    @property
    def theta(self):
        """The size as the hypothesis takes it: the value, or the vector of a k-parameter hypothesis."""
        return self.value if self.values is None else np.asarray(self.values, float)

    def as_dict(self) -> dict:
        return {"kind": self.kind, "station": self.station, "element": self.element, "value": self.value,
                "unit": self.unit, "std": self.std, "score": self.score, "delta_chi2": self.delta_chi2,
                "description": self.description, "significant": self.significant, "refit": self.refit,
                "new_value": self.new_value, "at_bound": self.at_bound,
                **({} if self.values is None else {
                    "parameters": {p.name: {"value": float(v), "std": float(sd), "unit": p.unit}
                                   for p, v, sd in zip(self.hypothesis.params, self.values, self.stds)}})}

    def sentence(self) -> str:
        if self.kind == "none":
            return "no effect beyond the noise"
        bound = " (at the bound of its range)" if self.at_bound else ""
        slip = _unit_slip(self.value, self.std) if self.kind in FACTOR_KINDS else ""
        return f"{self.description}: {self.size_text()}{slip}{bound}"

    def size_text(self, std: bool = True) -> str:
        """The size with its unit (a factor as x1.05, a crack as a/D, a delay in ms).

        Parameters
        ----------
        std : bool, optional
            Append the standard uncertainty (``+- ...``).
        """
        if self.kind == "none":
            return "-"
        if self.values is not None:
            return ", ".join(f"{p.name} {v:.4g}" + (f" +/- {sd:.2g}" if std else "") + f" {p.unit}"
                             for p, v, sd in zip(self.hypothesis.params, self.values, self.stds))
        if self.kind in FACTOR_KINDS:
            return f"x{self.value:.4g}" + (f" +/- {self.std:.2g}" if std else "")
        if self.kind == "crack":
            return f"a/D {self.value:.4g}" + (f" +/- {self.std:.2g}" if std else "")
        if self.kind in ("damping_scale", "frequency_scale", "distributed_stiffness"):
            return f"{100 * self.value:+.4g}" + (f" +/- {100 * self.std:.2g}" if std else "") + " %"
        if self.kind == "sensor_delay":
            return f"{1e3 * self.value:+.4g}" + (f" +/- {1e3 * self.std:.2g}" if std else "") + " ms"
        return f"{self.value:+.4g}" + (f" +/- {self.std:.2g}" if std else "") + f" {self.unit}"


#: held-out gain (ratio of the relative rms errors before and after) that "partly explained" requires:
#: the effects remove at least half of the held-out misfit (chi2 halved, gain >= sqrt 2).  A smaller gain
#: with a residual far above the noise is a stand-in absorbing a little of a misfit it does not explain
#: (an eleven-mass chain stiffened by 180 % against a beam's hammer test: gain 1.13, misfit 6e4)
PARTLY_GAIN = math.sqrt(2.0)


#: Kinds whose size is a factor on the measured channels.
FACTOR_KINDS = ("sensor_gain", "exciter_gain", "channel_scale")


#: Factors (data over model) a channel is off by when a unit is mistaken, and the likely mistake.
UNIT_SLIPS = ((1e6, "micro-units read as base units, e.g. um as m"),
              (1e3, "milli-units read as base units, e.g. mm as m"),
              (1e-3, "base units read as milli-units"), (1e-6, "base units read as micro-units"),
              (25.4, "millimetres read as inches"), (1 / 25.4, "inches read as millimetres"),
              (0.0254, "metres read as inches"), (1 / 0.0254, "inches read as metres"),
              (9.80665, "m/s^2 read as g"), (1 / 9.80665, "g read as m/s^2"),
              (4.4482216152605, "a force in lbf read as N"), (1 / 4.4482216152605, "a force in N read as lbf"),
              (-1.0, "polarity reversed"))


def _unit_slip(g: float, std: float) -> str:
    """Names a gain that is a unit mistake (within 2 % or 3 std of a known factor)."""
    for f, what in UNIT_SLIPS:
        if abs(g - f) <= max(0.02 * abs(f), 3 * std):
            return f" -- a unit slip? ({what})"
    return ""


@dataclass
class ResonanceRow:
    """Measured against modelled resonance of one channel.

    Attributes
    ----------
    channel : str
        The channel.
    measured_hz, measured_hz_std : float
        Measured resonance frequency [Hz] and its standard uncertainty (NaN: not reliable).
    model_hz : float
        The model's resonance frequency [Hz].
    measured_damping, measured_damping_std : float
        Measured damping ratio and its standard uncertainty.
    model_damping : float
        The model's damping ratio.
    measured_peak, model_peak : float
        Peak magnitudes (output unit per input unit).
    """
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
    """Model against data in one channel (SI units).

    Attributes
    ----------
    label : str
        The channel (``input->output``).
    source : str
        File the data came from.
    freq_hz : ndarray
        Frequencies [Hz].
    measured : complex ndarray
        The measured response.
    before : complex ndarray
        The engineering model's response.
    after : complex ndarray or None
        The extended model's response.
    role : str
        ``"fit"`` or ``"validate"`` (held out).
    """
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
    """Result of :func:`diagnose` (see its docstring); ``as_dict()`` is the ``--json`` object.

    Attributes
    ----------
    model_name : str
        Name of the engineering model.
    model_source : str or None
        Its file.
    noise : float
        Relative noise level estimated from the data (standard deviation of the complex log residual).
    findings : list of Finding
        Every hypothesis tested, best first (*none* included).
    verdict : Finding
        The first effect selected (or *none*).
    ambiguous_with : list of Finding
        Findings the data cannot tell from the verdict.
    separating_sensor : int or None
        Station whose response would separate them best.
    error_before, error_after : dict
        Held-out error of the engineering and of the extended model: ``{"rel": ..., "db": ...}``.
    gain : float
        ``error_before["rel"] / error_after["rel"]``.
    held_out : str
        Which data were held out, in words.
    channels : list of ChannelComparison
        Model against data per channel.
    resonances : list of ResonanceRow
        Measured against modelled resonances.
    summary : list of str
        The comparison in a few sentences.
    threshold : float
        The :math:`\\Delta\\chi^2` an effect must exceed (Bonferroni at ``alpha``).
    alpha : float
        The false-alarm rate.
    n_hypotheses : int
        Number of hypotheses tested.
    extended_model_text : str or None
        The extended model file's text.
    seconds : float
        Wall time of the diagnosis.
    notes : list of str
        Remarks on the data and the fit.
    n_residuals : int
        Number of real residuals of the fit (two per complex point).
    extended_model : str or None
        Path of the written extended model.
    mbi : dict or None
        The model-based identification at the finding, when asked for.
    sidebands : dict or None
        Sideband evidence when the data were taken at speed (rotors).
    breathing : dict or None
        A crack turning with the shaft, fitted when the sidebands call for it.
    status : str
        ``"explained"``, ``"partly explained"`` or ``"not explained"``.
    effects : list of Finding
        The accepted findings, in the order of selection.
    fit_quality : FitQuality or None
        Lack-of-fit test of the final model on the fitted data.
    noise_reference : NoiseReference or None
        The model-free noise reference.
    unmatched : dict or None
        Resonances without a partner: ``{"measured": [...], "model": [...]}``.
    localized : dict or None
        Where an unexplained misfit lives (:mod:`mutext.diagnose._localize`).
    held_quality : FitQuality or None
        Lack-of-fit test of the final model on the held-out data.
    amplitude : LevelTest or None
        The same channels measured at another excitation level compared
        (:mod:`mutext.diagnose._amplitude`), when a repeat was given.
    """
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
    status: str = "explained"       # "explained", "partly explained" or "not explained"
    effects: list = field(default_factory=list)    # the accepted findings, in the order of selection
    fit_quality: object = None      # _fit_quality.FitQuality of the final model
    noise_reference: object = None  # _fit_quality.NoiseReference
    unmatched: dict | None = None   # resonances without a partner: {"measured": [...], "model": [...]}
    localized: dict | None = None   # where an unexplained misfit lives (mutext.diagnose._localize)
    held_quality: object = None     # the lack-of-fit test of the final model on the held-out data
    amplitude: object = None        # _amplitude.LevelTest: the repeat at another excitation level

    @property
    def confirmed(self) -> bool:
        """Whether the extended model is a fix: explained with an effect (the status requires that it
        does better on held-out data, or, for a channel's own scale, no worse)."""
        return self.status == "explained" and bool(self.effects)

    def headline(self) -> str:
        """The verdict in one line: the status first, then what was found (a response that depends on the
        excitation level before anything else)."""
        amp = self.amplitude
        if amp is not None and amp.significant:
            eff = "; ".join(f.sentence() for f in self.effects) or "the engineering model"
            if self.status == "partly explained":
                at = amp.levels[1] if amp.lower == "repeat" else amp.levels[0]
                at = f"at {at}" if at else ("at the lower level" if amp.lower == "repeat" else
                                            "at the level of the fitted data")
                rest = (f"no linear model holds at both levels; {at} {eff} fits at the noise "
                        "(a linearisation there, not the cause)")
            else:
                rest = "no linear model holds at both levels; " + self._headline().split(": ", 1)[1]
            return f"{self.status.upper()}: {amp.sentence()}; {rest}"
        return self._headline()

    def _headline(self) -> str:
        """The verdict in one line without the repeat at another excitation level."""
        q = self.fit_quality
        eff = "; ".join(f.sentence() for f in self.effects) or "no effect beyond the noise"
        if self.status == "explained":
            return f"EXPLAINED: {eff}"
        left = "" if q is None else (f"the residual stays at {q.misfit:.3g} times the noise "
                                     f"(at most {q.limit:.3g} if explained), {q.where()}")
        if q is not None and q.nonlinear:
            left += ("; " if left else "") + "even a model-free rational fit stays above the noise at " + ", ".join(
                f"{c} {a:.4g}-{b:.4g} Hz" for c, a, b, _ in q.nonlinear[:3]) + (
                " (a response that depends on the amplitude, a time-varying system, leakage, or more modes "
                "than that fit holds)")
        if self.status == "partly explained":
            return (f"PARTLY EXPLAINED: {eff} helps (held-out gain {self.gain:.3g}x) but {left}; "
                    f"uncertainties are inflated by the misfit, and the cause may lie beyond the hypotheses")
        why = []
        hq = self.held_quality
        if q is not None and q.at_noise and hq is not None and not hq.at_noise:
            why.append(f"the fitted data are at the noise but the held-out data are not ({hq.misfit:.3g} times the "
                       f"noise, at most {hq.limit:.3g}: {hq.where()})")
            left = ""
        if self.effects and not self.gain > 1:
            why.append(f"the best hypotheses ({eff}) make held-out data worse (gain {self.gain:.3g}x)")
        elif self.effects and not (q is not None and q.at_noise) and self.gain < PARTLY_GAIN:
            why.append(f"the best hypotheses ({eff}) remove less than half of the held-out misfit "
                       f"(gain {self.gain:.3g}x, {1 - 1 / self.gain ** 2:.0%} of it)")
        elif self.effects:
            why.append(f"the best hypotheses ({eff}) fit but are not confirmed")
        else:
            best = next((f for f in self.findings if f.kind != "none"), None)
            if best is not None:
                why.append(f"no hypothesis is significant (best: {best.description})")
        if left:
            why.append(left)
        return "NOT EXPLAINED: " + "; ".join(why)

    def as_dict(self) -> dict:
        return {
            "model": self.model_source or self.model_name,
            "status": self.status,
            "headline": self.headline(),
            "effects": [f.as_dict() for f in self.effects],
            "confirmed": self.confirmed,
            "fit_quality": None if self.fit_quality is None else self.fit_quality.as_dict(),
            "held_out_quality": None if self.held_quality is None else self.held_quality.as_dict(),
            "noise_reference": None if self.noise_reference is None else self.noise_reference.as_dict(),
            "unmatched_resonances": self.unmatched,
            "amplitude_dependence": None if self.amplitude is None else self.amplitude.as_dict(),
            "localized": None if self.localized is None else {
                k: ([[float(x.real), float(x.imag)] for x in v] if k in ("required_impedance", "msd_fit") else v)
                for k, v in self.localized.items()},
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
        """The misfit after ``finding``, in units of what noise alone leaves (about 1 for the right model).

        Parameters
        ----------
        finding : Finding
            One of ``findings``.
        """
        none = next(f for f in self.findings if f.kind == "none")
        return (none.score - finding.delta_chi2) / max(self.n_residuals, 1)

    def at_speed_lines(self) -> list:
        """What the data taken at speed say: the sideband verdict and a crack turning with the shaft (rotors;
        empty otherwise).  The text report and the HTML report both print these lines."""
        out = []
        if self.sidebands:
            sb = self.sidebands
            found = [c for c in sb["candidates"] if c["found"]]
            out.append(f"sidebands (data taken at {sb['speed_hz']:.4g} Hz): {sb['verdict']}: {sb['meaning']}"
                       + ("" if not found else "; at " + ", ".join(
                           f"{c['freq_hz']:.1f} Hz (k={c['k']:+d})" for c in found[:6])))
        if self.breathing:
            b = self.breathing
            ti = b["time_invariant_crack"]
            line = (("NOT SUPPORTED (" + b["rejected"] + "): " if b.get("rejected") else "")
                    + f"crack turning with the shaft ({b['law']} breathing) in the {b['element']}: a/D = "
                    f"{b['depth_ratio']:.4g} +/- {b['depth_std']:.2g} (time-invariant crack there: "
                    f"a/D {ti['depth_ratio']:.4g}); misfit left {b['misfit_left']:.3g}")
            if b["delta_chi2_vs_time_invariant"] is not None:
                line += f", delta chi2 {b['delta_chi2_vs_time_invariant']:.1f} over the time-invariant crack"
            if b.get("truncation_error") is not None:
                # the fit's harmonic balance keeps 6 harmonics: its own model error, beside the misfit
                line += f"; harmonic-balance truncation error {b['truncation_error']:.2g} of the peak"
            out.append(line)
            he = b["held_out_error"]
            tie = ti.get("held_out_error")
            out.append(f"  held-out: {100 * he['rel']:.3g} % rms complex error"
                       + ("" if not tie else f" (time-invariant crack: {100 * tie['rel']:.3g} %)")
                       + f"; projection error of the reduced rotor {b['projection_error']:.1g}; {b['seconds']:.0f} s")
            out.append("  add to the model file: " + b["model_addition"].strip().replace("\n", "; "))
        return out

    def report(self) -> str:
        """Plain-text report (what the command prints)."""
        nr = self.noise_reference
        how = "" if nr is None else {
            "rational": f" by model-free rational fits, {nr.dof:.0f} degrees of freedom"
                        + (f"; neighbouring lines correlated (r1 = {nr.r1:.2f}), counted as fewer" if nr.inflation > 1
                           else ""),
            "fourth differences": " by fourth differences along frequency (approximate)",
            "given": " (given)"}[nr.method]
        out = [f"verdict: {self.headline()}", "",
               f"model: {self.model_source or self.model_name}",
               f"noise level: {100 * self.noise:.3g} % (relative, rms){how}", ""]
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
        out.append(f"  {'rank':<4} {'kind':<13} {'station':>7} {'element':<14} {'size':>26} {'delta chi2':>11} "
                   f"{'misfit left':>11} {'significant':>11}")
        for k, f in enumerate(self.findings[:8], start=1):
            sig = "yes" if f.significant else ("at bound" if f.at_bound else "")
            out.append(f"  {k:<4} {f.kind:<13} {str(f.station or '-'):>7} {str(f.element or '-'):<14} "
                       f"{f.size_text():>26} {f.delta_chi2:>11.1f} {self.misfit_left(f):>11.3g} {sig:>11}")
        out.append("")
        q = self.fit_quality
        if q is not None:
            out.append(f"goodness of fit of the final model ({len(self.effects)} effect(s)): misfit "
                       f"{q.misfit:.3g} x the noise, at most {q.limit:.3g} when explained "
                       f"(p = {q.p_value:.2g}): " + ("at the noise" if q.at_noise else f"above the noise: {q.where()}"))
        if self.unmatched and (self.unmatched.get("measured") or self.unmatched.get("model")):
            um = self.unmatched
            if um.get("measured"):
                out.append("  measured resonances the model has no partner for: " + ", ".join(
                    f"{x['freq_hz']:.4g} Hz ({x['channel']})" for x in um["measured"]))
            if um.get("model"):
                out.append("  model resonances outside the measured band: " + ", ".join(
                    f"{x:.4g} Hz" for x in um["model"][:8]))
        out.append(f"status: {self.status.upper()}")
        for k, f in enumerate(self.effects, start=1):
            out.append(f"  effect {k}: {f.sentence()}")
        if not self.effects:
            out.append("  no effect accepted")
        if self.breathing and not self.breathing.get("rejected"):
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
        out += self.at_speed_lines()
        if self.extended_model:
            out.append(f"extended model: {self.extended_model}" + ("" if self.confirmed else
                       " (NOT a confirmed fix: written under a name that says so)"))
        for n in self.notes:
            out.append(f"note: {n}")
        out.append(f"({self.seconds:.1f} s)")
        return "\n".join(out)
