"""The extended model file, its refit with tune(), and the thesis's reading by model-based identification."""
from __future__ import annotations

import math
import os
import time
from dataclasses import replace
from ..errors import ModelError
from ..response import FRF
from ..rotor.model import loads_model
from ..rotor.model_writer import ModelFile
from ..rotor.tuning import DB_PER_NEPER, tune
from ._hypotheses import write_finding
from ._result import Diagnosis, Finding
from ._screen import _Data
from .faults import structure as _structure

def extended_model_text(model_text: str, finding: Finding, model) -> str:
    """The model file's text with the finding built in (a comment names the finding).

    The edit is structural (:class:`mutext.rotor.model_writer.ModelFile`): the value is set in the table
    the finding names, or a table is appended; the user's comments and layout are kept."""
    h = finding.hypothesis
    note = f"mutext diagnose: {finding.sentence()}"
    header = f"# Extended by mutext diagnose: {finding.sentence()}\n"
    if h is None or finding.kind == "none":
        return model_text
    if h.glob is not None:
        return header + _structure.model_text(model_text, finding, note)
    if finding.kind in ("sensor_gain", "channel_scale", "sensor_delay", "sensor_mass"):
        return header + "# (a correction of the measurement: the model itself is unchanged)\n" + model_text
    if h.kind == "exciter_gain":
        st = h.gain[1]
        port = model.inputs[st[1]] if (model.layout.kind != "lumped" and st[0] == "port") else None
        if port is None:
            return header + "# (the force input's gain: the model itself is unchanged)\n" + model_text
        mf = ModelFile(model_text)
        ki = float(model.parameter(port.gain).value) * finding.value
        mf.set("exciter", lambda t: t.get("station") == port.node, "force_per_ampere", ki, note)
        return header + mf.text()
    mf = ModelFile(model_text)
    write_finding(mf, finding, model, note)
    return header + mf.text()


def write_model(result: Diagnosis, out_dir) -> str | None:
    """Write the extended model to ``out_dir/model_extended.toml`` (copying a station table it names).

    Only a confirmed fix (:attr:`Diagnosis.confirmed`: explained, and better on held-out data) gets that
    name; any other extended model is written as ``model_extended_NOT_CONFIRMED.toml`` with the
    diagnosis's status in its first lines."""
    if result.extended_model_text is None:
        return None
    import shutil
    import tomllib
    os.makedirs(out_dir, exist_ok=True)
    text = result.extended_model_text
    doc = tomllib.loads(text)
    table = doc.get("shaft", {}).get("station_table")
    if table and result.model_source:
        src = table if os.path.isabs(table) else os.path.join(os.path.dirname(os.path.abspath(
            result.model_source)), table)
        dst = os.path.join(out_dir, os.path.basename(table))
        if os.path.abspath(src) != os.path.abspath(dst):
            shutil.copyfile(src, dst)
        text = text.replace(f'"{table}"', f'"{os.path.basename(table)}"')
    if result.confirmed:
        out = os.path.join(out_dir, "model_extended.toml")
    else:
        # not a fix: the file says so in its name and its first lines
        out = os.path.join(out_dir, "model_extended_NOT_CONFIRMED.toml")
        text = (f"# NOT A CONFIRMED FIX. Diagnosis status: {result.status}; held-out gain {result.gain:.3g}x.\n"
                f"# {result.headline()}\n" + text)
    with open(out, "w", encoding="utf-8") as fh:
        fh.write(text)
    result.extended_model = out
    return out


def mbi_reading(model_text: str, path: str, finding: Finding, frf: FRF, excitation: str,
                measurement: str, progress=None) -> dict:
    r"""The thesis's route to the same finding: a mu-controller at the finding's mass absorbs the effect.

    The engineering model gets a force input and a displacement output at the
    finding's mass; :func:`mutext.mbi.identify` tunes a controller there so that
    the model follows the measured channel ``frf`` (``excitation`` to
    ``measurement``), and reads it as an added mass, damper and spring
    (:func:`mutext.mbi.fit_impedance`).  The quantity of the finding's kind is
    compared with the diagnosis: they agree when they differ by at most three
    combined standard uncertainties (the MBI one from its impedance fit:
    the larger of the coefficient's standard error and the fit's relative
    residual times the coefficient).

    Only lumped chains and findings at one mass (a mass, a grounded spring or
    damper) have a single controller location; other findings raise ModelError.
    ``progress(stage, fraction)`` is passed to :func:`mutext.mbi.identify`.
    """
    import tomllib
    from ..mbi import identify       # D-K iteration: imported only when asked for (--mbi)
    h = finding.hypothesis
    doc = tomllib.loads(model_text)
    if "mass" not in doc:
        raise ModelError("model-based identification is run on lumped chains only (a rotor needs a reduced "
                         "model and minutes of D-K iteration)")
    if h is None or h.gain is not None or len(h.dofs) != 1 or h.params:
        raise ModelError(f"a {finding.kind} finding between two masses, on a gain or with several parameters has "
                         "no single controller location and coefficient to compare")
    mass = doc["mass"][h.station - 1]["name"]
    text = model_text + (f'\n[[force]]\nname = "u_mbi"\nmass = "{mass}"\n'
                         f'[[sensor]]\nname = "y_mbi"\nmass = "{mass}"\n')
    ext = loads_model(text, source=f"{path} (controller at {mass})",
                      base_dir=os.path.dirname(os.path.abspath(path)))
    E = ext.state_space(inputs=[excitation, "u_mbi"], outputs=[measurement, "y_mbi"])
    t0 = time.perf_counter()
    res = identify(frf, E, excitation=excitation, measurement=measurement, control_input="u_mbi",
                   control_output="y_mbi", out=None, progress=progress)
    fit = res.fit
    coef = {"mass": ("dm", 0), "damping": ("dc", 1), "stiffness": ("dk", 2)}[finding.kind]
    v = float(getattr(fit, coef[0]))
    sd = max(float(fit.sigma[coef[1]]), float(fit.residual) * abs(v))
    comb = math.sqrt(sd ** 2 + finding.std ** 2)
    return {"location": mass, "reading": fit.description, "mu": float(res.mu_upper), "Wz": float(res.Wz),
            "dm": float(fit.dm), "dc": float(fit.dc), "dk": float(fit.dk),
            "sigma": [float(x) for x in fit.sigma], "residual": float(fit.residual),
            "compared": coef[0], "mbi_value": v, "mbi_std": sd, "diagnosis_value": finding.value,
            "agrees": bool(abs(v - finding.value) <= 3 * comb), "seconds": time.perf_counter() - t0}


def _refit(f: Finding, model_text, path, eng, fit: _Data, s2, N, rss0, threshold, progress=None):
    """Fit the size again with tune() on the extended model; update the finding in place.

    ``progress(stage, fraction)`` is passed to :func:`mutext.rotor.tuning.tune`."""
    h = f.hypothesis
    start = f.value if not h.added else max(f.value, 1e-3 * h.scale)
    trial = Finding(**{**f.__dict__, "value": start,
                       "new_value": None if h.added else h.nominal + start})
    text = extended_model_text(model_text, trial, eng)
    ext = loads_model(text, source=f"{path} (extended)", base_dir=os.path.dirname(os.path.abspath(path)))
    name = h.parameter
    lo = 1e-9 * h.scale if h.added else h.nominal + h.lower
    hi = h.upper if h.added else h.nominal + h.upper
    frfs = [replace(c.frf, freq_hz=fs, response=m, metadata=dict(c.frf.metadata))
            for c, fs, m in zip(fit.chans, fit.freq_hz, fit.meas)]
    x0 = min(max(float(ext.values()[ext.parameter_names.index(name)]), lo), hi)
    res = tune(ext, frfs, [name], bounds={name: (lo, hi)}, start={name: x0}, max_iter=60, progress=progress)
    v = res.values[name]
    rms = (res.residual_rms_db / DB_PER_NEPER) ** 2 + math.radians(res.residual_rms_deg) ** 2
    rss = res.n_points * rms
    f.value = float(v - h.nominal)
    f.new_value = None if h.added else float(v)
    f.std = float(res.std[name]) * math.sqrt(s2) / max(res.sigma, 1e-300)
    f.delta_chi2 = float((rss0 - rss) / s2)
    f.score = rss / s2 + math.log(N)
    f.significant = bool(f.delta_chi2 > threshold)
    f.refit = True
