r"""Orbits: the path of a shaft station in the x-y plane, from its harmonic components.

A steady response periodic in the revolution is

.. math::
    x(t) = \mathrm{Re}\sum_{k \ge 0} X_k e^{jk\Omega t},\qquad
    y(t) = \mathrm{Re}\sum_{k \ge 0} Y_k e^{jk\Omega t},

with complex amplitudes :math:`X_k, Y_k` [m] of the order :math:`k` (1x,
2x, ...; :math:`k = 0` the static offset, real).  Written as the complex
position :math:`z = x + jy`, each order is the sum of a forward and a
backward circle,

.. math::
    z_k(t) = R_k^+ e^{jk\Omega t} + R_k^- e^{-jk\Omega t},\qquad
    R_k^+ = \tfrac12(X_k + jY_k),\quad R_k^- = \tfrac12\overline{(X_k - jY_k)},

so the orbit of one order is an ellipse with semi-major axis
:math:`|R^+| + |R^-|`, semi-minor axis :math:`\big||R^+| - |R^-|\big|`,
the major axis at the angle :math:`\tfrac12(\arg R^+ + \arg R^-)` from
:math:`x`, travelled forward (in the sense of the spin, from +x to +y)
when :math:`|R^+| > |R^-|` (Friswell et al. 2010, sec. 3.5).  A 2x
component added to a 1x ellipse of similar size makes the orbit cross
itself: the inner loop of a shaft with a breathing crack running near half
its critical speed.

Everything here is arithmetic on given components; the components come from
:func:`mutext.rotor.unbalance.unbalance_response` (1x) or
:func:`mutext.rotor.periodic_orbit.periodic_unbalance_response` (all orders
of a rotor with a breathing crack).

References
----------
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010, sec. 3.5 and 3.6.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._validation import Integer, Real, check_param, validate_params
from ..errors import ModelError

__all__ = ["Ellipse", "ellipse", "Orbit", "orbit"]


@dataclass(frozen=True)
class Ellipse:
    """The orbit of one harmonic (see the module docstring); lengths in m, angle in rad.

    Attributes
    ----------
    forward : complex
        Forward-whirling component :math:`R_+` [m].
    backward : complex
        Backward-whirling component :math:`R_-` [m].
    semi_major, semi_minor : float
        Semi-axes [m].
    angle : float
        Angle of the major axis from x [rad].
    direction : str
        ``"forward"``, ``"backward"`` or ``"straight"`` (a line).
    """
    forward: complex            # R+
    backward: complex           # R-
    semi_major: float
    semi_minor: float
    angle: float                # of the major axis from x
    direction: str              # "forward", "backward" or "straight" (a line)

    def to_dict(self) -> dict:
        return {"semi_major_m": self.semi_major, "semi_minor_m": self.semi_minor, "angle_rad": self.angle,
                "direction": self.direction, "forward_m": abs(self.forward), "backward_m": abs(self.backward)}


def ellipse(X, Y) -> Ellipse:
    r"""Forward/backward decomposition of one harmonic with complex amplitudes ``X``, ``Y`` [m].

    Parameters
    ----------
    X, Y : complex
        Amplitudes [m] of :math:`x = \mathrm{Re}\,X e^{j\Omega t}` and likewise y.

    Examples
    --------
    >>> from mutext.rotor.orbits import ellipse
    >>> e = ellipse(2e-6, 1e-6j)                        # x = 2 cos, y = -1 sin: an ellipse whirling backward
    >>> e.direction, round(e.semi_major * 1e6, 6), round(e.semi_minor * 1e6, 6)
    ('backward', 2.0, 1.0)
    """
    X, Y = complex(X), complex(Y)
    rp = 0.5 * (X + 1j * Y)
    rm = 0.5 * np.conj(X - 1j * Y)
    a, b = abs(rp), abs(rm)
    scale = max(a, b)
    if scale == 0.0:
        return Ellipse(rp, complex(rm), 0.0, 0.0, 0.0, "straight")
    if abs(a - b) <= 1e-12 * scale:
        direction = "straight"
    else:
        direction = "forward" if a > b else "backward"
    ang = 0.5 * (np.angle(rp) + np.angle(rm)) if a > 0 and b > 0 else (np.angle(rp) if a > 0 else np.angle(rm))
    ang = float((ang + np.pi / 2) % np.pi - np.pi / 2)
    return Ellipse(rp, complex(rm), float(a + b), float(abs(a - b)), ang, direction)


@dataclass
class Orbit:
    r"""An orbit over one revolution.

    Attributes
    ----------
    speed : float
        Spin speed [rad/s].
    harmonics : dict
        order k -> (X_k, Y_k) [m] (order 0: the static offset).
    t : ndarray
        Times over one revolution [s], from the keyphasor (t = 0).
    x, y : ndarray
        The path [m].
    label : str
    """
    speed: float
    harmonics: dict
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    label: str = ""

    def ellipse(self, order: int = 1) -> Ellipse:
        """The forward/backward decomposition of one order.

        Parameters
        ----------
        order : int, optional
            Harmonic order (a key of ``harmonics``).
        """
        if order not in self.harmonics:
            raise ModelError(f"order {order} is not among the orbit's harmonics {sorted(self.harmonics)}")
        return ellipse(*self.harmonics[order])

    def loops(self) -> int:
        """Number of self-crossings of the path over one revolution (0: a simple closed curve;
        an inner loop from a 2x component adds crossings), counted on the sampled polygon."""
        p = np.stack([self.x, self.y], axis=1)
        a, b = p[:-1], p[1:]                       # segments; the last point closes the curve
        n = len(a)

        def cross(u, v):
            return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

        A, B, C, D = a[:, None], b[:, None], a[None, :], b[None, :]
        d1, d2 = cross(B - A, C - A), cross(B - A, D - A)
        d3, d4 = cross(D - C, A - C), cross(D - C, B - C)
        hit = (d1 * d2 < 0) & (d3 * d4 < 0)
        i, j = np.triu_indices(n, k=2)
        keep = ~((i == 0) & (j == n - 1))          # neighbours across the closing point
        return int(np.sum(hit[i[keep], j[keep]]))

    def to_dict(self) -> dict:
        return {"speed_rad_s": self.speed, "label": self.label,
                "harmonics": {int(k): {"x_re": X.real, "x_im": X.imag, "y_re": Y.real, "y_im": Y.imag}
                              for k, (X, Y) in ((k, (complex(a), complex(b))) for k, (a, b) in
                                                self.harmonics.items())},
                "ellipses": {int(k): self.ellipse(k).to_dict() for k in self.harmonics if k > 0}}


@validate_params({"speed": Real(lo=0, closed="neither"), "points": Integer(lo=8)})
def orbit(harmonics, speed: float, *, points: int = 361, label: str = "") -> Orbit:
    """The orbit over one revolution from harmonic components.

    Parameters
    ----------
    harmonics : mapping
        order ``k`` (int >= 0) -> ``(X_k, Y_k)`` complex amplitudes [m] of
        :math:`x = \\mathrm{Re}\\,X_k e^{jk\\Omega t}`, likewise y.
    speed : float
        Spin speed [rad/s] (> 0).
    points : int
        Samples over the revolution (the last closes the curve).
    label : str, optional
        Name of the orbit (e.g. the probe), for plots.

    Examples
    --------
    >>> from mutext.rotor.orbits import orbit
    >>> o = orbit({1: (1e-5, -1e-5j)}, 100.0)          # a forward circle of 10 µm
    >>> e = o.ellipse(1)
    >>> round(e.semi_major * 1e6, 6), round(e.semi_minor * 1e6, 6), e.direction
    (10.0, 10.0, 'forward')
    """
    speed = float(speed)
    if not isinstance(harmonics, Mapping):
        raise ModelError(f"orbit: harmonics must be a mapping order -> (X, Y), got {type(harmonics).__name__}")
    h = {}
    for k, xy in harmonics.items():
        check_param("orbit", "each of the harmonic orders", k, Integer(lo=0))
        try:
            X, Y = (complex(v) for v in xy)
        except (TypeError, ValueError):
            raise ModelError(f"orbit: harmonic {k} must be a pair (X, Y) of complex amplitudes [m], "
                             f"got {xy!r}") from None
        if not (np.isfinite(X) and np.isfinite(Y)):
            raise ModelError(f"orbit: harmonic {k} is not finite: {xy!r}")
        h[int(k)] = (X, Y)
    if not h:
        raise ModelError("orbit: needs at least one harmonic")
    t = np.linspace(0.0, 2 * np.pi / speed, int(points))
    x = np.zeros_like(t)
    y = np.zeros_like(t)
    for k, (X, Y) in h.items():
        e = np.exp(1j * k * speed * t)
        x += (X * e).real
        y += (Y * e).real
    return Orbit(speed, h, t, x, y, label)
