r"""Steady synchronous response to unbalance: Bode and polar data, run-up and coast-down.

An unbalance :math:`U = m e` [kg m] at station :math:`s`, at the angle
:math:`\varphi` from the keyphasor mark, turns with the shaft and loads it
with the centrifugal force

.. math::
    f_x = U\Omega^2\cos(\Omega t + \varphi),\quad f_y = U\Omega^2\sin(\Omega t + \varphi)
    \;\Longrightarrow\; F_x = U\Omega^2 e^{j\varphi},\quad F_y = -jU\Omega^2 e^{j\varphi}

(complex amplitudes of :math:`\mathrm{Re}\,F e^{j\Omega t}`, spin about +z
from x to y).  The steady response of the linear rotor is synchronous,
:math:`q = \mathrm{Re}\,Q e^{j\Omega t}`, with

.. math:: \left(K - \Omega^2 M + j\Omega(C + \Omega G)\right) Q = F ,

one complex solve per speed: the gyroscopic matrix is evaluated at the same
speed as the excitation frequency.  A probe at the angle :math:`\alpha`
from x reads :math:`P = X\cos\alpha + Y\sin\alpha`; its amplitude
:math:`|P|` and phase :math:`\arg P` (negative: the response lags the
unbalance mark) against speed are the Bode plot, :math:`P` in the complex
plane the polar (Nyquist) plot.  Near a forward critical speed the
amplitude peaks and the phase falls by about 180 degrees.

**Run-up and coast-down.**  The response at the 1x order tracked against
speed is this same solve when the speed changes slowly compared with the
decay of the modes (the quasi-steady run-up); :func:`run_up` returns it
for a sweep of speeds in either direction.  A fast run-up shifts and
lowers the peak (Friswell et al. 2010, sec. 3.7): that transient is
:func:`mutext.rotor.transient.transient_run_up` (the equations of motion
integrated in time through the critical speeds).

For the Jeffcott rotor (a disk of mass :math:`m` on a shaft of stiffness
:math:`k` and damping :math:`c`) this is
:math:`X = U\Omega^2/(k - m\Omega^2 + jc\Omega)`, the classical result the
tests check.

References
----------
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010, sec. 3.5 (Jeffcott
rotor), 3.7 (run-up) and 5.8 (unbalance response of finite-element rotors).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .._validation import Integer, check_param
from ..errors import ModelError
from ..lti import blas_single_thread
from .analysis import _finite_number, _values
from .campbell_diagram import speed_grid
from .orbits import Orbit, ellipse, orbit

__all__ = ["UnbalanceResponse", "unbalance_response", "run_up", "unbalance_force", "parse_probes"]


def parse_probes(model, probes) -> list[tuple[int, float]]:
    """``probes`` as ``[(station, angle_rad), ...]``: a station alone is a probe along x (angle 0).

    Parameters
    ----------
    model : Structure or Rotor
        The model whose stations the probes refer to.
    probes : int or sequence
        A station, a list of stations, or ``(station, angle_rad)`` pairs.
    """
    if probes is None:
        raise ModelError(f"{model.name}: give the probes (stations, or (station, angle_rad) pairs)")
    if isinstance(probes, (int, np.integer)) or (isinstance(probes, tuple) and len(probes) == 2
                                                 and isinstance(probes[1], float)):
        probes = [probes]
    out = []
    for p in probes:
        st, ang = (p, 0.0) if not isinstance(p, (tuple, list)) else tuple(p) if len(p) == 2 else (None, None)
        check_param(f"{model.name}: probe {p!r}", "the station", st, Integer(1, model.layout.n_nodes))
        ang = _finite_number(ang, f"{model.name}: probe {p!r}: the angle", "rad from x")
        out.append((int(st), ang))
    if not out:
        raise ModelError(f"{model.name}: needs at least one probe")
    return out


def _unbalances(model, station, unbalance_kg_m, phase):
    st = np.atleast_1d(np.asarray(station, dtype=object))
    U = np.atleast_1d(np.asarray(unbalance_kg_m, dtype=object))
    try:
        ph = np.atleast_1d(np.asarray(phase, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"{model.name}: the unbalance phase must be a number or numbers (rad), got {phase!r}") from None
    n = st.size
    if U.size == 1:
        U = np.repeat(U, n)
    if ph.size == 1:
        ph = np.repeat(ph, n)
    if U.size != n or ph.size != n:
        raise ModelError(f"{model.name}: {n} unbalance station(s) but {U.size} amount(s) and {ph.size} phase(s)")
    out = []
    for s, u, p in zip(st, U, ph):
        check_param(model.name, "unbalance station", s, Integer(1, model.layout.n_nodes))
        try:
            u = float(u)
        except (TypeError, ValueError):
            raise ModelError(f"{model.name}: unbalance_kg_m must be a number (kg m), got {u!r}") from None
        if not np.isfinite(u) or u < 0:
            raise ModelError(f"{model.name}: unbalance_kg_m must be finite and non-negative (kg m: mass times "
                             f"eccentricity), got {u!r}")
        if not np.isfinite(p):
            raise ModelError(f"{model.name}: the unbalance phase must be finite (rad), got {p!r}")
        out.append((int(s), u, float(p)))
    return out


def unbalance_force(model, unbalances, speed: float) -> np.ndarray:
    r"""Complex force vector :math:`F` (``ndof``) of ``[(station, U [kg m], phase [rad]), ...]`` at ``speed``.

    Parameters
    ----------
    model : Rotor
        The rotor (two planes).
    unbalances : sequence of (int, float, float)
        ``(station, U [kg m], phase [rad])`` per unbalance.
    speed : float
        Spin speed [rad/s].
    """
    F = np.zeros(model.ndof, complex)
    for s, u, p in unbalances:
        a = u * speed ** 2 * np.exp(1j * p)
        F[model.layout.dof(s, "u")] += a
        F[model.layout.dof(s, "v")] += -1j * a
    return F


@dataclass
class UnbalanceResponse:
    """Steady 1x response at the probes (see the module docstring).

    Attributes
    ----------
    speeds : ndarray (s,)
        Spin speeds [rad/s].
    probes : list of (station, angle_rad)
    X, Y : complex ndarray (s, p)
        x and y amplitudes [m] at each probe's station.
    unbalances : list of (station, U [kg m], phase [rad])
    name : str
        Name of the model.
    """
    speeds: np.ndarray
    probes: list
    X: np.ndarray
    Y: np.ndarray
    unbalances: list
    name: str = ""

    @property
    def speeds_rpm(self) -> np.ndarray:
        return self.speeds * 30.0 / np.pi

    @property
    def response(self) -> np.ndarray:
        """Complex amplitude [m] along each probe's direction, shape (s, p)."""
        ang = np.array([a for _, a in self.probes])
        return self.X * np.cos(ang) + self.Y * np.sin(ang)

    @property
    def amplitude(self) -> np.ndarray:
        """|response| [m] (zero-to-peak), shape (s, p)."""
        return np.abs(self.response)

    @property
    def phase(self) -> np.ndarray:
        """arg(response) [rad] from the unbalance mark, unwrapped along speed (negative: lag)."""
        return np.unwrap(np.angle(self.response), axis=0)

    @property
    def semi_major(self) -> np.ndarray:
        """Semi-major axis of the 1x orbit [m] at each probe's station, shape (s, p)."""
        return np.array([[ellipse(x, y).semi_major for x, y in zip(rx, ry)] for rx, ry in zip(self.X, self.Y)])

    def peak(self, probe: int = 0) -> tuple[float, float]:
        """(speed [rad/s], amplitude [m]) of the largest amplitude at ``probe`` (index) on the grid.

        Parameters
        ----------
        probe : int, optional
            Index into ``probes``.
        """
        i = int(np.argmax(self.amplitude[:, probe]))
        return float(self.speeds[i]), float(self.amplitude[i, probe])

    def orbit(self, speed_index: int, probe: int = 0, *, points: int = 361) -> Orbit:
        """The 1x orbit at ``probe`` (index) and ``speeds[speed_index]``.

        Parameters
        ----------
        speed_index : int
            Index into ``speeds``.
        probe : int, optional
            Index into ``probes``.
        points : int, optional
            Samples over the revolution.
        """
        st, _ = self.probes[probe]
        return orbit({1: (self.X[speed_index, probe], self.Y[speed_index, probe])}, self.speeds[speed_index],
                     points=points, label=f"station {st}, {self.speeds_rpm[speed_index]:.0f} rpm")

    def to_dict(self) -> dict:
        return {"model": self.name, "speeds_rad_s": self.speeds.tolist(), "speeds_rpm": self.speeds_rpm.tolist(),
                "probes": [{"station": s, "angle_rad": a} for s, a in self.probes],
                "unbalances": [{"station": s, "kg_m": u, "phase_rad": p} for s, u, p in self.unbalances],
                "amplitude_m": self.amplitude.T.tolist(), "phase_rad": self.phase.T.tolist()}


def unbalance_response(model, station, unbalance_kg_m, speeds: Sequence[float], probes, *, phase: float = 0.0,
                       values=None) -> UnbalanceResponse:
    """Steady synchronous response to unbalance at the probes, for each speed.

    Parameters
    ----------
    model : Rotor
        A rotor with two bending planes.
    station : int or sequence of int
        Station(s) of the unbalance (1-based).
    unbalance_kg_m : float or sequence
        Unbalance [kg m] (mass times eccentricity) at each station.
    speeds : array_like
        Spin speeds [rad/s], positive and increasing.
    probes : int, (int, float) or sequence of them
        Probe stations, alone (along x) or with the probe angle from x [rad].
    phase : float or sequence
        Angle of each unbalance from the keyphasor mark [rad].
    values : mapping or array, optional
        Parameter values.

    Examples
    --------
    >>> from mutext.examples.friswell import rotor
    >>> from mutext.rotor.unbalance import unbalance_response
    >>> r = unbalance_response(rotor(), 3, 1e-4, [50.0, 100.0], [3, (3, 1.5707963)])
    >>> r.amplitude.shape
    (2, 2)
    """
    if getattr(getattr(model, "layout", None), "kind", "") != "rotor":
        raise ModelError(f"{getattr(model, 'name', model)!r}: an unbalance response needs a rotor with two bending "
                         "planes (planes = 2)")
    s = speed_grid(speeds, model.name)
    if s[0] <= 0:
        raise ModelError(f"{model.name}: unbalance response speeds must be positive (rad/s); at standstill "
                         "an unbalance exerts no force")
    ub = _unbalances(model, station, unbalance_kg_m, phase)
    pr = parse_probes(model, probes)
    v = _values(model, values)
    with blas_single_thread():
        M, C, K, G = model.matrices(v)
        F = np.stack([unbalance_force(model, ub, om) for om in s])            # (s, ndof)
        Z = K[None] - (s ** 2)[:, None, None] * M[None] + 1j * s[:, None, None] * (C[None] + s[:, None, None] * G[None])
        try:
            Q = np.linalg.solve(Z, F[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            raise ModelError(f"{model.name}: the dynamic stiffness is singular at one of the speeds (an undamped "
                             "critical speed hit exactly)") from None
    if not np.all(np.isfinite(Q)):
        raise ModelError(f"{model.name}: the unbalance response is not finite (an undamped critical speed hit "
                         "exactly, or a rigid-body mode)")
    iu = [model.layout.dof(st, "u") for st, _ in pr]
    iv = [model.layout.dof(st, "v") for st, _ in pr]
    return UnbalanceResponse(s, pr, Q[:, iu], Q[:, iv], ub, model.name)


def run_up(model, station, unbalance_kg_m, speeds: Sequence[float], probes, *, phase: float = 0.0,
           values=None, coast_down: bool = False) -> UnbalanceResponse:
    """The 1x order tracked over a slow run-up (or coast-down): :func:`unbalance_response` on ``speeds``,
    returned in the order of the run (decreasing for ``coast_down``).  The quasi-steady limit: valid
    while the speed changes little over the decay time of the modes (module docstring).

    Parameters
    ----------
    model : Rotor
        The rotor.
    station : int
        1-based station of the unbalance.
    unbalance_kg_m : float
        Unbalance :math:`U = m e` [kg m].
    speeds : sequence of float
        Speeds of the run [rad/s], in any order.
    probes : int or sequence
        Stations, or ``(station, angle_rad)`` pairs (:func:`parse_probes`).
    phase : float, optional
        Angle of the unbalance [rad].
    values : mapping or array_like, optional
        Parameter values (see :meth:`~mutext.rotor.assembly.Structure.values`).
    coast_down : bool, optional
        Return the result in decreasing speed.
    """
    try:
        s = np.sort(np.atleast_1d(np.asarray(speeds, dtype=float)))
    except (TypeError, ValueError):
        raise ModelError(f"{model.name}: speeds must be numbers (rad/s), got {speeds!r}") from None
    r = unbalance_response(model, station, unbalance_kg_m, s, probes, phase=phase, values=values)
    if coast_down:
        r = UnbalanceResponse(r.speeds[::-1].copy(), r.probes, r.X[::-1].copy(), r.Y[::-1].copy(), r.unbalances,
                              r.name)
    return r
