"""``mutext demo crack``: the thesis's chapter-4 identification on the cracked rotor at speed.

1. The rig: the thesis rotor at 10 Hz with a breathing crack at station 15
   (40 % deep, Mayes law), swept 20-225 Hz in 0.5 Hz steps from the exciter
   current (station 12) to the sensor (station 13) the way the analyzer
   measures it (harmonic balance, :func:`mutext.rig.measure_rotor`), with
   noise.
2. What a time-invariant model cannot hold: the sideband evidence
   (:func:`mutext.diagnose.sideband_evidence`).
3. Model-based identification (thesis sec. 4.4): the healthy model, reduced
   by modal truncation, as the engineering system; the measured sweep,
   fitted by a stable rational model, as the true system; the controller
   at the crack station (force and displacement at station 15, x); the W_z
   search of :func:`mutext.mbi.identify`.
4. What K means: its dynamic stiffness near the first mode against the
   point-spring loss that reproduces the rig's own noise-free sweep exactly
   (:func:`mutext.mbi.required_impedance`), and against the loss the
   revolution-averaged crack alone would imply.

``--thesis-tables`` also runs the thesis's own data path: its hand-tuned
cracked station table (density and disk mass) as the true system.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from ..examples import cracked_rotor as ex


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a report")
    p.add_argument("--plots", metavar="DIR", help="save the figures (PNG) in DIR")
    p.add_argument("--depth", type=float, default=0.4, help="crack depth over diameter (default 0.4)")
    p.add_argument("--law", default="mayes", choices=("mayes", "gasch", "open"),
                   help="breathing law of the rig's crack (default mayes)")
    p.add_argument("--noise", type=float, default=0.001,
                   help="relative noise of the sweep (default 0.001; the 1X sidebands are about 0.4 %%)")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    p.add_argument("--cutoff", type=float, default=250.0,
                   help="modal truncation of the engineering model [Hz] (default 250)")
    p.add_argument("--thesis-tables", action="store_true",
                   help="also identify the thesis's cracked station table against the healthy one")


def _rel_rms(H, ref) -> float:
    return float(np.sqrt(np.mean(np.abs(H - ref) ** 2) / np.mean(np.abs(ref) ** 2)))


def _first_mode_band(f1, f):
    sel = (f >= 0.7 * f1) & (f <= 1.3 * f1)
    return sel if sel.sum() >= 3 else np.abs(f - f1) <= np.sort(np.abs(f - f1))[2]


def _identify(measured, E, out, progress=None):
    from ..mbi import identify
    return identify(measured, E, excitation=ex.EXCITATION, measurement=ex.MEASUREMENT,
                    control_input=ex.CONTROL_INPUT, control_output=ex.CONTROL_OUTPUT, Ww=ex.THESIS["Ww"],
                    out=out, progress=progress)


def _k_peaks(K, f):
    from ..lti import freqresp
    from ..response import local_extrema
    return [float(x) for x in local_extrema(f, np.abs(freqresp(K, 2 * np.pi * f)[0, 0]))[0]]


def solve(depth: float = 0.4, law: str = "mayes", noise: float = 0.001, seed: int = 0,
          cutoff_hz: float = 250.0, thesis_tables: bool = False, out=sys.stderr, progress=None) -> dict:
    """Everything the demo reports, as a dict (SI; frequencies in Hz).

    ``out`` gets the log, ``progress(stage, fraction)`` the identification's progress
    (:func:`mutext.mbi.identify`).

    Parameters
    ----------
    depth : float, optional
        Crack depth over shaft diameter, a/D.
    law : {"mayes", "gasch", "open"}, optional
        Breathing law of the rig's crack.
    noise : float, optional
        Relative noise of the measured sweep.
    seed : int, optional
        Seed of the noise.
    cutoff_hz : float, optional
        Modal truncation of the engineering model [Hz].
    thesis_tables : bool, optional
        Also identify the thesis's cracked station table (:func:`thesis_tables_path`).
    out : file-like, optional
        Where the log is written.
    progress : callable, optional
        ``progress(stage, fraction)`` for the long steps.
    """
    from ..diagnose import sideband_evidence
    from ..errors import ModelError
    from ..lti import freqresp
    from ..mbi import required_impedance
    from ..rig import measure, measure_rotor, with_noise
    from ..rotor import modal_truncation

    if not (np.isfinite(noise) and 0 <= noise < 1):
        raise ModelError(f"--noise must be a relative level in [0, 1), got {noise!r}")
    t0 = time.perf_counter()

    def say(msg):
        if out is not None:
            print(f"[crack] {msg} ({time.perf_counter() - t0:.1f} s)", file=out, flush=True)

    healthy = ex.healthy_rotor()
    cracked = ex.cracked_rotor(depth, breathing=law)
    exact = measure_rotor(cracked, ex.EXCITATION, ex.MEASUREMENT)
    f = exact.freq_hz
    measured = with_noise(exact, noise, rng=seed)
    say(f"rig: {law} crack, depth {depth:g} D at station {ex.CONTROL_OUTPUT[1:]}, {ex.SPEED_HZ:g} Hz; "
        f"{f.size} frequencies {f[0]:g}-{f[-1]:g} Hz, noise {noise:g} (Ritz reduction error "
        f"{exact.metadata.get('reduction_error')})")
    modes_hz = healthy.natural_frequencies(n=8)
    ev = sideband_evidence(measured, modes_hz, ex.SPEED_HZ)
    say(f"sidebands: {ev.verdict} ({len(ev.found())} found, noise {100 * ev.noise:.2g} %)")

    ports = dict(inputs=[ex.EXCITATION, ex.CONTROL_INPUT], outputs=[ex.MEASUREMENT, ex.CONTROL_OUTPUT])
    full = healthy.state_space(**ports)
    red = modal_truncation(healthy, cutoff_hz, static_correction=False, band_hz=(float(f[0]), float(f[-1])),
                           hinf=False, **ports)
    E = red.system
    w = 2 * np.pi * f
    Gf, Gr = freqresp(full, w), freqresp(E, w)
    red_err = float(np.max(np.abs(Gr - Gf) / np.max(np.abs(Gf), axis=-1, keepdims=True)))
    say(f"engineering model: healthy rotor, modal truncation at {cutoff_hz:g} Hz -> {red.order} states "
        f"(error {red_err:.2g} of the peak, every channel)")

    res = _identify(measured, E, out, progress)
    say(f"identified: mu {res.mu_upper:.4f} at W_z {res.Wz:.3g} m, K of order {res.K.nstates}")

    # what K means: its dynamic stiffness near the first mode against the exact requirement
    f1 = float(min(m for m, _ in ev.modes)) if ev.modes else float(modes_hz[0])
    band1 = _first_mode_band(f1, f)
    D_rig = required_impedance(full, exact, excitation=ex.EXCITATION, measurement=ex.MEASUREMENT,
                               control_input=ex.CONTROL_INPUT, control_output=ex.CONTROL_OUTPUT)
    mean_lti = measure(lambda w_: cracked.frf(w_ / (2 * np.pi), inputs=[ex.EXCITATION],
                                              outputs=[ex.MEASUREMENT]).H[0, 0], 0, 0, f)
    D_mean = required_impedance(full, mean_lti, excitation=ex.EXCITATION, measurement=ex.MEASUREMENT,
                                control_input=ex.CONTROL_INPUT, control_output=ex.CONTROL_OUTPUT)
    K = freqresp(res.K, w)[0, 0]
    equivalent = -float(np.median(D_rig[band1].real))
    identified = -float(np.median(K[band1].real))
    blind = float(f[int(np.argmax(np.abs(D_rig)))])
    He = Gf[0, 0]
    Hc = freqresp(res.controlled, w)[0, 0]
    result = {
        "mu": res.mu_upper, "mu_lower": res.mu_lower, "Wz": res.Wz, "K_order": int(res.K.nstates),
        "equivalent_stiffness_loss": equivalent,
        "identified_stiffness_loss": identified,
        "identified_error": abs(identified - equivalent) / abs(equivalent),
        "mean_stiffness_loss": -float(np.median(D_mean[band1].real)),
        "first_mode_band_hz": [float(f[band1][0]), float(f[band1][-1])],
        "port_blind_hz": blind,
        "K_reading": res.fit.description,
        "K_peaks_hz": _k_peaks(res.K, f),
        "fit_error_before": _rel_rms(He, measured.response),
        "fit_error_after": _rel_rms(Hc, measured.response),
        "measured_fit": {"order": res.measured_fit.order, "residual": res.measured_fit.residual},
        "reduction_error": max(red_err, float(exact.metadata.get("reduction_error", 0.0))),
        "reduction": {"engineering_order": int(red.order), "engineering_error": red_err,
                      "rig_ritz_error": float(exact.metadata.get("reduction_error", "nan"))},
        "sidebands": ev.to_dict(), "sidebands_evidence": ev,
        "rig": {"law": law, "depth_ratio": depth, "station": int(ex.CONTROL_OUTPUT[1:]),
                "speed_hz": ex.SPEED_HZ, "noise": noise, "seed": seed},
        "thesis": dict(ex.THESIS),
        "tries": [{"Wz": t.Wz, "mu": t.mu_upper} for t in res.tries],
        "notes": list(res.notes),
        "freqs_hz": f, "measured": measured.response, "engineering": He, "controlled": Hc,
        "K": K, "D_rig": D_rig, "D_mean": D_mean,
    }
    result.update(engineering_system=E, first_mode_mask=band1)
    if thesis_tables:
        say("thesis data path: cracked station table (density, disk mass) as the true system")
        result["thesis_tables"] = thesis_tables_path(result, out=out, progress=progress)
    result["seconds"] = time.perf_counter() - t0
    return result


def thesis_tables_path(result, *, out=None, progress=None) -> dict:
    """The thesis's own data path: its cracked station table (density and disk mass tuned by hand,
    no crack element) as the true system, against the same engineering model as ``result``
    (a dict of :func:`solve`), with the same noise.

    Parameters
    ----------
    result : dict
        The result of :func:`solve`.
    out : file-like, optional
        Where the log is written.
    progress : callable, optional
        ``progress(stage, fraction)`` for the long steps.
    """
    from ..lti import freqresp
    from ..rig import measure
    f = result["freqs_hz"]
    w = 2 * np.pi * f
    rig = result["rig"]
    table = ex.thesis_cracked_table_rotor()
    tm = measure(table.state_space(inputs=[ex.EXCITATION], outputs=[ex.MEASUREMENT]), ex.EXCITATION,
                 ex.MEASUREMENT, f, noise=rig["noise"], rng=rig["seed"])
    tm.input_name, tm.output_name = ex.EXCITATION, ex.MEASUREMENT
    rt = _identify(tm, result["engineering_system"], out, progress)
    Kt = freqresp(rt.K, w)[0, 0]
    return {"mu": rt.mu_upper, "Wz": rt.Wz, "K_order": int(rt.K.nstates), "K_reading": rt.fit.description,
            "K_peaks_hz": _k_peaks(rt.K, f), "K_at_first_mode": -float(np.median(Kt[result["first_mode_mask"]].real)),
            "fit_error_before": _rel_rms(result["engineering"], tm.response),
            "fit_error_after": _rel_rms(freqresp(rt.controlled, w)[0, 0], tm.response),
            "notes": list(rt.notes), "K": Kt}


JSON_KEYS = ("mu", "mu_lower", "Wz", "K_order", "equivalent_stiffness_loss", "identified_stiffness_loss",
             "identified_error", "mean_stiffness_loss", "first_mode_band_hz", "port_blind_hz", "K_reading",
             "K_peaks_hz", "fit_error_before", "fit_error_after", "measured_fit", "reduction_error", "reduction",
             "sidebands", "rig", "thesis", "tries", "notes", "seconds")


def run(args) -> int:
    """Run the subcommand with the parsed ``args``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        The exit status.
    """
    if getattr(args, "plots", None) is not None:
        from .._files import output_directory
        output_directory(args.plots, "--plots")     # checked before the work, not after it
    from ..progress import ProgressLine
    prog = ProgressLine()        # the log and the identification's bar, both on stderr
    out = solve(args.depth, args.law, args.noise, args.seed, args.cutoff, args.thesis_tables, out=prog,
                progress=prog)
    if args.json:
        from ..jsonio import print_json
        d = {k: out[k] for k in JSON_KEYS}
        if "thesis_tables" in out:
            d["thesis_tables"] = {k: v for k, v in out["thesis_tables"].items() if k != "K"}
        print_json(d)
    else:
        _report(out)
    if args.plots:
        from ..plots import crack_figures
        files = crack_figures(out, args.plots)
        print("plots saved: " + ", ".join(files), file=sys.stderr if args.json else sys.stdout)
    return 0


def _report(o):
    rig, th = o["rig"], o["thesis"]
    ev = o["sidebands"]
    print(f"cracked rotor at {rig['speed_hz']:g} Hz (thesis ch. 4): {rig['law']} crack, {rig['depth_ratio']:g} D "
          f"at station {rig['station']}, sweep i12 -> x13, noise {rig['noise']:g}")
    print(f"sidebands ({ev['speed_hz']:g} Hz speed): {ev['verdict']} ({ev['meaning']}); found at "
          + (", ".join(f"{c['freq_hz']:.1f} Hz (k={c['k']:+d}, {100 * c['relative_size']:.2f} %)"
                       for c in ev["candidates"] if c["found"]) or "none")
          + f"; smallest detectable about {100 * ev['detectable']:.2g} %")
    print(f"model-based identification: mu <= {o['mu']:.4f} at W_z = {o['Wz']:.3g} m "
          f"(thesis: mu <= {th['mu']} at {th['Wz']:g} m); K of order {o['K_order']}")
    print(f"  fit error (relative RMS on the band): healthy model {o['fit_error_before']:.3f} -> with K "
          f"{o['fit_error_after']:.3f}; true-system fit order {o['measured_fit']['order']}, residual "
          f"{o['measured_fit']['residual']:.3g}; reductions: engineering {o['reduction']['engineering_error']:.2g}, "
          f"rig {o['reduction']['rig_ritz_error']:.2g}")
    b = o["first_mode_band_hz"]
    print(f"what K means, near the first mode ({b[0]:g}-{b[1]:g} Hz):")
    print(f"  point-spring loss at station {rig['station']} that reproduces the rig's own sweep: "
          f"{o['equivalent_stiffness_loss']:.0f} N/m")
    print(f"  read from K: {o['identified_stiffness_loss']:.0f} N/m "
          f"({100 * o['identified_error']:.1f} % off)")
    print(f"  the revolution-averaged crack alone would imply {o['mean_stiffness_loss']:.0f} N/m: breathing "
          "makes the crack look softer at resonance than its average stiffness")
    print(f"  as mass/damper/spring: {o['K_reading']}")
    print(f"  a force at station {rig['station']} cannot explain the sweep near {o['port_blind_hz']:.1f} Hz "
          "(the station barely moves in the mode that changed there): K grows without meaning, as the "
          f"thesis's K did at {th['K_resonances_hz'][0]:g} and {th['K_resonances_hz'][1]:g} Hz")
    if "thesis_tables" in o:
        t = o["thesis_tables"]
        print(f"thesis data path (cracked station table as the true system): mu <= {t['mu']:.4f} at "
              f"W_z = {t['Wz']:.3g} m; K: {t['K_reading']}; |K| peaks at "
              + (", ".join(f"{x:.1f}" for x in t["K_peaks_hz"]) or "none") + " Hz")
    print(f"time: {o['seconds']:.1f} s")
