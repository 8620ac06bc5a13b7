"""The extended model file, its refit with tune(), and the thesis's reading by model-based identification."""
from __future__ import annotations

import math
import os
import re
import time
from dataclasses import replace
from typing import Callable

from ..errors import ModelError
from ..response import FRF
from ..rotor.model import loads_model
from ..rotor.tuning import DB_PER_NEPER, tune
from ._result import Diagnosis, Finding
from ._screen import _Data
from .faults import structure as _structure

def _toml_number(x: float) -> str:
    return f"{x:.8g}" if "e" not in f"{x:.8g}" else f"{x:.8e}"


def _replace_value(text: str, table: str, match: Callable[[dict], bool], doc_tables: list, key: str,
                   value: float, comment: str) -> str:
    """Set ``key = value`` in the k-th ``[[table]]`` of TOML text (the one ``match`` selects)."""
    k = next((i for i, t in enumerate(doc_tables) if match(t)), None)
    if k is None:
        raise ModelError(f"cannot find the [[{table}]] entry to change in the model file")
    lines = text.splitlines()
    count, start = -1, None
    for i, ln in enumerate(lines):
        if re.match(rf"^\s*\[\[\s*{re.escape(table)}\s*\]\]", ln):
            count += 1
            if count == k:
                start = i
                break
    if start is None:
        raise ModelError(f"cannot locate [[{table}]] #{k + 1} in the model text")
    for i in range(start + 1, len(lines)):
        if re.match(r"^\s*\[", lines[i]):
            break
        m = re.match(rf"^(\s*{re.escape(key)}\s*=\s*)([^#]*?)(\s*(#.*)?)$", lines[i])
        if m:
            lines[i] = f"{m.group(1)}{_toml_number(value)}   # {comment} (was {m.group(2).strip()})"
            return "\n".join(lines) + "\n"
    # key absent: insert after the header
    lines.insert(start + 1, f"{key} = {_toml_number(value)}   # {comment}")
    return "\n".join(lines) + "\n"


def extended_model_text(model_text: str, finding: Finding, model) -> str:
    """The model file's text with the finding built in (a comment names the finding)."""
    import tomllib
    doc = tomllib.loads(model_text)
    h = finding.hypothesis
    note = f"mutext diagnose: {finding.sentence()}"
    header = f"# Extended by mutext diagnose: {finding.sentence()}\n"
    lay = model.layout
    if h is None or finding.kind == "none":
        return model_text
    if h.glob is not None:
        return header + _structure.model_text(model_text, finding, note)
    if finding.kind in ("sensor_gain", "channel_scale", "sensor_delay", "sensor_mass"):
        return header + "# (a correction of the measurement: the model itself is unchanged)\n" + model_text
    if lay.kind == "lumped":
        names = lay.node_names
        if h.added:
            tbl = "spring" if h.kind == "stiffness" else "damper"
            key = "stiffness" if h.kind == "stiffness" else "damping"
            return (header + model_text.rstrip("\n") + f"\n\n# {note}\n[[{tbl}]]\nname = \"{h.element}\"\n"
                    f"{key} = {_toml_number(finding.value)}\nbetween = [\"{names[h.station - 1]}\", \"ground\"]\n")
        if h.kind == "exciter_gain":
            return header + "# (the force input's gain: the model itself is unchanged)\n" + model_text
        tbl, key = {"mass": ("mass", "mass"), "stiffness": ("spring", "stiffness"),
                    "damping": ("damper", "damping")}[h.kind]
        new = finding.new_value
        return header + _replace_value(model_text, tbl, lambda t: t.get("name") == h.element,
                                       doc.get(tbl, []), key, new, note)
    # rotors
    if h.kind == "bearing":
        key = "stiffness" if h.order == 0 else "damping"
        new = finding.new_value if finding.new_value is not None else h.nominal + finding.value
        return header + _replace_value(model_text, "bearing", lambda t: t.get("station") == h.station,
                                       doc.get("bearing", []), key, new, note)
    if h.kind == "exciter_gain":
        st = h.gain[1]
        port = model.inputs[st[1]] if st[0] == "port" else None
        if port is None:
            return header + "# (the force input's gain: the model itself is unchanged)\n" + model_text
        ki = float(model.parameter(port.gain).value) * finding.value
        return header + _replace_value(model_text, "exciter", lambda t: t.get("station") == port.node,
                                       doc.get("exciter", []), "force_per_ampere", ki, note)
    add = {"stiffness": f"[[bearing]]\nname = \"{h.element}\"\nstation = {h.station}\n"
                        f"stiffness = {_toml_number(finding.value)}\ndamping = 0.0\n",
           "damping": f"[[bearing]]\nname = \"{h.element}\"\nstation = {h.station}\nstiffness = 0.0\n"
                      f"damping = {_toml_number(finding.value)}\n",
           "mass": f"[[disk]]\nname = \"{h.element}\"\nstation = {h.station}\nmass = {_toml_number(finding.value)}\n",
           "crack": f"[[crack]]\nstation = {h.station}\ndepth_ratio = {_toml_number(finding.value)}\n"}[h.kind]
    return header + model_text.rstrip("\n") + f"\n\n# {note}\n" + add


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
    if h is None or h.gain is not None or len(h.dofs) != 1:
        raise ModelError(f"a {finding.kind} finding between two masses or on a gain has no single controller "
                         "location")
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
