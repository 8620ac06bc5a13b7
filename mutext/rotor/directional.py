r"""Two-plane FRFs of a rotor and the directional FRFs that tell forward from backward whirl.

Planar FRF matrix
-----------------
Excited in x and in y at one station and measured in x and in y at another,
a rotor has four FRFs (time dependence :math:`e^{j\omega t}`, as
:func:`mutext.rotor.analysis.frf`):

.. math::
    \begin{bmatrix} X\\ Y\end{bmatrix} =
    \begin{bmatrix} H_{xx} & H_{xy}\\ H_{yx} & H_{yy}\end{bmatrix}
    \begin{bmatrix} F_x\\ F_y\end{bmatrix},

:math:`H_{xy}` the x response to a y force.  :class:`PlanarFRF` holds them
(the virtual rig records it: :func:`mutext.rig.measure_rotor` with
``planes="xy"``).

Directional FRFs
----------------
With the complex coordinates :math:`p = x + jy` and :math:`f_p = f_x + j
f_y` ([Lee93]_ ch. 4, [LJ93]_), and the rotor spinning about +z so that a
*forward* whirl turns from +x to +y (:math:`p \propto e^{j\omega t}`,
:math:`\omega > 0`; the same sense as the whirl index of
:mod:`mutext.rotor.analysis`), the real impulse responses
:math:`h_{xx}, \dots` combine as
:math:`p = h_{pp} * f_p + h_{p\bar p} * \bar f_p`.  Writing
:math:`f_x = (f_p + \bar f_p)/2`, :math:`f_y = (f_p - \bar f_p)/(2j)` in
:math:`p = (h_{xx} f_x + h_{xy} f_y) + j(h_{yx} f_x + h_{yy} f_y)` and
transforming,

.. math::
    H_{pp} &= \tfrac12\left[H_{xx} + H_{yy} + j(H_{yx} - H_{xy})\right]
        \quad\text{(forward, "normal" dFRF)}\\
    H_{\bar p\bar p} &= \tfrac12\left[H_{xx} + H_{yy} - j(H_{yx} - H_{xy})\right]
        \quad\text{(backward)}\\
    H_{p\bar p} &= \tfrac12\left[H_{xx} - H_{yy} + j(H_{yx} + H_{xy})\right]
        \quad\text{(reverse, anisotropy)}\\
    H_{\bar p p} &= \tfrac12\left[H_{xx} - H_{yy} - j(H_{yx} + H_{xy})\right] .

Because the planar FRFs are transforms of real signals,
:math:`H(-\omega) = \overline{H(\omega)}`, and so

.. math::
    H_{\bar p\bar p}(\omega) = \overline{H_{pp}(-\omega)},\qquad
    H_{\bar p p}(\omega) = \overline{H_{p\bar p}(-\omega)} .

**What a one-sided measurement shows.**  The complex equation of motion has
its forward modes at :math:`\lambda \approx +j\omega_f` and its backward
modes at :math:`\lambda \approx -j\omega_b`: on the two-sided axis
:math:`H_{pp}` resonates at :math:`+\omega_f` and at :math:`-\omega_b`.  A
sweep over positive frequencies only therefore sees the forward modes as the
peaks of :math:`H_{pp}` and the backward modes as the peaks of
:math:`H_{\bar p\bar p}` (the negative-frequency half of :math:`H_{pp}`,
mirrored); :meth:`DirectionalFRF.two_sided` puts them back on one axis.
Which of the two is larger at a peak is the whirl sense of the mode
(:func:`whirl_peaks`), even where a forward and a backward mode lie closer
than their half-power bandwidth and :math:`H_{xx}` shows one peak.

An isotropic rotor (axisymmetric, isotropic bearings) has :math:`H_{yy} =
H_{xx}` and :math:`H_{xy} = -H_{yx}`, hence :math:`H_{p\bar p} = H_{\bar p
p} = 0`, and its modes whirl in circles; at standstill moreover
:math:`H_{yx} = 0` and :math:`H_{pp} = H_{\bar p\bar p}`.  Anisotropic
bearings couple :math:`p` and :math:`\bar p` (elliptic whirl) and make the
reverse dFRF :math:`H_{p\bar p}` non-zero, of the order of the anisotropy.

References
----------
.. [Lee93] C.-W. Lee, *Vibration Analysis of Rotors*, Kluwer, 1993, ch. 4
   (complex modal analysis, directional frequency response functions).
.. [LJ93] C.-W. Lee and C.-Y. Joh, "Theory of excitation methods and
   estimation of frequency response functions in complex modal testing of
   rotating machinery", *Mechanical Systems and Signal Processing* 7(1),
   57-74, 1993.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..response import FRF

__all__ = ["PlanarFRF", "DirectionalFRF", "WhirlPeak", "planar_rotor", "directional_frf", "whirl_peaks"]

#: What each directional FRF is, by attribute of :class:`DirectionalFRF`.
MEANING = {
    "pp": "H_pp: forward (normal) dFRF, p = x + jy per f_p = f_x + j f_y; peaks at forward whirl modes",
    "bb": "H_bb (p-bar p-bar): backward (normal) dFRF, conj(H_pp(-w)); peaks at backward whirl modes",
    "pb": "H_pb (p p-bar): reverse dFRF, p per conj(f_p); zero for an isotropic rotor",
    "bp": "H_bp (p-bar p): reverse dFRF, conj(p) per f_p, conj(H_pb(-w)); zero for an isotropic rotor",
}


@dataclass
class PlanarFRF:
    r"""The 2x2 planar FRF matrix of a rotor between two stations.

    Attributes
    ----------
    channels : tuple of tuples of FRF
        ``((xx, xy), (yx, yy))``: ``channels[i][j]`` is output plane ``i``
        per input plane ``j`` (0 = x, 1 = y), each a
        :class:`mutext.response.FRF` on the same frequencies, stations,
        quantities and speed.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.response import FRF
    >>> f = np.array([1.0, 2.0])
    >>> ch = lambda o, i, h: FRF(f, h, 1, 1, output_direction=o, input_direction=i)
    >>> P = PlanarFRF(((ch("x", "x", [1, 1]), ch("x", "y", [0, 0])), (ch("y", "x", [0, 0]), ch("y", "y", [1, 1]))))
    >>> P.H.shape
    (2, 2, 2)
    """
    channels: tuple

    def __post_init__(self):
        try:
            rows = tuple(tuple(r) for r in self.channels)
        except TypeError:
            raise ModelError("PlanarFRF: channels must be ((xx, xy), (yx, yy)), four FRFs") from None
        if len(rows) != 2 or any(len(r) != 2 for r in rows):
            raise ModelError(f"PlanarFRF: channels must be 2 x 2 ((xx, xy), (yx, yy)), got "
                             f"{[len(r) for r in rows]} per row")
        ref = rows[0][0]
        for i, o in enumerate("xy"):
            for j, d in enumerate("xy"):
                c = rows[i][j]
                if not isinstance(c, FRF):
                    raise ModelError(f"PlanarFRF: H_{o}{d} is a {type(c).__name__}, not an FRF")
                if c.output_direction != o or c.input_direction != d:
                    raise ModelError(f"PlanarFRF: entry [{i}][{j}] must be H_{o}{d} (output {o}, input {d}), got "
                                     f"output {c.output_direction}, input {c.input_direction}")
                if c.freq_hz.shape != ref.freq_hz.shape or not np.array_equal(c.freq_hz, ref.freq_hz):
                    raise ModelError(f"PlanarFRF: H_{o}{d} is on other frequencies than H_xx")
                for a in ("input_station", "output_station", "input_quantity", "output_quantity", "speed_hz"):
                    if getattr(c, a) != getattr(ref, a):
                        raise ModelError(f"PlanarFRF: H_{o}{d} has {a} = {getattr(c, a)!r}, H_xx "
                                         f"{getattr(ref, a)!r}; the four must be one station pair and speed")
        self.channels = rows

    @property
    def freq_hz(self) -> np.ndarray:
        """Frequencies [Hz]."""
        return self.channels[0][0].freq_hz

    @property
    def speed_hz(self):
        """Running speed [Hz] (None when not stated)."""
        return self.channels[0][0].speed_hz

    @property
    def H(self) -> np.ndarray:
        """``H[i, j, k]``: output plane ``i`` per input plane ``j`` (0 = x, 1 = y) at ``freq_hz[k]``."""
        return np.array([[c.response for c in r] for r in self.channels])

    def __getitem__(self, key: str) -> FRF:
        """One channel by name: ``"xx"``, ``"xy"`` (x per y force), ``"yx"``, ``"yy"``."""
        if not (isinstance(key, str) and len(key) == 2 and set(key) <= {"x", "y"}):
            raise ModelError(f"PlanarFRF: channel must be 'xx', 'xy', 'yx' or 'yy', got {key!r}")
        return self.channels["xy".index(key[0])]["xy".index(key[1])]

    def directional(self) -> "DirectionalFRF":
        """:func:`directional_frf` of this matrix."""
        return directional_frf(self)


@dataclass
class DirectionalFRF:
    r"""The four directional FRFs of a station pair (module docstring, [Lee93]_).

    Attributes
    ----------
    freq_hz : ndarray
        Frequencies [Hz] of the planar measurement (positive).
    pp, bb, pb, bp : complex ndarray
        :math:`H_{pp}` (forward), :math:`H_{\bar p\bar p}` (backward),
        :math:`H_{p\bar p}`, :math:`H_{\bar p p}` (reverse), in the planar
        FRFs' units.
    speed_hz : float or None
        Running speed [Hz].
    meaning : dict
        Attribute -> what it is (:data:`MEANING`).
    """
    freq_hz: np.ndarray
    pp: np.ndarray
    bb: np.ndarray
    pb: np.ndarray
    bp: np.ndarray
    speed_hz: float | None = None
    meaning: dict = field(default_factory=lambda: dict(MEANING))

    def two_sided(self):
        r"""``(f, H_pp)`` on negative and positive frequencies: :math:`H_{pp}(-f) =
        \overline{H_{\bar p\bar p}(f)}` below zero (backward modes), :math:`H_{pp}(f)` above."""
        return (np.concatenate([-self.freq_hz[::-1], self.freq_hz]),
                np.concatenate([np.conj(self.bb[::-1]), self.pp]))

    def planar(self) -> np.ndarray:
        r"""The planar matrix back, ``H[i, j, k]`` (0 = x, 1 = y): :math:`H_{xx} = (H_{pp} +
        H_{\bar p\bar p} + H_{p\bar p} + H_{\bar p p})/2` and so on (the inverse of the module's
        equations)."""
        pp, bb, pb, bp = self.pp, self.bb, self.pb, self.bp
        return np.array([[(pp + bb + pb + bp) / 2, (pb - bp - pp + bb) / 2j],
                         [(pp - bb + pb - bp) / 2j, (pp + bb - pb - bp) / 2]])

    def peaks(self, **kw) -> list:
        """:func:`whirl_peaks` of these dFRFs.

        Parameters
        ----------
        **kw
            Options of :func:`whirl_peaks` (``rel_height``).
        """
        return whirl_peaks(self, **kw)


def directional_frf(planar, freq_hz=None, *, speed_hz: float | None = None) -> DirectionalFRF:
    r"""Directional FRFs from the planar FRF matrix ([Lee93]_ ch. 4, [LJ93]_).

    .. math::
        H_{pp} = \tfrac12[H_{xx} + H_{yy} + j(H_{yx} - H_{xy})],\quad
        H_{\bar p\bar p} = \tfrac12[H_{xx} + H_{yy} - j(H_{yx} - H_{xy})],

        H_{p\bar p} = \tfrac12[H_{xx} - H_{yy} + j(H_{yx} + H_{xy})],\quad
        H_{\bar p p} = \tfrac12[H_{xx} - H_{yy} - j(H_{yx} + H_{xy})],

    with :math:`p = x + jy`, forward whirl from +x to +y, time dependence
    :math:`e^{j\omega t}` (derivation in the module docstring).  On positive
    frequencies :math:`H_{pp}` peaks at the forward modes and
    :math:`H_{\bar p\bar p}` at the backward ones.

    Parameters
    ----------
    planar : PlanarFRF, 2x2 nested sequence of FRF, or array_like (2, 2, n)
        ``[[H_xx, H_xy], [H_yx, H_yy]]`` (``H_xy``: x response per y force).
    freq_hz : array_like (n,), optional
        Frequencies [Hz]; required with an array, taken from the FRFs otherwise.
    speed_hz : float, optional
        Running speed [Hz] (taken from the FRFs when they state it).

    Returns
    -------
    DirectionalFRF

    Raises
    ------
    ModelError
        The matrix is not 2 x 2 over one frequency grid, or the frequencies
        are missing.

    Examples
    --------
    An isotropic rotor whirling forward only (:math:`H_{yx} = -jH_{xx}`,
    :math:`H_{xy} = jH_{xx}`, :math:`H_{yy} = H_{xx}`) has all of its
    response in :math:`H_{pp}`:

    >>> import numpy as np
    >>> h = np.array([1.0 + 0.5j])
    >>> d = directional_frf([[h, 1j * h], [-1j * h, h]], freq_hz=[10.0])
    >>> complex(d.pp[0]), float(abs(d.bb[0])), float(abs(d.pb[0]))
    ((2+1j), 0.0, 0.0)
    """
    if isinstance(planar, PlanarFRF):
        P = planar
    elif isinstance(planar, (list, tuple)) and len(planar) == 2 and all(
            isinstance(r, (list, tuple)) and len(r) == 2 and all(isinstance(c, FRF) for c in r) for r in planar):
        P = PlanarFRF(tuple(tuple(r) for r in planar))
    else:
        P = None
    if P is not None:
        if freq_hz is not None and not np.allclose(np.asarray(freq_hz, float), P.freq_hz):
            raise ModelError("directional_frf: freq_hz differs from the FRFs' frequencies")
        H, f = P.H, P.freq_hz
        speed_hz = P.speed_hz if speed_hz is None else speed_hz
    else:
        try:
            H = np.asarray(planar, dtype=complex)
        except (TypeError, ValueError):
            raise ModelError(f"directional_frf: expected a PlanarFRF, 2x2 FRFs or an array (2, 2, n), got "
                             f"{type(planar).__name__}") from None
        if H.ndim == 2:
            H = H[:, :, None]
        if H.ndim != 3 or H.shape[:2] != (2, 2):
            raise ModelError(f"directional_frf: the planar matrix must have shape (2, 2, n) "
                             f"[[H_xx, H_xy], [H_yx, H_yy]], got {H.shape}")
        if freq_hz is None:
            raise ModelError("directional_frf: an array needs freq_hz (Hz, one per column)")
        f = np.atleast_1d(np.asarray(freq_hz, dtype=float))
        if f.shape != (H.shape[2],):
            raise ModelError(f"directional_frf: {f.size} frequencies for {H.shape[2]} response values")
        if not np.all(np.isfinite(H)):
            raise ModelError("directional_frf: the planar matrix holds NaN or infinite values")
    if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) > 0)):
        raise ModelError("directional_frf: frequencies must be finite, positive and increasing [Hz]")
    xx, xy, yx, yy = H[0, 0], H[0, 1], H[1, 0], H[1, 1]
    return DirectionalFRF(freq_hz=f.copy(), pp=0.5 * (xx + yy + 1j * (yx - xy)), bb=0.5 * (xx + yy - 1j * (yx - xy)),
                          pb=0.5 * (xx - yy + 1j * (yx + xy)), bp=0.5 * (xx - yy - 1j * (yx + xy)),
                          speed_hz=None if speed_hz is None else float(speed_hz))


@dataclass(frozen=True)
class WhirlPeak:
    r"""A resonance of the directional FRFs.

    Attributes
    ----------
    frequency_hz : float
        Peak frequency [Hz] (parabolic fit of :math:`\log|H|` through the
        largest sample and its neighbours).
    direction : str
        ``"forward"`` (a peak of :math:`H_{pp}`) or ``"backward"`` (of
        :math:`H_{\bar p\bar p}`).
    index : float
        :math:`(|H_{pp}| - |H_{\bar p\bar p}|)/(|H_{pp}| + |H_{\bar p\bar p}|)`
        at the peak sample: +1 all forward, -1 all backward; the tails of
        neighbouring modes of the other sense draw it towards 0, so it is
        the ellipse of the mode only for a well separated one.
    forward, backward : float
        :math:`|H_{pp}|` and :math:`|H_{\bar p\bar p}|` at the peak sample.
    """
    frequency_hz: float
    direction: str
    index: float
    forward: float
    backward: float


def _refine(f, a, i):
    """Vertex of the parabola through log|H| at samples i-1, i, i+1 (the sample itself at an edge)."""
    if i == 0 or i == f.size - 1:
        return float(f[i])
    y = np.log(a[i - 1:i + 2])
    x = f[i - 1:i + 2]
    den = (x[0] - x[1]) * (x[0] - x[2]) * (x[1] - x[2])
    A = (x[2] * (y[1] - y[0]) + x[1] * (y[0] - y[2]) + x[0] * (y[2] - y[1])) / den
    B = (x[2] ** 2 * (y[0] - y[1]) + x[1] ** 2 * (y[2] - y[0]) + x[0] ** 2 * (y[1] - y[2])) / den
    if not A < 0:
        return float(f[i])
    return float(min(max(-B / (2 * A), x[0]), x[2]))


def _one_mode(d: DirectionalFRF, k: int, tol: float = 0.5) -> bool:
    r"""Whether the dFRF matrix :math:`[[H_{pp}, H_{p\bar p}], [H_{\bar p p}, H_{\bar p\bar p}]]` at sample
    ``k`` is near rank one, :math:`|\det| < ` ``tol`` :math:`(|H_{pp}H_{\bar p\bar p}| + |H_{p\bar p}H_{\bar p p}|)`:
    the residue of one mode is rank one (its right times its left eigenvector), two modes at one
    frequency (an isotropic rotor's forward and backward twins) make it full rank."""
    a, b, c, e = d.pp[k], d.pb[k], d.bp[k], d.bb[k]
    return bool(abs(a * e - b * c) < tol * (abs(a * e) + abs(b * c)))


def whirl_peaks(dfrf: DirectionalFRF, *, rel_height: float = 1e-3) -> list:
    r"""The resonances of the directional FRFs and their whirl sense.

    On positive frequencies a local maximum of :math:`|H_{pp}|` is a forward
    mode and one of :math:`|H_{\bar p\bar p}|` a backward mode (module
    docstring).  An anisotropic rotor's elliptic mode shows in both dFRFs at
    the same frequency (the same pole); there the larger maximum tells the
    sense and the smaller one is not counted again.  Two maxima within two
    frequency steps of each other are one peak (the larger) unless they are
    of opposite sense and the 2 x 2 dFRF matrix there is far from rank one
    (:math:`|\det| \ge \tfrac12(|H_{pp}H_{\bar p\bar p}| + |H_{p\bar p}H_{\bar p
    p}|)`): one mode's residue is rank one, while a forward and a backward
    mode at one frequency (a mode without gyroscopic split, or a close pair
    on a coarse sweep) are two.  So a forward and a backward mode are both
    reported even inside one half-power bandwidth, where :math:`H_{xx}`
    shows a single peak; their frequencies are as fine as the sweep allows.

    Parameters
    ----------
    dfrf : DirectionalFRF
    rel_height : float
        Peaks lower than this fraction of the largest :math:`|H|` of both
        dFRFs are left out (noise ripple, far tails).

    Returns
    -------
    list of WhirlPeak
        Sorted by frequency.

    Examples
    --------
    A forward mode at 10 Hz and a backward one at 12 Hz of an isotropic
    rotor, :math:`H_{pp} = 1/(\omega_f^2 - \omega^2 + 2j\zeta\omega_f\omega)`
    and the same with :math:`\omega_b` for :math:`H_{\bar p\bar p}`:

    >>> import numpy as np
    >>> f = np.linspace(5.0, 15.0, 401)
    >>> h = lambda fn: 1 / (fn ** 2 - f ** 2 + 0.02j * fn * f)
    >>> d = DirectionalFRF(f, h(10.0), h(12.0), 0 * f, 0 * f)
    >>> [(round(p.frequency_hz, 2), p.direction) for p in whirl_peaks(d)]
    [(10.0, 'forward'), (12.0, 'backward')]
    """
    if not isinstance(dfrf, DirectionalFRF):
        raise ModelError(f"whirl_peaks: expected a DirectionalFRF (directional_frf(...)), got "
                         f"{type(dfrf).__name__}")
    if not (0.0 <= rel_height < 1.0):
        raise ModelError(f"whirl_peaks: rel_height must be in [0, 1), got {rel_height!r}")
    f = dfrf.freq_hz
    a_f, a_b = np.abs(dfrf.pp), np.abs(dfrf.bb)
    if f.size < 3:
        raise ModelError(f"whirl_peaks: needs at least 3 frequencies, got {f.size}")
    top = max(float(a_f.max()), float(a_b.max()))
    if top == 0.0:
        return []
    cands = []
    for a, sense in ((a_f, "forward"), (a_b, "backward")):
        i = np.arange(1, f.size - 1)
        mx = i[(a[i] > a[i - 1]) & (a[i] >= a[i + 1]) & (a[i] >= rel_height * top)]
        cands += [(float(a[k]), int(k), a, sense) for k in mx]
    cands.sort(key=lambda c: -c[0])
    kept = []
    for c in cands:
        if all(abs(c[1] - k[1]) > 2 or (c[3] != k[3] and not _one_mode(dfrf, c[1])) for k in kept):
            kept.append(c)
    out = []
    for _, k, a, sense in sorted(kept, key=lambda c: c[1]):
        idx = float((a_f[k] - a_b[k]) / (a_f[k] + a_b[k]))
        out.append(WhirlPeak(_refine(f, a, k), sense, idx, float(a_f[k]), float(a_b[k])))
    return out


def planar_rotor(model, in_port, out_port, *, speed: float | None = None, values=None):
    r"""The (possibly time-periodic) rotor with the two-plane ports of :func:`planar_ports`.

    Parameters
    ----------
    model : mutext.rotor.Rotor
        A two-plane rotor; breathing cracks are kept (time-periodic at speed).
    in_port, out_port : str or int
        As :func:`mutext.rotor.frf_channels.planar_ports`.
    speed : float, optional
        Running speed [rad/s] (default: the model's).
    values : mapping or array, optional
        Parameter values (default: nominal).

    Returns
    -------
    mutext.rotor.periodic.PeriodicRotor
        Inputs ``[x, y]`` at the input station, outputs ``[x, y]`` at the
        output station; its :func:`~mutext.rotor.periodic.harmonic_response`
        and :func:`~mutext.rotor.periodic.analyzer_frf` are 2 x 2.
    """
    from .frf_channels import planar_ports
    from .periodic_orbit import _periodic_matrices
    pp = planar_ports(model, in_port, out_port, values=values)
    pr = _periodic_matrices(model, speed, values)
    return dataclasses.replace(pr, B=pp.B, Cy=pp.Cy, inputs=list(pp.inputs), outputs=list(pp.outputs),
                               ports=dict(pp.ports))
