"""Figures for the demos and the book (matplotlib, safe with the Agg backend).

Every function draws on axes it is given or creates, and returns the figure
or axes; nothing here computes more than a frequency response.  Frequencies
are in rad/s, magnitudes in dB unless stated.
"""
from __future__ import annotations

import os

import numpy as np

from . import response
from ._mpl import db as _db, pyplot as _plt, save as _save
from .lti import as_ss, freqresp, sigma_max
from .report import diagnosis_figures

__all__ = ["systems_grid", "bode_mag", "bode_phase", "sigma_plot", "closed_loop_figure",
           "controller_figure", "sigma_figure", "two_mass_hinf_figures", "mbi_figure", "diagnosis_figures",
           "sideband_figure", "crack_identification_figure", "crack_figures",
           "campbell_figure", "mode_shapes_figure", "unbalance_bode_figure", "unbalance_polar_figure",
           "orbit_figure"]


def systems_grid(*systems, decades: float = 1.5, n: int = 800) -> np.ndarray:
    """Log-spaced grid (rad/s) covering the pole magnitudes of ``systems``.

    :func:`mutext.response.frequency_grid` over their poles: the grid extends
    ``decades`` beyond the slowest and fastest nonzero pole and contains the
    imaginary parts of lightly damped poles, so resonance peaks are not missed
    (undamped poles: points 0.1 % either side).

    Parameters
    ----------
    *systems : control.StateSpace
        The systems whose poles the grid covers.
    decades : float, optional
        How far the grid reaches beyond the slowest and fastest pole.
    n : int, optional
        Number of log-spaced points.

    Examples
    --------
    >>> from mutext.lti import ss
    >>> from mutext.plots import systems_grid
    >>> w = systems_grid(ss([[-10.0]], [[1.0]], [[1.0]], [[0.0]]), n=100)
    >>> bool(w.min() < 1.0 and w.max() > 100.0)          # 1.5 decades either side of 10 rad/s
    True
    """
    poles = [np.linalg.eigvals(np.asarray(s.A, float)) for s in map(as_ss, systems) if s.nstates]
    return response.frequency_grid(n=n, poles=np.concatenate(poles) if poles else (),
                                   margin=(10.0 ** decades, 10.0 ** decades), resonance_offsets=(0.0,))


def _system_and_grid(sys, omega, *others):
    """``sys`` as a state space and the frequencies [rad/s] to draw it on: ``omega`` as given, or
    :func:`systems_grid` over ``sys`` and ``others`` when it is None."""
    sys = as_ss(sys)
    return sys, np.asarray(systems_grid(sys, *others) if omega is None else omega, float)


def _finish(fig, title=None, **kw):
    """A figure's last step: its title (``suptitle``, with ``kw``) when given, then the tight layout."""
    if title:
        fig.suptitle(title, **kw)
    fig.tight_layout()
    return fig


def bode_mag(ax, sys, omega, out_index: int = 0, in_index: int = 0, db: bool = True, **kw):
    """Plot ``|G_ij(j w)|`` of one channel on ``ax`` (dB if ``db``, else absolute).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    sys : control.StateSpace
    omega : array_like
        Frequencies in rad/s.
    out_index, in_index : int
        Output and input of the channel.
    db : bool
        Plot ``20 log10 |G|`` (default) or ``|G|``.
    **kw
        Passed to :meth:`matplotlib.axes.Axes.semilogx`.

    Returns
    -------
    matplotlib.axes.Axes
    """
    G = freqresp(sys, omega)[out_index, in_index]
    ax.semilogx(omega, _db(G) if db else np.abs(G), **kw)
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("magnitude [dB]" if db else "magnitude")
    ax.grid(True, which="both", alpha=0.3)
    return ax


def bode_phase(ax, sys, omega, out_index: int = 0, in_index: int = 0, **kw):
    """Plot the unwrapped phase (degrees) of one channel on ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes to draw on.
    sys : control.StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The system.
    omega : array_like
        Frequencies in rad/s.

    out_index, in_index : int, optional
        Output and input of the channel.
    **kw
        Passed to :meth:`matplotlib.axes.Axes.semilogx`.
    """
    G = freqresp(sys, omega)[out_index, in_index]
    ax.semilogx(omega, np.degrees(np.unwrap(np.angle(G))), **kw)
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("phase [deg]")
    ax.grid(True, which="both", alpha=0.3)
    return ax


def sigma_plot(ax, sys, omega, db: bool = False, **kw):
    """Plot the largest singular value of ``G(j w)`` on ``ax`` (absolute by default).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes to draw on.
    sys : control.StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The system.
    omega : array_like
        Frequencies in rad/s.

    db : bool, optional
        Plot in dB instead of absolute.
    **kw
        Passed to :meth:`matplotlib.axes.Axes.semilogx`.
    """
    s = sigma_max(sys, omega)
    ax.semilogx(omega, _db(s) if db else s, **kw)
    ax.set_xlabel("frequency [rad/s]")
    ax.set_ylabel("largest singular value" + (" [dB]" if db else ""))
    ax.grid(True, which="both", alpha=0.3)
    return ax


def closed_loop_figure(CL, omega=None, P=None, input_names=None, output_names=None, title=None):
    """Magnitude of every channel of a closed loop (thesis Fig. 2.6 analogue).

    Parameters
    ----------
    CL : control.StateSpace
        Closed loop ``w -> z``.
    omega : array_like, optional
        Frequencies in rad/s (default: :func:`systems_grid`).
    P : control.StateSpace, optional
        Generalized plant; if given, its open-loop ``w -> z`` channels
        (control input left at zero) are drawn dashed for comparison.
    input_names, output_names : list of str, optional
        Axis labels (default: the system's signal names).
    title : str, optional
        Title of the figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    CL, omega = _system_and_grid(CL, omega, *([] if P is None else [P]))
    nz, nw = CL.noutputs, CL.ninputs
    input_names = input_names or list(CL.input_labels)
    output_names = output_names or list(CL.output_labels)
    # at most 7 in wide: the book's text column, so the text is not scaled down
    fig, axes = plt.subplots(nz, nw, figsize=(min(4.2 * nw, 7.0), 2.8 * nz), sharex=True, squeeze=False)
    G = freqresp(CL, omega)
    G0 = None
    if P is not None:
        P = as_ss(P)
        G0 = freqresp(P, omega)[:nz, :nw]
    for i in range(nz):
        for j in range(nw):
            ax = axes[i, j]
            ax.semilogx(omega, _db(G[i, j]), label="closed loop")
            if G0 is not None and np.any(np.abs(G0[i, j]) > 0):
                ax.semilogx(omega, _db(G0[i, j]), "--", lw=1, label="open loop (u = 0)")
            top = float(np.max(_db(G[i, j])))
            # undamped open-loop peaks and exact notches are infinite: clip the view
            ax.set_ylim(max(float(np.min(_db(G[i, j]))), top - 120.0) - 5.0, top + 40.0)
            ax.set_title(f"{input_names[j]} -> {output_names[i]}", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            if j == 0:
                ax.set_ylabel("magnitude [dB]")
            if i == nz - 1:
                ax.set_xlabel("frequency [rad/s]")
    if G0 is not None:
        axes[0, 0].legend(fontsize=8)
    return _finish(fig, title)


def controller_figure(K, omega=None, title=None):
    """Bode magnitude and phase of a SISO controller (thesis Fig. 2.7 analogue).

    Parameters
    ----------
    K : control.StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The SISO controller.
    omega : array_like, optional
        Frequencies in rad/s (default: :func:`systems_grid` of ``K``).
    title : str, optional
        Title of the figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    K, omega = _system_and_grid(K, omega)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 5.0), sharex=True)
    bode_mag(a1, K, omega)
    a1.set_xlabel("")
    a1.set_ylabel("|K| [dB re 1 N/m]")
    bode_phase(a2, K, omega)
    return _finish(fig, title)


def sigma_figure(CL, omega=None, levels=None, title=None):
    """Largest singular value of a closed loop against frequency, with
    horizontal reference levels (thesis Fig. 2.8 analogue).

    Parameters
    ----------
    CL : control.StateSpace
    omega : array_like, optional
        Frequencies in rad/s.
    levels : dict of str -> float, optional
        Horizontal lines to draw, e.g. ``{"optimal gamma": 1.0069}``.
    title : str, optional
        Title of the figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    CL, omega = _system_and_grid(CL, omega)
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    sigma_plot(ax, CL, omega, label="closed loop")
    styles = iter([":", "--", "-.", (0, (1, 3))])
    for name, value in (levels or {}).items():
        ax.axhline(value, ls=next(styles, ":"), color="k", lw=1, label=f"{name} = {value:.4f}")
    ax.set_ylim(0.0, 1.15 * max([float(sigma_max(CL, omega).max())] + list((levels or {}).values())))
    ax.legend(fontsize=8, loc="lower left")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    return fig


def two_mass_hinf_figures(res, P, outdir, thesis_gamma: float | None = None) -> list[str]:
    """Save the analogues of thesis Figures 2.6-2.8 for the two-mass H-infinity design.

    Parameters
    ----------
    res : mutext.hinf.HinfResult
        Result of :func:`mutext.hinf.hinfsyn` on ``P``.
    P : control.StateSpace
        The generalized plant (inputs ``f1, f2, u``; outputs ``z1, z2, y``).
    outdir : str or path
        Directory (created if missing).
    thesis_gamma : float, optional
        The thesis's gamma, drawn beside the optimal one in Fig. 2.8
        (:data:`mutext.examples.two_mass.THESIS_GAMMA`); not drawn when None.

    Returns
    -------
    list of str
        Paths of the PNG files written: closed-loop channels (Fig. 2.6),
        controller frequency response (Fig. 2.7), largest singular value of
        the closed loop (Fig. 2.8).
    """
    plt = _plt()
    os.makedirs(outdir, exist_ok=True)
    omega = np.logspace(-1, 3, 1200)
    omega = np.unique(np.concatenate([omega, systems_grid(P, decades=0.5, n=2)]))
    levels = {"optimal gamma (LMI)": res.gamma}
    if thesis_gamma is not None:
        levels["thesis gamma"] = thesis_gamma
    files = []
    figs = [
        ("two_mass_fig2_6_closed_loop.png",
         closed_loop_figure(res.CL, omega, P=P,
                            input_names=["f1 (f_e / 10 N)", "f2 (eta / 1e-4 m)"],
                            output_names=["z1 (x1 / x_max)", "z2 (u / u_max)"],
                            title="closed-loop channels (normalised signals)")),
        ("two_mass_fig2_7_controller.png",
         controller_figure(res.K, omega, title=f"H-infinity controller ({res.controller_order} states)")),
        ("two_mass_fig2_8_sigma.png",
         sigma_figure(res.CL, omega, levels=levels,
                      title="largest singular value of the closed loop")),
    ]
    for name, fig in figs:
        path = os.path.join(str(outdir), name)
        fig.savefig(path, dpi=120)
        plt.close(fig)
        files.append(path)
    return files


def mbi_figure(result, true_systems, Du=None, title=None):
    r"""Model-based identification at a glance (thesis Figs. 3.13-3.15 analogues).

    Three panels: (a) the measured response of the true systems (one line per
    sample of the uncertainty set), the engineering model and the controlled
    engineering model; (b) the identified dynamics :math:`K` against the known
    difference :math:`D_u` (magnitude and phase), with the identifiable band
    shaded; (c) the error :math:`|x_t - x_e|` of the controlled model for every
    true system, against the accepted bound :math:`W_z`.

    Parameters
    ----------
    result : mutext.mbi.MBIResult
    true_systems : sequence of control.StateSpace
        Samples of the true system (inputs/outputs named as in the plant).
    Du : dict, optional
        Known difference ``{"dm", "dc", "dk"}`` to draw beside ``K``.
    title : str, optional
    """
    from .mbi import impedance_response
    plt = _plt()
    w = result.omega
    pr = result.plant.ports
    E = result.plant.engineering
    ie, oe = list(E.input_labels).index(pr["excitation"]), list(E.output_labels).index(pr["measurement"])
    fig, ax = plt.subplots(2, 2, figsize=(7, 5.6))   # the book's text column
    a = ax[0, 0]
    for k, T in enumerate(true_systems):
        T = as_ss(T)
        i, o = list(T.input_labels).index(pr["excitation"]), list(T.output_labels).index(pr["measurement"])
        a.loglog(w, np.abs(freqresp(T, w)[o, i]), color="0.6", lw=2.5, label="true system" if k == 0 else None)
    a.loglog(w, np.abs(freqresp(E, w)[oe, ie]), "C1--", label="engineering model")
    a.loglog(w, np.abs(freqresp(result.controlled, w)[0, 0]), "C0", lw=1, label="with identified K")
    a.set_ylabel(f"|{pr['measurement']}/{pr['excitation']}|")
    a.set_title("(a) responses")
    a.legend(fontsize=8)
    Kj = freqresp(result.K, w)[0, 0]
    lo, hi = result.fit.band
    for a, part in ((ax[0, 1], "mag"), (ax[1, 0], "phase")):
        a.axvspan(lo, hi, color="C2", alpha=0.1, label="identifiable band")
        if part == "mag":
            a.loglog(w, np.abs(Kj), "C0", label="K")
            if Du is not None:
                a.loglog(w, np.abs(impedance_response(Du, w)), "k:", label="$D_u$")
            a.set_ylabel("|K| [N/m]")
            a.set_title("(b) identified dynamics")
            a.legend(fontsize=8)
        else:
            a.semilogx(w, np.degrees(np.unwrap(np.angle(Kj))), "C0", label="K")
            if Du is not None:
                a.semilogx(w, np.degrees(np.unwrap(np.angle(impedance_response(Du, w)))), "k:", label="$D_u$")
            a.set_ylabel("phase [deg]")
            a.set_title("(c) phase of K" + (" and $D_u$" if Du is not None else ""))
    a = ax[1, 1]
    for k, T in enumerate(true_systems):
        a.loglog(w, result.error(T), color="C0", alpha=0.6, lw=1, label="true samples" if k == 0 else None)
    if result.plant.Wz_shape is None:
        a.axhline(result.Wz, color="C3", ls="--", label=f"$W_z$ = {result.Wz:.3g}")
    else:       # a bound shaped by the spread of the true systems
        a.loglog(w, result.bound(w), color="C3", ls="--", label=f"$W_z|S|$, $W_z$ = {result.Wz:.3g}")
    a.set_ylabel(r"$|x_t - x_e|$ per unit input")
    a.set_title("(d) error of the controlled model")
    a.legend(fontsize=8)
    from matplotlib.ticker import NullFormatter
    for a in ax.ravel():
        a.set_xlabel("frequency [rad/s]")
        a.grid(True, which="both", alpha=0.3)
        a.xaxis.set_minor_formatter(NullFormatter())     # a band of under two decades labels its minor ticks
    return _finish(fig, title)


def sideband_figure(frf, evidence, reference=None, title=None, band=None):
    """A measured sweep with the sideband candidates of :func:`mutext.diagnose.sideband_evidence`.

    Top: the magnitude (m per input unit, log scale) with ``reference`` (a
    time-invariant model's response at the same frequencies, optional), the
    modes (dotted) and each tested candidate (green where found, grey where
    not), all named in the legend.  Bottom: each candidate's size relative to
    the local response against the level the noise lets the test see.
    ``band`` = (f_min, f_max) in Hz shows only that band (sidebands are a few
    tenths of a percent of the response: over the whole sweep they do not show).

    Parameters
    ----------
    frf : mutext.response.FRF
        The measured sweep.
    evidence : mutext.diagnose.SidebandEvidence
        The result of :func:`mutext.diagnose.sideband_evidence` on it.
    reference : array_like of complex, optional
        A time-invariant model's response at ``frf.freq_hz``.
    title : str, optional
        Title of the figure.

    band : (float, float), optional
        Frequency band [Hz] shown.
    """
    plt = _plt()
    from matplotlib.lines import Line2D
    f = np.asarray(frf.freq_hz, float)
    keep = np.ones(f.size, bool) if band is None else (f >= band[0]) & (f <= band[1])
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True,
                                 gridspec_kw={"height_ratios": [2, 1]})
    ax.semilogy(f[keep], np.abs(np.asarray(frf.response)[keep]), ".", ms=2.5, color="k", label="measured")
    if reference is not None:
        ax.semilogy(f[keep], np.abs(np.asarray(reference)[keep]), "-", color="C0", lw=1,
                    label="time-invariant model")
    inside = (lambda x: True) if band is None else (lambda x: band[0] <= x <= band[1])
    for fm, _ in evidence.modes:
        if inside(fm):
            ax.axvline(fm, color="C0", ls=":", lw=0.8)
    tested = [c for c in evidence.candidates if not c.masked and inside(c.freq_hz)]
    for c in tested:
        ax.axvline(c.freq_hz, color="C2" if c.found else "0.75", lw=1.0 if c.found else 0.6)
    handles, _ = ax.get_legend_handles_labels()
    handles += [Line2D([], [], color="C0", ls=":", lw=0.8, label="mode of the model"),
                Line2D([], [], color="C2", lw=1.0, label="sideband found"),
                Line2D([], [], color="0.75", lw=0.6, label="candidate, not found")]
    ax.set_ylabel("|H| [m per input unit]")
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    ax.set_title(title or f"sidebands at {evidence.speed_hz:g} Hz running speed: {evidence.verdict}",
                 fontsize=10)
    for c in tested:
        bx.semilogy([c.freq_hz], [max(c.relative_size, 1e-6)], "o" if c.found else "x",
                    color="C2" if c.found else "0.5", ms=5)
        bx.annotate(f"{c.k:+d}", (c.freq_hz, max(c.relative_size, 1e-6)), textcoords="offset points",
                    xytext=(3, 3), fontsize=8)
    bx.axhline(evidence.detectable, color="C3", ls="--", lw=1, label="detectable at this noise")
    bx.plot([], [], "o", color="C2", ms=5, label="found (order k)")
    bx.plot([], [], "x", color="0.5", ms=5, label="not found")
    bx.set_xlabel("frequency [Hz]")
    bx.set_ylabel("sideband size / |H|")
    bx.legend(loc="upper right", fontsize=8)
    if band is not None:
        bx.set_xlim(*band)
    fig.tight_layout()
    return fig


def crack_identification_figure(out, title=None):
    """The chapter-4 identification: sweeps (measured, healthy, with K) and what K means.

    ``out`` is the dict of :func:`mutext.demos.crack.solve` (or anything with
    its keys ``freqs_hz``, ``measured``, ``engineering``, ``controlled``,
    ``K``, ``D_rig``, ``D_mean``, ``first_mode_band_hz``).

    Parameters
    ----------
    out : dict
        The result of :func:`mutext.demos.crack.solve` (or a dict with its keys).
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    f = out["freqs_hz"]
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    ax.semilogy(f, np.abs(out["measured"]), ".", ms=2.5, color="k", label="measured (cracked, at speed)")
    ax.semilogy(f, np.abs(out["engineering"]), "-", color="C0", lw=1, label="healthy model")
    ax.semilogy(f, np.abs(out["controlled"]), "--", color="C3", lw=1, label="healthy model with K")
    ax.set_ylabel("|x13 / i12| [m/A]")
    ax.legend(fontsize=8)
    ax.set_title(title or "crack identification: controller at station 15")
    bx.semilogy(f, np.abs(out["D_rig"].real), "-", color="k", lw=1, label="required (exact, from the rig's sweep)")
    bx.semilogy(f, np.abs(out["D_mean"].real), ":", color="C0", lw=1, label="required by the averaged crack")
    bx.semilogy(f, np.abs(out["K"].real), "--", color="C3", lw=1.2, label="K (identified)")
    lo, hi = out["first_mode_band_hz"]
    bx.axvspan(lo, hi, color="C2", alpha=0.12, lw=0, label="first-mode band (spring reading)")
    bx.set_xlabel("frequency [Hz]")
    bx.set_ylabel("|Re dynamic stiffness| [N/m]")
    bx.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def crack_figures(out, outdir) -> list[str]:
    """Save the figures of ``mutext demo crack`` (identification, sidebands) in ``outdir``.

    Parameters
    ----------
    out : dict
        The result of :func:`mutext.demos.crack.solve`.
    outdir : str or path-like
        Folder for the PNG files (created if missing).

    Returns
    -------
    list of str
        The files written.
    """
    from .errors import ModelError
    from .response import FRF
    try:
        os.makedirs(outdir, exist_ok=True)
    except OSError as exc:
        raise ModelError(f"cannot write figures to {outdir!r}: {exc.strerror or exc}") from None
    files = [_save(crack_identification_figure(out), outdir, "crack_identification.png")]
    if "sidebands_evidence" in out:
        meas = FRF(out["freqs_hz"], out["measured"])
        files.append(_save(sideband_figure(meas, out["sidebands_evidence"], out["engineering"]), outdir,
                           "crack_sidebands.png"))
    return files


# ----------------------------------------------------------------------------- rotordynamics
# Each draws a result of mutext.rotor (campbell, mode_shapes, unbalance_response, orbit): data only.

_WHIRL_STYLE = {"forward": ("^", "C0"), "backward": ("v", "C3"), "mixed": ("o", "0.5"),
                "degenerate": ("o", "0.5"), "": ("o", "0.5")}


def campbell_figure(cd, *, log_dec: bool = True, title=None, label_orders=(1, 2, 3)):
    """Campbell diagram of a :class:`mutext.rotor.CampbellDiagram`: whirl frequencies against speed
    (forward up-triangles, backward down-triangles), the excitation lines of its orders, the critical
    speeds found on them (circles; forward ones of ``label_orders`` labelled in rpm), and, with ``log_dec``,
    the logarithmic decrement of every mode below.

    Parameters
    ----------
    cd : mutext.rotor.CampbellDiagram
        The diagram's data (:func:`mutext.rotor.campbell`).
    log_dec : bool, optional
        Add the panel of logarithmic decrements.
    title : str, optional
        Title of the figure.

    label_orders : sequence of int, optional
        Orders whose forward critical speeds are labelled.
    """
    plt = _plt()
    rpm = cd.speeds_rpm
    if log_dec:
        fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 6.0), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    else:
        fig, ax = plt.subplots(figsize=(7.0, 4.5))
        bx = None
    n = cd.frequencies_hz.shape[1]
    for r in range(n):
        ax.plot(rpm, cd.frequencies_hz[:, r], "-", color="0.75", lw=0.8, zorder=1)
        for name, (m, c) in _WHIRL_STYLE.items():
            k = np.array([cd.direction[i][r] == name for i in range(rpm.size)])
            if k.any():
                ax.plot(rpm[k], cd.frequencies_hz[k, r], m, color=c, ms=4, zorder=2)
                if bx is not None:
                    bx.plot(rpm[k], cd.log_dec[k, r], m, color=c, ms=3)
        if bx is not None:
            bx.plot(rpm, cd.log_dec[:, r], "-", color="0.75", lw=0.8, zorder=1)
    top = np.nanmax(cd.frequencies_hz) * 1.08
    for j, k in enumerate(cd.orders):
        ax.plot(rpm, k * rpm / 60.0, "k", ls=["-", "--", ":", "-."][j % 4], lw=0.9, label=f"{k}x")
    for c in cd.crossings:
        ax.plot(c.speed_rpm, c.frequency_hz, "o", mfc="none", mec="k", ms=7, zorder=3)
        if c.whirl == "forward" and c.order in label_orders:
            ax.annotate(f"{c.order}x: {c.speed_rpm:.0f} rpm", (c.speed_rpm, c.frequency_hz),
                        textcoords="offset points", xytext=(4, -12 - 9 * (c.order % 2)), fontsize=8)
    ax.plot([], [], "^", color="C0", label="forward whirl")
    ax.plot([], [], "v", color="C3", label="backward whirl")
    ax.plot([], [], "o", mfc="none", mec="k", label="critical speed (crossing)")
    ax.set_ylim(0, top)
    ax.set_xlim(rpm[0], rpm[-1])
    ax.set_ylabel("frequency [Hz]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title or f"Campbell diagram: {cd.name}", fontsize=10)
    if bx is not None:
        bx.set_ylabel("log decrement")
        bx.grid(True, alpha=0.3)
        bx.set_xlabel("speed [rpm]")
    else:
        ax.set_xlabel("speed [rpm]")
    fig.tight_layout()
    return fig


def mode_shapes_figure(ms, *, marks=None, title=None):
    """Mode shapes of a :class:`mutext.rotor.ModeShapes` along the shaft: per mode the whirl envelope
    (the semi-major axis at each station, shaded) and the planar snapshot along the major axis
    (``ms.shape``, signs show the nodes); the title of each panel gives frequency, damping ratio, log decrement and whirl.
    ``marks`` maps a station to a label (bearings, disks) drawn as vertical lines.

    Parameters
    ----------
    ms : mutext.rotor.ModeShapes
        The modes (:func:`mutext.rotor.mode_shapes`).
    marks : dict of int to str, optional
        Station -> label drawn as a vertical line.
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    n = ms.frequencies_hz.size
    fig, axes = plt.subplots(n, 1, figsize=(7.0, 1.7 * n + 0.6), sharex=True, squeeze=False)
    z = 1e3 * ms.positions
    for r, ax in enumerate(axes[:, 0]):
        ax.fill_between(z, -ms.semi_major[:, r], ms.semi_major[:, r], color="C0", alpha=0.15, lw=0)
        ax.plot(z, ms.shape[:, r], "C0o-", lw=1.2, ms=2.5, label="shape (along the major axis)")
        for st, lab in (marks or {}).items():
            ax.axvline(z[st - 1], color="0.5", lw=0.7, ls=":")
            if r == 0:
                ax.text(z[st - 1], 1.12, lab, fontsize=7, ha="center", color="0.3")
        ax.set_ylim(-1.25, 1.25)
        ax.set_title(f"mode {r + 1}: {ms.frequencies_hz[r]:.2f} Hz, zeta = {ms.damping_ratio[r]:.4f}, "
                     f"log dec = {ms.log_dec[r]:.4f}, {ms.direction[r]}", fontsize=8, loc="left")
        ax.grid(True, alpha=0.3)
    axes[0, 0].fill_between([], [], [], color="C0", alpha=0.15, lw=0, label="whirl envelope (semi-major axis)")
    axes[0, 0].legend(fontsize=7, loc="lower right")
    axes[-1, 0].set_xlabel("axial position [mm]")
    fig.suptitle(title or f"mode shapes at {ms.speed * 30 / np.pi:.0f} rpm (whirl envelope shaded)", fontsize=10)
    fig.tight_layout()
    return fig


def _probe_label(p):
    st, a = p
    return f"station {st}" + (f", {np.degrees(a):.0f} deg" if a else " (x)")


def unbalance_bode_figure(resp, *, critical=None, title=None):
    """Bode plot of a :class:`mutext.rotor.UnbalanceResponse`: amplitude [µm] and phase [deg] at every probe
    against speed [rpm]; ``critical`` (a list of :class:`mutext.rotor.Crossing`) drawn as vertical lines.

    Parameters
    ----------
    resp : mutext.rotor.UnbalanceResponse
        The response (:func:`mutext.rotor.unbalance_response`).
    critical : list of mutext.rotor.Crossing, optional
        Critical speeds drawn as vertical lines.
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.0, 5.0), sharex=True)
    for j, p in enumerate(resp.probes):
        a1.semilogy(resp.speeds_rpm, 1e6 * resp.amplitude[:, j], label=_probe_label(p))
        a2.plot(resp.speeds_rpm, np.degrees(resp.phase[:, j]))
    for c in critical or ():
        for a in (a1, a2):
            a.axvline(c.speed_rpm, color="0.4", lw=0.8, ls=":")
        a1.annotate(f"{c.order}x crit. {c.speed_rpm:.0f} rpm", (c.speed_rpm, a1.get_ylim()[1]),
                    textcoords="offset points", xytext=(3, -10), fontsize=7, color="0.3")
    a1.set_ylabel("amplitude [µm, 0-peak]")
    a2.set_ylabel("phase [deg]")
    a2.set_xlabel("speed [rpm]")
    a1.legend(fontsize=8)
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    u = ", ".join(f"{1e6 * m:g} g mm at station {s}" for s, m, _ in resp.unbalances)
    a1.set_title(title or f"unbalance response ({u})", fontsize=10)
    fig.tight_layout()
    return fig


def unbalance_polar_figure(resp, *, probe: int = 0, every=None, title=None):
    """Polar (Nyquist) plot of one probe of a :class:`mutext.rotor.UnbalanceResponse`: the complex 1x
    amplitude [µm] as the speed rises, with a few speeds labelled in rpm.

    Parameters
    ----------
    resp : mutext.rotor.UnbalanceResponse
        The response (:func:`mutext.rotor.unbalance_response`).
    probe : int, optional
        Index of the probe.
    every : int, optional
        Label every ``every``-th speed (default: about eight labels).
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    P = 1e6 * resp.response[:, probe]
    fig, ax = plt.subplots(figsize=(5.2, 5.0))
    ax.plot(P.real, P.imag, "C0.-", ms=2.5, lw=0.8)
    every = every or max(1, resp.speeds.size // 8)
    for i in range(0, resp.speeds.size, every):
        ax.annotate(f"{resp.speeds_rpm[i]:.0f}", (P[i].real, P[i].imag), fontsize=7, textcoords="offset points",
                    xytext=(3, 3))
    ax.plot([0], [0], "k+")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("real [µm]")
    ax.set_ylabel("imaginary [µm]")
    ax.grid(True, alpha=0.3)
    ax.set_title(title or f"polar plot, {_probe_label(resp.probes[probe])} (speeds in rpm)", fontsize=10)
    fig.tight_layout()
    return fig


def orbit_figure(orbits, *, titles=None, title=None):
    """Orbits (:class:`mutext.rotor.Orbit`) side by side in µm: the path, the keyphasor mark at t = 0 (dot)
    and the sense of travel (arrow).

    Parameters
    ----------
    orbits : iterable of mutext.rotor.Orbit
        The orbits, one panel each.
    titles : sequence of str, optional
        Title of each panel.
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    orbits = list(orbits)
    fig, axes = plt.subplots(1, len(orbits), figsize=(min(7.0, 3.3 * len(orbits)), 3.4), squeeze=False)
    for j, (o, ax) in enumerate(zip(orbits, axes[0])):
        x, y = 1e6 * o.x, 1e6 * o.y
        ax.plot(x, y, "C0-", lw=1.1)
        ax.plot(x[0], y[0], "ko", ms=4)
        k = max(1, len(x) // 40)
        ax.annotate("", xy=(x[k], y[k]), xytext=(x[0], y[0]), arrowprops=dict(arrowstyle="->", color="C3"))
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [µm]")
        ax.set_ylabel("y [µm]")
        ax.grid(True, alpha=0.3)
        ax.set_title((titles[j] if titles else o.label), fontsize=8)
    return _finish(fig, title, fontsize=10)


def run_up_figure(result, *, others=(), trace: bool = True, title=None):
    """Envelope of a transient run-up or coast-down (:class:`mutext.rotor.TransientRunUp`) against speed
    [rpm]: the largest orbit radius [µm] in each revolution at every output station, the radius itself
    (thin, ``trace``), the peak marked, and the steady unbalance response (semi-major axis) dashed.

    Parameters
    ----------
    result : mutext.rotor.TransientRunUp
        The run (:func:`mutext.rotor.transient_run_up`).
    others : sequence of mutext.rotor.TransientRunUp, optional
        More runs drawn on the same axes (a coast-down beside the run-up, another acceleration); the
        steady response is drawn once, from ``result``.
    trace : bool, optional
        Draw the orbit radius at every time step too.
    title : str, optional
        Title of the figure.
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    runs = [result, *others]
    for i, r in enumerate(runs):
        kind = "run-up" if r.acceleration > 0 else "coast-down" if r.acceleration < 0 else "constant speed"
        for j, st in enumerate(r.stations):
            color = f"C{(i * len(r.stations) + j) % 10}"
            if trace:
                ax.plot(r.speed_rpm, 1e6 * r.radius[:, j], color=color, lw=0.4, alpha=0.35)
            ax.plot(r.rev_speed_rpm, 1e6 * r.envelope[:, j], color=color, lw=1.4,
                    label=f"{kind} {abs(r.acceleration) * 30 / np.pi:.0f} rpm/s, station {st}")
            w, a = r.peak(j)
            ax.plot([w * 30 / np.pi], [1e6 * a], "o", color=color, ms=5)
            ax.annotate(f"{w * 30 / np.pi:.0f} rpm", (w * 30 / np.pi, 1e6 * a), textcoords="offset points",
                        xytext=(4, 4), fontsize=7, color=color)
    for j, st in enumerate(result.stations):
        ax.plot(result.steady.speeds_rpm, 1e6 * result.steady.semi_major[:, j], "k--", lw=0.9,
                label=f"steady, station {st}")
    ax.set_xlabel("speed [rpm]")
    ax.set_ylabel("orbit radius [µm, 0-peak]")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    u = ", ".join(f"{1e6 * m:g} g mm at station {s}" for s, m, _ in result.unbalances)
    ax.set_title(title or f"transient run-up through the critical speeds ({u})", fontsize=10)
    fig.tight_layout()
    return fig
