"""``mutext demo rotor``: the thesis rotor on ball bearings (thesis sec. 4.3).

Builds the healthy and the cracked rotor from the thesis station tables with
the bearings, exciter and damping of ``mutext/data/rotor.toml``, prints the
natural frequencies (Hz) at the sweep speed (10 Hz rotation) and the
frequency response from the exciter current (station 12, A) to the exciter
sensor (station 13, m) over the measured band 20-225 Hz, the healthy rotor's
Campbell diagram (0-6000 rpm: the mode frequencies and the forward critical speeds of the
1x, 2x and 3x lines, :func:`mutext.rotor.campbell`) and the orbit at the sensor station
for an unbalance at the crack station at the sweep speed
(:func:`mutext.rotor.unbalance_response`, :func:`mutext.rotor.orbit`).

The "cracked" model is the thesis's hand-tuned cracked table (density and
disk mass changed); it contains no crack element.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

CRACKED_NOTE = ("'cracked' is the thesis's hand-tuned cracked station table (density 0.29 lb/in^3, disk "
                "5.21 lb); it has no crack element")
ASSUMED = ("ASSUMED (not in the thesis): bearing stiffness 1e7 N/m at stations 2 and 29, exciter 40 N/A, "
           "Poisson's ratio 0.3, 1 % modal damping")


#: Unbalance of the orbit: 10 g mm at the crack station, seen by the sensor station.
UNBALANCE = {"station": 15, "kg_m": 1e-5, "probe": 13}


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a report")
    p.add_argument("--plots", metavar="DIR",
                   help="save the FRF, Campbell diagram, unbalance response and orbits (PNG) in DIR")
    p.add_argument("--model", metavar="TOML", help="model file (default: mutext/data/rotor.toml)")
    p.add_argument("--modes", type=int, default=6, help="number of natural frequencies to report (default 6)")
    p.add_argument("--points", type=int, default=400, help="FRF frequencies in 20-225 Hz (default 400)")


def solve(model_path=None, *, n_modes=6, points=400, band=(20.0, 225.0), campbell_speeds=13):
    """Everything the demo reports, as a dict (SI; frequencies in Hz).

    Parameters
    ----------
    model_path : str or path-like, optional
        Model file (default: ``mutext/data/rotor.toml``).
    n_modes : int, optional
        Number of natural frequencies reported.
    points : int, optional
        FRF frequencies in ``band``.
    band : (float, float), optional
        Frequency band [Hz] of the FRF.
    campbell_speeds : int, optional
        Speeds of the Campbell diagram over 0-6000 rpm (13: every 500 rpm; ``--plots`` asks for
        49, every 125 rpm, so that its figure and the reported critical speeds come from one
        diagram).
    """
    from ..errors import ModelError
    from ..response import local_extrema
    from ..rotor import data_path, load_model
    for name, v, lo in (("--modes (n_modes)", n_modes, 1), ("--points (points)", points, 2),
                        ("campbell_speeds", campbell_speeds, 2)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ModelError(f"{name} must be an integer >= {lo}, got {v!r}")
    if points > 1_000_000:
        raise ModelError(f"--points (points) must be at most 1000000, got {points}")
    try:
        lo_hz, hi_hz = (float(x) for x in band)
    except (TypeError, ValueError):
        raise ModelError(f"band must be two frequencies (Hz), got {band!r}") from None
    if not (np.isfinite(lo_hz) and np.isfinite(hi_hz) and 0 <= lo_hz < hi_hz):
        raise ModelError(f"band must satisfy 0 <= low < high (finite, Hz), got {band!r}")
    t0 = time.perf_counter()
    model_path = model_path or data_path("rotor.toml")
    rotors = {"healthy": load_model(model_path),
              "cracked": load_model(model_path, station_table=data_path("rotor_cracked.txt"))}
    f = np.linspace(band[0], band[1], points)
    out = {"natural_frequencies_hz": {}, "whirl": {}, "frf_peaks_hz": {}, "frf_antiresonances_hz": {},
           "frf": {}, "rotors": rotors, "freqs_hz": f}
    for key, r in rotors.items():
        md = r.modes(n=n_modes)
        out["natural_frequencies_hz"][key] = [float(x) for x in md.frequencies_hz]
        out["whirl"][key] = md.whirl_direction()
        H = r.frf(f, inputs=["i12"], outputs=["x13"])("x13", "i12")
        out["frf"][key] = H
        pk, an = local_extrema(f, np.abs(H))
        out["frf_peaks_hz"][key] = [float(x) for x in pk]
        out["frf_antiresonances_hz"][key] = [float(x) for x in an]
    r = rotors["healthy"]
    from ..rotor.campbell_diagram import campbell
    from ..rotor.orbits import orbit
    from ..rotor.unbalance import unbalance_response
    rpm = np.linspace(0.0, 6000.0, campbell_speeds)
    cd = campbell(r, rpm * np.pi / 30.0, n_modes=4, orders=(1, 2, 3))
    out["_campbell"] = cd
    out["campbell"] = {"speeds_rpm": [float(x) for x in rpm],
                       "frequencies_hz": [[float(x) for x in row] for row in cd.frequencies_hz],
                       **{f"critical_speeds_{k}x_forward": [c.to_dict() for c in cd.critical_speeds(k, "forward")]
                          for k in (1, 2, 3)}}
    ub = UNBALANCE
    u = unbalance_response(r, ub["station"], ub["kg_m"], [r.speed], [ub["probe"]])
    orb = orbit({1: (complex(u.X[0, 0]), complex(u.Y[0, 0]))}, r.speed, label=f"station {ub['probe']}")
    e = orb.ellipse(1)
    out["orbit"] = {**ub, "speed_rpm": r.speed * 30.0 / np.pi, "semi_major_m": float(e.semi_major),
                    "semi_minor_m": float(e.semi_minor), "direction": e.direction}
    out.update(_unbalance_and_breathing(model_path, r, cd))
    out["speed_rpm"] = r.speed * 60.0 / (2.0 * np.pi)
    out["bearing_stiffness_n_per_m"] = r.parameter("bearing2.k").value
    out["force_per_ampere_n_per_a"] = r.parameter("exciter12.ki").value
    out["note"] = CRACKED_NOTE
    out["assumptions"] = ASSUMED
    out["seconds"] = time.perf_counter() - t0
    return out


def _unbalance_and_breathing(model_path, healthy, cd) -> dict:
    """The unbalance response over 60-6000 rpm (1x, healthy rotor) and, a little below the 2x forward
    critical speed (where the 2x response of a breathing crack resonates), the orbits of the healthy rotor
    and of the same rotor with the rig's breathing crack (weight and unbalance, harmonic balance)."""
    from ..errors import ModelError
    from ..examples.cracked_rotor import cracked_rotor
    from ..rotor.periodic_orbit import periodic_unbalance_response
    from ..rotor.unbalance import unbalance_response
    ub = UNBALANCE
    rpm = np.linspace(60.0, 6000.0, 331)
    resp = unbalance_response(healthy, ub["station"], ub["kg_m"], rpm * np.pi / 30.0, [ub["probe"]])
    s_pk, a_pk = resp.peak(0)
    out = {"unbalance": {**ub, "peak_rpm": s_pk * 30.0 / np.pi, "peak_m": a_pk,
                         "speeds_rpm": [float(x) for x in rpm],
                         "amplitude_m": [float(x) for x in resp.amplitude[:, 0]]},
           "_unbalance_response": resp, "_critical_1x": cd.critical_speeds(1, "forward")}
    two = cd.critical_speeds(2, "forward")
    if not two:
        out["breathing_orbit"] = {"skipped": "no 2x forward critical speed in 0-6000 rpm"}
        return out
    speed = 0.93 * two[0].speed
    try:
        cracked = periodic_unbalance_response(cracked_rotor(model_path=model_path), speed, [ub["probe"]],
                                              unbalance=(ub["station"], ub["kg_m"]), harmonics=4)
    except ModelError as exc:      # a model file without the rig's crack station
        out["breathing_orbit"] = {"skipped": f"the rig's crack does not fit this model ({exc})"}
        return out
    plain = unbalance_response(healthy, ub["station"], ub["kg_m"], [speed], [ub["probe"]])
    orbit = cracked.orbit(0)
    out["breathing_orbit"] = {"speed_rpm": speed * 30.0 / np.pi, "probe": ub["probe"],
                              "amplitude_m": {f"{k}x": cracked.amplitude(k) for k in (1, 2, 3)},
                              "healthy_1x_m": float(plain.amplitude[0, 0]), "loops": orbit.loops()}
    out["_orbits"] = [plain.orbit(0), orbit]
    return out


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
    out = solve(args.model, n_modes=args.modes, points=args.points,
                campbell_speeds=49 if getattr(args, "plots", None) is not None else 13)
    if args.json:
        from ..jsonio import print_json
        keys = ("natural_frequencies_hz", "whirl", "frf_peaks_hz", "frf_antiresonances_hz", "speed_rpm",
                "bearing_stiffness_n_per_m", "force_per_ampere_n_per_a", "campbell", "orbit", "unbalance",
                "breathing_orbit", "note",
                "assumptions", "seconds")
        print_json({k: out[k] for k in keys})
    else:
        r = out["rotors"]["healthy"]
        print(f"thesis rotor (sec. 4.3): {r.n_stations} stations, {r.positions[-1] / 0.0254:.3f} in long, "
              f"{r.ndof} DOFs, {len(r.parameters)} parameters; spin {out['speed_rpm']:.0f} rpm")
        print(ASSUMED)
        print(f"note: {CRACKED_NOTE}")
        for key in ("healthy", "cracked"):
            fr = out["natural_frequencies_hz"][key]
            wh = out["whirl"][key]
            print(f"{key:>8} natural frequencies [Hz]: " +
                  ", ".join(f"{x:.2f}{w[:1].upper() if w else ''}" for x, w in zip(fr, wh)) +
                  "   (B/F: backward/forward whirl)")
        for key in ("healthy", "cracked"):
            H = out["frf"][key]
            k = int(np.argmax(np.abs(H)))
            print(f"{key:>8} FRF i12 -> x13 (20-225 Hz): peaks at "
                  + ", ".join(f"{x:.1f}" for x in out["frf_peaks_hz"][key]) + " Hz; anti-resonances at "
                  + ", ".join(f"{x:.1f}" for x in out["frf_antiresonances_hz"][key])
                  + f" Hz; max |H| = {abs(H[k]) * 1e6:.3g} um/A at {out['freqs_hz'][k]:.1f} Hz")
        cb = out["campbell"]
        # the rows nearest 0, 2000, 4000 and 6000 rpm, whatever the number of speeds computed
        sp = np.asarray(cb["speeds_rpm"])
        rows = sorted({int(np.argmin(np.abs(sp - x))) for x in (0.0, 2000.0, 4000.0, 6000.0)})
        print("Campbell (healthy) [Hz] at " + ", ".join(f"{sp[i]:.0f}" for i in rows) + " rpm: "
              + "; ".join(", ".join(f"{x:.1f}" for x in cb["frequencies_hz"][i]) for i in rows))
        for k in (1, 2, 3):
            crit = cb[f"critical_speeds_{k}x_forward"]
            print(f"{k}x forward critical speeds (0-6000 rpm): " + (", ".join(
                f"{c['speed_rpm']:.0f} rpm ({c['frequency_hz']:.1f} Hz)" for c in crit) or "none"))
        o = out["orbit"]
        print(f"orbit at station {o['probe']} ({o['kg_m'] * 1e6:g} g mm unbalance at station {o['station']}, "
              f"{o['speed_rpm']:.0f} rpm): ellipse {o['semi_major_m'] * 1e6:.3g} x {o['semi_minor_m'] * 1e6:.3g} um, "
              f"{o['direction']}")
        u = out["unbalance"]
        print(f"unbalance response at station {u['probe']} (60-6000 rpm): peak {u['peak_m'] * 1e6:.3g} um at "
              f"{u['peak_rpm']:.0f} rpm (the 1x forward critical speed)")
        b = out["breathing_orbit"]
        if "skipped" in b:
            print(f"breathing-crack orbit: skipped ({b['skipped']})")
        else:
            a = b["amplitude_m"]
            print(f"breathing crack (rig's, a/D 0.4 at station 15) at {b['speed_rpm']:.0f} rpm, station {b['probe']}: "
                  + ", ".join(f"{k} {v * 1e6:.3g} um" for k, v in a.items())
                  + f" (healthy 1x {b['healthy_1x_m'] * 1e6:.3g} um); the orbit crosses itself "
                  f"{b['loops']} time(s)")
        print(f"time: {out['seconds']:.2f} s")
    if args.plots:
        files = save_plots(out, args.plots)
        print("plots saved: " + ", ".join(files), file=sys.stderr if args.json else sys.stdout)
    return 0


def save_plots(out, directory):
    """PNG files: the FRF (magnitude and phase) of both rotors, the healthy rotor's Campbell diagram (1x,
    2x, 3x) and unbalance response (Bode), and the orbits of the healthy and the breathing-cracked rotor.

    Parameters
    ----------
    out : dict
        The result of :func:`solve`.
    directory : str or path-like
        Folder for the PNG files (created if missing).
    """
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from ..errors import ModelError
    try:
        os.makedirs(directory, exist_ok=True)
        probe = os.path.join(directory, ".mutext_write_test")
        with open(probe, "w"):
            pass
        os.remove(probe)
    except OSError as exc:
        raise ModelError(f"--plots {directory!r}: cannot write plots there ({exc.strerror or exc})") from None
    files = []

    def save(fig, name):
        files.append(os.path.join(directory, name))
        fig.savefig(files[-1], dpi=120)
        plt.close(fig)

    f = out["freqs_hz"]
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    for key, style in (("healthy", "-"), ("cracked", "--")):
        H = out["frf"][key]
        a1.semilogy(f, np.abs(H) * 1e6, style, label=key)
        a2.plot(f, np.degrees(np.unwrap(np.angle(H))), style, label=key)
    a1.set_ylabel("|x13 / i12| [um/A]")
    a2.set_ylabel("phase [deg]")
    a2.set_xlabel("frequency [Hz]")
    a1.legend()
    a1.set_title("exciter current (station 12) to sensor (station 13)")
    fig.tight_layout()
    save(fig, "rotor_frf.png")

    from .. import plots
    # the diagram whose critical speeds the report gives (solve(campbell_speeds=49) for a smooth figure)
    save(plots.campbell_figure(out["_campbell"], title="Campbell diagram, healthy thesis rotor (1x, 2x, 3x)"),
         "rotor_campbell.png")
    save(plots.unbalance_bode_figure(out["_unbalance_response"], critical=out["_critical_1x"],
                                     title=f"unbalance {UNBALANCE['kg_m'] * 1e6:g} g mm at station "
                                           f"{UNBALANCE['station']}, healthy rotor"), "rotor_unbalance.png")
    if "_orbits" in out:
        rpm = out["breathing_orbit"]["speed_rpm"]
        save(plots.orbit_figure(out["_orbits"], titles=[f"healthy, 1x, {rpm:.0f} rpm",
                                                        f"breathing crack, {rpm:.0f} rpm"]), "rotor_orbits.png")
    return files
