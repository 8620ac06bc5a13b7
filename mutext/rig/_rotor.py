r"""The virtual rig on a finite-element rotor (:func:`measure_rotor`): the exact response of a time-invariant
rotor, or the analyzer's stepped sine on a rotor with a breathing crack at speed, with its combination
frequencies or the planar 2 x 2 matrix."""
from __future__ import annotations

import math
from typing import Mapping, Sequence

import numpy as np

from .._validation import AnyOf, Integer, Real, check_param
from ..errors import ModelError
from ..response import FRF, sweep_frequencies
from ._measure import with_noise
from ._noise import _active, _as_noise, _generator, _noisy


def measure_rotor(model, in_port: str, out_port: str, freq_hz=None, *, noise=None, rng=None,
                  harmonics: int | str = "auto", cutoff_hz: float = 1000.0, revolutions: int = 40,
                  settle_s: float = 0.7, metadata: Mapping[str, str] | None = None,
                  combination: Sequence[int] | None = None, speed_hz: float | None = None,
                  planes: str = "x", tol: float | None = None, max_harmonics: int | None = None):
    r"""Virtual sine sweep of a finite-element rotor, as the rig's analyzer measures it.

    A rotor without a breathing crack is time-invariant: the measurement is
    its exact frequency response (:func:`mutext.rotor.analysis.frf`).  With a
    breathing crack (``breathing = "mayes"``, ``"gasch"`` or ``"gaping"`` in
    the model file) and a running speed, the rotor is time-periodic and the
    measurement is the analyzer's correlation of the response with the
    excitation (:func:`mutext.rotor.periodic.analyzer_frf`: harmonic balance
    with ``harmonics`` terms either side, on the Ritz-reduced model below
    ``cutoff_hz``; the reduction error is stored in the metadata), which
    shows the sidebands a time-invariant model cannot hold.

    The truncation is chosen for the relative truncation error ``tol``
    (``harmonics="auto"``, :func:`mutext.rotor.periodic.analyzer_truncation`:
    N doubled from 2, with a Richardson extrapolation in :math:`1/N` for the
    slowly converging Gasch law, up to ``max_harmonics``); ``tol`` defaults to
    a tenth of the relative noise level, at most 1e-2 and at least 1e-5, or
    1e-4 without a relative noise.  The metadata's ``truncation`` says what was
    used and the estimated error (``truncation_error``); with an integer
    ``harmonics`` that N is used and its error is estimated and stored all the
    same.  A ``RuntimeWarning`` says when the cap stopped the choice before
    ``tol``.  Cost of the harmonic balance on the thesis rotor at 10 Hz, 411
    points: a Mayes crack 0.4 CPU-s (N = 16; the fixed N = 6 took 0.5 s and is
    9e-5 off), a Gasch crack 15 CPU-s for 1e-3 (the extrapolation from N = 128
    and 256) and 33 CPU-s for 1e-4, which it does not confirm by the cap
    N = 512 (estimate 1.6e-4, true error 3.5e-5; the fixed N = 6 is 7.5e-2 off).

    With ``combination`` (orders :math:`k`, e.g. ``(-2, -1, 1, 2)``) the
    analyzer also correlates the response at the combination frequencies
    :math:`f + kF` (:func:`mutext.rotor.periodic.analyzer_combination`, the
    off-diagonal harmonic transfer functions: the time-periodic rotor's
    first-order signature); a time-invariant rotor gives zero there.  The
    noise of such a channel is the noise of the excitation-frequency channel
    at the same step in absolute terms, :math:`\sigma = r|\hat H_0| + s`
    (same sensor, same correlation length; the relative level ``r`` is not
    applied to the much smaller combination response, which would make it
    look cleaner than it is).

    With ``planes="xy"`` the rig excites in x and in y at the input's
    station and measures x and y at the output's (two sensors, one sweep per
    excitation plane): the planar FRF matrix :math:`[[H_{xx}, H_{xy}],
    [H_{yx}, H_{yy}]]` of which the directional FRFs are made
    (:mod:`mutext.rotor.directional`: forward and backward whirl, [Lee]_).
    An exciter current drives the y axis with the force per ampere of the
    port's axis (a magnetic bearing has both; the model declares one).  Each
    of the four channels gets its own noise from one generator.

    Parameters
    ----------
    model : mutext.rotor.Rotor
    in_port, out_port : str
        Port names (e.g. ``"i12"``, ``"x13"``); with ``planes="xy"`` also
        station numbers (a unit force; the displacement there).
    freq_hz : array_like, optional
        Default :func:`sweep_frequencies` (20-225 Hz, 0.5 Hz).
    noise, rng
        As in :func:`measure`.
    metadata : mapping, optional
        Extra metadata stored in every FRF recorded.
    harmonics, cutoff_hz, revolutions, settle_s
        Harmonic-balance truncation (an integer N or ``"auto"``), reduction cutoff [Hz] and the
        analyzer's correlation length and settling time (thesis: 40 revolutions, 700 ms).
    combination : sequence of int, optional
        Orders :math:`k \ne 0` to record besides the excitation frequency.
    speed_hz : float, optional
        Running speed [Hz] (default: the model's).
    planes : {"x", "xy"}
        ``"x"`` (default): the one channel ``in_port -> out_port``;
        ``"xy"``: the 2 x 2 planar matrix at their stations (not with
        ``combination``).
    tol : float, optional
        Relative truncation error of ``harmonics="auto"`` (default: from the noise, above).
    max_harmonics : int, optional
        The cap on N of ``harmonics="auto"`` (default 512).

    Returns
    -------
    FRF, list of FRF with ``combination``, or PlanarFRF with ``planes="xy"``
        With the ports' stations, directions and quantities and the speed.
        With ``combination``: the excitation-frequency FRF first, then one
        per order, whose metadata holds ``order`` and
        ``response_frequency``.  With ``planes="xy"``: a
        :class:`mutext.rotor.directional.PlanarFRF`
        (``.directional()`` gives the dFRFs).

    References
    ----------
    .. [Lee] C.-W. Lee, *Vibration Analysis of Rotors*, Kluwer, 1993, ch. 4.

    Examples
    --------
    >>> from mutext.rotor import load_model, data_path
    >>> P = measure_rotor(load_model(data_path("rotor.toml")), "i12", "x13", [150.0, 190.0], planes="xy")
    >>> [[c.label for c in row] for row in P.channels]
    [['i12->x13', 'i12y->x13'], ['i12->y13', 'i12y->y13']]
    """
    from ..rotor.periodic import periodic_rotor
    f = sweep_frequencies() if freq_hz is None else np.asarray(freq_hz, dtype=float).ravel()
    orders, speed = _check_rotor_args(combination, speed_hz, planes)
    trunc = _truncation_options(harmonics, tol, max_harmonics, noise)
    if planes == "xy":
        return _measure_planar(model, in_port, out_port, f, speed, speed_hz, noise, rng, trunc, cutoff_hz,
                               revolutions, settle_s, metadata)
    pr = periodic_rotor(model, inputs=[in_port], outputs=[out_port], speed=speed)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    combos = {}
    if pr.time_invariant():
        H = model.frf(f, inputs=[in_port], outputs=[out_port], **({} if speed is None else {"speed": speed}))
        meta.setdefault("analyzer", "time-invariant model: exact frequency response")
        if orders:
            combos = {k: np.zeros(f.size, complex) for k in orders}
    else:
        red = pr.reduce(cutoff_hz, band_hz=(float(f.min()), float(f.max())))
        H, combos, tr = _analyzed(red, f, orders or [], trunc, revolutions, settle_s)
        meta.update(_analyzer_metadata(pr, red, tr, revolutions, settle_s))
    ch = H.channel(out_port, in_port)
    if speed is not None:
        ch.speed_hz = float(speed_hz)
    ch.metadata = meta
    if not orders:
        return with_noise(ch, noise, rng=rng)
    return _with_combinations(ch, combos, orders, meta, noise, rng)


def _check_rotor_args(combination, speed_hz, planes) -> tuple[list[int] | None, float | None]:
    """The combination orders (None without) and the running speed [rad/s] (None: the model's) of
    :func:`measure_rotor`, after checking them and ``planes``."""
    orders = None
    if combination is not None:
        orders = []
        for k in combination:
            orders.append(int(check_param("measure_rotor", "a combination order (k of f + k F)", k,
                                          AnyOf(Integer(hi=-1), Integer(lo=1)))))
        if not orders or len(set(orders)) != len(orders):
            raise ModelError(f"measure_rotor: combination must list distinct non-zero orders, got {combination!r}")
    speed = None
    if speed_hz is not None:
        check_param("measure_rotor", "speed_hz (the running speed [Hz])", speed_hz, Real(lo=0))
        speed = 2.0 * math.pi * float(speed_hz)
    if planes not in ("x", "xy"):
        raise ModelError(f"measure_rotor: planes must be 'x' (one channel) or 'xy' (the planar 2 x 2 "
                         f"matrix), got {planes!r}")
    if planes == "xy":
        if orders:
            raise ModelError("measure_rotor: combination= records one channel; it does not go with planes='xy'")
    return orders, speed


def _truncation_options(harmonics, tol, max_harmonics, noise) -> dict:
    """The truncation options of :func:`measure_rotor` checked, ``tol`` defaulted from the noise."""
    from ..rotor.periodic._truncation import AUTO, _check_options
    auto = isinstance(harmonics, str)
    if auto and tol is None:
        nz = _as_noise(noise)
        tol = min(max(0.1 * nz.relative, 1e-5), 1e-2) if nz is not None and nz.relative > 0 else AUTO["tol"]
    _check_options(harmonics, tol, max_harmonics, "measure_rotor")
    return {"harmonics": harmonics, "tol": tol, "max_harmonics": max_harmonics}


def _analyzed(red, f, orders, trunc, revolutions, settle_s):
    """The analyzer's FRF (FRFMatrix), the combination responses ``{k: array}`` and the
    :class:`~mutext.rotor.periodic.Truncation` of the reduced time-periodic rotor ``red``."""
    from ..rotor.periodic import analyzer_combination, analyzer_frf, analyzer_truncation
    from ..rotor.periodic._truncation import _warn_unconverged
    ks = (0,) + tuple(orders)
    if trunc["harmonics"] == "auto":
        tr = analyzer_truncation(red, f, orders=ks, revolutions=revolutions, settle_s=settle_s, **trunc)
        _warn_unconverged(tr, "measure_rotor")
        H = tr.responses[0]
    else:
        # the given N, its truncation error estimated from 2N and 4N
        N = trunc["harmonics"]
        tr = analyzer_truncation(red, f, harmonics=N, orders=ks, revolutions=revolutions, settle_s=settle_s)
        H = analyzer_frf(red, f, harmonics=N, revolutions=revolutions, settle_s=settle_s)
        if orders:
            tr.responses.update(analyzer_combination(red, f, orders, harmonics=N, revolutions=revolutions,
                                                     settle_s=settle_s))
    return H, {k: tr.responses[k].H[0, 0] for k in orders}, tr


def _analyzer_metadata(pr, red, tr, revolutions, settle_s) -> dict:
    """What the analyzer's measurement of a time-periodic rotor states: the analyzer, the breathing cracks,
    the error of the reduced model ``red`` and the truncation ``tr`` of the harmonic balance."""
    return {"analyzer": f"stepped sine, {revolutions} revolutions per correlation, "
                        f"{settle_s:g} s settling; harmonic balance N = {tr.harmonics}",
            "breathing": ", ".join(f"{c.name} {c.law}" for c in pr.cracks),
            "reduction_error": f"{red.reduction_error:.3g}",
            "truncation": tr.note,
            "truncation_error": f"{tr.error:.3g}"}


def _with_combinations(ch: FRF, combos, orders, meta, noise, rng) -> list[FRF]:
    """The excitation-frequency channel ``ch`` measured with ``noise``, then one FRF per combination order
    ``k`` (exact responses ``combos[k]``) with the main channel's absolute noise, all from one generator."""
    gen = _generator(rng)
    main = with_noise(ch, noise, rng=gen)
    out = [main]
    nz = _as_noise(noise)
    F = ch.speed_hz
    for k in orders:
        G = np.asarray(combos[k], complex)
        m = dict(meta, order=str(k), response_frequency=f"f_exc {'+' if k > 0 else '-'} {abs(k)} x {F:g} Hz")
        if _active(nz):
            G = _noisy(G, nz.relative * np.abs(ch.response) + nz.floor, gen)
            m["noise_relative"] = repr(nz.relative)
            m["noise_floor"] = repr(nz.floor)
            m["noise_reference"] = "the excitation-frequency response (absolute noise of the main channel)"
        c = FRF(freq_hz=ch.freq_hz.copy(), response=G, input_station=ch.input_station,
                output_station=ch.output_station, input_quantity=ch.input_quantity,
                output_quantity=ch.output_quantity, speed_hz=F, metadata=m,
                input_direction=ch.input_direction, output_direction=ch.output_direction)
        c.input_name, c.output_name = ch.input_name, ch.output_name
        out.append(c)
    return out


def _measure_planar(model, in_port, out_port, f, speed, speed_hz, noise, rng, trunc, cutoff_hz,
                    revolutions, settle_s, metadata):
    """The planar 2 x 2 measurement of :func:`measure_rotor` (``planes="xy"``): the same analyzer on
    a rotor with x and y ports at the two stations."""
    from ..rotor.directional import PlanarFRF, planar_rotor
    from ..rotor.periodic import harmonic_response
    pr = planar_rotor(model, in_port, out_port, speed=speed)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    if pr.time_invariant():
        # exact: the k = 0 harmonic of a time-invariant rotor is its frequency response
        H = harmonic_response(pr, f, harmonics=0)(0)
        meta.setdefault("analyzer", "time-invariant model: exact frequency response")
    else:
        red = pr.reduce(cutoff_hz, band_hz=(float(f.min()), float(f.max())))
        Hm, _, tr = _analyzed(red, f, [], trunc, revolutions, settle_s)
        H = Hm.H
        meta.update(_analyzer_metadata(pr, red, tr, revolutions, settle_s))
    gen = _generator(rng)
    F = float(speed_hz) if speed_hz is not None else (pr.speed / (2 * math.pi) if pr.speed else None)
    rows = []
    for i, o in enumerate(pr.outputs):
        row = []
        for j, q in enumerate(pr.inputs):
            si, di, qi = pr.ports[q]
            so, do, _ = pr.ports[o]
            ch = FRF(freq_hz=f.copy(), response=H[i, j], input_station=si, output_station=so,
                     input_quantity=qi, output_quantity="displacement", speed_hz=F, metadata=dict(meta),
                     input_direction=di, output_direction=do, input_name=q, output_name=o)
            row.append(with_noise(ch, noise, rng=gen))
        rows.append(tuple(row))
    return PlanarFRF(tuple(rows))
