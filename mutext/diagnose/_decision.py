"""The decisions of :func:`mutext.diagnose.diagnose`: each finding judged significant or not, the verdict
among the screened hypotheses, the forward and backward selection of further effects, and the status
(explained, partly explained, not explained)."""
from __future__ import annotations

import math

import numpy as np
import scipy.stats as sst

from ._fit_quality import fit_quality
from ._result import PARTLY_GAIN, Finding
from ._screen import _separating_station
from ._select import MAX_EFFECTS, Compound, _rss_of, at_bound, fit_one_given, joint_fit


def threshold_k(threshold: float, k: int) -> float:
    """The delta chi2 threshold of a k-parameter hypothesis at the false-alarm rate of the one-parameter
    ``threshold`` (the same tail probability of chi2 with k degrees of freedom)."""
    return threshold if k == 1 else float(sst.chi2.isf(sst.chi2.sf(threshold, 1), k))


def _finding(h, theta, std, rss, rss0, s2, N, threshold) -> Finding:
    dchi = (rss0 - rss) / s2
    new = None
    if h.gain is None and not h.added:
        new = h.nominal + theta
    return Finding(h.kind, h.station, h.element, float(theta), h.unit, float(std),
                   rss / s2 + h.n_params * math.log(N), float(dchi), h.description,
                   bool(dchi > threshold_k(threshold, h.n_params)), False, new, h)


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


def _status(effects, quality, gain, held_quality) -> str:
    """Explained: the fitted and the held-out data at the noise (and, with effects, the held-out data better
    than before); partly: effects that remove at least half of the held-out misfit (:data:`PARTLY_GAIN`),
    a residual above the noise; otherwise not explained."""
    # a channel's scale acts on its own file only: other files cannot confirm it, only not contradict it
    better = gain > 1 or (bool(effects) and all(e.kind == "channel_scale" for e in effects) and gain >= 1 - 1e-9)
    if quality.at_noise and held_quality.at_noise:
        return "explained" if (not effects or better) else "not explained"
    return "partly explained" if (effects and gain >= PARTLY_GAIN) else "not explained"


def _in_model_file(f) -> bool:
    """Whether a finding is a structural change written into the model file (not a correction of the data)."""
    h = f.hypothesis
    return f.kind != "none" and h is not None and h.gain is None and h.glob is None


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
            tried.append((not ok, rss_new, h, th, sd, dchi, dheld, stuck, left, hs, held_new))
        tried.sort(key=lambda x: (x[0], x[1]))
        if not tried[0][0]:
            # candidates the fitted data cannot tell apart (within one unit of chi2: a sensor's gain and the
            # scale of the one fitted file it is in) are decided by the held-out data
            level = [x for x in tried if not x[0] and (x[1] - tried[0][1]) / s2 < 1.0]
            best = min(level, key=lambda x: x[10])
            tried.remove(best)
            tried.insert(0, best)
        failed, rss_new, h, th, sd, dchi, dheld, stuck, left, hs, _ = tried[0]
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

