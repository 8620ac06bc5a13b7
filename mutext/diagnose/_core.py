"""The entry point :func:`diagnose`."""
from __future__ import annotations

import logging
import math
import os
import time
from dataclasses import replace
from typing import Callable

import numpy as np
import scipy.stats as sst

from ..errors import ModelError
from ..lti import blas_single_thread
from ..response import FRF
from ..rig import read_frfs
from ..rotor.model import load_model, loads_model
from ..rotor.tuning import model_response
from ._compare import _errors, _model_modes, _resonance_table, _summary
from ._extend import _identify_at, _refit, extended_model_text, mbi_element, write_model
from ._hypotheses import Hypothesis, hypotheses
from .faults import channel as _channel
from .faults import structure as _structure
from ._result import ChannelComparison, Diagnosis, Finding
from ._channels import _resolve, _src
from ._fit_quality import fit_quality, noise_reference
from ._screen import (_Data, _Evaluator, _Receptance, _fit_size, _fit_vector, _jacobian_std, _rss,
                      _separating_station)
from ._select import MAX_EFFECTS, Compound, _rss_of, at_bound, fit_one_given, joint_fit

log = logging.getLogger("mutext.diagnose")

#: Without validation files, every this many-th frequency of each channel is held out of the fit.
HOLDOUT_EVERY = 5

def _as_frfs(frfs) -> list[FRF]:
    """FRFs given as objects or files (a Universal File may hold several: all are used)."""
    if frfs is None:
        return []
    if isinstance(frfs, (FRF, str, os.PathLike)):
        frfs = [frfs]
    out = []
    for f in frfs:
        out += [f] if isinstance(f, FRF) else read_frfs([f])
    return out


def _same_data(a: FRF, b: FRF) -> bool:
    return (a.freq_hz.shape == b.freq_hz.shape and np.array_equal(a.freq_hz, b.freq_hz)
            and np.array_equal(a.response, b.response))


def diagnose(model, frfs, validate=None, *, alpha: float = 0.01, refit: int = 3, noise: float | None = None,
             out_dir=None, progress: Callable[[str, float], None] | None = None,
             only: Callable[[Hypothesis], bool] | None = None, mbi: bool = False) -> Diagnosis:
    r"""Find what ``model`` gets wrong against measured FRFs, name the cause, extend the model, measure the gain.

    See the module docstring for the method and the statistics.

    Parameters
    ----------
    model : str or os.PathLike
        Model file (TOML, :mod:`mutext.rotor.model`): a lumped chain or a rotor.
        (A path is needed to write the extended model next to it.)
    frfs : sequence of FRF or paths
        Measured channels used for the fit.  Stations as numbered in the model
        file (masses 1..n of a chain); directions ``input_direction`` /
        ``output_direction`` (default x).
    validate : sequence of FRF or paths, optional
        Channels held out of the fit, on which the gain is measured.  Default:
        every :data:`HOLDOUT_EVERY`-th frequency of each fitted channel.
    alpha : float
        False-alarm rate of the *none* verdict (Bonferroni over the hypotheses).
    refit : int
        Number of best hypotheses refitted on the extended model with
        :func:`mutext.rotor.tuning.tune`.
    noise : float, optional
        Relative noise level; default estimated from the data
        (model-free rational fits, :mod:`mutext.diagnose._fit_quality`).
    out_dir : path, optional
        Write ``model_extended.toml`` there (:func:`write_model`; :func:`mutext.report.write_diagnosis`
        writes the report and figures too).
    progress : callable(stage: str, fraction: float), optional
        Called as the work proceeds (the command line draws a progress line).
    mbi : bool
        Also read the top finding the thesis's way (lumped chains): model-based
        identification (:func:`mutext.mbi.identify`, D-K iteration) with the
        controller at the finding's mass, K read as mass, damper and spring,
        compared with the diagnosis (``Diagnosis.mbi``).  Takes 5-60 s more.
        When the hypotheses do not explain the data, the controller goes to the
        station the misfit is localized to, is tuned on the fitted lines of the
        channel that sees that station best, and becomes an element of its own
        extended model (a mass, spring and damper when its reading is physical,
        else an ``[[impedance]]``), judged on the held-out lines
        (``Diagnosis.mbi["element"]``, ``["held_out_gain"]``, ``["status"]``;
        :func:`mutext.diagnose._extend.mbi_element`).
    only : callable(Hypothesis) -> bool, optional
        Test only the hypotheses it accepts (e.g. a fit told the kind and the
        location: ``only=lambda h: (h.kind, h.station) == ("mass", 3)``); the
        Bonferroni threshold counts the hypotheses actually tested.

    Returns
    -------
    Diagnosis

    Examples
    --------
    The three-mass rig with a hidden stiffness change, its sweeps noisy at 1 %:
    the diagnosis names the kind and the mass, and the extended model fits the
    held-out data better (the sizes as the screen fitted them, ``refit=0``:
    about 2 s instead of 4).

    >>> from mutext.diagnose import diagnose
    >>> from mutext.hide import hidden_effect_data
    >>> case = hidden_effect_data("three_mass", seed=3, kind="stiffness", noise=0.01)
    >>> d = diagnose(case.model, case.measured, validate=case.validate, refit=0)
    >>> d.findings[0].kind == case.key["kind"], d.findings[0].station == case.key["station"]
    (True, True)
    >>> bool(d.gain > 3)
    True
    """
    with blas_single_thread():        # small dense problems: extra BLAS threads only spin on a busy machine
        return _diagnose(model, frfs, validate, alpha, refit, noise, out_dir, progress, only, mbi)


def _diagnose(model, frfs, validate, alpha, refit, noise, out_dir, progress, only, mbi) -> Diagnosis:
    t0 = time.perf_counter()

    def tell(stage, frac):
        log.info("%s (%.0f %%)", stage, 100 * frac)
        if progress is not None:
            progress(stage, frac)

    # a rotor's model is built (symbolic finite elements) while the files are read: seconds to tens of seconds
    tell("reading the model file and the data (a rotor's finite elements are built here)", 0.0)
    path, eng, model_text, chans, vchans, speed, input_notes = _inputs(model, frfs, validate, alpha)
    tell("noise level of the data (model-free rational fits)", 0.01)
    ref = noise_reference(chans, _noise(noise))
    noise = ref.sigma
    s2 = noise ** 2 / 2.0
    tell("engineering model's receptance", 0.02)
    allf = np.unique(np.concatenate([c.frf.freq_hz for c in chans + vchans]))    # one grid for all
    rec = _Receptance(eng, None, speed, 2 * np.pi * allf)
    fit, held, all_fit, held_desc = _data_sets(rec, allf, chans, vchans)

    # 1. what the simulation gets wrong
    before = all_fit.H0
    unmatched: dict = {}
    rows = _resonance_table(chans, before, eng, speed, noise, unmatched)
    unmatched["measured"] = _group_unmatched(unmatched.get("measured", []))
    summary = _summary(rows, chans, before)

    # 2. the hypotheses, screened, the best refitted on the extended model, the verdict
    hyps = hypotheses(eng) + _channel.candidates(eng, chans) + _structure.candidates(eng)
    if only is not None:
        hyps = [h for h in hyps if only(h)]
        if not hyps:
            raise ModelError("diagnose: no hypothesis passes the 'only' filter")
    N = 2 * fit.n_points
    rss0 = _rss(fit.H0, fit.meas)
    threshold = float(sst.chi2.isf(alpha / len(hyps), 1))
    findings = _screen_all(hyps, rec, fit, s2, N, rss0, threshold, tell)
    notes = input_notes + _refit_best(findings, refit, model_text, path, eng, fit, s2, N, rss0, threshold, tell)
    for f in findings:
        _judge(f, N, threshold)
    for f in findings[:5]:
        if f.at_bound:
            notes.append(f"{f.description} fits best at the bound of its range ({f.size_text(std=False)}): "
                         "not accepted (the data ask for more than the hypothesis allows)")
    none = Finding("none", None, None, 0.0, "", 0.0, rss0 / s2, 0.0, "no effect beyond the noise")
    findings.sort(key=lambda f: f.score)
    findings.insert(next((i for i, f in enumerate(findings) if f.score > none.score), len(findings)), none)
    verdict, ambiguous, sensor = _decide(findings, none, threshold, N, rec, fit, eng, notes, held, s2)

    # 3. goodness of fit; further effects while the residual stays above the noise
    effects = [] if verdict is none else [verdict]
    first = None
    if _in_model_file(verdict):
        # the model file with the finding is what the user receives (with modal damping its damping follows
        # the change, which the screen holds fixed): judged on its own responses
        first = _quality_of_file(verdict, model_text, eng, path, rec, chans, all_fit, held, s2, ref, alpha)
    effects, quality = _select_more(effects, hyps, rec, fit, held, s2, N, threshold, alpha, ref, notes, tell,
                                    first)
    if len(effects) > 1:
        verdict = effects[0]

    # 4. the extended model and its gain on held-out data
    tell("held-out gain", 0.95)
    text = None
    if effects:
        text = model_text
        for e in effects:
            text = extended_model_text(text, e, eng)
    if len(effects) > 1:
        comp = [e.hypothesis for e in effects], [e.theta for e in effects]
        after_all = Compound(rec, all_fit, comp[0]).responses(comp[1])
        after_held = Compound(rec, held, comp[0]).responses(comp[1])
    else:
        after_all, after_held = _after(verdict, text, path, rec, chans, all_fit, held)
        if _in_model_file(verdict):
            quality = first
    err_before = _errors(held.H0, held.meas)
    err_after = _errors(after_held, held.meas)
    gain = err_before["rel"] / err_after["rel"] if err_after["rel"] > 0 else math.inf
    comps = [ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response, before[k],
                               None if after_all is None else after_all[k], "fit") for k, c in enumerate(chans)]
    comps += [ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response, held.H0[k],
                                None if verdict is none else after_held[k], "validate")
              for k, c in enumerate(vchans)]
    with np.errstate(all="ignore"):
        held_quality = fit_quality([np.log(h / m) for h, m in zip(after_held, held.meas)], held.freq_hz,
                                   [c.label for c in held.chans], s2, 0, ref, alpha)
    status = _status(effects, quality, gain, held_quality)
    if quality.at_noise and not held_quality.at_noise:
        notes.append(f"the fitted data are explained, the held-out data are not: misfit {held_quality.misfit:.3g} "
                     f"times the noise (at most {held_quality.limit:.3g}), {held_quality.where()}")
    if effects and not quality.at_noise:
        infl = math.sqrt(max(quality.misfit, 1.0))
        for e in effects:
            e.std *= infl
        notes.append(f"the residual is above the noise: the effects' uncertainties are inflated by "
                     f"sqrt(misfit) = {infl:.3g}")
    if effects and status == "not explained" and not gain > 1:
        notes.append(f"the extended model fits the held-out data worse than the engineering model "
                     f"(gain {gain:.3g}x): it is not a fix")
    localized = None
    if status != "explained":
        tell("where the misfit lives (an impedance at each station)", 0.955)
        from ._localize import describe, localize
        localized = localize(rec, fit, held, eng, s2)
        if localized is not None:
            notes.append(describe(localized))
    result = Diagnosis(eng.name, path, noise, findings, verdict, ambiguous, sensor, err_before, err_after, gain,
                       held_desc, comps, rows, summary, threshold, alpha, len(hyps), text,
                       time.perf_counter() - t0, notes, N, status=status, effects=effects, fit_quality=quality,
                       noise_reference=ref, unmatched=unmatched, localized=localized,
                       held_quality=held_quality)
    if speed > 0 and hasattr(eng, "n_stations"):
        # where to look: the modes of the best time-invariant model (a mode the engineering model misplaces
        # is not a sideband)
        best_ti = eng
        if text is not None and any(e.hypothesis.gain is None for e in effects):
            try:
                best_ti = loads_model(text, source=f"{path} (extended)",
                                      base_dir=os.path.dirname(os.path.abspath(path)))
            except ModelError:
                pass
        result.sidebands = _sidebands(best_ti, speed, chans)
        if result.sidebands and result.sidebands["verdict"] != "none" and model_text is not None:
            tell("a crack that turns with the shaft, at the best crack station (time-periodic fit)", 0.96)
            result.breathing = _breathing(findings, result.sidebands, model_text, path, speed, chans, fit,
                                          held, s2, rss0, verdict, err_after, result.notes)
            result.seconds = time.perf_counter() - t0
        _sideband_claim(result)
    at = verdict
    if mbi and localized is not None and eng.layout.kind == "lumped":
        # not explained: the thesis's controller goes where the misfit lives, read against that element
        h = Hypothesis("mass", localized["station"], None, f"element at station {localized['station']}", "kg",
                       True, 0.0, math.inf, 1.0, [localized["dof"]])
        at = Finding("mass", localized["station"], None, localized["msd"]["m"], "kg", math.inf, 0.0, 0.0,
                     h.description, hypothesis=h)
    if mbi and at is not none:
        tell("model-based identification at the finding (D-K iteration)", 0.97)
        # the controller is tuned on the first channel's fitted lines only: the held-out lines, on which the
        # element it becomes is judged, stay unseen
        k0 = 0 if at is verdict else _channel_at(fit.chans, at.station)
        c0 = fit.chans[k0]
        seen = replace(c0.frf, freq_hz=fit.freq_hz[k0], response=fit.meas[k0], metadata=dict(c0.frf.metadata))
        try:
            result.mbi, res, E = _identify_at(model_text, path, at, seen, c0.in_name, c0.out_name,
                                              progress=lambda stage, frac: tell(
                                                  f"model-based identification: {stage}", 0.97 + 0.02 * frac))
        except ModelError as exc:
            result.mbi = {"location": None, "reading": f"not run: {exc}", "agrees": None}
        else:
            if at is not verdict:
                # nothing the hypotheses name explains the data: K itself becomes the element of the model
                tell("the controller as an element of the model, judged on the held-out data", 0.99)
                try:
                    result.mbi.update(mbi_element(result.mbi, res, E, model_text, eng, localized["station"],
                                                  localized["dof"], rec, held, s2, ref, alpha, seen, c0.in_name,
                                                  c0.out_name, err_before))
                except ModelError as exc:
                    result.mbi["element"] = None
                    result.notes.append(f"the controller was not written as an element: {exc}")
        result.seconds = time.perf_counter() - t0
    if out_dir is not None:
        write_model(result, out_dir)
    tell("done", 1.0)
    return result


def _channel_at(chans, station: int) -> int:
    """The channel that sees a station best: its driving point, else one that measures or drives it, else the
    first.  (A controller tuned on a channel where the station hardly moves is free where it does not.)"""
    for test in (lambda c: c.frf.input_station == station and c.frf.output_station == station,
                 lambda c: c.frf.output_station == station, lambda c: c.frf.input_station == station):
        k = next((k for k, c in enumerate(chans) if test(c)), None)
        if k is not None:
            return k
    return 0


def _breathing(findings, sidebands, model_text, path, speed, chans, fit, held, s2, rss0, verdict, err_after,
               notes):
    """Depth of a turning crack at the best crack station, when the sidebands call for one."""
    from ._breathing import fit_breathing_crack
    cracks = [f for f in findings if f.kind == "crack" and f.station is not None]
    if not cracks:
        return None
    best = min(cracks, key=lambda f: f.score)
    laws = ("mayes", "gasch") if sidebands["verdict"] == "once per revolution" else ("open",)
    try:
        out = fit_breathing_crack(model_text, os.path.dirname(os.path.abspath(path)) if path else ".",
                                  best.station, speed, chans, fit, held, s2, laws,
                                  rss0 - best.delta_chi2 * s2)
    except ModelError as exc:
        notes.append(f"a breathing crack was not fitted: {exc}")
        return None
    out["time_invariant_crack"] = {"depth_ratio": best.value, "depth_std": best.std,
                                   "held_out_error": err_after if verdict is best else None}
    return out


def _sidebands(model, speed, chans):
    """Sideband evidence on the channels that share the first one's grid (data taken at speed)."""
    from ._sidebands import sideband_evidence
    f0 = chans[0].frf.freq_hz
    same = [c.frf for c in chans if c.frf.freq_hz.shape == f0.shape and np.allclose(c.frf.freq_hz, f0)]
    fm, _ = _model_modes(model, speed)
    try:
        ev = sideband_evidence(same, fm, speed / (2 * math.pi))
    except ModelError as exc:
        return {"verdict": "none", "meaning": f"not computed: {exc}", "candidates": [], "speed_hz":
                speed / (2 * math.pi), "orders_found": []}
    return ev.to_dict()


def _sideband_claim(result) -> None:
    """The time-periodic claim is made only when a time-periodic model fits better than the time-invariant
    one; otherwise the sidebands are reported as not explaining the data."""
    sb, b = result.sidebands, result.breathing
    if not sb or sb["verdict"] == "none":
        return
    worse = None
    if b is not None:
        d = b.get("delta_chi2_vs_time_invariant")
        ti = (b.get("time_invariant_crack") or {}).get("held_out_error")
        if d is not None and d < 0:
            worse = f"it fits the measured data worse (delta chi2 {d:.1f})"
        elif ti and b["held_out_error"]["rel"] > ti["rel"]:
            worse = (f"it fits the held-out data worse ({100 * b['held_out_error']['rel']:.3g} % against "
                     f"{100 * ti['rel']:.3g} %)")
    if worse:
        result.notes.append(f"sideband-like peaks were found ({sb['verdict']}), but the time-periodic (breathing "
                            f"crack) model does not explain them: {worse}; no time-periodic claim is made")
        sb["verdict_found"], sb["verdict"] = sb["verdict"], "none"
        sb["meaning"] = "peaks near f_n -/+ kF that a time-periodic model does not explain"
        b["rejected"] = worse
        return
    result.notes.append(f"the data show sidebands ({sb['verdict']}): the rotor is time-periodic, which no "
                        f"time-invariant hypothesis above can hold; {sb['meaning']}"
                        + (". The crack finding is a crack held still facing x (time-invariant), not one "
                           "turning with the shaft"
                           if result.verdict.kind == "crack" else ""))


def _inputs(model, frfs, validate, alpha):
    """The model file and the channels, checked: (path, model, text, fit channels, held-out channels, speed)."""
    if not isinstance(model, (str, os.PathLike)):
        raise ModelError("diagnose: give the model as a model file path (TOML); the extended model is "
                         "written from it")
    path = os.fspath(model)
    eng = load_model(path)
    with open(path, encoding="utf-8") as fh:
        model_text = fh.read()
    if not 0 < alpha < 1:
        raise ModelError(f"diagnose: alpha must be in (0, 1), got {alpha}")
    fit_frfs = _as_frfs(frfs)
    if not fit_frfs:
        raise ModelError("diagnose: no measured FRF given")
    val_frfs = _as_frfs(validate)
    for group, what in ((fit_frfs, "measured"), (val_frfs, "validation")):
        for i, a in enumerate(group):
            for b in group[:i]:
                if _same_data(a, b):
                    raise ModelError(f"{what} data {_src(a, i + 1)} holds the same data as {_src(b, 0)}: the "
                                     f"same measurement given twice would count as two independent channels "
                                     f"(uncertainties too small); give it once")
    for v in val_frfs:
        for f in fit_frfs:
            if _same_data(v, f):
                raise ModelError(f"validation file {_src(v, 0)} holds the same data as the fitted "
                                 f"{_src(f, 0)}: held-out data must not be used in the fit")
    notes: list = []
    if eng.layout.kind == "lumped":
        # a chain moves along one direction: a file's Y (an analyser's default axis) is that direction
        fit_frfs, val_frfs = _along_the_chain(fit_frfs, notes), _along_the_chain(val_frfs, notes)
    for k, f in enumerate(fit_frfs + val_frfs, start=1):
        for n in (f.metadata.get("notes") or []):
            notes.append(f"{_src(f, k)}: {n}")
        if f.metadata.get("conversion"):
            notes.append(f"{_src(f, k)}: {f.metadata['conversion']}")
    chans, _ = _resolve(eng, fit_frfs, "data")
    vchans, _ = _resolve(eng, val_frfs, "validation") if val_frfs else ([], None)
    speeds = {c.speed for c in chans + vchans}
    if len(speeds) > 1:
        raise ModelError(f"diagnose: the FRFs were measured at different running speeds "
                         f"({sorted(s / (2 * math.pi) for s in speeds)} Hz); diagnose one speed at a time")
    speed = speeds.pop()
    # frequency overlap with the model's modes: at least one model resonance within the data band
    fmin = min(c.frf.freq_hz[0] for c in chans)
    fmax = max(c.frf.freq_hz[-1] for c in chans)
    fmodes, _ = _model_modes(eng, speed)
    if not np.any((fmodes >= fmin) & (fmodes <= fmax)):
        raise ModelError(f"diagnose: the data cover {fmin:g}-{fmax:g} Hz but the model has no resonance there "
                         f"(model resonances: {', '.join(f'{x:.4g}' for x in fmodes[:6])} Hz): check the units of "
                         f"the frequency column and that the file belongs to this model")
    return path, eng, model_text, chans, vchans, speed, list(dict.fromkeys(notes))


def _noise(noise) -> float | None:
    """The relative noise level given by the user, checked (None: estimated from the data)."""
    if noise is None:
        return None
    if isinstance(noise, bool) or not (isinstance(noise, (int, float)) and math.isfinite(noise) and 0 < noise < 1):
        raise ModelError(f"diagnose: noise must be a relative level in (0, 1), e.g. 0.01 for 1 %; got {noise!r}")
    return max(float(noise), 1e-6)


def _along_the_chain(frfs: list, notes: list) -> list:
    """FRFs of a lumped chain with their directions set to the chain's one (x), with a note."""
    from dataclasses import replace
    out = []
    for k, f in enumerate(frfs, start=1):
        if f.input_direction != "x" or f.output_direction != "x":
            notes.append(f"{_src(f, k)}: measured along {f.input_direction}/{f.output_direction}; a lumped chain "
                         "moves along one direction, taken as that one")
            f = replace(f, input_direction="x", output_direction="x", metadata=dict(f.metadata))
        out.append(f)
    return out


def _group_unmatched(rows: list) -> list:
    """Unmatched measured resonances of several channels merged into one entry per mode (within 2 %)."""
    out: list = []
    for r in sorted(rows, key=lambda x: x["freq_hz"]):
        if out and abs(r["freq_hz"] / out[-1]["freq_hz"] - 1) <= 0.02:
            if r["channel"] not in out[-1]["channel"].split(", "):
                out[-1]["channel"] += ", " + r["channel"]
            continue
        out.append(dict(r))
    return out


def _judge(f: Finding, N: int, threshold: float) -> None:
    """Significance as the name says: the improvement passes the test against the larger of the noise and
    what the hypothesis itself leaves (an F test when the residual is above the noise), and the size
    does not sit at a bound of its range."""
    if f.kind == "none" or f.hypothesis is None:
        return
    h = f.hypothesis
    f.at_bound = bool(f.delta_chi2 > 0 and at_bound(h, f.value if f.values is None else f.values))
    k = h.n_params
    left = max(1.0, (f.score - k * math.log(N)) / max(N - k, 1))
    f.significant = bool(f.delta_chi2 / left > threshold_k(threshold, k) and not f.at_bound)


def _status(effects, quality, gain, held_quality) -> str:
    """Explained: the fitted and the held-out data at the noise (and, with effects, the held-out data better
    than before); partly: effects that help on held-out data, a residual above the noise; otherwise not
    explained."""
    # a channel's scale acts on its own file only: other files cannot confirm it, only not contradict it
    better = gain > 1 or (bool(effects) and all(e.kind == "channel_scale" for e in effects) and gain >= 1 - 1e-9)
    if quality.at_noise and held_quality.at_noise:
        return "explained" if (not effects or better) else "not explained"
    return "partly explained" if (effects and better) else "not explained"


def _in_model_file(f) -> bool:
    """Whether a finding is a structural change written into the model file (not a correction of the data)."""
    h = f.hypothesis
    return f.kind != "none" and h is not None and h.gain is None and h.glob is None


def _quality_of_file(verdict, model_text, eng, path, rec, chans, all_fit, held, s2, ref, alpha):
    """The lack-of-fit test of the extended model file itself, on every fitted line."""
    text = extended_model_text(model_text, verdict, eng)
    after_all, _ = _after(verdict, text, path, rec, chans, all_fit, held)
    with np.errstate(all="ignore"):
        r = [np.log(h / m) for h, m in zip(after_all, all_fit.meas)]
    return fit_quality(r, all_fit.freq_hz, [c.label for c in all_fit.chans], s2, verdict.hypothesis.n_params, ref,
                       alpha)


def _select_more(effects, hyps, rec, fit, held, s2, N, threshold, alpha, ref, notes, tell, first=None):
    """Forward selection (see :mod:`mutext.diagnose._select`): returns (effects, fit quality of the last model).

    ``first``: the fit quality of the first effect when it is judged on the model file itself."""
    labels = [c.label for c in fit.chans]

    def quality_of(effs, thetas):
        Hs = Compound(rec, fit, [e.hypothesis for e in effs]).responses(thetas) if effs else fit.H0
        with np.errstate(all="ignore"):
            r = [np.log(h / m) for h, m in zip(Hs, fit.meas)]
        return fit_quality(r, fit.freq_hz, labels, s2, len(effs), ref, alpha)

    thetas = [e.theta for e in effects]
    quality = first if first is not None else quality_of(effects, thetas)
    chi_held = float(sst.chi2.isf(alpha, 1))
    while effects and not quality.at_noise and len(effects) < MAX_EFFECTS:
        tell(f"the residual is above the noise: screening a further effect given {len(effects)}", 0.9)
        base = [e.hypothesis for e in effects]
        rss_a = _rss_of(Compound(rec, fit, base).responses(thetas), fit.meas)
        held_a = _rss_of(Compound(rec, held, base).responses(thetas), held.meas)
        if held_a > _rss_of(held.H0, held.meas):
            notes.append(f"no further effect searched: the {len(effects)} effect(s) found make the held-out data "
                         "worse")
            break
        cands = []
        for h in hyps:
            if any(h is b for b in base) or h.params:      # a k-parameter kind is found first or not at all
                continue
            t, r = fit_one_given(rec, fit, base, thetas, h)
            cands.append((r, id(h), h, t))
        if not cands:
            break
        cands.sort(key=lambda x: x[:2])
        # the best few, fitted jointly with those accepted; of them the best that passes every test (a channel's
        # scale and a sensor's gain can tie on the fitted data and part on the held-out data)
        tried = []
        for r, _, h, t in cands[:4]:
            hs = base + [h]
            th, rss_new, sd = joint_fit(rec, fit, hs, thetas + [t], s2)
            hs, th, rss_new, sd = _nested_at_bound(hs, th, rss_new, sd, hyps, rec, fit, s2, notes)
            dchi = (rss_a - rss_new) / s2
            held_new = _rss_of(Compound(rec, held, hs).responses(th), held.meas)
            dheld = (held_a - held_new) / s2
            stuck = [x.description for x, tt in zip(hs, th) if at_bound(x, tt)]
            left = max(1.0, rss_new / (s2 * max(N - sum(x.n_params for x in hs), 1)))
            # an effect on one fitted file only (its scale) cannot show on other files: not held against them
            own_file_only = held_new == held_a and h.kind == "channel_scale"
            ok = dchi / left > threshold and (dheld > chi_held or own_file_only) and not stuck
            tried.append((not ok, rss_new, h, th, sd, dchi, dheld, stuck, left, hs))
        tried.sort(key=lambda x: (x[0], x[1]))
        failed, rss_new, h, th, sd, dchi, dheld, stuck, left, hs = tried[0]
        if failed:
            why = ("a size at the bound of its range: " + ", ".join(stuck)) if stuck else (
                f"delta chi2 {dchi:.1f} on the fitted data (threshold {threshold:.1f}"
                + (f", {threshold * left:.1f} against the misfit left" if left > 1 else "")
                + f"), {dheld:.1f} on the held-out data (threshold {chi_held:.1f})")
            notes.append(f"no further effect accepted; the best candidate, {h.description}, given "
                         f"{len(effects)} effect(s): {why}")
            break
        new = _findings_of(hs, th, sd, rss_new, s2, N, [e.delta_chi2 for e in effects] + [dchi])
        effects = _drop_redundant(new, rec, fit, s2, N, threshold, notes)
        thetas = [e.theta for e in effects]
        quality = quality_of(effects, thetas)
    if len(effects) > 1:
        simpler = _simplify(effects, hyps, rec, fit, s2, N, threshold, notes)
        if simpler is not effects:
            effects = simpler
            quality = quality_of(effects, [e.theta for e in effects])
    return effects, quality


def _findings_of(hs, th, sd, rss, s2, N, delta_chi2s):
    """Findings for the jointly fitted hypotheses ``hs`` at sizes ``th`` with stds ``sd``."""
    n_par = sum(x.n_params for x in hs)
    out = []
    for x, t, d, dchi in zip(hs, th, sd, delta_chi2s):
        vec = np.ndim(t) > 0
        t0, d0 = (float(t[0]), float(d[0])) if vec else (float(t), float(d))
        f = Finding(x.kind, x.station, x.element, t0, x.unit, d0, rss / s2 + n_par * math.log(N), float(dchi),
                    x.description, True, False, None if (x.gain is not None or x.added) else x.nominal + t0, x)
        if vec:
            f.values, f.stds = tuple(float(v) for v in t), tuple(float(v) for v in d)
        out.append(f)
    return out


def _drop_redundant(effects, rec, fit, s2, N, threshold, notes):
    """The backward step of the selection: an earlier effect that the later ones make unnecessary is dropped.

    A first effect can stand in for two (a common loss of all springs imitates one weaker spring and a
    heavier roof); once those two are in, the stand-in's joint size is noise.  Each effect but the newest
    (which has just passed its test given the others) is removed in turn and the rest refitted jointly; the
    one whose removal costs least is dropped when that cost is below the threshold of its parameter count,
    against the misfit left, and the step repeats."""
    while len(effects) > 1:
        hs, th = [e.hypothesis for e in effects], [e.theta for e in effects]
        full = _rss_of(Compound(rec, fit, hs).responses(th), fit.meas)
        left = max(1.0, full / (s2 * max(N - sum(h.n_params for h in hs), 1)))
        best = None
        for k, e in enumerate(effects[:-1]):
            rest, rest_th = hs[:k] + hs[k + 1:], th[:k] + th[k + 1:]
            th2, rss2, sd2 = joint_fit(rec, fit, rest, rest_th, s2)
            cost = (rss2 - full) / s2 / left
            if cost < threshold_k(threshold, e.hypothesis.n_params) and (best is None or cost < best[0]):
                best = (cost, k, rest, th2, rss2, sd2)
        if best is None:
            return effects
        cost, k, rest, th2, rss2, sd2 = best
        notes.append(f"{effects[k].description} dropped: given the later effects it improves the fit by delta "
                     f"chi2 {cost:.1f} only (threshold {threshold_k(threshold, effects[k].hypothesis.n_params):.1f})")
        kept = effects[:k] + effects[k + 1:]
        effects = _findings_of(rest, th2, sd2, rss2, s2, N, [e.delta_chi2 for e in kept])
    return effects


def _nested_at_bound(hs, th, rss, sd, hyps, rec, fit, s2, notes):
    """A k-parameter effect that a joint fit drives to a bound of a parameter (an absorber's spring to its
    stiffest: a mass) replaced by its nested one-parameter reading (``Hypothesis.nested``), refitted jointly.
    Returns ``(hypotheses, sizes, rss, stds)``, unchanged when there is nothing to replace."""
    for j, x in enumerate(hs):
        if not (x.params and x.nested and at_bound(x, th[j])):
            continue
        g = next((y for y in hyps if (y.kind, y.element) == x.nested[0]), None)
        if g is None or any(g is y for y in hs):
            continue
        rest, rest_th = hs[:j] + hs[j + 1:], th[:j] + th[j + 1:]
        t0, _ = fit_one_given(rec, fit, rest, rest_th, g)
        hs2 = hs[:j] + [g] + hs[j + 1:]
        th2, rss2, sd2 = joint_fit(rec, fit, hs2, th[:j] + [t0] + th[j + 1:], s2)
        notes.append(f"{x.description} reached the bound of a parameter given the other effects: read as "
                     f"{g.description} (its limit) and refitted")
        return hs2, th2, rss2, sd2
    return hs, th, rss, sd


def _simplify(effects, hyps, rec, fit, s2, N, threshold, notes):
    """Effects with a k-parameter one replaced by its nested one-parameter reading (``Hypothesis.nested``) when,
    fitted jointly with the others, the simpler reading is not worse by more than the chi2_(k-1) threshold
    (a pedestal whose mass the joint fit leaves at zero is a softer spring).  Returns ``effects`` itself when
    nothing is replaced."""
    n_par = sum(e.hypothesis.n_params for e in effects)
    full = _rss_of(Compound(rec, fit, [e.hypothesis for e in effects]).responses([e.theta for e in effects]),
                   fit.meas)
    left = max(1.0, full / (s2 * max(N - n_par, 1)))
    for k, e in enumerate(effects):
        h = e.hypothesis
        if not h.params or not h.nested:
            continue
        others = [x for j, x in enumerate(effects) if j != k]
        base, th = [x.hypothesis for x in others], [x.theta for x in others]
        for key in h.nested:
            g = next((x for x in hyps if (x.kind, x.element) == key), None)
            if g is None:
                continue
            t, _ = fit_one_given(rec, fit, base, th, g)
            th2, rss2, sd2 = joint_fit(rec, fit, base + [g], th + [t], s2)
            if (rss2 - full) / s2 / left >= threshold_k(threshold, h.n_params - 1):
                continue
            notes.append(f"{h.description} reads as {g.description} given the other effects (its "
                         f"{h.n_params - 1} further parameter(s) improve the fit by delta chi2 "
                         f"{(rss2 - full) / s2:.1f} only): the simpler reading is kept")
            score = rss2 / s2 + (n_par - h.n_params + 1) * math.log(N)
            out = []
            for x, t2, d2 in zip(others + [None], th2, sd2):
                xh = g if x is None else x.hypothesis
                vec = np.ndim(t2) > 0
                t0, d0 = (float(t2[0]), float(d2[0])) if vec else (float(t2), float(d2))
                f = Finding(xh.kind, xh.station, xh.element, t0, xh.unit, d0, score,
                            e.delta_chi2 if x is None else x.delta_chi2, xh.description, True, False,
                            None if (xh.gain is not None or xh.added) else xh.nominal + t0, xh)
                if vec:
                    f.values, f.stds = tuple(float(v) for v in t2), tuple(float(v) for v in d2)
                out.append(f)
            return out[:k] + [out[-1]] + out[k:-1]
    return effects


def _data_sets(rec, allf, chans, vchans):
    """(fit, held out, all fitted channels, description of the held-out data)."""
    def data_for(cs, keep):
        idx, meas, H0, b, fs, cols = [], [], [], [], [], {}
        for k, (c, kp) in enumerate(zip(cs, keep)):
            pos = np.searchsorted(allf, c.frf.freq_hz[kp])
            bb = rec.input_vector(c.in_spec)
            Rb = np.einsum("kij,j->ki", rec.R[pos], bb)        # R b at every DOF, shared by all hypotheses
            cols[k] = (Rb, rec.R[pos, c.out_dof, :])
            idx.append(pos)
            meas.append(c.frf.response[kp])
            H0.append(Rb[:, c.out_dof])
            b.append(bb)
            fs.append(c.frf.freq_hz[kp])
        return _Data(list(cs), idx, meas, H0, b, fs, cols)

    every = [np.arange(c.frf.freq_hz.size) for c in chans]
    if vchans:
        fit = data_for(chans, every)
        held = data_for(vchans, [np.arange(c.frf.freq_hz.size) for c in vchans])
        desc = f"{len(vchans)} validation channel(s): " + ", ".join(_src(c.frf, k) for k, c in enumerate(vchans, 1))
    else:
        out = [k[k % HOLDOUT_EVERY == HOLDOUT_EVERY // 2] for k in every]
        kept = [k[k % HOLDOUT_EVERY != HOLDOUT_EVERY // 2] for k in every]
        fit, held = data_for(chans, kept), data_for(chans, out)
        desc = (f"every {HOLDOUT_EVERY}th frequency of the fitted channels, held out of the fit "
                f"(no validation files given; neighbouring frequencies are not independent data)")
    return fit, held, data_for(chans, every), desc


def _screen_all(hyps, rec, fit, s2, N, rss0, threshold, tell) -> list:
    """Every hypothesis fitted exactly through the receptance, ranked by score."""
    findings = []
    nh = len(hyps)
    for k, h in enumerate(hyps):
        if k % max(1, nh // 20) == 0:
            tell(f"screening hypotheses {k + 1}/{nh}", 0.05 + 0.6 * k / nh)
        ev = _Evaluator(rec, fit, h)
        if h.params:                         # k > 1 parameters: a bounded least-squares fit of the vector
            findings.append(_vector_finding(ev, h, s2, rss0, N, threshold, quick=True))
            continue
        theta, rss = _fit_size(ev)
        std = _jacobian_std(ev, theta, s2) if rss < rss0 else math.inf
        findings.append(_finding(h, theta, std, rss, rss0, s2, N, threshold))
    # k-parameter hypotheses were fitted quickly (one start, loose tolerances) at every location; the
    # contenders are fitted in full: the best few of each kind, and any within the threshold of the best
    findings.sort(key=lambda f: f.score)
    best = findings[0].score if findings else math.inf
    per_kind: dict = {}
    for j, f in enumerate(findings):
        h = f.hypothesis
        if h is None or not h.params:
            continue
        per_kind[h.kind] = per_kind.get(h.kind, 0) + 1
        if per_kind[h.kind] <= _FULL_VECTOR_FITS or f.score - best < 2 * threshold:
            full = _vector_finding(_Evaluator(rec, fit, h), h, s2, rss0, N, threshold)
            if full.score <= f.score:
                findings[j] = full
    findings.sort(key=lambda f: f.score)
    return findings


#: k-parameter hypotheses of each kind fitted in full after the screen's quick pass
_FULL_VECTOR_FITS = 3


def _vector_finding(ev, h, s2, rss0, N, threshold, quick=False):
    theta, rss, stds = _fit_vector(ev, s2, quick=quick)
    f = _finding(h, theta[0], stds[0], rss, rss0, s2, N, threshold)
    f.values, f.stds = tuple(float(x) for x in theta), tuple(float(x) for x in stds)
    return f


def _refit_best(findings, refit, model_text, path, eng, fit, s2, N, rss0, threshold, tell) -> list:
    """Refit the best few on the extended model file itself (with modal damping the damping matrix follows
    the changed stiffness and mass there, unlike in the screen); returns notes on refits that failed."""
    notes, n_ref = [], 0
    left = (findings[0].score - math.log(N)) / N if findings else 0.0
    if left > 10:
        # no single hypothesis comes near the noise: the refit's small correction of a size is not what
        # decides this diagnosis (its cost is: a tune per hypothesis)
        notes.append(f"the best single hypothesis leaves {left:.3g} times the noise's misfit: sizes are the "
                     "screen's, not refitted on the extended model")
        return notes
    for f in findings:
        if n_ref >= refit:
            break
        if f.delta_chi2 <= 0.5 * threshold:      # cannot become significant: no need to refit
            continue
        h = f.hypothesis
        if h.gain is not None or h.parameter is None:
            continue
        n_ref += 1
        stage, at = f"refitting {f.kind} at {f.station} on the extended model", 0.7 + 0.2 * n_ref / max(refit, 1)
        tell(stage, at)
        try:
            _refit(f, model_text, path, eng, fit, s2, N, rss0, threshold,
                   progress=lambda line, _, stage=stage, at=at: tell(f"{stage}: {line}", at))
        except Exception as exc:   # the screen's value stands; say why
            notes.append(f"refit of {f.kind} at station {f.station} failed ({exc}); the screen's value is shown")
    return notes


def _decide(findings, none, threshold, N, rec, fit, eng, notes, held, s2):
    """The verdict (the best significant hypothesis, or none), those it cannot be told from, and the
    sensor station that would separate them; notes are appended to ``notes``.

    Among hypotheses the fitted data cannot tell apart, the held-out data decide when they can (one
    fits them better by more than chi2_1(0.95) noise units): e.g. a sensor's gain and the scale of its
    one fitted file are the same on the fitted data, not on other files of that sensor."""
    best = next((f for f in findings if f.kind != "none" and not f.at_bound),
                next(f for f in findings if f.kind != "none"))
    verdict = best if best.significant else none
    if verdict is none:
        if best.delta_chi2 > 0:
            notes.append(f"best hypothesis ({best.description}) improves the fit by delta chi2 = "
                         f"{best.delta_chi2:.1f}, below the threshold {threshold:.1f}")
        return verdict, [], None
    tie = float(sst.chi2.isf(0.05, 1))
    ambiguous = [f for f in findings if f is not verdict and f.kind != "none" and f.significant
                 and (f.score - verdict.score) < tie]
    if ambiguous:
        held_rss = {id(f): _rss_of(Compound(rec, held, [f.hypothesis]).responses([f.theta]), held.meas)
                    for f in [verdict] + ambiguous}
        alt = min(ambiguous, key=lambda f: held_rss[id(f)])
        if (held_rss[id(verdict)] - held_rss[id(alt)]) / s2 > tie:
            notes.append(f"{alt.description} and {verdict.description} fit the fitted data equally; the "
                         f"held-out data prefer {alt.description}")
            ambiguous = [verdict] + [f for f in ambiguous if f is not alt]
            verdict = alt
    sensor = _separating_station(rec, fit, [verdict] + ambiguous, eng) if ambiguous else None
    return verdict, ambiguous, sensor


def _after(verdict, text, path, rec, chans, all_fit, held):
    """Responses of the extended model on the fitted channels and on the held-out data."""
    if verdict.kind == "none":
        return None, held.H0
    if verdict.hypothesis.gain is not None or verdict.hypothesis.glob is not None:
        return (_Evaluator(rec, all_fit, verdict.hypothesis).responses(verdict.value),
                _Evaluator(rec, held, verdict.hypothesis).responses(verdict.value))
    # the extended model file itself, loaded as a user would load it
    ext = loads_model(text, source=f"{path} (extended)", base_dir=os.path.dirname(os.path.abspath(path)))
    return ([model_response(ext, c.frf) for c in chans],
            [model_response(ext, c.frf, freq_hz=fs) for c, fs in zip(held.chans, held.freq_hz)])


def _finding(h, theta, std, rss, rss0, s2, N, threshold) -> Finding:
    dchi = (rss0 - rss) / s2
    new = None
    if h.gain is None and not h.added:
        new = h.nominal + theta
    return Finding(h.kind, h.station, h.element, float(theta), h.unit, float(std),
                   rss / s2 + h.n_params * math.log(N), float(dchi), h.description,
                   bool(dchi > threshold_k(threshold, h.n_params)), False, new, h)


def threshold_k(threshold: float, k: int) -> float:
    """The delta chi2 threshold of a k-parameter hypothesis at the false-alarm rate of the one-parameter
    ``threshold`` (the same tail probability of chi2 with k degrees of freedom)."""
    return threshold if k == 1 else float(sst.chi2.isf(sst.chi2.sf(threshold, 1), k))
