r"""A breathing crack fitted to data taken at speed (after the sidebands say the rotor is time-periodic).

The time-invariant hypotheses of the screen can place a crack but fit it as
a crack held still, its normal facing :math:`x` (not turning with the shaft,
and not its stiffness averaged over a revolution either: the two read
different depths), and they leave the sidebands unexplained.  When the sideband evidence says the stiffness changes with
the rotation, this step fits the depth :math:`a/D` of a crack that turns with
the shaft (breathing law ``mayes`` or ``gasch`` for once-per-revolution
sidebands, ``open`` for twice-per-revolution ones) at the crack station the
screen ranked best, through the analyzer's response of the time-periodic
rotor (:func:`mutext.rotor.periodic.analyzer_frf`), on the same complex log
misfit as the screen.  The crack is assumed to face :math:`x` at
:math:`t = 0` (the phase of the rotor at the start of each step is not in the
data files).

The Ritz basis is computed once, at a mid depth, and the model at every
other depth is projected on it; its error at the fitted depth is measured
against the full model and reported.

The harmonic balance is truncated at the analyzer's default N = 6 at every
depth tried; its truncation error at the fitted depth is estimated
(:func:`mutext.rotor.periodic.analyzer_truncation`, from N = 12 and 24) and
reported as ``truncation_error`` (relative to the peak): 1e-4 to 1e-3 for the
Mayes law, but several percent for the Gasch law, whose harmonics fall like
1/m, so a Gasch fit can be off by more than the noise.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.optimize import minimize_scalar

from ..errors import ModelError

NAME = "breathing_crack"


def a_fmt(a: float) -> str:
    return f"{a:.4g}"


def _model(model_text, base_dir, station, law):
    from ..rotor import loads_model
    extra = (f"\n[[crack]]\nname = \"{NAME}\"\nstation = {int(station)}\ndepth_ratio = 0.25\n"
             f"breathing = \"{law}\"\n")
    return loads_model(model_text + extra, source=f"model + breathing crack at {station}", base_dir=base_dir)


def fit_breathing_crack(model_text: str, base_dir: str, station: int, speed: float, chans, fit, held,
                        s2: float, laws=("mayes", "gasch"), rss_time_invariant: float | None = None) -> dict:
    """Depth of a breathing crack at ``station`` fitted to the ``fit`` data; its held-out error.

    ``chans`` are the diagnosis's channels (port names ``in_name``/``out_name``),
    ``fit`` and ``held`` its data sets, ``s2`` the noise variance of one real
    residual.  Returns a dict for :attr:`mutext.diagnose.Diagnosis.breathing`.
    """
    from ..rotor.periodic import analyzer_frf, analyzer_truncation, periodic_rotor
    from ._compare import _errors
    from ._screen import _rss
    t0 = time.perf_counter()
    ins = sorted({c.in_name for c in chans})
    outs = sorted({c.out_name for c in chans})
    best = None
    tried = []
    allf = np.unique(np.concatenate(list(fit.freq_hz) + list(held.freq_hz)))
    for law in laws:
        model = _model(model_text, base_dir, station, law)
        # the basis alone: its error is measured below, at the fitted depth
        basis = periodic_rotor(model, inputs=ins, outputs=outs, speed=speed).ritz_basis(1000.0)

        def responses(a, data):
            pr = periodic_rotor(model, inputs=ins, outputs=outs, speed=speed,
                                values={f"{NAME}.depth_ratio": float(a)}).project(basis)
            H = analyzer_frf(pr, allf)
            out = []
            for c, f in zip(chans, data.freq_hz):
                pos = np.searchsorted(allf, f)
                out.append(H(c.out_name, c.in_name)[pos])
            return out

        def rss(a):
            return _rss(responses(a, fit), fit.meas)

        res = minimize_scalar(rss, bounds=(0.005, 0.5), method="bounded", options={"xatol": 2e-4})
        a = float(res.x)
        h = max(1e-3, 1e-2 * a)
        curv = (rss(min(a + h, 0.5)) - 2 * res.fun + rss(max(a - h, 0.0))) / h**2
        std = float(np.sqrt(2.0 * s2 / curv)) if curv > 0 else float("nan")
        # the projected model's error at the fitted depth, against the full model
        full = periodic_rotor(model, inputs=ins, outputs=outs, speed=speed, values={f"{NAME}.depth_ratio": a})
        fr = np.unique(np.concatenate(list(fit.freq_hz)))[::10]
        Hf = analyzer_frf(full, fr).H
        Hp = analyzer_frf(full.project(basis), fr).H
        proj_err = float(np.max(np.abs(Hp - Hf) / np.max(np.abs(Hf), axis=-1, keepdims=True)))
        trunc_err = analyzer_truncation(full.project(basis), fr, harmonics=6).error
        row = {"law": law, "depth_ratio": a, "depth_std": std, "rss": float(res.fun),
               "evaluations": int(res.nfev), "projection_error": proj_err, "truncation_error": trunc_err}
        tried.append(row)
        if best is None or row["rss"] < best[0]["rss"]:
            best = (row, responses(a, held))
        if row["rss"] / s2 / max(2 * fit.n_points, 1) < 1.5:
            break           # at the noise already: the other laws cannot do better than noise
    row, held_resp = best
    n = 2 * fit.n_points
    out = dict(row)
    out.update({
        "station": int(station), "element": f"shaft element {station}-{station + 1}",
        "misfit_left": row["rss"] / s2 / max(n, 1),
        "delta_chi2_vs_time_invariant": None if rss_time_invariant is None else (rss_time_invariant - row["rss"]) / s2,
        "held_out_error": _errors(held_resp, held.meas),
        "laws_tried": tried,
        "model_addition": (f"[[crack]]\nstation = {int(station)}\ndepth_ratio = {a_fmt(row['depth_ratio'])}\n"
                           f"breathing = \"{row['law']}\"\n"),
        "seconds": time.perf_counter() - t0,
    })
    if not np.isfinite(out["depth_std"]):
        raise ModelError("breathing crack: the misfit is flat in the depth; no size can be read")
    return out
