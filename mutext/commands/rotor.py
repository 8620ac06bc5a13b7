"""``mutext rotor campbell MODEL.toml --speeds 0:3000:31 [--modes N] [--orders 1,2,3] [--plot FILE] [--json]``
``mutext rotor whirl MODEL.toml --input PORT --output PORT [--speed RPM] [--freqs START:STOP:COUNT] [--json]``
and ``mutext rotor runup MODEL.toml --unbalance STATION:MASS_KG:RADIUS_M --speeds START:STOP --duration S
--output STATION [--plot FILE] [--json]``.

``campbell``: the Campbell diagram of a rotor model file (:func:`mutext.rotor.campbell`):
the whirl frequencies of the lowest modes against speed, forward or backward,
their logarithmic decrement, and the critical speeds where the excitation
lines of the orders (1x unbalance, 2x and 3x a breathing crack) cross them.
Speeds are given in rpm as ``START:STOP:COUNT`` (evenly spaced, both ends
included) or as a comma-separated list.

``whirl``: the two-plane sweep the virtual rig would record (excited in x and
in y at the input's station, measured in x and y at the output's:
:func:`mutext.rig.measure_rotor` with ``planes="xy"``), its directional FRFs and
their resonances labelled forward or backward (:func:`mutext.rotor.whirl_peaks`).

``runup``: the rotor driven through its critical speeds at a constant
acceleration with an unbalance, integrated in time
(:func:`mutext.rotor.transient_run_up`): the peak orbit radius at each output
station and the speed where it occurs, beside the peak of the steady unbalance
response (lower and later in a run-up, earlier in a coast-down).
"""
from __future__ import annotations

import math


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    sub = p.add_subparsers(dest="action", required=True)
    c = sub.add_parser("campbell", help="Campbell diagram: whirl frequencies, log decrement and critical speeds",
                       description="The Campbell diagram of a rotor model file: whirl frequencies of the lowest "
                                   "modes against speed (forward/backward), their log decrement, and the critical "
                                   "speeds where the 1x, 2x, 3x lines cross them.")
    c.add_argument("model", metavar="MODEL.toml", help="rotor model file (two bending planes)")
    c.add_argument("--speeds", default="0:3000:31", metavar="START:STOP:COUNT",
                   help="speeds in rpm: START:STOP:COUNT (default 0:3000:31) or a list such as 0,500,1000")
    c.add_argument("--modes", type=int, default=6, metavar="N", help="lowest modes kept at each speed (default 6)")
    c.add_argument("--orders", default="1,2,3", help="excitation orders whose crossings are sought (default 1,2,3)")
    c.add_argument("--refine", action="store_true", help="locate each critical speed on the eigenproblem "
                                                          "(Brent's method) instead of interpolating")
    c.add_argument("--plot", metavar="FILE", help="save the diagram as an image (PNG, SVG or PDF by extension)")
    c.add_argument("--json", action="store_true", help="print the whole diagram as one JSON object")

    _add_whirl(sub)
    _add_runup(sub)

def _add_whirl(sub):
    w = sub.add_parser("whirl", help="forward and backward whirl peaks of a two-plane sweep (directional FRFs)",
                       description="Excite the rotor in x and in y at the input's station, measure x and y at the "
                                   "output's (the virtual rig, no noise), and list the resonances of the forward "
                                   "and backward directional FRFs.")
    w.add_argument("model", metavar="MODEL.toml", help="rotor model file (two bending planes)")
    w.add_argument("--input", required=True, metavar="PORT",
                   help="excitation: a port of the model (e.g. i12) or a station number (a unit force)")
    w.add_argument("--output", required=True, metavar="PORT",
                   help="measurement: a port of the model (e.g. x13) or a station number")
    w.add_argument("--speed", type=float, default=None, metavar="RPM", help="running speed in rpm "
                   "(default: the model's speed_rpm)")
    w.add_argument("--freqs", default="20:225:4101", metavar="START:STOP:COUNT",
                   help="sweep frequencies in Hz (default 20:225:4101, a 0.05 Hz step)")
    w.add_argument("--json", action="store_true", help="print the peaks as one JSON object")


def _add_runup(sub):
    r = sub.add_parser("runup", help="transient run-up or coast-down through the critical speeds with an unbalance",
                       description="Drive the rotor from START to STOP rpm at a constant acceleration with an "
                                   "unbalance, integrate the response in time (Newmark, on the lowest modes plus "
                                   "the static shapes of the unbalance forces), and print the peak orbit radius "
                                   "at each output beside the steady unbalance response's peak.")
    r.add_argument("model", metavar="MODEL.toml", help="rotor model file (two bending planes)")
    r.add_argument("--unbalance", required=True, action="append", metavar="STATION:MASS_KG:RADIUS_M[:PHASE_DEG]",
                   help="an unbalance mass at a station (repeat the option for more)")
    r.add_argument("--speeds", required=True, metavar="START:STOP",
                   help="start and stop speeds in rpm (STOP < START: a coast-down)")
    how = r.add_mutually_exclusive_group(required=True)
    how.add_argument("--duration", type=float, metavar="S", help="length of the run in seconds")
    how.add_argument("--acceleration", type=float, metavar="RPM_PER_S", help="rate of the speed change in rpm/s")
    r.add_argument("--output", required=True, action="append", metavar="STATION",
                   help="station whose orbit is recorded (repeat, or a comma-separated list)")
    r.add_argument("--modes", type=int, default=None, metavar="N",
                   help="undamped modes kept (default: those up to four times the top speed)")
    r.add_argument("--plot", metavar="FILE", help="save the envelope against speed as an image (PNG, SVG or PDF)")
    r.add_argument("--json", action="store_true", help="print the peaks and envelopes as one JSON object")


def _unbalance_arg(text: str):
    """``STATION:MASS_KG:RADIUS_M[:PHASE_DEG]`` -> (station, mass, radius, phase_rad), or a UsageError."""
    from ..errors import UsageError
    parts = str(text).split(":")
    try:
        if len(parts) not in (3, 4):
            raise ValueError
        st, m, e = int(parts[0]), float(parts[1]), float(parts[2])
        ph = math.radians(float(parts[3])) if len(parts) == 4 else 0.0
        if not all(math.isfinite(v) for v in (m, e, ph)) or m < 0 or e < 0:
            raise ValueError
    except ValueError:
        raise UsageError(f"--unbalance {text!r}: expected STATION:MASS_KG:RADIUS_M[:PHASE_DEG] with a non-negative "
                         "mass and radius (e.g. 16:0.001:0.01)") from None
    return st, m, e, ph


def _outputs_arg(values):
    from ..errors import UsageError
    out = []
    for text in values:
        for part in str(text).split(","):
            if not part.strip().isdigit():
                raise UsageError(f"--output {text!r}: expected station numbers (e.g. 16 or 13,16)")
            out.append(int(part))
    return out


def run_runup(args) -> int:
    """``mutext rotor runup``: the transient run-up's peaks beside the steady response's.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        The exit status.
    """
    import os

    from ..errors import ModelError, UsageError
    from ..jsonio import print_json
    from ..rotor import load_model, rpm_to_rad_s, transient_run_up
    parts = str(args.speeds).split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
        if not (math.isfinite(a) and math.isfinite(b)) or a < 0 or b < 0 or a == b:
            raise ValueError
    except ValueError:
        raise UsageError(f"--speeds {args.speeds!r}: expected START:STOP in rpm, two different non-negative "
                         "speeds (e.g. 1000:3000, or 3000:1000 for a coast-down)") from None
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise UsageError(f"--duration {args.duration}: expected a positive time in seconds")
    if args.acceleration is not None and not (math.isfinite(args.acceleration) and args.acceleration > 0):
        raise UsageError(f"--acceleration {args.acceleration}: expected a positive rate in rpm/s")
    if args.modes is not None and args.modes < 1:
        raise UsageError(f"--modes must be a positive integer, got {args.modes}")
    unbalance = [_unbalance_arg(u) for u in args.unbalance]
    outputs = _outputs_arg(args.output)
    _check_plot(args.plot)
    if not os.path.isfile(args.model):
        raise ModelError(f"{args.model}: no such model file")
    model = load_model(args.model)
    kw = {"duration": args.duration} if args.duration is not None else \
        {"acceleration": float(rpm_to_rad_s(args.acceleration))}
    r = transient_run_up(model, (float(rpm_to_rad_s(a)), float(rpm_to_rad_s(b))), unbalance, outputs,
                         modes=args.modes, **kw)
    if args.plot:
        from .. import plots
        from .._mpl import pyplot
        fig = plots.run_up_figure(r)
        fig.savefig(args.plot, dpi=120)
        pyplot().close(fig)
    if args.json:
        out = r.to_dict()
        if args.plot:
            out["plot"] = args.plot
        print_json(out)
        return 0
    kind = "run-up" if b > a else "coast-down"
    rate = abs(r.acceleration) * 30 / math.pi
    print(f"{kind} of {model.name}: {a:g} -> {b:g} rpm in {r.t[-1]:.3g} s ({rate:.4g} rpm/s), "
          f"{r.t.size - 1} steps of {r.dt:.3g} s, {r.basis_hz.size} coordinates (modes and static shapes)")
    for s, u, p in r.unbalances:
        print(f"  unbalance {1e6 * u:g} g mm at station {s}, {math.degrees(p):g} deg")
    print(f"\n{'station':>7} {'peak [rpm]':>11} {'peak [um]':>10} {'steady peak [rpm]':>18} {'steady [um]':>12}"
          f" {'ratio':>6}")
    for j, st in enumerate(r.stations):
        w, amp = r.peak(j)
        ws, amps = r.steady_peak(j)
        print(f"{st:>7} {w * 30 / math.pi:>11.1f} {1e6 * amp:>10.4g} {ws * 30 / math.pi:>18.1f} {1e6 * amps:>12.4g}"
              f" {amp / amps:>6.3f}")
    print("\norbit radius, 0-peak; steady: the semi-major axis of the steady unbalance response")
    if args.plot:
        print(f"\nplot: {args.plot}")
    return 0


def _check_plot(path):
    import os

    from ..errors import ModelError, UsageError
    if not path:
        return
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".png", ".svg", ".pdf"):
        raise UsageError(f"--plot {path}: the extension must be .png, .svg or .pdf")
    d = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(d):
        raise ModelError(f"--plot {path}: the directory {d} does not exist")


def _port(text: str):
    """A port name, or a station number given as digits."""
    return int(text) if text.isdigit() else text


def run_whirl(args) -> int:
    """``mutext rotor whirl``: the directional FRFs' resonances with their whirl sense.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        The exit status.
    """
    import os

    from ..errors import ModelError
    from ..jsonio import print_json
    from ..rig import measure_rotor
    from ..rotor import load_model, whirl_peaks
    f = parse_grid(args.freqs, "--freqs", "Hz", example="20:225:4101", least=3, lowest=0.0)
    if args.speed is not None and not (math.isfinite(args.speed) and args.speed >= 0):
        from ..errors import UsageError
        raise UsageError(f"--speed {args.speed}: expected a non-negative speed in rpm")
    if not os.path.isfile(args.model):
        raise ModelError(f"{args.model}: no such model file")
    model = load_model(args.model)
    speed_hz = None if args.speed is None else args.speed / 60.0
    d = measure_rotor(model, _port(args.input), _port(args.output), f, planes="xy",
                      speed_hz=speed_hz).directional()
    peaks = whirl_peaks(d)
    rpm = 60.0 * d.speed_hz if d.speed_hz is not None else float("nan")
    if args.json:
        print_json({"model": model.name, "input": args.input, "output": args.output, "speed_rpm": rpm,
                    "freq_hz": [float(f[0]), float(f[-1]), int(f.size)],
                    "peaks": [{"frequency_hz": p.frequency_hz, "direction": p.direction, "index": p.index,
                               "forward": p.forward, "backward": p.backward} for p in peaks]})
        return 0
    print(f"directional FRFs of {model.name}: input {args.input}, output {args.output}, {rpm:g} rpm, "
          f"{f[0]:g}..{f[-1]:g} Hz ({f.size} frequencies)")
    if not peaks:
        print("  no resonance in the band")
        return 0
    print(f"\n{'peak [Hz]':>10} {'whirl':>9} {'index':>7} {'|H_pp|':>11} {'|H_bb|':>11}")
    for p in peaks:
        print(f"{p.frequency_hz:>10.3f} {p.direction:>9} {p.index:>+7.3f} {p.forward:>11.4g} {p.backward:>11.4g}")
    print("\nindex (|H_pp| - |H_bb|)/(|H_pp| + |H_bb|): +1 all forward, -1 all backward")
    return 0


def parse_grid(text: str, option: str, unit: str, *, example: str, least: int = 2, lowest: float | None = None,
               lists: bool = False):
    """An option's values: ``START:STOP:COUNT`` (COUNT evenly spaced, both ends included:
    :func:`numpy.linspace`) or, with ``lists``, a comma-separated list -> array of float, or a
    UsageError naming ``option``.

    Parameters
    ----------
    text : str
        The option's text.
    option : str
        The option's name as typed (``"--freqs"``), for the message.
    unit : str
        The unit of the values (``"Hz"``, ``"rpm"``), for the message.
    example : str
        A valid ``START:STOP:COUNT``, for the message.
    least : int, optional
        The smallest COUNT.
    lowest : float, optional
        The smallest START (default: none).
    lists : bool, optional
        Whether a comma-separated list is accepted too.

    Examples
    --------
    >>> from mutext.commands.rotor import parse_grid
    >>> parse_grid("20:30:3", "--freqs", "Hz", example="20:225:4101").tolist()
    [20.0, 25.0, 30.0]
    """
    import numpy as np

    from ..errors import UsageError
    t = str(text).strip()
    try:
        if ":" in t or not lists:
            parts = t.split(":")
            if len(parts) != 3:
                raise ValueError
            a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
            if n < least or not (math.isfinite(a) and math.isfinite(b)) or b <= a or (lowest is not None and a < lowest):
                raise ValueError
            return np.linspace(a, b, n)
        vals = [float(x) for x in t.split(",") if x.strip()]
        if not vals or not all(math.isfinite(v) for v in vals):
            raise ValueError
        return np.array(vals)
    except ValueError:
        start = "STOP > START" if lowest is None else f"STOP > START >= {lowest:g}"
        also = f", or a comma-separated list of {option.lstrip('-')} in {unit}" if lists else ""
        raise UsageError(f"{option} {text!r}: expected START:STOP:COUNT in {unit} with {start} and COUNT >= {least} "
                         f"(e.g. {example}){also}") from None


def parse_speeds(text: str):
    """``"0:3000:31"`` or ``"0,500,1000"`` (rpm) -> list of float, or UsageError naming the option.

    Parameters
    ----------
    text : str
        ``START:STOP:COUNT`` or a comma-separated list, in rpm.

    Examples
    --------
    >>> from mutext.commands.rotor import parse_speeds
    >>> parse_speeds("0:3000:4"), parse_speeds("600, 1200")
    ([0.0, 1000.0, 2000.0, 3000.0], [600.0, 1200.0])
    """
    return parse_grid(text, "--speeds", "rpm", example="0:3000:31", lists=True).tolist()


def _orders(text: str):
    from ..errors import UsageError
    try:
        out = [int(x) for x in str(text).split(",") if x.strip()]
    except ValueError:
        out = []
    if not out or any(k < 1 for k in out):
        raise UsageError(f"--orders {text!r}: expected positive integers separated by commas (e.g. 1,2,3)")
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
    if args.action == "whirl":
        return run_whirl(args)
    if args.action == "runup":
        return run_runup(args)
    import os

    from ..errors import ModelError, UsageError
    from ..jsonio import print_json
    from ..rotor import campbell, load_model, rpm_to_rad_s
    speeds = parse_speeds(args.speeds)
    orders = _orders(args.orders)
    if args.modes < 1:
        raise UsageError(f"--modes must be a positive integer, got {args.modes}")
    if args.plot:
        ext = os.path.splitext(args.plot)[1].lower()
        if ext not in (".png", ".svg", ".pdf"):
            raise UsageError(f"--plot {args.plot}: the extension must be .png, .svg or .pdf")
        d = os.path.dirname(os.path.abspath(args.plot))
        if not os.path.isdir(d):
            raise ModelError(f"--plot {args.plot}: the directory {d} does not exist")
    if not os.path.isfile(args.model):
        raise ModelError(f"{args.model}: no such model file")
    model = load_model(args.model)
    cd = campbell(model, rpm_to_rad_s(speeds), args.modes, orders=orders, refine=args.refine)
    if args.plot:
        from .. import plots
        from .._mpl import pyplot
        fig = plots.campbell_figure(cd)
        fig.savefig(args.plot, dpi=120)
        pyplot().close(fig)
    if args.json:
        out = cd.to_dict()
        if args.plot:
            out["plot"] = args.plot
        print_json(out)
        return 0
    print(f"Campbell diagram of {model.name}: {len(speeds)} speeds {speeds[0]:g}..{speeds[-1]:g} rpm, "
          f"{args.modes} modes")
    print(f"\n{'mode':>4} {'at ' + format(speeds[0], 'g') + ' rpm [Hz]':>18} {'at ' + format(speeds[-1], 'g') + ' rpm [Hz]':>18}"
          f" {'whirl':>10} {'log dec':>9}")
    for r in range(cd.frequencies_hz.shape[1]):
        print(f"{r + 1:>4} {cd.frequencies_hz[0, r]:>18.3f} {cd.frequencies_hz[-1, r]:>18.3f} "
              f"{cd.direction[-1][r]:>10} {cd.log_dec[-1, r]:>9.4f}")
    print(f"\ncritical speeds (crossings of the {', '.join(f'{k}x' for k in orders)} lines"
          f"{', refined' if args.refine else ', interpolated'}):")
    if not cd.crossings:
        print("  none in the speed range")
    for c in cd.crossings:
        print(f"  {c.order}x  mode {c.mode + 1:<2} {c.whirl:<10} {c.speed_rpm:10.1f} rpm  ({c.frequency_hz:.3f} Hz)")
    if args.plot:
        print(f"\nplot: {args.plot}")
    return 0
