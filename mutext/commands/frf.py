r"""``mutext frf convert`` and ``mutext frf resonances``: FRF files in and out, and what they show.

``mutext frf convert IN [IN ...] OUT [--ordinate Q] [--binary] [--unit U] [--map NODE=STATION]... [--units L=U]...``
converts an FRF file from mutext's CSV format to Universal File data set 58
and back.  The format of each file is chosen by its extension: ``.csv`` is
mutext's FRF file (:mod:`mutext.rig`: ``# key: value`` header,
``freq_hz,re,im`` rows), ``.uff`` and ``.unv`` a Universal File with data sets
58 (:mod:`mutext.uff`).  Reading and writing are :func:`mutext.rig.read_frfs`,
:func:`mutext.rig.write_frf` and :func:`mutext.uff.write_uff58`; so a
velocity or acceleration FRF becomes displacement per force in SI on the way
in (the conversion is printed as a note), and the UFF written holds
displacement per force unless ``--ordinate`` says otherwise.

Precision: a CSV file holds 17 significant digits (exact); an ASCII
Universal File holds 12 (values, format E20.12) and writes the frequency
grid in E13.5 (exact for an even grid whose start and step have at most 6
significant digits; otherwise the command says by how much frequencies
moved); ``--binary`` writes data set 58b in double precision (exact).

``mutext frf resonances FILE [FILE ...] [--band FMIN FMAX] [--boot N] [--json]`` prints the
model-free resonance table: every channel of the files is fitted on its own
(:func:`mutext.frfit.resonances`, its relative noise from
:func:`mutext.frfit.noise_level`) as a mobility :math:`j\omega H` -- the poles
of the receptance :math:`H`, but the rigid-body modes of a free structure (a
double pole at 0 Hz in :math:`H`, which a fit may split into a low
"resonance") are a single real pole there --, and the resonances of different channels
that are one mode -- natural frequencies within 3 combined standard
uncertainties or within 1 % -- are one row: natural frequency and damping
ratio with their standard uncertainties, and the channels that see it
(:func:`group_resonances`); poles that no channel's bootstrap finds again are
listed apart as not reproducible.

What the readers did that the user should know -- lines at 0 Hz dropped,
text read as Latin-1, a velocity or acceleration converted to displacement
(``FRF.metadata["notes"]``, a list of str, and ``FRF.metadata["conversion"]``)
-- both commands print as notes on standard error (:func:`reading_notes`).
"""
from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

#: extension -> format
FORMATS = {".csv": "csv", ".uff": "uff", ".unv": "uff"}

#: resonances of two channels are one mode within this many combined standard uncertainties ...
GROUP_SIGMAS = 3.0
#: ... or within this relative difference of their natural frequencies
GROUP_RELATIVE = 0.01

_UNITS_HELP = ("read a units label of the files as another, once per label (e.g. --units 'EU/lbf=g/lbf'); "
               "labels known without it: m, mm, um, in ... per N, kN, lbf, A, mA, with /s, /s^2 (s², s2) or g for "
               "velocity and acceleration, e.g. 'm/s^2/N', '(1/N)*(m/s²)', 'g/lbf'")


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    sub = p.add_subparsers(dest="action", required=True)
    c = sub.add_parser(
        "convert", help="convert FRF files between mutext's CSV (.csv) and Universal File data set 58 (.uff/.unv)",
        description="Convert FRF files between mutext's CSV format (.csv) and Universal File data set 58 "
                    "(.uff, .unv); the extension of each file says its format.  Several inputs go into one "
                    "Universal File; a Universal File with several FRFs gives one CSV file per FRF "
                    "(OUT_1.csv, OUT_2.csv, ...).  Velocity and acceleration per force are read as displacement "
                    "per force (SI); the conversion, a dropped 0 Hz line and header text read as Latin-1 are "
                    "printed as notes.",
        epilog="Exit code 0 on success, 1 with a message naming the file for a missing or malformed file, an "
               "unknown extension or a file that cannot be written.")
    c.add_argument("inputs", nargs="+", metavar="IN", help="FRF file(s) to read (.csv, .uff or .unv)")
    c.add_argument("output", metavar="OUT", help="file to write (.csv, .uff or .unv)")
    c.add_argument("--ordinate", choices=("displacement", "velocity", "acceleration"), default=None,
                   help="what a Universal File holds: displacement (m/N, default), velocity (m/s/N) or "
                        "acceleration (m/s^2/N) per force (or per A)")
    c.add_argument("--binary", action="store_true",
                   help="write the Universal File as binary data set 58b (double precision, exact) instead of "
                        "ASCII (12 significant digits)")
    c.add_argument("--unit", choices=("m", "mm", "um", "in"), default=None,
                   help="output unit of a CSV file (per N or A); default: the unit of the CSV read, else m")
    c.add_argument("--map", action="append", default=None, metavar="NODE=STATION",
                   help="Universal File node -> model station, once per node (for reading and writing UFF; "
                        "default: the station is the node)")
    c.add_argument("--units", action="append", default=None, metavar="LABEL=UNIT", help=_UNITS_HELP)

    r = sub.add_parser(
        "resonances", help="model-free resonance table of FRF files: natural frequencies and damping ratios with "
                           "uncertainties, and the channels that see each",
        description="Model-free resonance table.  Every FRF channel of the files (CSV, or every data set 58 of a "
                    "Universal File; velocity and acceleration read as displacement per force) is fitted on its "
                    "own by vector fitting (mutext.frfit.resonances), as a mobility (velocity per force, the "
                    "same poles; a free structure's rigid-body modes are then one real pole at 0 Hz): its "
                    "lightly damped pole pairs that stand "
                    "out of its noise (estimated from the data, mutext.frfit.noise_level) are resonances, with "
                    "standard uncertainties from a parametric bootstrap.  Resonances of different channels "
                    f"within {GROUP_SIGMAS:g} combined standard uncertainties or {100 * GROUP_RELATIVE:g} % of "
                    "each other are one mode: one row with the weighted mean natural frequency and damping "
                    "ratio (uncertainty: the larger of the internal and the external one, the latter from the "
                    "channels' scatter) and the channels that see it.  Poles that no channel's bootstrap finds "
                    "again (noise or background patched by the fit) are listed apart as not reproducible.  The "
                    "uncertainties "
                    "are the scatter due to the noise; a bias of the fit (modes outside the band, a fit that "
                    "stops short of the noise level) is not in them.  What the readers did (a 0 Hz line dropped, "
                    "Latin-1 text, acceleration or velocity converted to displacement) is printed as notes on "
                    "standard error.",
        epilog="Exit code 0 (also when no resonance is found), 2 with a message naming the file for a missing, "
               "unreadable or malformed file or a channel too short to fit.  --json prints one JSON object: "
               "'resonances' (freq_hz, freq_std, damping_ratio, damping_std, channels, estimates), "
               "'channels' (name, file, data_set, stations, noise, resonances) and 'notes'.")
    r.add_argument("files", nargs="+", metavar="FILE", help="FRF file(s) (.csv, .uff, .unv)")
    r.add_argument("--band", nargs=2, type=float, default=None, metavar=("FMIN", "FMAX"),
                   help="report resonances in this band [Hz] only (the whole data are fitted)")
    r.add_argument("--boot", type=int, default=20, metavar="N",
                   help="bootstrap replicates per channel for the uncertainties (default 20; the uncertainties "
                        "scatter by about 1/sqrt(2(N-1)), 16 %% for 20)")
    r.add_argument("--map", action="append", default=None, metavar="NODE=STATION",
                   help="Universal File node -> station, once per node (default: the station is the node)")
    r.add_argument("--units", action="append", default=None, metavar="LABEL=UNIT", help=_UNITS_HELP)
    r.add_argument("--json", action="store_true", help="print one JSON object instead of the table")


def _format(path, role) -> str:
    from ..errors import ModelError
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        ext = Path(path).suffix or "no extension"
        raise ModelError(f"{path}: unknown extension ({ext}) of the {role} file; expected .csv (mutext FRF "
                         f"file) or .uff / .unv (Universal File data set 58)")
    return fmt


def _mapping(items):
    from ..errors import ModelError, UsageError
    if items is None:
        return None
    out = {}
    for it in items:
        node, sep, station = it.partition("=")
        try:
            if not sep:
                raise ValueError
            out[int(node)] = int(station)
        except ValueError:
            raise UsageError(f"--map: {it!r} is not NODE=STATION (two integers, e.g. 101=3)") from None
    return out


def _units(items):
    from ..errors import ModelError, UsageError
    if items is None:
        return None
    out = {}
    for it in items:
        label, sep, unit = it.rpartition("=")
        if not sep or not label.strip() or not unit.strip():
            raise UsageError(f"--units: {it!r} is not LABEL=UNIT (e.g. 'EU/lbf=g/lbf')")
        out[label.strip()] = unit.strip()
    return out


def reading_notes(frfs) -> list[str]:
    """What the readers noted about ``frfs`` (``metadata["notes"]``, a list of str) and the conversions they
    made (``metadata["conversion"]``), one line per note and file: the data sets or channels a note is
    about are named together.

    Parameters
    ----------
    frfs : iterable of mutext.response.FRF
        The FRFs as read.
    """
    seen: dict[tuple[str, str], list[str]] = {}
    for h in frfs:
        md = h.metadata
        texts = list(md["notes"]) if isinstance(md.get("notes"), (list, tuple)) else []
        if md.get("conversion"):
            texts.append(f"read {md['conversion']}")
        who = f"data set {md['uff_dataset']}" if md.get("uff_dataset") else ""
        for t in texts:
            seen.setdefault((str(h.source) if h.source is not None else h.label, str(t)), []).append(who)
    out = []
    for (src, t), whos in seen.items():
        whos = [w for w in whos if w]
        if len(whos) > 1:
            whos = ["data sets " + ", ".join(w.split()[-1] for w in whos)]
        out.append(f"{src}{', ' + whos[0] if whos else ''}: {t}")
    return out


def convert(inputs, output, *, ordinate=None, binary=False, unit=None, mapping=None, notes=None, units=None):
    """Read the FRFs of ``inputs`` and write them to ``output`` in the format of its extension.

    Returns the list of files written.  ``notes`` (a list) receives what the
    user should know (what the readers did: :func:`reading_notes`; precision,
    header entries UFF cannot hold).  ``units``: labels to read differently
    (:func:`mutext.uff.read_uff58`).

    Parameters
    ----------
    inputs : sequence of str or path-like
        FRF files to read (.csv, .uff, .unv).
    output : str or path-like
        File to write; its extension sets the format.
    ordinate : {"displacement", "velocity", "acceleration"}, optional
        Ordinate of a Universal File written (default displacement per force).
    binary : bool, optional
        Write a Universal File as binary data set 58b (double precision).
    unit : {"m", "mm", "um", "in"}, optional
        Output unit of a CSV file (per N or A).
    mapping : dict, optional
        Universal File node -> model station.
    units : dict, optional
        Units labels to read differently (label -> unit, :func:`mutext.uff.read_uff58`).

    notes : list, optional
        Receives the notes, one str each.
    """
    from ..errors import ModelError, UsageError
    from ..rig import FRFFileError, read_frfs, write_frf
    from ..uff import write_uff58
    notes = [] if notes is None else notes
    out_fmt = _format(output, "output")
    if out_fmt == "csv" and (ordinate is not None or binary):
        raise UsageError(f"{output}: --ordinate and --binary are for a Universal File output (.uff, .unv); a CSV "
                         f"file holds displacement per force or current")
    if out_fmt == "uff" and unit is not None:
        raise UsageError(f"{output}: --unit is for a CSV output; a Universal File written by mutext is in SI")
    for p in inputs:
        _format(p, "input")
        if not Path(p).exists():
            raise FRFFileError(p, None, None, "no such file")
        if not Path(p).is_file():
            raise FRFFileError(p, None, None, "not a file")
    frfs = read_frfs([str(p) for p in inputs], mapping=mapping, units=units)
    notes.extend(reading_notes(frfs))
    output = Path(output)
    written = []
    if out_fmt == "uff":
        dropped = sorted({k for h in frfs for k in h.metadata
                          if k not in ("file_output_unit", "file_input_unit", "conversion", "notes")
                          and not k.startswith("uff_")})
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            write_uff58(output, frfs, ordinate=ordinate or "displacement", binary=binary, mapping=mapping)
        for w in caught:
            msg = str(w.message)
            if issubclass(w.category, UserWarning) and msg.startswith("write_uff58"):
                notes.append(msg.split(": ", 1)[-1])
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        written.append(output)
        if dropped:
            notes.append(f"header entries with no place in data set 58 were not written: {', '.join(dropped)}")
        return written
    if len(frfs) == 1:
        targets = [output]
    else:
        targets = [output.with_name(f"{output.stem}_{k}{output.suffix}") for k in range(1, len(frfs) + 1)]
    for h, target in zip(frfs, targets):
        u = unit or h.metadata.get("file_output_unit", "m")
        if u not in ("m", "mm", "um", "in"):
            u = "m"
        try:
            write_frf(target, h, output_unit=u)
        except OSError as exc:
            raise ModelError(f"cannot write {target}: {exc.strerror or exc}") from None
        written.append(target)
    return written


# ----------------------------------------------------------------------------- resonances

def _combine(values, stds):
    """Weighted mean of estimates of one quantity and its standard uncertainty: weights 1/std^2 over the
    estimates with a finite positive std (all, if none has one); the uncertainty is the larger of the
    internal (1/sqrt(sum w)) and the external one (the weighted scatter, Birge), NaN for a single estimate
    without a std."""
    import numpy as np
    x, s = np.asarray(values, dtype=float), np.asarray(stds, dtype=float)
    ok = np.isfinite(s) & (s > 0)
    if ok.any():
        x, s = x[ok], s[ok]
        w = 1.0 / s ** 2
        m = float(np.sum(w * x) / np.sum(w))
        u = 1.0 / math.sqrt(float(np.sum(w)))
        if x.size > 1:
            u = max(u, math.sqrt(float(np.sum(w * (x - m) ** 2)) / ((x.size - 1) * float(np.sum(w)))))
        return m, u
    zero = np.isfinite(s) & (s == 0)
    m = float(np.mean(x))
    if zero.all():
        return m, 0.0
    return m, (float(np.std(x, ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan)


def group_resonances(per_channel, *, sigmas: float = GROUP_SIGMAS, relative: float = GROUP_RELATIVE):
    """Resonances of several channels grouped into modes.

    Parameters
    ----------
    per_channel : sequence of (name, list of mutext.frfit.Resonance)
    sigmas, relative : float
        Two resonances are one mode when their natural frequencies differ by
        at most ``sigmas`` combined standard uncertainties
        (:math:`\\sqrt{u_1^2 + u_2^2}`, NaN counted as 0) or by ``relative``
        of the frequency.  A mode holds at most one resonance per channel;
        going up in frequency, each resonance joins the nearest mode that
        takes it, else starts one.

    Returns
    -------
    list of dict
        Sorted by frequency: ``freq_hz``, ``freq_std``, ``damping_ratio``,
        ``damping_std`` (:func:`_combine` of the channels' estimates),
        ``reproducible`` (False when no channel's bootstrap found the pole
        again: its uncertainty is NaN, :func:`mutext.frfit.resonances` -- a
        pole that fits the noise or the background rather than a mode),
        ``channels`` (names, in the order given) and ``estimates`` (per
        channel: name, freq_hz, freq_std, damping_ratio, damping_std, peak).
    """
    order = {name: k for k, (name, _) in enumerate(per_channel)}
    items = sorted(((r, name) for name, rs in per_channel for r in rs), key=lambda t: t[0].freq_hz)
    groups: list[list] = []
    for r, name in items:
        best, best_d = None, math.inf
        for g in groups:
            if any(n == name for _, n in g):
                continue
            fm, um = _combine([q.freq_hz for q, _ in g], [q.freq_std for q, _ in g])
            d = abs(r.freq_hz - fm)
            u = math.sqrt((um if math.isfinite(um) else 0.0) ** 2
                          + (r.freq_std if math.isfinite(r.freq_std) else 0.0) ** 2)
            if (d <= sigmas * u or d <= relative * fm) and d < best_d:
                best, best_d = g, d
        if best is None:
            groups.append([(r, name)])
        else:
            best.append((r, name))
    out = []
    for g in groups:
        g.sort(key=lambda t: order[t[1]])
        f, fs = _combine([q.freq_hz for q, _ in g], [q.freq_std for q, _ in g])
        z, zs = _combine([q.damping_ratio for q, _ in g], [q.damping_std for q, _ in g])
        out.append({"freq_hz": f, "freq_std": fs, "damping_ratio": z, "damping_std": zs,
                    "reproducible": any(math.isfinite(q.freq_std) for q, _ in g),
                    "channels": [n for _, n in g],
                    "estimates": [{"channel": n, "freq_hz": q.freq_hz, "freq_std": q.freq_std,
                                   "damping_ratio": q.damping_ratio, "damping_std": q.damping_std,
                                   "peak": q.peak} for q, n in g]})
    return sorted(out, key=lambda m: m["freq_hz"])


def _channel_names(frfs) -> list[str]:
    """The channels' labels; with the data set or file where two would read the same."""
    names = [h.label for h in frfs]
    if len(set(names)) == len(names):
        return names
    out = []
    for h in frfs:
        ds = h.metadata.get("uff_dataset")
        src = Path(h.source).name if h.source is not None else "?"
        out.append(f"{src}#{ds} {h.label}" if ds else f"{src} {h.label}")
    if len(set(out)) < len(out):
        out = [f"{k + 1}:{n}" for k, n in enumerate(out)]
    return out


def resonance_table(paths, *, band=None, n_boot: int = 20, mapping=None, units=None) -> dict:
    """Read the FRF files ``paths`` and find their resonances (see the module docstring).

    Parameters
    ----------
    paths : sequence of str or path-like
        FRF files.
    band : (float, float), optional
        Report resonances in this band [Hz] only.
    n_boot : int, optional
        Bootstrap refits for the uncertainties.
    mapping : dict, optional
        Universal File node -> model station.
    units : dict, optional
        Units labels to read differently (label -> unit, :func:`mutext.uff.read_uff58`).

    Returns
    -------
    dict
        ``resonances`` (:func:`group_resonances`), ``channels`` (per channel:
        name, file, data_set, input_station, output_station, directions,
        band_hz, noise -- the relative noise level -- and its own resonances;
        ``peak`` is the fitted receptance's magnitude at the natural frequency,
        m/N or m/A) and ``notes`` (:func:`reading_notes`).  With ``n_boot`` < 2 there are
        no uncertainties and ``reproducible`` is None.

    Raises
    ------
    mutext.errors.ModelError
        (and its FRFFileError) for a missing or malformed file or a channel
        that cannot be fitted, naming it.
    """
    from dataclasses import replace

    import numpy as np

    from ..errors import ModelError
    from ..frfit import noise_level, resonances
    from ..rig import FRFFileError, read_frfs
    for p in paths:
        if not Path(p).exists():
            raise FRFFileError(p, None, None, "no such file")
        if not Path(p).is_file():
            raise FRFFileError(p, None, None, "not a file")
    frfs = read_frfs([str(p) for p in paths], mapping=mapping, units=units)
    names = _channel_names(frfs)
    per_channel, channels = [], []
    for h, name in zip(frfs, names):
        where = f"{h.source}" + (f", data set {h.metadata['uff_dataset']}" if h.metadata.get("uff_dataset") else "")
        # the mobility j*omega*H: the receptance's poles, and a free structure's rigid-body modes (a double
        # pole at 0 in the receptance, which a fit may split into a low "resonance") are a single one
        w = 2 * np.pi * h.freq_hz
        mobility = 1j * w * h.response
        try:
            sigma = noise_level(h.freq_hz, mobility)
            found = resonances(h.freq_hz, mobility, band=band, noise=sigma, n_boot=n_boot)
        except ModelError as exc:
            raise ModelError(f"{where} ({h.label}): {exc}") from None
        # peaks of the receptance
        found = [replace(r, peak=r.peak / (2 * np.pi * r.freq_hz)) for r in found]
        per_channel.append((name, found))
        channels.append({"name": name, "file": str(h.source), "data_set": h.metadata.get("uff_dataset"),
                         "input_station": h.input_station, "output_station": h.output_station,
                         "input_direction": h.input_direction, "output_direction": h.output_direction,
                         "band_hz": [float(h.freq_hz[0]), float(h.freq_hz[-1])], "noise": sigma,
                         "resonances": [{"freq_hz": r.freq_hz, "freq_std": r.freq_std,
                                         "damping_ratio": r.damping_ratio, "damping_std": r.damping_std,
                                         "peak": r.peak} for r in found]})
    modes = group_resonances(per_channel)
    if n_boot < 2:              # no bootstrap, no judgement
        for m in modes:
            m["reproducible"] = None
    return {"resonances": modes, "channels": channels, "notes": reading_notes(frfs)}


def _pm(value, std, scale=1.0) -> str:
    """``value ± std`` with the digits the uncertainty supports (two significant digits of it)."""
    v, s = value * scale, std * scale
    if not math.isfinite(s) or s <= 0:
        return f"{v:.6g} ± {'?' if not math.isfinite(s) else '0'}"
    d = min(max(0, 1 - int(math.floor(math.log10(s)))), 9)
    return f"{v:.{d}f} ± {s:.{d}f}"


def format_table(res) -> str:
    """The text table of :func:`resonance_table`'s result: the channels, then one row per mode (natural
    frequency and damping ratio, each +/- one standard uncertainty, and the channels that see it), then
    the poles that were not reproducible.

    Parameters
    ----------
    res : dict
        The result of :func:`resonance_table`.
    """
    chans = res["channels"]
    wn = max([len("channel")] + [len(c["name"]) for c in chans])
    out = [f"Resonances of {len(chans)} channel{'s' if len(chans) != 1 else ''} (model-free: a rational fit per "
           f"channel; ± one standard uncertainty, bootstrap)", "",
           f"{'channel':<{wn}}  {'band [Hz]':>15}  {'noise':>6}  found  file"]
    for c in chans:
        f0, f1 = c["band_hz"]
        out.append(f"{c['name']:<{wn}}  {f'{f0:g}-{f1:g}':>15}  {100 * c['noise']:5.2f}%  "
                   f"{len(c['resonances']):5d}  {c['file']}" + (f", data set {c['data_set']}" if c["data_set"] else ""))
    out.append("")
    modes = [m for m in res["resonances"] if m["reproducible"] is not False]
    doubtful = [m for m in res["resonances"] if m["reproducible"] is False]
    if not modes:
        out.append("no resonance found")
    else:
        rows = [(str(k), _pm(m["freq_hz"], m["freq_std"]), _pm(m["damping_ratio"], m["damping_std"], 100.0),
                 ", ".join(m["channels"])) for k, m in enumerate(modes, 1)]
        w1 = max(len("f_n [Hz]"), *(len(r[1]) for r in rows))
        w2 = max(len("zeta [%]"), *(len(r[2]) for r in rows))
        out.append(f"{'mode':>4}  {'f_n [Hz]':>{w1}}  {'zeta [%]':>{w2}}  seen by")
        out += [f"{k:>4}  {f:>{w1}}  {z:>{w2}}  {ch}" for k, f, z, ch in rows]
    if doubtful:
        out += ["", "not reproducible (the bootstrap refits did not find these poles again: noise or background, "
                    "not modes):"]
        out += [f"      {m['freq_hz']:.4g} Hz, zeta {100 * m['damping_ratio']:.3g} %  ({', '.join(m['channels'])})"
                for m in doubtful]
    return "\n".join(out)


def _run_resonances(args) -> int:
    from ..errors import MutextError
    from ..jsonio import print_json
    try:
        res = resonance_table(args.files, band=args.band, n_boot=args.boot, mapping=_mapping(args.map),
                              units=_units(args.units))
    except MutextError as exc:
        print(f"mutext frf resonances: error: {exc}", file=sys.stderr)
        return 2
    for n in res["notes"]:
        print(f"mutext frf resonances: note: {n}", file=sys.stderr)
    if args.json:
        print_json(res)
    else:
        print(format_table(res))
    return 0


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
    if args.action == "resonances":
        return _run_resonances(args)
    notes = []
    written = convert(args.inputs, args.output, ordinate=args.ordinate, binary=args.binary, unit=args.unit,
                      mapping=_mapping(args.map), notes=notes, units=_units(args.units))
    for n in notes:
        print(f"mutext frf convert: note: {n}", file=sys.stderr)
    for w in written:
        print(w)
    return 0
