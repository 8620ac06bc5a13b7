r"""Campbell diagram: whirl frequencies against spin speed, and the critical speeds.

At each spin speed :math:`\Omega` the modes of

.. math:: \left(\lambda^2 M + \lambda (C + \Omega G) + K\right)\hat q = 0

are computed (:func:`mutext.rotor.analysis.modes`); for each mode the damped
natural frequency :math:`f = \mathrm{Im}\,\lambda/2\pi`, the damping ratio
:math:`\zeta = -\mathrm{Re}\,\lambda/|\lambda|`, the logarithmic decrement

.. math:: \delta = \ln\frac{x(t)}{x(t + T_d)} = -\frac{2\pi\,\mathrm{Re}\,\lambda}{\mathrm{Im}\,\lambda}
    = \frac{2\pi\zeta}{\sqrt{1-\zeta^2}}

and the whirl direction read from the mode shape (the whirl index of
:func:`mutext.rotor.analysis.whirl_index`: +1 circular forward, -1 circular
backward; ``forward`` above 0.5, ``backward`` below -0.5, ``mixed`` between).
Where two frequencies at one speed agree to :math:`10^{-6}` (relative), the
pair is degenerate (an isotropic rotor at standstill): any combination of the
two shapes is a mode, the whirl of each is undefined and both are labelled
``degenerate``.

Modes are sorted by frequency at every speed (no mode tracking): the
:math:`r`-th curve is continuous in :math:`\Omega`, and where two modes cross
the curves exchange them.

**Critical speeds.**  An excitation of order :math:`k` (:math:`k = 1`:
unbalance; 2 and 3: a breathing crack, misalignment) has the frequency
:math:`k\Omega/2\pi`.  It crosses curve :math:`r` where
:math:`g(\Omega) = f_r(\Omega) - k\Omega/2\pi` changes sign between two
neighbouring speeds of the grid; the crossing speed is interpolated linearly
in :math:`g` or, with ``refine=True``, found by Brent's method on the
eigenvalue problem itself.  The crossings of the :math:`1\times` line with
forward modes are the unbalance critical speeds; :math:`2\times` crossing
the first forward mode near half its critical speed is the speed at which a
breathing crack shows its inner loop.

References
----------
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010, sec. 3.6 and 5.7
(Campbell diagram, whirl, critical speeds).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..errors import ModelError
from ..lti import blas_single_thread
from .analysis import _check_n, _speed_array, _values, modes, whirl_label
from .sparse_modal import sparse_modes

__all__ = ["CampbellDiagram", "Crossing", "campbell", "log_decrement", "whirl_labels", "speed_grid"]

#: relative frequency difference below which two modes at one speed are a degenerate pair
DEGENERATE_TOL = 1e-6


def log_decrement(eigenvalues) -> np.ndarray:
    r"""Logarithmic decrement :math:`\delta = -2\pi\,\mathrm{Re}\,\lambda/\mathrm{Im}\,\lambda` of each root.

    Parameters
    ----------
    eigenvalues : array_like of complex
        Roots :math:`\lambda` [1/s] (upper half plane: positive imaginary part).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.rotor.campbell_diagram import log_decrement
    >>> zeta, wn = 0.01, 100.0
    >>> lam = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    >>> round(float(log_decrement([lam])[0]), 4)          # 2 pi zeta / sqrt(1 - zeta^2)
    0.0628
    """
    lam = np.asarray(eigenvalues, complex)
    return -2.0 * np.pi * lam.real / lam.imag


def whirl_labels(whirl, frequencies_hz, *, threshold: float = 0.5) -> list[str]:
    """``forward``/``backward``/``mixed`` per mode from the whirl index; ``degenerate`` for the
    members of a pair whose frequencies agree to :data:`DEGENERATE_TOL` (relative).

    Parameters
    ----------
    whirl : (n,) array_like
        Whirl index of each mode.
    frequencies_hz : (n,) array_like
        Frequency [Hz] of each mode (NaN for a missing mode).
    threshold : float, optional
        Whirl index above which a mode is forward (below minus it, backward).
    """
    f = np.asarray(frequencies_hz, float)
    out = []
    for r, w in enumerate(np.asarray(whirl, float)):
        near = [s for s in (r - 1, r + 1) if 0 <= s < f.size and np.isfinite(f[s])]
        if np.isfinite(f[r]) and any(abs(f[s] - f[r]) <= DEGENERATE_TOL * abs(f[r]) for s in near):
            out.append("degenerate")
        else:
            out.append(whirl_label(w, threshold))
    return out


@dataclass(frozen=True)
class Crossing:
    """Where the excitation line of ``order`` crosses mode curve ``mode`` (0-based).

    Attributes
    ----------
    order : int
        Excitation order (the line f = order x speed).
    mode : int
        0-based index of the mode curve.
    speed : float
        Speed of the crossing [rad/s].
    frequency_hz : float
        Frequency of the crossing [Hz].
    whirl : str
        Whirl of the mode there (``forward``, ``backward``, ``mixed``, ``degenerate``).
    """
    order: int
    mode: int
    speed: float            # rad/s
    frequency_hz: float
    whirl: str

    @property
    def speed_rpm(self) -> float:
        return self.speed * 30.0 / math.pi

    def to_dict(self) -> dict:
        return {"order": self.order, "mode": self.mode, "speed_rad_s": self.speed, "speed_rpm": self.speed_rpm,
                "frequency_hz": self.frequency_hz, "whirl": self.whirl}


@dataclass
class CampbellDiagram:
    """Whirl frequencies against speed (see the module docstring).

    Attributes
    ----------
    speeds : ndarray (s,)
        Spin speeds [rad/s].
    frequencies_hz : ndarray (s, n)
        Damped natural frequency of the n lowest modes at each speed [Hz] (NaN where fewer exist).
    damping_ratio, log_dec, whirl : ndarray (s, n)
        Damping ratio, logarithmic decrement and whirl index.
    direction : list of list of str
        ``forward``, ``backward``, ``mixed`` or ``degenerate`` per speed and mode.
    orders : tuple of int
        Excitation orders whose crossings were sought.
    crossings : list of Crossing
        Sorted by order, then speed.
    name : str
        Name of the model.
    """
    speeds: np.ndarray
    frequencies_hz: np.ndarray
    damping_ratio: np.ndarray
    log_dec: np.ndarray
    whirl: np.ndarray
    direction: list
    orders: tuple
    crossings: list = field(default_factory=list)
    name: str = ""

    @property
    def speeds_rpm(self) -> np.ndarray:
        return self.speeds * 30.0 / np.pi

    def critical_speeds(self, order: int = 1, whirl: str | None = "forward") -> list[Crossing]:
        """Crossings of the ``order`` line, with modes of ``whirl`` direction (None: all).

        Parameters
        ----------
        order : int, optional
            Excitation order (1 for the 1x line).
        whirl : {"forward", "backward", "mixed"} or None, optional
            Keep the crossings with modes of this whirl (None: all).
        """
        return [c for c in self.crossings if c.order == order and (whirl is None or c.whirl == whirl)]

    def to_dict(self) -> dict:
        return {"model": self.name, "speeds_rad_s": self.speeds.tolist(), "speeds_rpm": self.speeds_rpm.tolist(),
                "frequencies_hz": self.frequencies_hz.tolist(), "damping_ratio": self.damping_ratio.tolist(),
                "log_dec": self.log_dec.tolist(), "whirl_index": self.whirl.tolist(),
                "direction": self.direction, "orders": list(self.orders),
                "crossings": [c.to_dict() for c in self.crossings]}


def speed_grid(speeds, name="model") -> np.ndarray:
    """``speeds`` [rad/s] checked: a non-empty 1-D array of finite, non-negative, increasing speeds.

    Parameters
    ----------
    speeds : array_like
        Speeds [rad/s].
    name : str, optional
        Name of the model in the error message.
    """
    s = _speed_array(speeds, name)
    if np.any(s < 0) or np.any(np.diff(s) <= 0):
        raise ModelError(f"{name}: speeds must be non-negative and strictly increasing (rad/s), got "
                         f"{s[:5].tolist()}{'...' if s.size > 5 else ''}")
    return s


def _orders(orders) -> tuple:
    try:
        out = tuple(int(k) for k in orders)
    except (TypeError, ValueError):
        raise ModelError(f"orders must be positive integers (1 for 1x, ...), got {orders!r}") from None
    if any(k < 1 or k != o for k, o in zip(out, orders)):
        raise ModelError(f"orders must be positive integers (1 for 1x, ...), got {orders!r}")
    return out


def campbell(model, speeds: Sequence[float], n_modes: int = 6, *, orders: Sequence[int] = (1, 2, 3),
             values=None, refine: bool = False, method: str = "dense") -> CampbellDiagram:
    """Campbell diagram of a two-plane rotor: frequencies, whirl, log decrement and critical speeds.

    Parameters
    ----------
    model : Rotor
        A rotor with two bending planes (``planes = 2``).
    speeds : array_like
        Spin speeds [rad/s], non-negative and increasing
        (:func:`mutext.rotor.units.rpm_to_rad_s` converts from rpm).
    n_modes : int
        Number of lowest modes kept at each speed.
    orders : sequence of int
        Excitation orders whose crossings are sought (default 1x, 2x, 3x).
    values : mapping or array, optional
        Parameter values (default: nominal).
    refine : bool
        Locate each crossing by Brent's method on the eigenvalue problem
        (a few extra eigen-solves per crossing) instead of linear interpolation.
    method : {"dense", "sparse"}
        ``"dense"``: every mode of the first-order system
        (:func:`mutext.rotor.analysis.modes`); ``"sparse"``: the ``n_modes`` lowest by
        shift-invert Arnoldi (:func:`mutext.rotor.sparse_modal.sparse_modes`), faster on
        fine meshes (``benchmarks/bench_rotor.py``).

    Returns
    -------
    CampbellDiagram

    Examples
    --------
    >>> from mutext.examples.friswell import rotor
    >>> from mutext.rotor.campbell_diagram import campbell
    >>> from mutext.rotor.units import rpm_to_rad_s
    >>> cd = campbell(rotor(), rpm_to_rad_s([0.0, 2000.0, 4000.0]), 4)
    >>> cd.direction[2]
    ['backward', 'forward', 'backward', 'forward']
    >>> round(cd.critical_speeds(1)[0].speed_rpm)       # the first forward critical speed [rpm]
    830
    """
    if getattr(getattr(model, "layout", None), "kind", "") != "rotor":
        raise ModelError(f"{getattr(model, 'name', model)!r}: a Campbell diagram needs a rotor with two bending "
                         "planes (planes = 2): whirl is the motion in both")
    s = speed_grid(speeds, model.name)
    n = _check_n(n_modes, "n_modes")
    if method not in ("dense", "sparse"):
        raise ModelError(f"{model.name}: method must be 'dense' or 'sparse', got {method!r}")
    ords = _orders(orders)
    v = _values(model, values)
    with blas_single_thread():
        mats = model.matrices(v)
    F = np.full((s.size, n), np.nan)
    Z, D, W = (np.full((s.size, n), np.nan) for _ in range(3))
    labels = []
    def solve(om, m):
        if method == "sparse":
            return sparse_modes(model, om, m, values=v)
        return modes(model, speed=om, matrices=mats, n=m)

    for i, om in enumerate(s):
        md = solve(om, n)
        m = md.frequencies_hz.size
        F[i, :m], Z[i, :m], W[i, :m] = md.frequencies_hz, md.damping_ratio, md.whirl
        D[i, :m] = log_decrement(md.eigenvalues)
        labels.append(whirl_labels(W[i], F[i]) if m else [""] * n)
    cd = CampbellDiagram(s, F, Z, D, W, labels, ords, name=model.name)

    def g_at(om, r, k):
        return solve(om, r + 1).frequencies_hz[r] - k * om / (2 * np.pi)

    for k in ords:
        for r in range(n):
            g = F[:, r] - k * s / (2 * np.pi)
            for i in range(s.size - 1):
                a, b = g[i], g[i + 1]
                if not (np.isfinite(a) and np.isfinite(b)) or a == 0 or not (a * b < 0 or b == 0):
                    continue
                t = a / (a - b)
                om = s[i] + t * (s[i + 1] - s[i])
                if refine and b != 0:
                    from scipy.optimize import brentq
                    with blas_single_thread():
                        om = brentq(g_at, s[i], s[i + 1], args=(r, k), xtol=1e-10 * max(s[i + 1], 1.0))
                # the whirl of the nearer grid point, unless it is a degenerate pair (then the other)
                near, far = (i, i + 1) if t < 0.5 else (i + 1, i)
                lab = labels[near][r] if labels[near][r] != "degenerate" else labels[far][r]
                cd.crossings.append(Crossing(k, r, float(om), float(k * om / (2 * np.pi)), lab))
    cd.crossings.sort(key=lambda c: (c.order, c.speed, c.mode))
    return cd
