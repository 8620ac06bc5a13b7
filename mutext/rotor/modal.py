r"""Mode shapes of a spinning rotor along the shaft, with frequency, damping, log decrement and whirl.

The modes at spin speed :math:`\Omega` are those of
:func:`mutext.rotor.analysis.modes`.  For each mode the translations
:math:`\hat u_s, \hat v_s` of every station :math:`s` are kept; at each
station they describe an ellipse (the free whirl orbit,
:func:`mutext.rotor.orbits.ellipse`), whose semi-major axis is the
amplitude drawn along the shaft.  The shape is scaled so that the largest
semi-major axis is 1 and the largest translation is real and positive.
The planar shape drawn along the shaft, :attr:`ModeShapes.shape`, is the
snapshot of the displacement along the major axis of the station that moves
most, at the instant that station is furthest out:
:math:`\mathrm{Re}\big((\hat u_s\cos\alpha + \hat v_s\sin\alpha)e^{-j\varphi}\big)`
with :math:`\alpha` that major axis' angle and :math:`\varphi` the phase of
its projection there (signs show the nodes).  The logarithmic decrement is
:math:`\delta = -2\pi\,\mathrm{Re}\,\lambda/\mathrm{Im}\,\lambda`; a
negative :math:`\delta` is an unstable mode.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from .analysis import _check_n, modes
from .campbell_diagram import log_decrement, whirl_labels
from .orbits import ellipse

__all__ = ["ModeShapes", "mode_shapes"]


@dataclass
class ModeShapes:
    """The ``n`` lowest modes at one speed (see the module docstring).

    Attributes
    ----------
    speed : float
        Spin speed [rad/s].
    eigenvalues : complex ndarray (n,)
    frequencies_hz, damping_ratio, log_dec, whirl : ndarray (n,)
    direction : list of str
        ``forward``, ``backward``, ``mixed`` or ``degenerate``.
    positions : ndarray (s,)
        Axial position of each station [m].
    u, v : complex ndarray (s, n)
        Translations in x and y at each station (scaled, see above).
    semi_major, semi_minor : ndarray (s, n)
        The whirl ellipse at each station.
    shape : ndarray (s, n)
        The planar snapshot along the major axis (module docstring), largest entry 1.
    """
    speed: float
    eigenvalues: np.ndarray
    frequencies_hz: np.ndarray
    damping_ratio: np.ndarray
    log_dec: np.ndarray
    whirl: np.ndarray
    direction: list
    positions: np.ndarray
    u: np.ndarray
    v: np.ndarray
    semi_major: np.ndarray
    semi_minor: np.ndarray
    shape: np.ndarray

    def to_dict(self) -> dict:
        return {"speed_rad_s": self.speed, "frequencies_hz": self.frequencies_hz.tolist(),
                "damping_ratio": self.damping_ratio.tolist(), "log_dec": self.log_dec.tolist(),
                "whirl_index": self.whirl.tolist(), "direction": self.direction,
                "positions_m": self.positions.tolist(), "semi_major": self.semi_major.T.tolist(),
                "shape": self.shape.T.tolist()}


def mode_shapes(model, speed: float | None = None, n: int = 4, *, values=None) -> ModeShapes:
    """Mode shapes along the shaft at ``speed`` [rad/s] (default: the model's speed).

    Parameters
    ----------
    model : Rotor
        A rotor with two bending planes.
    speed : float, optional
    n : int
        Number of lowest modes.
    values : mapping or array, optional

    Examples
    --------
    >>> from mutext.examples.friswell import rotor
    >>> from mutext.rotor.modal import mode_shapes
    >>> ms = mode_shapes(rotor(), 400.0, 2)
    >>> ms.direction, [round(float(x), 2) for x in ms.frequencies_hz]
    (['backward', 'forward'], [13.6, 13.97])
    """
    if getattr(getattr(model, "layout", None), "kind", "") != "rotor" or not hasattr(model, "positions"):
        raise ModelError(f"{getattr(model, 'name', model)!r}: mode shapes along the shaft need a Rotor with two "
                         "bending planes (planes = 2)")
    n = _check_n(n)
    md = modes(model, speed=speed, n=n, values=values)
    lay = model.layout
    iu = [lay.dof(s, "u") for s in range(1, lay.n_nodes + 1)]
    iv = [lay.dof(s, "v") for s in range(1, lay.n_nodes + 1)]
    U, V = md.shapes[iu].copy(), md.shapes[iv].copy()
    m = U.shape[1]
    major, minor = np.zeros((len(iu), m)), np.zeros((len(iu), m))
    snap = np.zeros((len(iu), m))
    for r in range(m):
        big = np.concatenate([U[:, r], V[:, r]])
        k = int(np.argmax(np.abs(big)))
        if big[k] != 0:
            ph = big[k] / abs(big[k])
            U[:, r] /= ph
            V[:, r] /= ph
        for s in range(len(iu)):
            e = ellipse(U[s, r], V[s, r])
            major[s, r], minor[s, r] = e.semi_major, e.semi_minor
        top = major[:, r].max()
        if top > 0:
            U[:, r] /= top
            V[:, r] /= top
            major[:, r] /= top
            minor[:, r] /= top
        ref = int(np.argmax(major[:, r]))
        alpha = ellipse(U[ref, r], V[ref, r]).angle
        proj = U[:, r] * np.cos(alpha) + V[:, r] * np.sin(alpha)
        if proj[ref] != 0:
            snap[:, r] = (proj * np.conj(proj[ref]) / abs(proj[ref])).real
        if np.max(np.abs(snap[:, r])) > 0:
            snap[:, r] /= np.max(np.abs(snap[:, r]))
    return ModeShapes(md.speed, md.eigenvalues, md.frequencies_hz, md.damping_ratio,
                      log_decrement(md.eigenvalues), md.whirl, whirl_labels(md.whirl, md.frequencies_hz),
                      np.asarray(model.positions, float), U, V, major, minor, snap)

