"""Written results of a diagnosis: ``diagnosis.json``, an HTML report with its figures, the extended model.

:func:`write_diagnosis` is what ``mutext diagnose --out DIR`` calls; the
figures are drawn by :func:`diagnosis_figures` (also offered as :func:`mutext.plots.diagnosis_figures`).
"""
from __future__ import annotations

import html
import os

import numpy as np

from ._mpl import db as _db, pyplot as _plt, save as _save
from .diagnose import Diagnosis, write_model
from .jsonio import to_json as _to_json

__all__ = ["write_diagnosis", "diagnosis_json", "diagnosis_figures", "mbi_lines"]



#: hypotheses shown in the ranking figure and the HTML table (the same ones)
RANKED = 12


def diagnosis_json(result: Diagnosis) -> str:
    """The diagnosis as one JSON object (non-finite numbers as strings ``"inf"``, ``"nan"``).

    Parameters
    ----------
    result : Diagnosis
        From :func:`mutext.diagnose.diagnose`.

    Returns
    -------
    str
        ``result.as_dict()`` as JSON text (what ``diagnosis.json`` holds).
    """
    return _to_json(result.as_dict())


def write_diagnosis(result: Diagnosis, out_dir) -> dict:
    """Write ``model_extended.toml`` (when there is a finding), ``diagnosis.json``, ``report.html``
    and the figures into ``out_dir``.

    Parameters
    ----------
    result : Diagnosis
        From :func:`mutext.diagnose.diagnose`.
    out_dir : path-like
        The directory (created when missing; files of the same names are replaced).

    Returns
    -------
    dict
        The paths written: ``extended_model`` (when there is one, :func:`mutext.diagnose.write_model`),
        ``figures`` (a list, :func:`diagnosis_figures`), ``json`` and ``report``.
    """
    os.makedirs(out_dir, exist_ok=True)
    paths = {}
    model = write_model(result, out_dir)
    if model:
        paths["extended_model"] = model
    figs = diagnosis_figures(result, out_dir)
    paths["figures"] = figs
    jpath = os.path.join(out_dir, "diagnosis.json")
    with open(jpath, "w", encoding="utf-8") as fh:
        fh.write(diagnosis_json(result))
    paths["json"] = jpath
    hpath = os.path.join(out_dir, "report.html")
    with open(hpath, "w", encoding="utf-8") as fh:
        fh.write(_html(result, [os.path.basename(p) for p in figs]))
    paths["report"] = hpath
    return paths


def diagnosis_figures(result, outdir) -> list[str]:
    """Figures of a :class:`mutext.diagnose.Diagnosis` saved as PNG in ``outdir``; returns the paths.

    ``overlay.png``: magnitude and phase of data, engineering model and extended
    model for each channel; ``residual.png``: the model/data log-magnitude
    ratio over frequency before and after; ``ranking.png``: the improvement
    left after each of the best hypotheses, in units of the misfit noise alone leaves (the right
    hypothesis brings it to about 1); ``impedance.png`` (when the misfit was localized): the
    impedance the data require at that station beside its mass-damper-spring reading;
    ``mbi_impedance.png`` (when model-based identification made an element): the controller K
    beside the required impedance.

    Parameters
    ----------
    result : Diagnosis
        From :func:`mutext.diagnose.diagnose`.
    outdir : path-like
        The directory the PNG files go to (created when missing).

    Returns
    -------
    list of str
        The paths of the figures written, in the order above.
    """
    plt = _plt()
    os.makedirs(outdir, exist_ok=True)
    paths = []
    chans = result.channels
    n = len(chans)
    ncol = min(n, 3)
    nrow = -(-n // ncol)
    # at most 7.2 in wide (790 px at the 110 dpi of _save): the width of a book or report column,
    # so the figure is shown at its own size and its text is not scaled down
    fig, axes = plt.subplots(2 * nrow, ncol, figsize=(min(4.4 * ncol, 7.2), 3.8 * nrow), squeeze=False,
                             sharex="col")
    for k in range(n, nrow * ncol):
        axes[2 * (k // ncol), k % ncol].set_visible(False)
        axes[2 * (k // ncol) + 1, k % ncol].set_visible(False)
    for k, c in enumerate(chans):
        ax, axp = axes[2 * (k // ncol), k % ncol], axes[2 * (k // ncol) + 1, k % ncol]
        ax.semilogy(c.freq_hz, np.abs(c.measured), ".", ms=2.5, color="0.3", label="measured")
        ax.semilogy(c.freq_hz, np.abs(c.before), "-", color="C3", lw=1.2, label="model")
        axp.plot(c.freq_hz, np.degrees(np.angle(c.measured)), ".", ms=2.5, color="0.3")
        axp.plot(c.freq_hz, np.degrees(np.angle(c.before)), "-", color="C3", lw=1.2)
        if c.after is not None:
            ax.semilogy(c.freq_hz, np.abs(c.after), "--", color="C0", lw=1.2, label="extended model")
            axp.plot(c.freq_hz, np.degrees(np.angle(c.after)), "--", color="C0", lw=1.2)
        ax.set_title(f"{c.label} ({c.role})", fontsize=9)
        axp.set_xlabel("frequency [Hz]")
        if k % ncol == 0:
            # receptance: displacement per force, or per current for an exciter driven by current
            ax.set_ylabel("|H| [m/N or m/A]")
            axp.set_ylabel("phase [deg]")
        if k == 0:
            ax.legend(fontsize=8)
    paths.append(_save(fig, outdir, "overlay.png"))

    fig, ax = plt.subplots(figsize=(7, 3.6))
    colors = plt.cm.tab20(np.linspace(0, 1, max(len(chans), 2)))
    for k, c in enumerate(chans):
        tag = f"{c.label} ({c.role})"
        ax.plot(c.freq_hz, _db(c.before) - _db(c.measured), "-", color=colors[k], lw=1, label=f"{tag} before")
        if c.after is not None:
            ax.plot(c.freq_hz, _db(c.after) - _db(c.measured), ":", color=colors[k], lw=1, label=f"{tag} after")
    noise_db = 20 * np.log10(1 + result.noise)
    ax.axhspan(-2 * noise_db, 2 * noise_db, color="0.85", label="2 x noise")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("model / measured [dB]")
    ax.legend(fontsize=7, ncol=2)
    paths.append(_save(fig, outdir, "residual.png"))

    top = [f for f in result.findings if f.kind != "none"][:RANKED]
    fig, ax = plt.subplots(figsize=(7, 0.35 * len(top) + 1.4))
    labels = [f"{f.kind} @ {f.station} ({f.element})" for f in top][::-1]
    vals = [max(result.misfit_left(f), 1e-3) for f in top][::-1]
    ax.barh(labels, vals, color=["C0" if f.significant else "0.6" for f in top][::-1])
    ax.axvline(1.0, color="C3", lw=1, label="noise alone")
    ax.set_xscale("log")
    ax.set_xlabel("misfit left after the hypothesis / misfit of the noise alone")
    ax.set_title(f"{result.n_hypotheses} hypotheses; before any: "
                 f"{result.misfit_left(next(f for f in result.findings if f.kind == 'none')):.3g}", fontsize=9)
    ax.tick_params(axis="y", labelsize=7)
    ax.legend(fontsize=7)
    paths.append(_save(fig, outdir, "ranking.png"))
    loc = result.localized
    if loc is not None:
        # what the station where the misfit lives asks for, beside its reading as mass, damper and spring
        f = np.asarray(loc["freq_hz"])
        z, zf = np.asarray(loc["required_impedance"]), np.asarray(loc["msd_fit"])
        fig, ax = plt.subplots(2, 1, figsize=(6.5, 4.5), sharex=True)
        ax[0].semilogy(f, np.abs(z), ".", ms=3, label="required (one value per frequency)")
        ax[0].semilogy(f, np.abs(zf), "-", label="mass, damper, spring to ground")
        ax[0].set_ylabel("|z| [N/m]")
        ax[0].legend(fontsize=7)
        ax[0].set_title(f"impedance at station {loc['station']}, where the misfit lives", fontsize=9)
        ax[1].plot(f, np.degrees(np.angle(z)), ".", ms=3)
        ax[1].plot(f, np.degrees(np.angle(zf)), "-")
        ax[1].set_ylabel("phase [deg]")
        ax[1].set_xlabel("frequency [Hz]")
        paths.append(_save(fig, outdir, "impedance.png"))
    imp = (result.mbi or {}).get("impedance")
    if imp:
        paths.append(_mbi_figure(plt, result.mbi, outdir))
    return paths


def _complex(pairs) -> np.ndarray:
    return np.array([complex(a, b) for a, b in pairs])


def _mbi_figure(plt, m: dict, outdir) -> str:
    """``mbi_impedance.png``: the controller K beside the impedance the data require, frequency by frequency."""
    imp = m["impedance"]
    f = np.asarray(imp["freq_hz"])
    K, D = _complex(imp["K"]), _complex(imp["required"])
    band = np.asarray(imp["band"], bool)
    el = m.get("element")
    fig, ax = plt.subplots(2, 1, figsize=(6.5, 4.5), sharex=True)
    ax[0].semilogy(f, np.abs(D), ".", ms=3, color="0.4", label="required (one value per frequency)")
    ax[0].semilogy(f, np.abs(K), "-", color="C0", label="controller K (D-K iteration)")
    ax[1].plot(f, np.degrees(np.angle(D)), ".", ms=3, color="0.4")
    ax[1].plot(f, np.degrees(np.angle(K)), "-", color="C0")
    if el is not None and el.get("kind") == "mass-damper-spring":
        # the element written is K's reading; beside K where it differs
        w = 2 * np.pi * f
        z = el["dk"] + 1j * w * el["dc"] - w * w * el["dm"]
        ax[0].semilogy(f, np.abs(z), "--", color="C1", label="element written (mass, damper, spring)")
        ax[1].plot(f, np.degrees(np.angle(z)), "--", color="C1")
    for a in ax:
        # shade what lies outside the identifiable band, where the data do not hold K
        for k in np.flatnonzero(~band):
            a.axvspan(f[max(k - 1, 0)], f[min(k + 1, f.size - 1)], color="0.92", lw=0)
    ax[0].set_ylabel("|K| [N/m]")
    ax[0].legend(fontsize=7)
    ax[0].set_title(f"impedance at {m.get('location')}: the controller and what the data require\n"
                    "(grey: outside the identifiable band)", fontsize=9)
    ax[1].set_ylabel("phase [deg]")
    ax[1].set_xlabel("frequency [Hz]")
    return _save(fig, outdir, "mbi_impedance.png")


def mbi_lines(result: Diagnosis, rows: int = 6) -> list[str]:
    """Text lines on the controller as an element of the model (what ``mutext diagnose --mbi`` prints).

    Parameters
    ----------
    result : Diagnosis
        A diagnosis run with ``mbi=True``.
    rows : int
        Frequencies of the identifiable band at which K and the required impedance are tabulated.

    Returns
    -------
    list of str
        What was written, its held-out gain, and the table; empty when the diagnosis made no element
        (the hypotheses explained the data, or model-based identification was not run).
    """
    m = result.mbi or {}
    el = m.get("element")
    if not el:
        return []
    out = [f"controller as an element at {m['location']}: {el['description']}",
           f"  held-out gain {m['held_out_gain']:.3g}x ({100 * m['held_out_error']['rel']:.3g} % rms against "
           f"{100 * result.error_before['rel']:.3g} % for the engineering model); {m['status']}"]
    if m.get("extended_model"):
        out.append(f"  written: {m['extended_model']}")
    imp = m.get("impedance")
    if imp:
        f = np.asarray(imp["freq_hz"])
        band = np.flatnonzero(np.asarray(imp["band"], bool))
        K, D = _complex(imp["K"]), _complex(imp["required"])
        out.append(f"  K against the required impedance on the identifiable band: {100 * imp['band_error']:.3g} % "
                   "rms (sensitivity-weighted)")
        out.append(f"  {'f [Hz]':>9} {'|K| [N/m]':>11} {'|required|':>11} {'phase K':>8} {'required':>9}")
        for k in (band[np.linspace(0, band.size - 1, min(rows, band.size)).round().astype(int)] if band.size
                  else []):
            out.append(f"  {f[k]:9.4g} {abs(K[k]):11.4g} {abs(D[k]):11.4g} {np.degrees(np.angle(K[k])):7.1f}d "
                       f"{np.degrees(np.angle(D[k])):8.1f}d")
    return out


def _mbi_html(r: Diagnosis) -> str:
    """The controller as an element of the model, in the HTML report."""
    m = r.mbi or {}
    el = m.get("element")
    if not el:
        return ""
    e = html.escape
    return (f"<h2>What no hypothesis names: the controller as an element</h2>"
            f"<p>Model-based identification at {e(str(m['location']))}: {e(m['reading'])}.</p>"
            f"<p>Written as: {e(el['description'])}; held-out gain {m['held_out_gain']:.3g}x "
            f"({100 * m['held_out_error']['rel']:.3g} % rms complex error); {e(m['status'])}"
            + (f"; file <code>{e(m['extended_model'])}</code>" if m.get("extended_model") else "")
            + f".</p><pre>{e(m['element_text'])}</pre>"
            "<p>The figure <code>mbi_impedance.png</code> shows K beside the impedance the data require "
            "frequency by frequency.</p>")


def _quality_html(r: Diagnosis) -> str:
    """The goodness of fit, the bands the final model leaves unexplained and the unmatched resonances."""
    e = html.escape
    q, out = r.fit_quality, []
    if q is not None:
        out.append(f"<p>Goodness of fit of the final model ({len(r.effects)} effect(s)): misfit {q.misfit:.3g} times "
                   f"the noise, at most {q.limit:.3g} when explained (p = {q.p_value:.2g}).</p>")
        if q.bands:
            out.append("<p>Where it stays above the noise: " + e(q.where(6)) + ".</p>")
    um = r.unmatched or {}
    if um.get("measured"):
        out.append("<p>Measured resonances the model has no partner for: " + e(", ".join(
            f"{x['freq_hz']:.4g} Hz ({x['channel']})" for x in um["measured"])) + ".</p>")
    if um.get("model"):
        out.append("<p>Model resonances outside the measured band: " + e(", ".join(
            f"{x:.4g} Hz" for x in um["model"][:8])) + ".</p>")
    if r.extended_model and not r.confirmed:
        out.append(f"<p><b>The extended model is not a confirmed fix</b> ({e(r.status)}, held-out gain "
                   f"{r.gain:.3g}x).</p>")
    return "".join(out)


def _html(r: Diagnosis, figs) -> str:
    e = html.escape
    rows = "".join(
        f"<tr><td>{k}</td><td>{e(f.kind)}</td><td>{f.station or '-'}</td><td>{e(str(f.element or '-'))}</td>"
        f"<td>{e(f.size_text(std=False))}</td>"
        f"<td>{'' if f.kind == 'none' else f'{f.std:.2g}'}</td><td>{f.delta_chi2:.1f}</td>"
        f"<td>{r.misfit_left(f):.3g}</td>"
        f"<td>{'yes' if f.significant else ('at bound' if f.at_bound else '')}</td></tr>"
        for k, f in enumerate([f for f in r.findings if f.kind != "none"][:RANKED], start=1))
    res = "".join(
        f"<tr><td>{e(x.channel)}</td><td>{x.measured_hz:.5g} &plusmn; {x.measured_hz_std:.2g}</td>"
        f"<td>{x.model_hz:.5g}</td><td>{100 * x.freq_error:+.2f} %</td>"
        f"<td>{x.measured_damping:.3g} &plusmn; {x.measured_damping_std:.2g}</td><td>{x.model_damping:.3g}</td></tr>"
        for x in r.resonances)
    amb = ""
    if r.ambiguous_with:
        amb = ("<p>Cannot be told apart with the channels measured: "
               + "; ".join(e(f"{f.kind} at {f.station} ({f.element})") for f in r.ambiguous_with)
               + (f". A sensor at station {r.separating_sensor} would separate them best." if r.separating_sensor
                  else ".") + "</p>")
    notes = "".join(f"<li>{e(n)}</li>" for n in r.notes)
    imgs = "".join(f'<p><img src="{e(f)}" style="max-width:100%"></p>' for f in figs)
    summary = "".join(f"<li>{e(s)}</li>" for s in r.summary)
    speed_lines = r.at_speed_lines()
    at_speed = ("<h2>At speed</h2><ul>" + "".join(f"<li>{e(x.strip())}</li>" for x in speed_lines) + "</ul>"
                if speed_lines else "")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>mutext diagnose: {e(r.model_name)}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:auto}} td,th{{padding:2px 8px;text-align:right}}
table{{border-collapse:collapse}} tr:nth-child(even){{background:#f3f3f3}}</style></head><body>
<h1>Diagnosis of {e(r.model_name)}</h1>
<p>Model file: <code>{e(str(r.model_source))}</code>. Noise level estimated from the data:
{100 * r.noise:.3g} % (relative).</p>
<h2>Verdict: {e(r.status)}</h2><p><b>{e(r.headline())}</b></p>{amb}
{_quality_html(r)}
{at_speed}<h2>What the model gets wrong</h2><ul>{summary}</ul>
<table><tr><th>channel</th><th>measured Hz</th><th>model Hz</th><th>error</th><th>damping measured</th>
<th>damping model</th></tr>{res}</table>
<h2>Hypotheses ({r.n_hypotheses} tested; accepted when delta chi2 &gt; {r.threshold:.1f},
false-alarm rate {100 * r.alpha:g} %)</h2>
<p>The {min(RANKED, r.n_hypotheses)} best; "misfit left / noise" is the figure's axis.</p>
<table><tr><th>rank</th><th>kind</th><th>station</th><th>element</th><th>size</th><th>std</th>
<th>delta chi2</th><th>misfit left / noise</th><th>significant</th></tr>{rows}</table>
<h2>Gain on held-out data</h2><p>{e(r.held_out)}</p>
<table><tr><th></th><th>rms complex error</th><th>rms log-magnitude error</th></tr>
<tr><td>engineering model</td><td>{100 * r.error_before['rel']:.3g} %</td><td>{r.error_before['db']:.3g} dB</td></tr>
<tr><td>extended model</td><td>{100 * r.error_after['rel']:.3g} %</td><td>{r.error_after['db']:.3g} dB</td></tr>
</table><p>Gain: {r.gain:.3g}x.</p>
{f'<p>Extended model: <code>{e(r.extended_model)}</code></p>' if r.extended_model else ''}
{_mbi_html(r)}
<h2>Figures</h2>{imgs}
{f'<h2>Notes</h2><ul>{notes}</ul>' if notes else ''}
<p><small>{r.seconds:.1f} s</small></p></body></html>
"""
