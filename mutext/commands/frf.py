"""``mutext frf convert IN [IN ...] OUT [--ordinate Q] [--binary] [--unit U] [--map NODE=STATION]...``:
an FRF file from mutext's CSV format to Universal File data set 58 and back.

The format of each file is chosen by its extension: ``.csv`` is mutext's
FRF file (:mod:`mutext.rig`: ``# key: value`` header, ``freq_hz,re,im``
rows), ``.uff`` and ``.unv`` a Universal File with data sets 58
(:mod:`mutext.uff`).  Reading and writing are :func:`mutext.rig.read_frfs`,
:func:`mutext.rig.write_frf` and :func:`mutext.uff.write_uff58`; so a
velocity or acceleration FRF in a Universal File becomes displacement per
force in SI on the way in (the conversion is stated), and the UFF written
holds displacement per force unless ``--ordinate`` says otherwise.

Precision: a CSV file holds 17 significant digits (exact); an ASCII
Universal File holds 12 (values, format E20.12) and writes the frequency
grid in E13.5 (exact for an even grid whose start and step have at most 6
significant digits; otherwise the command says by how much frequencies
moved); ``--binary`` writes data set 58b in double precision (exact).
"""
from __future__ import annotations

import warnings
from pathlib import Path

#: extension -> format
FORMATS = {".csv": "csv", ".uff": "uff", ".unv": "uff"}


def add_arguments(p):
    sub = p.add_subparsers(dest="action", required=True)
    c = sub.add_parser(
        "convert", help="convert FRF files between mutext's CSV (.csv) and Universal File data set 58 (.uff/.unv)",
        description="Convert FRF files between mutext's CSV format (.csv) and Universal File data set 58 "
                    "(.uff, .unv); the extension of each file says its format.  Several inputs go into one "
                    "Universal File; a Universal File with several FRFs gives one CSV file per FRF "
                    "(OUT_1.csv, OUT_2.csv, ...).",
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


def _format(path, role) -> str:
    from ..errors import ModelError
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        ext = Path(path).suffix or "no extension"
        raise ModelError(f"{path}: unknown extension ({ext}) of the {role} file; expected .csv (mutext FRF "
                         f"file) or .uff / .unv (Universal File data set 58)")
    return fmt


def _mapping(items):
    from ..errors import ModelError
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
            raise ModelError(f"--map: {it!r} is not NODE=STATION (two integers, e.g. 101=3)") from None
    return out


def convert(inputs, output, *, ordinate=None, binary=False, unit=None, mapping=None, notes=None):
    """Read the FRFs of ``inputs`` and write them to ``output`` in the format of its extension.

    Returns the list of files written.  ``notes`` (a list) receives what the
    user should know (precision, header entries UFF cannot hold).
    """
    from ..errors import ModelError
    from ..rig import FRFFileError, read_frfs, write_frf
    from ..uff import write_uff58
    notes = [] if notes is None else notes
    out_fmt = _format(output, "output")
    if out_fmt == "csv" and (ordinate is not None or binary):
        raise ModelError(f"{output}: --ordinate and --binary are for a Universal File output (.uff, .unv); a CSV "
                         f"file holds displacement per force or current")
    if out_fmt == "uff" and unit is not None:
        raise ModelError(f"{output}: --unit is for a CSV output; a Universal File written by mutext is in SI")
    for p in inputs:
        _format(p, "input")
        if not Path(p).exists():
            raise FRFFileError(p, None, None, "no such file")
        if not Path(p).is_file():
            raise FRFFileError(p, None, None, "not a file")
    frfs = read_frfs([str(p) for p in inputs], mapping=mapping)
    output = Path(output)
    written = []
    if out_fmt == "uff":
        dropped = sorted({k for h in frfs for k in h.metadata
                          if k not in ("file_output_unit", "file_input_unit") and not k.startswith("uff_")})
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


def run(args) -> int:
    import sys
    notes = []
    written = convert(args.inputs, args.output, ordinate=args.ordinate, binary=args.binary, unit=args.unit,
                      mapping=_mapping(args.map), notes=notes)
    for n in notes:
        print(f"mutext frf convert: note: {n}", file=sys.stderr)
    for w in written:
        print(w)
    return 0
