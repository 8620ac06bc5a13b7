"""Writing: FRFs as Universal File data sets 58 (one per FRF, function type 4), ASCII or binary, through
``pyuff``."""
from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np

from .._validation import Options, validate_params
from ..errors import ModelError
from ..response import FRF
from ._fields import _SI_LABEL, _TYPE_CODE


def _fmt13(v: float) -> float:
    """``v`` as the ASCII abscissa format E13.5 stores it."""
    return float(f"{v:13.5e}")


@validate_params({"ordinate": Options(("displacement", "velocity", "acceleration"))})
def write_uff58(path, frfs, *, ordinate: str = "displacement", binary: bool = False, mapping=None) -> Path:
    r"""Write FRFs as Universal File data sets 58 (one per FRF, function type 4), through ``pyuff``.

    Parameters
    ----------
    path : str or os.PathLike
        Overwritten.
    frfs : FRF or sequence of FRF
        Stations must be set.  Written in order.
    ordinate : {"displacement", "velocity", "acceleration"}
        Response written: displacement per force (m/N; per current m/A), or
        :math:`j\omega H` (m/s/N) or :math:`-\omega^2 H` (m/s^2/N).  The
        specific data types (8/11/12 over 13, or over 1 with units label ``A``
        for a current) and the units labels are written.
    binary : bool
        Binary 58b (values and abscissa in double precision, exact round trip)
        instead of ASCII.  ASCII data set 58 stores values with 12 significant
        digits (format E20.12) and the abscissa in E13.5: an evenly spaced
        grid whose start and step have at most 6 significant digits (e.g.
        20 Hz in 0.5 Hz steps) is exact; otherwise a warning states the
        largest change of a frequency.
    mapping : dict of int -> int, optional
        The node -> station mapping of :func:`read_uff58`; written nodes are
        the nodes of the stations (default node = station).

    Returns
    -------
    pathlib.Path

    Notes
    -----
    ID line 1 holds the channel label, ID line 2 ``mutext speed_hz=...
    input_name=... output_name=...`` (read back by :func:`read_uff58`).
    Directions: ``x`` is +1, ``y`` is +2.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from mutext.response import FRF
    >>> from mutext.uff import read_uff58, write_uff58
    >>> h = FRF(np.array([10.0, 20.0]), np.array([1e-3, 2e-3 + 1e-3j]), input_station=1, output_station=3)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = read_uff58(write_uff58(os.path.join(d, "h.uff"), [h]))
    >>> len(back), back[0].label, bool(np.allclose(back[0].response, h.response))
    (1, 'F1->x3', True)
    """
    import pyuff
    path = Path(path)
    if isinstance(frfs, FRF):
        frfs = [frfs]
    frfs = list(frfs)
    if not frfs:
        raise ModelError(f"write_uff58 {path}: no FRF to write")
    node_of = None
    if mapping is not None:
        node_of = {}
        for node, st in dict(mapping).items():
            node_of.setdefault(int(st), int(node))
    dsets = []
    for k, h in enumerate(frfs):
        dsets.append(_dataset(pyuff, path, k, h, node_of, ordinate, binary))
    try:
        path.write_bytes(b"")       # pyuff's binary writer truncates the file in 'overwrite' mode: always add
        with warnings.catch_warnings():
            # pyuff's binary writer drops (without closing) the text handle it reopens after the data
            warnings.simplefilter("ignore", ResourceWarning)
            pyuff.UFF(os.fspath(path)).write_sets(dsets, mode="add")
    except Exception as exc:  # noqa: BLE001 (pyuff raises bare Exception)
        raise ModelError(f"write_uff58 {path}: pyuff could not write the file: {exc}") from None
    return path


def _dataset(pyuff, path, k, h, node_of, ordinate, binary) -> dict:
    """The data set 58 of FRF ``k`` of the list written to ``path``, as ``pyuff.prepare_58`` makes it."""
    if not isinstance(h, FRF):
        raise ModelError(f"write_uff58 {path}: item {k} is not an FRF")
    if h.input_station is None or h.output_station is None:
        raise ModelError(f"write_uff58 {path}: FRF {k} ({h.label}): input_station and output_station must "
                         f"be set")
    nodes = []
    for st in (h.output_station, h.input_station):
        if node_of is None:
            nodes.append(int(st))
        elif int(st) in node_of:
            nodes.append(node_of[int(st)])
        else:
            raise ModelError(f"write_uff58 {path}: station {st} of FRF {k} is not in the node mapping")
    f = np.asarray(h.freq_hz, dtype=float)
    w = 2 * np.pi * f
    G = h.response.copy()
    if ordinate == "velocity":
        G = G * (1j * w)
    elif ordinate == "acceleration":
        G = G * (-(w ** 2))
    even = False if binary else _evenly_spaced(path, k, h, f)
    in_unit = "N" if h.input_quantity == "force" else "A"
    label = f"{h.label} ({ordinate}/{h.input_quantity}, mutext)"[:80]
    d = pyuff.prepare_58(
        binary=1 if binary else 0, id1=label, id2=_id_line_2(h), id3="NONE", id4="NONE", id5="NONE",
        func_type=4, ver_num=0, load_case_id=0,
        rsp_ent_name="NONE", rsp_node=nodes[0], rsp_dir=1 if h.output_direction == "x" else 2,
        ref_ent_name="NONE", ref_node=nodes[1], ref_dir=1 if h.input_direction == "x" else 2,
        abscissa_spacing=1 if even else 0,
        abscissa_spec_data_type=18, abscissa_len_unit_exp=0, abscissa_force_unit_exp=0,
        abscissa_temp_unit_exp=0, abscissa_axis_units_lab="Hz",
        ordinate_spec_data_type=_TYPE_CODE[ordinate], ordinate_len_unit_exp=1, ordinate_force_unit_exp=0,
        ordinate_temp_unit_exp=0, ordinate_axis_units_lab=_SI_LABEL[ordinate],
        orddenom_spec_data_type=13 if h.input_quantity == "force" else 1,
        orddenom_len_unit_exp=0, orddenom_force_unit_exp=1 if h.input_quantity == "force" else 0,
        orddenom_temp_unit_exp=0, orddenom_axis_units_lab=in_unit,
        z_axis_spec_data_type=0, z_axis_value=0.0,
        data=np.asarray(G, dtype=complex), x=f)
    d["ord_data_type"] = 6
    return d


def _evenly_spaced(path, k, h, f) -> bool:
    """Whether the ASCII abscissa (E13.5) holds the frequencies ``f`` of FRF ``k`` exactly as a start and a
    step; if not, a warning states the largest change of a frequency written point by point."""
    even = False
    if f.size > 1:
        df = (f[-1] - f[0]) / (f.size - 1)
        df13, f013 = _fmt13(df), _fmt13(f[0])
        even = bool(np.allclose(f013 + np.arange(f.size) * df13, f, rtol=1e-13, atol=0.0))
        if not even:
            change = float(np.max(np.abs(np.array([_fmt13(v) for v in f]) - f) / f))
            if change > 1e-13:
                # stacklevel 4 = write_uff58's own stacklevel 2 plus the two frames of _dataset and this one
                warnings.warn(f"write_uff58 {path}: FRF {k} ({h.label}): the ASCII abscissa (E13.5) changes "
                              f"frequencies by up to {change:.1e} (relative); use binary=True for an exact "
                              f"abscissa", UserWarning, stacklevel=4)
    return even


def _id_line_2(h) -> str:
    """ID line 2: ``mutext speed_hz=... input_name=... output_name=...`` (read back by the reader), or
    ``NONE``."""
    tokens = ["mutext"]
    if h.speed_hz is not None:
        tokens.append(f"speed_hz={float(h.speed_hz)!r}")
    for key in ("input_name", "output_name"):
        v = getattr(h, key)
        if v is not None and re.fullmatch(r"[^\s=]+", str(v)):
            tokens.append(f"{key}={v}")
    id2 = " ".join(tokens) if len(tokens) > 1 else "NONE"
    if len(id2) > 80:
        id2 = " ".join(tokens[:2])
    return id2
