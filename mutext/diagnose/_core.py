"""The entry point :func:`diagnose`."""
from __future__ import annotations

import logging
import math
import os
import time
from dataclasses import dataclass, field, replace
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
from ._amplitude import describe_levels, level_test, pair_channels, pair_noise
from ._screen import _Data, _Evaluator, _Receptance, _fit_size, _fit_vector, _jacobian_std, _rss
from ._decision import _decide, _finding, _in_model_file, _judge, _select_more, _status
from ._select import Compound

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


def diagnose(model, frfs, validate=None, *, repeat=None, alpha: float = 0.01, refit: int = 3,
             noise: float | None = None, out_dir=None, progress: Callable[[str, float], None] | None = None,
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
    repeat : sequence of FRF or paths, optional
        The same channels measured again at another excitation level (force
        amplitude), on the same frequencies (those both hold are compared).
        A nonlinear structure answers each level differently, which no
        linear hypothesis can hold: each channel is compared with its
        measured twin, without a model, a chi-square test at ``alpha`` against
        both sets' noise (:mod:`mutext.diagnose._amplitude`).  When the levels
        differ beyond the noise, the verdict says so first and the status is at
        most *partly explained* (when the final model fits the lower-level
        data; else *not explained*); otherwise a note says the repeat agreed.
        The repeat is not fitted.  A file's excitation level (header key
        ``excitation``, e.g. ``# excitation: 2 N``) is reported when given.
        ``Diagnosis.amplitude`` holds the test.
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
        try:
            return _diagnose(model, frfs, validate, alpha, refit, noise, out_dir, progress, only, mbi, repeat)
        finally:
            _EXTENDED.clear()


@dataclass
class _Reading:
    """What the first step of :func:`diagnose` reads and every later step uses.

    ``path``, ``eng``, ``model_text``: the model file, its model and its text; ``chans``, ``vchans``: the
    fitted and the validation channels; ``speed``: their running speed (rad/s); ``ref``: the noise
    reference, ``s2`` the noise variance of one real number; ``rec``: the engineering model's receptance on
    one grid for all; ``fit``, ``held``, ``all_fit``: the fitted, held-out and all fitted data sets;
    ``held_desc``: what the held-out data are; ``pairs``: the channels repeated at another excitation
    level with their measured twins (:func:`mutext.diagnose._amplitude.pair_channels`), ``rref`` the noise
    of one sweep estimated from both (:func:`mutext.diagnose._amplitude.pair_noise`)."""
    path: str
    eng: object
    model_text: str
    chans: list
    vchans: list
    speed: float
    ref: object
    s2: float
    rec: object
    fit: object
    held: object
    all_fit: object
    held_desc: str
    pairs: list = field(default_factory=list)
    rref: object = None


def _diagnose(model, frfs, validate, alpha, refit, noise, out_dir, progress, only, mbi, repeat=None) -> Diagnosis:
    """:func:`diagnose`, step by step (its arguments in the same order)."""
    t0 = time.perf_counter()

    def tell(stage, frac):
        log.info("%s (%.0f %%)", stage, 100 * frac)
        if progress is not None:
            progress(stage, frac)

    d, notes = _read(model, frfs, validate, alpha, noise, tell, repeat)
    # 1. what the simulation gets wrong
    before, rows, summary, unmatched = _what_is_wrong(d)
    # 2. the hypotheses, screened, the best refitted on the extended model, the verdict
    hyps, N, rss0, threshold, findings = _screened(d, alpha, refit, only, notes, tell)
    d.rec.release()
    none, verdict, ambiguous, sensor = _verdict(d, findings, N, rss0, threshold, notes)
    # 3. goodness of fit; further effects while the residual stays above the noise
    effects, quality, first, verdict = _selection(d, verdict, none, hyps, N, threshold, alpha, notes, tell)
    # 4. the extended model and its gain on held-out data
    text, quality, err_before, err_after, gain, comps, held_quality, status = _held_out(
        d, verdict, none, effects, quality, first, before, alpha, notes, tell)
    # where the misfit of the fitted data lives: asked of the status those data give
    localized = _localized(d, status, notes, tell)
    # 4b. the same channels at another excitation level: amplitude dependence
    amplitude, status = _amplitude_dependence(d, status, comps, effects, alpha, notes, tell)
    result = Diagnosis(d.eng.name, d.path, d.ref.sigma, findings, verdict, ambiguous, sensor, err_before, err_after,
                       gain, d.held_desc, comps, rows, summary, threshold, alpha, len(hyps), text,
                       time.perf_counter() - t0, notes, N, status=status, effects=effects, fit_quality=quality,
                       noise_reference=d.ref, unmatched=unmatched, localized=localized,
                       held_quality=held_quality, amplitude=amplitude)
    # 5. data taken at speed: sidebands, a crack turning with the shaft
    _at_speed(result, d, effects, text, findings, verdict, err_after, rss0, tell, t0)
    # 6. model-based identification at the finding, or where the misfit lives
    _mbi_fallback(result, d, mbi, verdict, none, localized, err_before, alpha, tell, t0)
    if out_dir is not None:
        write_model(result, out_dir)
    tell("done", 1.0)
    return result


def _read(model, frfs, validate, alpha, noise, tell, repeat=None):
    """The model file and the data, checked; the noise level; the engineering model's receptance and the data
    sets: ``(reading, notes on the inputs)``."""
    # a rotor's model is built (symbolic finite elements) while the files are read: seconds to tens of seconds
    tell("reading the model file and the data (a rotor's finite elements are built here)", 0.0)
    path, eng, model_text, chans, vchans, speed, input_notes, pairs = _inputs(model, frfs, validate, alpha, repeat)
    tell("noise level of the data (model-free rational fits)", 0.01)
    ref = noise_reference(chans, _noise(noise))
    rref = None
    if pairs:
        tell("noise level of the repeat at another excitation level", 0.015)
        rref = pair_noise(pairs, _noise(noise))
    s2 = ref.sigma ** 2 / 2.0
    tell("engineering model's receptance", 0.02)
    allf = np.unique(np.concatenate([c.frf.freq_hz for c in chans + vchans]))    # one grid for all
    rec = _Receptance(eng, None, speed, 2 * np.pi * allf)
    fit, held, all_fit, held_desc = _data_sets(rec, allf, chans, vchans)
    reading = _Reading(path, eng, model_text, chans, vchans, speed, ref, s2, rec, fit, held, all_fit, held_desc,
                       pairs, rref)
    return reading, input_notes


def _what_is_wrong(d):
    """What the simulation gets wrong: ``(the model's responses on the fitted channels, the resonance table,
    its summary, the unmatched resonances)``."""
    before = d.all_fit.H0
    unmatched: dict = {}
    rows = _resonance_table(d.chans, before, d.eng, d.speed, d.ref.sigma, unmatched)
    unmatched["measured"] = _group_unmatched(unmatched.get("measured", []))
    summary = _summary(rows, d.chans, before)
    return before, rows, summary, unmatched


def _screened(d, alpha, refit, only, notes, tell):
    """The hypotheses screened and the best few refitted on the extended model (notes on failed refits go to
    ``notes``): ``(hypotheses, number of real data N, rss of the engineering model, threshold, findings)``."""
    hyps = hypotheses(d.eng) + _channel.candidates(d.eng, d.chans) + _structure.candidates(d.eng)
    if only is not None:
        hyps = [h for h in hyps if only(h)]
        if not hyps:
            raise ModelError("diagnose: no hypothesis passes the 'only' filter")
    N = 2 * d.fit.n_points
    rss0 = _rss(d.fit.H0, d.fit.meas)
    threshold = float(sst.chi2.isf(alpha / len(hyps), 1))
    findings = _screen_all(hyps, d.rec, d.fit, d.s2, N, rss0, threshold, tell)
    notes += _refit_best(findings, refit, d.model_text, d.path, d.eng, d.fit, d.s2, N, rss0, threshold, tell)
    return hyps, N, rss0, threshold, findings


def _verdict(d, findings, N, rss0, threshold, notes):
    """Each finding judged, "no effect" ranked among them, the verdict decided: ``(the "none" finding, the
    verdict, those it cannot be told from, the sensor station that would separate them)``."""
    for f in findings:
        _judge(f, N, threshold)
    for f in findings[:5]:
        if f.at_bound:
            notes.append(f"{f.description} fits best at the bound of its range ({f.size_text(std=False)}): "
                         "not accepted (the data ask for more than the hypothesis allows)")
    none = Finding("none", None, None, 0.0, "", 0.0, rss0 / d.s2, 0.0, "no effect beyond the noise")
    findings.sort(key=lambda f: f.score)
    findings.insert(next((i for i, f in enumerate(findings) if f.score > none.score), len(findings)), none)
    verdict, ambiguous, sensor = _decide(findings, none, threshold, N, d.rec, d.fit, d.eng, notes, d.held, d.s2)
    return none, verdict, ambiguous, sensor


def _selection(d, verdict, none, hyps, N, threshold, alpha, notes, tell):
    """Further effects while the residual stays above the noise: ``(effects, fit quality of the last model,
    fit quality of the first effect's model file or None, verdict)``."""
    effects = [] if verdict is none else [verdict]
    first = None
    if _in_model_file(verdict):
        # the model file with the finding is what the user receives (with modal damping its damping follows
        # the change, which the screen holds fixed): judged on its own responses
        first = _quality_of_file(verdict, d.model_text, d.eng, d.path, d.rec, d.chans, d.all_fit, d.held, d.s2,
                                 d.ref, alpha)
    effects, quality = _select_more(effects, hyps, d.rec, d.fit, d.held, d.s2, N, threshold, alpha, d.ref, notes,
                                    tell, first)
    if len(effects) > 1:
        verdict = effects[0]
    return effects, quality, first, verdict


def _held_out(d, verdict, none, effects, quality, first, before, alpha, notes, tell):
    """The extended model and its gain on held-out data: ``(extended model text, fit quality, errors before
    and after, gain, channel comparisons, held-out fit quality, status)``."""
    tell("held-out gain", 0.95)
    text = None
    if effects:
        text = d.model_text
        for e in effects:
            text = extended_model_text(text, e, d.eng)
    if len(effects) > 1:
        comp = [e.hypothesis for e in effects], [e.theta for e in effects]
        after_all = Compound(d.rec, d.all_fit, comp[0]).responses(comp[1])
        after_held = Compound(d.rec, d.held, comp[0]).responses(comp[1])
    else:
        after_all, after_held = _after(verdict, text, d.path, d.rec, d.chans, d.all_fit, d.held)
        if _in_model_file(verdict):
            quality = first
    held = d.held
    err_before = _errors(held.H0, held.meas)
    err_after = _errors(after_held, held.meas)
    gain = err_before["rel"] / err_after["rel"] if err_after["rel"] > 0 else math.inf
    comps = [ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response, before[k],
                               None if after_all is None else after_all[k], "fit") for k, c in enumerate(d.chans)]
    comps += [ChannelComparison(c.label, _src(c.frf, k + 1), c.frf.freq_hz, c.frf.response, held.H0[k],
                                None if verdict is none else after_held[k], "validate")
              for k, c in enumerate(d.vchans)]
    with np.errstate(all="ignore"):
        held_quality = fit_quality([np.log(h / m) for h, m in zip(after_held, held.meas)], held.freq_hz,
                                   [c.label for c in held.chans], d.s2, 0, d.ref, alpha)
    status = _status(effects, quality, gain, held_quality)
    _held_out_notes(effects, quality, held_quality, gain, status, notes)
    return text, quality, err_before, err_after, gain, comps, held_quality, status


def _held_out_notes(effects, quality, held_quality, gain, status, notes) -> None:
    """Notes on a misfit left on the fitted or the held-out data (the effects' stds inflated by it)."""
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


def _amplitude_dependence(d, status, comps, effects, alpha, notes, tell):
    """The same channels at another excitation level compared (:mod:`mutext.diagnose._amplitude`): ``(the
    test or None, the status)``.  Levels that differ beyond the noise make the status at most *partly
    explained*: when the final model fits the lower-level data (the fitted data unless the files say the
    repeat is lower); otherwise *not explained*.  The first note says so."""
    if not d.pairs:
        return None, status
    tell("the repeated sweeps at another excitation level (amplitude dependence)", 0.952)
    test = level_test(d.pairs, d.rref, alpha)
    reps = list({id(p.rep): p.rep for p in d.pairs}.values())
    describe_levels(test, [c.frf for c in d.chans + d.vchans], [r.frf for r in reps])
    test.files = [_src(r.frf, k) for k, r in enumerate(reps, start=1)]
    if not test.significant:
        notes.append(test.sentence())
        return test, status
    if test.lower == "repeat":
        # the final model on the repeat's lines (the lower level): at the noise there?
        model_of = {id(c): (cmp.after if cmp.after is not None else cmp.before)
                    for c, cmp in zip(d.chans + d.vchans, comps)}
        with np.errstate(all="ignore"):
            rs = [np.log(model_of[id(p.chan)][p.ia] / p.rep.frf.response[p.ib]) for p in d.pairs]
        q = fit_quality(rs, [p.chan.frf.freq_hz[p.ia] for p in d.pairs], [p.chan.label for p in d.pairs],
                        d.rref.sigma ** 2 / 2.0, len(effects), d.rref, alpha)
        fits, where = q.at_noise, "the repeat's (lower-level) data"
    else:
        fits, where = status == "explained", "the fitted data" + (" (the lower level)" if test.lower else "")
    new = "partly explained" if fits else "not explained"
    what = "; ".join(e.sentence() for e in effects) or "the engineering model"
    notes.insert(0, f"{test.sentence()}. No linear time-invariant model holds at both levels: "
                 + (f"{what} fits {where} at the noise, a linearisation at that level, not the cause"
                    if fits else f"the best linear model ({what}) does not fit {where} at the noise")
                 + ("; the extended model is written as not confirmed" if effects else ""))
    return test, new


def _localized(d, status, notes, tell):
    """Where the misfit lives (an impedance at each station) when the data are not explained, or None."""
    localized = None
    if status != "explained":
        tell("where the misfit lives (an impedance at each station)", 0.955)
        from ._localize import describe, localize
        localized = localize(d.rec, d.fit, d.held, d.eng, d.s2)
        if localized is not None:
            notes.append(describe(localized))
    return localized


def _at_speed(result, d, effects, text, findings, verdict, err_after, rss0, tell, t0) -> None:
    """Data taken at speed on a rotor: the sideband evidence, a crack turning with the shaft when the
    sidebands call for one, and whether the time-periodic claim is made (all into ``result``)."""
    if d.speed > 0 and hasattr(d.eng, "n_stations"):
        # where to look: the modes of the best time-invariant model (a mode the engineering model misplaces
        # is not a sideband)
        best_ti = d.eng
        if text is not None and any(e.hypothesis.gain is None for e in effects):
            try:
                best_ti = _extended(text, d.path)
            except ModelError:
                pass
        result.sidebands = _sidebands(best_ti, d.speed, d.chans)
        if result.sidebands and result.sidebands["verdict"] != "none" and d.model_text is not None:
            tell("a crack that turns with the shaft, at the best crack station (time-periodic fit)", 0.96)
            result.breathing = _breathing(findings, result.sidebands, d.model_text, d.path, d.speed, d.chans,
                                          d.fit, d.held, d.s2, rss0, verdict, err_after, result.notes)
            result.seconds = time.perf_counter() - t0
        _sideband_claim(result)


def _mbi_fallback(result, d, mbi, verdict, none, localized, err_before, alpha, tell, t0) -> None:
    """With ``mbi``: model-based identification at the verdict or, not explained on a lumped chain, where
    the misfit lives, the controller then written as an element of the model (all into ``result``)."""
    at = verdict
    if mbi and localized is not None and d.eng.layout.kind == "lumped":
        # not explained: the thesis's controller goes where the misfit lives, read against that element
        h = Hypothesis("mass", localized["station"], None, f"element at station {localized['station']}", "kg",
                       True, 0.0, math.inf, 1.0, [localized["dof"]])
        at = Finding("mass", localized["station"], None, localized["msd"]["m"], "kg", math.inf, 0.0, 0.0,
                     h.description, hypothesis=h)
    if not (mbi and at is not none):
        return
    tell("model-based identification at the finding (D-K iteration)", 0.97)
    # the controller is tuned on the first channel's fitted lines only: the held-out lines, on which the
    # element it becomes is judged, stay unseen
    fit = d.fit
    k0 = 0 if at is verdict else _channel_at(fit.chans, at.station)
    c0 = fit.chans[k0]
    seen = replace(c0.frf, freq_hz=fit.freq_hz[k0], response=fit.meas[k0], metadata=dict(c0.frf.metadata))
    try:
        result.mbi, res, E = _identify_at(d.model_text, d.path, at, seen, c0.in_name, c0.out_name,
                                          progress=lambda stage, frac: tell(
                                              f"model-based identification: {stage}", 0.97 + 0.02 * frac))
    except ModelError as exc:
        result.mbi = {"location": None, "reading": f"not run: {exc}", "agrees": None}
    else:
        if at is not verdict:
            # nothing the hypotheses name explains the data: K itself becomes the element of the model
            tell("the controller as an element of the model, judged on the held-out data", 0.99)
            try:
                result.mbi.update(mbi_element(result.mbi, res, E, d.model_text, d.eng, localized["station"],
                                              localized["dof"], d.rec, d.held, d.s2, d.ref, alpha, seen,
                                              c0.in_name, c0.out_name, err_before))
            except ModelError as exc:
                result.mbi["element"] = None
                result.notes.append(f"the controller was not written as an element: {exc}")
    result.seconds = time.perf_counter() - t0




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


def _inputs(model, frfs, validate, alpha, repeat=None):
    """The model file and the channels, checked: (path, model, text, fit channels, held-out channels, speed,
    notes, the repeated channels paired with their measured twins)."""
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
    rep_frfs = _as_frfs(repeat)
    for group, what in ((fit_frfs, "measured"), (val_frfs, "validation"), (rep_frfs, "repeated")):
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
    for r in rep_frfs:
        for f in fit_frfs + val_frfs:
            if _same_data(r, f):
                raise ModelError(f"repeat {_src(r, 0)} holds the same data as {_src(f, 0)}: a repeat is a new "
                                 "measurement of the channel at another excitation level")
    notes: list = []
    if eng.layout.kind == "lumped":
        # a chain moves along one direction: a file's Y (an analyser's default axis) is that direction
        fit_frfs, val_frfs = _along_the_chain(fit_frfs, notes), _along_the_chain(val_frfs, notes)
        rep_frfs = _along_the_chain(rep_frfs, notes)
    for k, f in enumerate(fit_frfs + val_frfs + rep_frfs, start=1):
        for n in (f.metadata.get("notes") or []):
            notes.append(f"{_src(f, k)}: {n}")
        if f.metadata.get("conversion"):
            notes.append(f"{_src(f, k)}: {f.metadata['conversion']}")
    chans, _ = _resolve(eng, fit_frfs, "data")
    vchans, _ = _resolve(eng, val_frfs, "validation") if val_frfs else ([], None)
    # the repeat at another excitation level: each channel with its measured twin (errors name the file)
    pairs = pair_channels(chans + vchans, _resolve(eng, rep_frfs, "repeat")[0]) if rep_frfs else []
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
    return path, eng, model_text, chans, vchans, speed, list(dict.fromkeys(notes)), pairs


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


def _quality_of_file(verdict, model_text, eng, path, rec, chans, all_fit, held, s2, ref, alpha):
    """The lack-of-fit test of the extended model file itself, on every fitted line."""
    text = extended_model_text(model_text, verdict, eng)
    after_all, _ = _after(verdict, text, path, rec, chans, all_fit, held)
    with np.errstate(all="ignore"):
        r = [np.log(h / m) for h, m in zip(after_all, all_fit.meas)]
    return fit_quality(r, all_fit.freq_hz, [c.label for c in all_fit.chans], s2, verdict.hypothesis.n_params, ref,
                       alpha)


def _data_sets(rec, allf, chans, vchans):
    """(fit, held out, all fitted channels, description of the held-out data)."""
    def data_for(cs, keep):
        idx, meas, H0, b, fs, cols = [], [], [], [], [], {}
        for k, (c, kp) in enumerate(zip(cs, keep)):
            pos = np.searchsorted(allf, c.frf.freq_hz[kp])
            bb = rec.input_vector(c.in_spec)
            if rec.modal is None:
                Rb = rec.apply(pos, bb)             # R b at every DOF, shared by all hypotheses
                cols[k] = (Rb, rec.row(pos, c.out_dof))
                H0.append(Rb[:, c.out_dof])
            else:
                # from the modes: the response alone; the column and the row a hypothesis needs are formed
                # when first asked for (_Data.columns)
                H0.append(rec.modal.apply(rec.omega[pos], np.asarray(bb, float), rows=[c.out_dof])[:, 0])
            idx.append(pos)
            meas.append(c.frf.response[kp])
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
    # with validation files every fitted line is fitted: the fitted set is all of them (its receptance
    # pieces held once)
    return fit, held, fit if vchans else data_for(chans, every), desc


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


def _after(verdict, text, path, rec, chans, all_fit, held):
    """Responses of the extended model on the fitted channels and on the held-out data."""
    if verdict.kind == "none":
        return None, held.H0
    if verdict.hypothesis.gain is not None or verdict.hypothesis.glob is not None:
        return (_Evaluator(rec, all_fit, verdict.hypothesis).responses(verdict.value),
                _Evaluator(rec, held, verdict.hypothesis).responses(verdict.value))
    # the extended model file itself, loaded as a user would load it
    ext = _extended(text, path)
    if getattr(rec, "modal", None) is not None:
        # a rotor: the extended model's receptance from its own modes, the channels resolved on it
        # (what model_response gives, without a dense solve at every frequency)
        w_all = np.unique(np.concatenate([2 * np.pi * np.asarray(c.frf.freq_hz, float) for c in chans]
                                         + [2 * np.pi * np.asarray(f, float) for f in held.freq_hz]))
        speeds = {c.speed for c in chans} | {c.speed for c in held.chans}
        if len(speeds) == 1:
            rx = _Receptance(ext, None, speeds.pop(), w_all)
            if rx.modal is not None:
                fit_ch, _ = _resolve(ext, [c.frf for c in chans], "data")
                held_ch, _ = _resolve(ext, [c.frf for c in held.chans], "validation")
                return ([rx.channel(c, c.frf.freq_hz) for c in fit_ch],
                        [rx.channel(c, fs) for c, fs in zip(held_ch, held.freq_hz)])
    return ([model_response(ext, c.frf) for c in chans],
            [model_response(ext, c.frf, freq_hz=fs) for c, fs in zip(held.chans, held.freq_hz)])


#: The extended model file of the diagnosis under way, loaded once (its effect is judged, written, and its
#: modes looked at): ``(text, path) -> model``, cleared when the diagnosis ends.
_EXTENDED: dict = {}


def _extended(text, path):
    """The extended model ``text`` (next to the model file ``path``), loaded as a user would load it."""
    key = (text, os.path.abspath(path))
    if key not in _EXTENDED:
        _EXTENDED.clear()
        _EXTENDED[key] = loads_model(text, source=f"{path} (extended)",
                                     base_dir=os.path.dirname(os.path.abspath(path)))
    return _EXTENDED[key]


