"""The extended model file, its refit with tune(), and the thesis's reading by model-based identification."""
from __future__ import annotations

import math
import os
import time
from dataclasses import replace

import numpy as np

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
    the finding names, or a table is appended; the user's comments and layout are kept.

    Parameters
    ----------
    model_text : str
        The engineering model file's text (TOML, :mod:`mutext.rotor.model`).
    finding : Finding
        The effect to build in (its hypothesis and fitted ``value`` in the
        unit of its kind, e.g. N/m for a stiffness).  A ``"none"`` finding
        leaves the text unchanged; a correction of the measurement (sensor
        gain, delay or mass, channel scale, an exciter gain on a lumped chain)
        only adds the comment.
    model : mutext.rotor.assembly.Structure
        The model built from ``model_text`` (:func:`mutext.rotor.model.loads_model`):
        the parameters and ports the finding refers to.

    Returns
    -------
    str
        The extended model file's text, opened by a comment line naming the finding.
    """
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
        mf.set("exciter", lambda t: t.get("station") == port.node, "force_per_ampere", ki, note, si=True)
        return header + mf.text()
    mf = ModelFile(model_text)
    write_finding(mf, finding, model, note)
    return header + mf.text()


def _write_model_text(out_dir, text: str, confirmed: bool, unconfirmed_name: str, header) -> str:
    """Write an extended model's ``text`` into ``out_dir``: as ``model_extended.toml`` when it is a
    confirmed fix, otherwise as ``unconfirmed_name`` with ``header()`` (why not) in its first lines, so
    that the file says in its name and its text that it is not a fix.  Returns the path written."""
    if confirmed:
        out = os.path.join(out_dir, "model_extended.toml")
    else:
        out = os.path.join(out_dir, unconfirmed_name)
        text = header() + text
    with open(out, "w", encoding="utf-8") as fh:
        fh.write(text)
    return out


def write_model(result: Diagnosis, out_dir) -> str | None:
    """Write the extended model to ``out_dir/model_extended.toml`` (copying a station table it names).

    Only a confirmed fix (:attr:`Diagnosis.confirmed`: explained, and better on held-out data) gets that
    name; any other extended model is written as ``model_extended_NOT_CONFIRMED.toml`` with the
    diagnosis's status in its first lines.  The model with the controller element of model-based
    identification, when there is one, is written too (:func:`write_mbi_model`).

    Parameters
    ----------
    result : Diagnosis
        From :func:`mutext.diagnose.diagnose`; ``result.extended_model`` is set to the path written.
    out_dir : path-like
        The directory (created when missing).

    Returns
    -------
    str or None
        The path of the extended model written; None when the diagnosis found nothing to build in.
    """
    if result.extended_model_text is None:
        write_mbi_model(result, out_dir)
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
    out = _write_model_text(out_dir, text, result.confirmed, "model_extended_NOT_CONFIRMED.toml", lambda: (
        f"# NOT A CONFIRMED FIX. Diagnosis status: {result.status}; held-out gain {result.gain:.3g}x.\n"
        f"# {result.headline()}\n"))
    result.extended_model = out
    write_mbi_model(result, out_dir)
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

    Parameters
    ----------
    model_text : str
        The engineering model file's text (a lumped chain, ``[[mass]]`` tables).
    path : str
        The model file's path: names it in messages and resolves the files it refers to.
    finding : Finding
        A ``mass``, ``damping`` or ``stiffness`` finding at one mass.
    frf : mutext.response.FRF
        The measured channel the controller is tuned on (receptance, m/N).
    excitation : str
        Name of the model's force input that channel is excited at.
    measurement : str
        Name of the model's sensor output that channel is measured at.
    progress : callable, optional
        ``progress(stage, fraction)``, passed to :func:`mutext.mbi.identify`.

    Returns
    -------
    dict
        ``location`` (the mass's name), ``reading`` (the description of K as
        mass, damper and spring), ``mu`` and ``Wz`` of the identification,
        ``dm`` [kg], ``dc`` [N s/m], ``dk`` [N/m] with their standard errors
        ``sigma`` and the fit's relative ``residual``, ``compared`` (the
        coefficient of the finding's kind), ``mbi_value`` and ``mbi_std``,
        ``diagnosis_value``, ``agrees`` and ``seconds``.

    Raises
    ------
    ModelError
        A model that is not a lumped chain, or a finding without a single
        controller location.
    """
    return _identify_at(model_text, path, finding, frf, excitation, measurement, progress)[0]


def _identify_at(model_text, path, finding, frf, excitation, measurement, progress=None):
    """:func:`mbi_reading`'s dict, the :class:`mutext.mbi.MBIResult` and the engineering model with the
    controller's ports (``u_mbi``, ``y_mbi``)."""
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
    return ({"location": mass, "reading": fit.description, "mu": float(res.mu_upper), "Wz": float(res.Wz),
             "dm": float(fit.dm), "dc": float(fit.dc), "dk": float(fit.dk),
             "sigma": [float(x) for x in fit.sigma], "residual": float(fit.residual),
             "compared": coef[0], "mbi_value": v, "mbi_std": sd, "diagnosis_value": finding.value,
             "agrees": bool(abs(v - finding.value) <= 3 * comb), "seconds": time.perf_counter() - t0},
            res, E)


#: Largest sensitivity-weighted RMS relative difference between the written rational element and the
#: controller K (the order of the element is raised until it is within this).
ELEMENT_TOL = 0.01


def _physical(fit, host_mass: float) -> bool:
    """A mass-damper-spring reading that is one: it describes K, the damper and spring are not negative
    and the host keeps a positive mass."""
    return bool(fit.fits and fit.dc >= 0 and fit.dk >= 0 and host_mass + fit.dm > 0)


def realise_controller(res, host_mass: float, tol: float = ELEMENT_TOL) -> dict:
    r"""The identified controller :math:`K(s)` as an element the model file can hold.

    When its mass-damper-spring reading (:attr:`mutext.mbi.MBIResult.fit`) describes
    ``K`` on its identifiable band with a damper and a spring that are not negative
    and a host mass that stays positive (:math:`m + \Delta m > 0`), the element is
    that mass change with a spring and a damper to ground.  Otherwise it is a rational
    impedance :math:`K(s) = N(s)/D(s)` (``[[impedance]]``,
    :class:`mutext.rotor.lumped_elements.Impedance`): ``K`` reduced by balanced
    truncation that keeps the static gain (:func:`control.balred`, ``matchdc``) to the lowest order whose
    response differs from ``K``'s by at most ``tol`` (RMS relative, each frequency
    of the search grid weighted by the sensitivity :math:`|s(\omega)|` of
    :func:`mutext.mbi.identifiable_band`, i.e. by how much it moves the measured
    output), and whose loop with the engineering model stays stable.

    Parameters
    ----------
    res : mutext.mbi.MBIResult
        The identification: its controller ``K``, reading ``fit``, grid ``omega`` and ``plant``.
    host_mass : float
        The mass [kg] the controller acts on, as the model file gives it.
    tol : float
        Largest weighted RMS relative difference between the written impedance and ``K``.

    Returns
    -------
    dict
        ``kind`` (``"mass-damper-spring"`` or ``"impedance"``), the coefficients
        (``dm, dc, dk`` or ``numerator, denominator`` in descending powers of
        :math:`s`), ``order`` (states added), ``realisation_error`` (the weighted
        difference from ``K`` on the grid, for the impedance), ``description``.
    """
    import control as ct
    from ..lti import freqresp
    from ..mbi import controlled_engineering, identifiable_band, relative_error
    from ..rotor.lumped_elements import Impedance
    fit = res.fit
    if _physical(fit, host_mass):
        return {"kind": "mass-damper-spring", "dm": float(fit.dm), "dc": float(fit.dc), "dk": float(fit.dk),
                "order": 0, "realisation_error": float(fit.residual),
                "description": f"mass {fit.dm:+.4g} kg at the host, spring {fit.dk:.4g} N/m and damper "
                               f"{fit.dc:.4g} N s/m to ground"}
    K = res.K
    omega = np.asarray(res.omega, float)
    sens, _ = identifiable_band(res.plant, K, omega)
    Kj = freqresp(K, omega)[0, 0]
    best = None
    for r in range(1, K.nstates + 1):
        try:
            Kr = K if r == K.nstates else ct.balred(K, r, method="matchdc")
            tf = ct.ss2tf(Kr)
            num = np.atleast_1d(np.squeeze(tf.num[0][0])).astype(float)
            den = np.atleast_1d(np.squeeze(tf.den[0][0])).astype(float)
            num, den = num / den[0], den / den[0]
            el = Impedance(1, num, den, name="K")
        except Exception as exc:      # noqa: BLE001 -- slycot and python-control raise their own kinds
            # a reduction or conversion that fails at this order: the next order is tried
            best = best or ("error", str(exc))
            continue
        err = relative_error(el.response(omega), Kj, omega, weight=sens)
        if not err <= tol:
            continue
        # the loop of the engineering model with the written element must be stable
        A = np.asarray(controlled_engineering(res.plant, ct.ss(*el.realisation())).A, float)
        if A.size and np.max(np.linalg.eigvals(A).real) >= 0:
            continue
        return {"kind": "impedance", "numerator": num.tolist(), "denominator": den.tolist(),
                "order": int(den.size - 1), "realisation_error": float(err),
                "description": f"rational impedance of order {den.size - 1} to ground ("
                               + (f"K reduced from order {K.nstates}" if r < K.nstates else "K's own order")
                               + f"; it differs from K by {100 * err:.2g} % rms, sensitivity-weighted)"}
    why = f" ({best[1]})" if best else ""
    raise ModelError(f"the controller (order {K.nstates}) has no stable realisation as a rational impedance "
                     f"within {100 * tol:g} % of its response{why}")


def element_response(element: dict, omega) -> np.ndarray:
    r"""The element's dynamic stiffness :math:`z(\omega)` [N/m].

    Parameters
    ----------
    element : dict
        From :func:`realise_controller`.
    omega : array_like
        Frequencies [rad/s].

    Returns
    -------
    ndarray of complex
        :math:`dk + j\omega dc - \omega^2 dm`, or :math:`N(j\omega)/D(j\omega)`.
    """
    w = np.asarray(omega, float)
    if element["kind"] == "mass-damper-spring":
        return element["dk"] + 1j * w * element["dc"] - w * w * element["dm"]
    s = 1j * w
    return np.polyval(element["numerator"], s) / np.polyval(element["denominator"], s)


def element_model_text(model_text: str, element: dict, mass: str, host_mass: float, note: str) -> str:
    """The model file's text with the realised controller at a mass (the user's comments kept).

    Parameters
    ----------
    model_text : str
        The engineering model file (a lumped chain).
    element : dict
        From :func:`realise_controller`.
    mass : str
        Name of the mass it acts on.
    host_mass : float
        That mass's value [kg] in the file (a mass change is written as the new value).
    note : str
        The comment that opens the file and each table written.

    Returns
    -------
    str
    """
    mf = ModelFile(model_text)
    if element["kind"] == "mass-damper-spring":
        mf.set("mass", lambda t: t.get("name") == mass, "mass", host_mass + element["dm"], note, si=True)
        mf.append("spring", {"name": f"k_mbi_{mass}", "stiffness": element["dk"], "between": [mass, "ground"]},
                  note, si=True)
        mf.append("damper", {"name": f"c_mbi_{mass}", "damping": element["dc"], "between": [mass, "ground"]},
                  note, si=True)
    else:
        mf.append("impedance", {"name": f"K_mbi_{mass}", "mass": mass, "numerator": element["numerator"],
                                "denominator": element["denominator"]}, note, si=True)
    return f"# Extended by mutext diagnose: {note}\n" + mf.text()


def with_impedance(rec, data, dof: int, z_of) -> list:
    r"""The channels of ``data`` with a dynamic stiffness :math:`z(\omega)` to ground at ``dof`` (exact).

    Sherman-Morrison on the engineering model's receptance :math:`R`:
    :math:`H_c = H^0_c - z R_{od} R_{db} / (1 + z R_{dd})`.

    Parameters
    ----------
    rec : mutext.diagnose._screen._Receptance
        The engineering model's receptance on the diagnosis's grid.
    data : mutext.diagnose._screen._Data
        The channels (fitted or held out).
    dof : int
        The degree of freedom the element acts on (0-based).
    z_of : callable
        ``z_of(omega)``: the element's dynamic stiffness [N/m] at ``omega`` [rad/s].

    Returns
    -------
    list of ndarray
        Per channel, the responses at its frequencies.
    """
    out = []
    for k, idx in enumerate(data.idx):
        Rb, Ro = data.columns(rec, k)
        z = z_of(rec.omega[idx])
        out.append(data.H0[k] - z * Ro[:, dof] * Rb[:, dof] / (1 + z * rec.block(idx, [dof], [dof])[:, 0, 0]))
    return out


def impedance_comparison(res, E, frf: FRF, excitation: str, measurement: str) -> dict:
    r"""K's frequency response beside the impedance the data require, on ``frf``'s frequencies.

    The required impedance is :func:`mutext.mbi.required_impedance` (one value per
    frequency, no fit); the identifiable band is where :math:`|s K| \ge 1`
    (:func:`mutext.mbi.identifiable_band`).  ``band_error`` is the RMS relative
    difference :math:`|K - D|/|D|` over the band's frequencies, each weighted by
    :math:`|s|` (``sensitivity``; :func:`mutext.mbi.relative_error`); complex
    values are ``[re, im]`` pairs.

    Parameters
    ----------
    res : mutext.mbi.MBIResult
    E : control.StateSpace
        The engineering model with the controller's ports ``u_mbi`` and ``y_mbi``.
    frf : mutext.response.FRF
        The measured channel the controller was tuned on.
    excitation, measurement : str
        Its input and output port names.

    Returns
    -------
    dict
        ``freq_hz``, ``K``, ``required``, ``band``, ``sensitivity``, ``band_error``, ``band_hz``.
    """
    from ..lti import freqresp
    from ..mbi import identifiable_band, relative_error, required_impedance
    w = 2 * np.pi * np.asarray(frf.freq_hz, float)
    D = required_impedance(E, frf, excitation=excitation, measurement=measurement, control_input="u_mbi",
                           control_output="y_mbi")
    Kj = freqresp(res.K, w)[0, 0]
    sens, band = identifiable_band(res.plant, res.K, w)
    ok = band & np.isfinite(D)
    err = relative_error(Kj[ok], D[ok], w[ok], weight=sens[ok]) if ok.sum() >= 1 else math.nan
    pair = lambda z: [[float(x.real), float(x.imag)] for x in z]    # noqa: E731
    return {"freq_hz": [float(x) for x in frf.freq_hz], "K": pair(Kj), "required": pair(D),
            "band": [bool(x) for x in band], "sensitivity": [float(x) for x in sens], "band_error": float(err),
            "band_hz": [float(w[band].min() / (2 * np.pi)), float(w[band].max() / (2 * np.pi))]
            if band.any() else None}


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
    on_modes = _refit_on_modes(ext, name, lo, hi, x0, h.scale, fit)
    if on_modes is not None:
        v, rss, jj = on_modes
        f.std = math.sqrt(s2 / jj) if jj > 0 else math.inf
    else:
        res = tune(ext, frfs, [name], bounds={name: (lo, hi)}, start={name: x0}, max_iter=60, progress=progress)
        v = res.values[name]
        rms = (res.residual_rms_db / DB_PER_NEPER) ** 2 + math.radians(res.residual_rms_deg) ** 2
        rss = res.n_points * rms
        f.std = float(res.std[name]) * math.sqrt(s2) / max(res.sigma, 1e-300)
    f.value = float(v - h.nominal)
    f.new_value = None if h.added else float(v)
    f.delta_chi2 = float((rss0 - rss) / s2)
    f.score = rss / s2 + math.log(N)
    f.significant = bool(f.delta_chi2 > threshold)
    f.refit = True


def _refit_on_modes(ext, name: str, lo: float, hi: float, x0: float, scale: float, fit: _Data):
    """The one-parameter refit of :func:`_refit` on a rotor's modes: ``(value, rss, J.J)`` or None.

    The objective is :func:`mutext.rotor.tuning.tune`'s (the squared complex log error of the model
    against the data, summed over the fitted points); the model's response at each value comes from the
    modes of its state space (:class:`mutext.diagnose._screen._Receptance`, modal damping formed again for
    the changed stiffness and mass), one eigen-decomposition per value instead of a dense solve per
    frequency, so the cost grows with the DOFs as the screen's does.  Bounded Gauss-Newton with a
    forward-difference derivative and step halving.  None where the modal form does not hold (a lumped
    chain, an impedance element, several speeds, a defective model): :func:`_refit` then calls ``tune``."""
    from ..rotor.lumped_elements import impedances
    from ._channels import _resolve
    from ._screen import _NotModal, _Receptance
    speeds = {c.speed for c in fit.chans}
    if ext.layout.kind != "rotor" or impedances(ext) or len(speeds) != 1:
        return None
    speed = speeds.pop()
    w_all = np.unique(np.concatenate([2 * np.pi * np.asarray(fs, float) for fs in fit.freq_hz]))
    chans, _ = _resolve(ext, [c.frf for c in fit.chans], "data")
    i = ext.parameter_names.index(name)
    base = ext.values()

    def residual(v):
        vals = base.copy()
        vals[i] = v
        rec = _Receptance(ext, vals, speed, w_all)
        if rec.modal is None:
            raise _NotModal
        r = np.concatenate([np.log(rec.channel(c, fs) / m) for c, fs, m in zip(chans, fit.freq_hz, fit.meas)])
        return np.concatenate([r.real, r.imag])

    try:
        v, r = x0, residual(x0)
        for _ in range(30):
            dh = 1e-6 * max(abs(v), scale)
            dh = -dh if v + dh > hi else dh
            J = (residual(v + dh) - r) / dh
            jj = float(J @ J)
            if not (jj > 0 and np.all(np.isfinite(J))):
                break
            step = -float(J @ r) / jj
            for _ in range(12):                    # halve the step until the misfit does not grow
                v_new = min(max(v + step, lo), hi)
                r_new = residual(v_new)
                if float(r_new @ r_new) <= float(r @ r):
                    break
                step *= 0.5
            else:
                break
            moved = abs(v_new - v)
            v, r = v_new, r_new
            if moved <= 1e-9 * max(abs(v), scale):
                break
        dh = 1e-6 * max(abs(v), scale)
        dh = -dh if v + dh > hi else dh
        J = (residual(v + dh) - r) / dh
    except (_NotModal, np.linalg.LinAlgError, FloatingPointError):
        return None
    return float(v), float(r @ r), float(J @ J)


def mbi_element(reading: dict, res, E, model_text: str, eng, station: int, dof: int, rec, held: _Data, s2: float,
                ref, alpha: float, frf: FRF, excitation: str, measurement: str, err_before: dict) -> dict:
    r"""The identified controller as an element of the extended model, judged on the held-out data.

    :func:`realise_controller` gives the element at ``station``; the held-out
    channels with it are computed exactly from the engineering model's
    receptance (:func:`with_impedance`) and checked against the written model
    file read back; the gain is the engineering model's held-out RMS complex
    error over the extended model's, as for the diagnosis's own effects, and
    the lack-of-fit test of :func:`mutext.diagnose._fit_quality.fit_quality`
    says whether the held-out data are then at the noise.

    Parameters
    ----------
    reading : dict
        :func:`mbi_reading`'s dict (not changed).
    res : mutext.mbi.MBIResult
    E : control.StateSpace
        The engineering model with the controller's ports.
    model_text : str
        The engineering model file.
    eng : mutext.rotor.assembly.Structure
        The engineering model (a lumped chain).
    station, dof : int
        Where the controller acts: the mass (1-based) and its degree of freedom (0-based).
    rec, held
        The engineering model's receptance and the held-out channels of the diagnosis.
    s2 : float
        Noise variance of a log residual (real and imaginary part each).
    ref : mutext.diagnose._fit_quality.NoiseReference
    alpha : float
        False-alarm rate of the lack-of-fit test.
    frf : mutext.response.FRF
        The channel (fitted lines) the controller was tuned on.
    excitation, measurement : str
        Its port names.
    err_before : dict
        The engineering model's held-out error (``rel``, ``db``).

    Returns
    -------
    dict
        Added to :attr:`Diagnosis.mbi`: ``element`` (see :func:`realise_controller`),
        ``element_text`` (the TOML the model file gains), ``extended_model_text``,
        ``held_out_error``, ``held_out_gain``, ``held_out_quality``, ``status``
        (``"explained"`` when the gain exceeds 1 and the held-out data are at
        the noise, else ``"not explained"``) and ``impedance``
        (:func:`impedance_comparison`).
    """
    from ._compare import _errors
    from ._fit_quality import fit_quality
    host = eng.layout.node_names[station - 1]
    host_mass = float(eng.parameter(host).value)
    el = realise_controller(res, host_mass)
    after = with_impedance(rec, held, dof, lambda w: element_response(el, w))
    note = f"model-based identification: {el['description']} at {host}"
    text = element_model_text(model_text, el, host, host_mass, note)
    # the file as written must give the responses the gain is measured on
    ext = loads_model(text, source="extended model (controller element)")
    c0 = held.chans[0]
    H = ext.frf(held.freq_hz[0], inputs=[c0.in_name], outputs=[c0.out_name]).H[0, 0]
    mism = float(np.max(np.abs(H - after[0]) / np.abs(after[0])))
    if not mism < 1e-6:
        raise ModelError(f"the extended model with the controller element does not reproduce the responses its "
                         f"gain is measured on (largest relative difference {mism:.3g})")
    err_after = _errors(after, held.meas)
    gain = err_before["rel"] / err_after["rel"] if err_after["rel"] > 0 else math.inf
    with np.errstate(all="ignore"):
        hq = fit_quality([np.log(h / m) for h, m in zip(after, held.meas)], held.freq_hz,
                         [c.label for c in held.chans], s2, 0, ref, alpha)
    status = "explained" if gain > 1 and hq.at_noise else "not explained"
    snippet = ModelFile("")
    if el["kind"] == "mass-damper-spring":
        snippet.append("spring", {"name": f"k_mbi_{host}", "stiffness": el["dk"], "between": [host, "ground"]})
        snippet.append("damper", {"name": f"c_mbi_{host}", "damping": el["dc"], "between": [host, "ground"]})
        element_text = f"# [[mass]] {host}: mass = {host_mass + el['dm']!r} (was {host_mass!r})\n" + snippet.text()
    else:
        snippet.append("impedance", {"name": f"K_mbi_{host}", "mass": host, "numerator": el["numerator"],
                                     "denominator": el["denominator"]})
        element_text = snippet.text()
    return {"element": el, "element_text": element_text.strip() + "\n", "extended_model_text": text,
            "held_out_error": err_after, "held_out_gain": float(gain), "held_out_quality": hq.as_dict(),
            "status": status, "impedance": impedance_comparison(res, E, frf, excitation, measurement)}


def write_mbi_model(result: Diagnosis, out_dir) -> str | None:
    """Write the extended model with the controller element (:func:`mbi_element`), when there is one.

    ``model_extended.toml`` when its status is explained (held-out gain above 1 and
    the held-out data at the noise) and the diagnosis's own extended model is not a
    confirmed fix; otherwise ``model_extended_mbi_NOT_CONFIRMED.toml``, its status
    in its first lines.  The path is kept in ``result.mbi["extended_model"]``.

    Parameters
    ----------
    result : Diagnosis
    out_dir : path-like

    Returns
    -------
    str or None
        The path written; None when the diagnosis made no element.
    """
    m = result.mbi or {}
    text = m.get("extended_model_text")
    if not text:
        return None
    os.makedirs(out_dir, exist_ok=True)
    out = _write_model_text(out_dir, text, m["status"] == "explained" and not result.confirmed,
                            "model_extended_mbi_NOT_CONFIRMED.toml", lambda: (
                                f"# NOT A CONFIRMED FIX. Model-based identification element: {m['status']}; "
                                f"held-out gain {m['held_out_gain']:.3g}x.\n"))
    m["extended_model"] = out
    return out
