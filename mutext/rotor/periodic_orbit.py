r"""Steady response of a rotor with a breathing crack to its weight and unbalance: all orders, orbits.

A crack that breathes with the rotation makes the stiffness periodic in the
shaft angle, :math:`K(t) = \sum_m K_m e^{jm\Omega t}`
(:class:`mutext.rotor.periodic.PeriodicRotor`).  Loaded by its weight
:math:`f_0` (constant, :math:`-g` on the :math:`y` translations through the
mass matrix: :math:`y` is up, as the breathing law assumes) and an
unbalance :math:`\mathrm{Re}\,F e^{j\Omega t}`
(:func:`mutext.rotor.unbalance.unbalance_force`), the steady response is
periodic with one revolution, :math:`q(t) = \sum_{k=-N}^{N} Q_k e^{jk\Omega t}`,
:math:`Q_{-k} = \overline{Q_k}`.  Harmonic balance gives the block system

.. math::
    Z(k\Omega)\,Q_k + \sum_{m \ne 0} K_m\,Q_{k-m} = f_k,\qquad
    Z(\nu) = K_0 - \nu^2 M + j\nu(C + \Omega G),\qquad k = -N..N,

with :math:`f_0` the weight, :math:`f_{\pm1} = F/2,\ \overline F/2` and the
other :math:`f_k = 0`: one dense solve of size :math:`(2N+1)n`.  The
amplitude of order :math:`k \ge 1` is :math:`X_k = 2Q_k` (of
:math:`\mathrm{Re}\,X_k e^{jk\Omega t}`), the order 0 the static sag.

The weight times the breathing stiffness drives the orders 1, 2, 3 (Mayes
law) even without unbalance; the 2x order resonates where :math:`2\Omega`
meets the first forward mode, near half the critical speed, and the orbit
at a probe (:func:`mutext.rotor.orbits.orbit`) then shows an inner loop
([Ga93]_, [PF02]_).  Without a breathing crack the system is
time-invariant and :math:`X_1` is the unbalance response.

References
----------
.. [Ga93] R. Gasch, "A survey of the dynamic behaviour of a simple rotating
   shaft with a transverse crack", *J. Sound Vib.* 160(2) (1993) 313-332.
.. [PF02] J. E. T. Penny and M. I. Friswell, "Simplified modelling of rotor
   cracks", *Proceedings of ISMA 2002*, Leuven, 607-615.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import Integer, validate_params
from ..errors import ModelError
from ..lti import blas_single_thread
from .orbits import Orbit, orbit
from .periodic import PeriodicRotor, periodic_rotor
from .unbalance import _unbalances, parse_probes, unbalance_force

__all__ = ["PeriodicResponse", "periodic_unbalance_response", "periodic_steady_state", "weight_force"]

#: standard gravity [m/s^2]
GRAVITY = 9.80665


def weight_force(model, M=None, gravity: float = GRAVITY) -> np.ndarray:
    """Consistent weight load [N, N m]: :math:`-g\\,M e_y`, with :math:`e_y` one on every y translation.

    Parameters
    ----------
    model : Rotor
        The rotor (two planes).
    M : (ndof, ndof) ndarray, optional
        Mass matrix (default: ``model.matrices().M``).
    gravity : float, optional
        Acceleration of gravity [m/s^2].
    """
    if M is None:
        M = model.matrices().M
    e = np.zeros(model.ndof)
    e[[model.layout.dof(s, "v") for s in range(1, model.layout.n_nodes + 1)]] = 1.0
    return -gravity * (M @ e)


def _periodic_matrices(model, speed, values) -> PeriodicRotor:
    """The time-periodic matrices of ``model``; without ports only the matrices are needed, so a model that
    declares no input or output gets placeholder ports (the harmonic balance here loads DOFs directly)."""
    from .assembly import Rotor
    if not isinstance(model, Rotor) or model.layout.kind != "rotor":
        raise ModelError(f"{getattr(model, 'name', model)!r}: needs a Rotor with two bending planes (planes = 2)")
    if model.input_names and model.output_names:
        return periodic_rotor(model, inputs=model.input_names[:1], outputs=model.output_names[:1], speed=speed,
                              values=values)
    from .elements import InputPort, OutputPort
    ported = Rotor(model.elements, planes=2, speed=model.speed, n_stations=model.n_stations,
                   inputs=[InputPort("_F1", 1)], outputs=[OutputPort("_x1", 1)], damping=model.damping,
                   name=model.name)
    v = None if values is None else model.values(values)
    return periodic_rotor(ported, speed=speed, values=v)


def periodic_steady_state(pr, forces: dict, harmonics: int) -> np.ndarray:
    r"""Harmonic balance of a :class:`~mutext.rotor.periodic.PeriodicRotor` under forcing of orders of the speed.

    ``forces`` maps order k >= 0 to the complex force of :math:`\mathrm{Re}\,F_k e^{jk\Omega t}` (order 0:
    real, constant).  Returns :math:`Q` of shape ``(2N+1, n)``, row ``k + N`` the two-sided coefficient of
    :math:`e^{jk\Omega t}`.

    Parameters
    ----------
    pr : PeriodicRotor
        The time-periodic model.
    forces : dict
        Order k >= 0 -> complex force vector (``n``) [N].
    harmonics : int
        Truncation N of the harmonic balance.
    """
    N = int(harmonics)
    n = pr.n
    nb = 2 * N + 1
    Km = pr.stiffness_harmonics(2 * N)
    A = np.zeros((nb * n, nb * n), complex)
    rhs = np.zeros(nb * n, complex)
    W = pr.speed
    for bi, k in enumerate(range(-N, N + 1)):
        nu = k * W
        for bj, l in enumerate(range(-N, N + 1)):
            m = k - l
            blk = Km[m] if m != 0 else Km[0] - nu * nu * pr.M + 1j * nu * pr.D
            if m == 0 or np.any(blk):
                A[bi * n:(bi + 1) * n, bj * n:(bj + 1) * n] = blk
    for k, F in forces.items():
        F = np.asarray(F, complex)
        if k == 0:
            rhs[N * n:(N + 1) * n] += F.real
        elif k <= N:
            rhs[(N + k) * n:(N + k + 1) * n] += 0.5 * F
            rhs[(N - k) * n:(N - k + 1) * n] += 0.5 * np.conj(F)
    with blas_single_thread():
        try:
            Q = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            raise ModelError(f"{pr.name}: the harmonic balance is singular (an undamped resonance of an order "
                             "hit exactly)") from None
    return Q.reshape(nb, n)


@dataclass
class PeriodicResponse:
    """Harmonics of the steady response at the probes.

    Attributes
    ----------
    speed : float
        [rad/s]
    probes : list of (station, angle_rad)
    X, Y : complex ndarray (N+1, p)
        Row k: amplitude of order k (one-sided, ``Re X_k e^{jk Omega t}``; row 0 the static offset) [m].
    harmonics : int
    name : str
        Name of the model.
    """
    speed: float
    probes: list
    X: np.ndarray
    Y: np.ndarray
    harmonics: int
    name: str = ""

    def amplitude(self, order: int, probe: int = 0) -> float:
        """Amplitude [m] of ``order`` along the probe's direction.

        Parameters
        ----------
        order : int
            Harmonic order (0..harmonics).
        probe : int, optional
            Index into ``probes``.
        """
        a = self.probes[probe][1]
        return float(abs(self.X[order, probe] * np.cos(a) + self.Y[order, probe] * np.sin(a)))

    def orbit(self, probe: int = 0, *, orders=None, points: int = 721, static: bool = False) -> Orbit:
        """The orbit at ``probe`` (index) from ``orders`` (default all k >= 1; ``static`` adds the sag).

        Parameters
        ----------
        probe : int, optional
            Index into ``probes``.
        orders : sequence of int, optional
            Harmonic orders to include (default: all k >= 1).
        points : int, optional
            Samples over the revolution.
        static : bool, optional
            Include the static offset (order 0, the sag under weight).
        """
        ks = range(0 if static else 1, self.harmonics + 1) if orders is None else orders
        h = {int(k): (self.X[k, probe], self.Y[k, probe]) for k in ks}
        return orbit(h, self.speed, points=points,
                     label=f"station {self.probes[probe][0]}, {self.speed * 30 / np.pi:.0f} rpm")


@validate_params({"harmonics": Integer(lo=1)})
def periodic_unbalance_response(model, speed: float, probes, *, unbalance=None, weight: bool = True,
                                harmonics: int = 6, values=None) -> PeriodicResponse:
    """Steady response of a rotor with breathing crack(s) to weight and unbalance, all orders up to ``harmonics``.

    Parameters
    ----------
    model : Rotor
        With ``breathing`` cracks (others make it time-invariant).
    speed : float
        Running speed [rad/s] (> 0).
    probes : int, (int, float) or sequence
        As for :func:`mutext.rotor.unbalance.unbalance_response`.
    unbalance : (station, kg_m) or (station, kg_m, phase_rad), or a list of them, optional
    weight : bool
        Load the rotor with its weight (y up).
    harmonics : int
        Highest order N kept in the harmonic balance.
    values : mapping, optional
    """
    try:
        speed = float(speed)
    except (TypeError, ValueError):
        raise ModelError(f"{model.name}: speed must be a number (rad/s), got {speed!r}") from None
    if not (np.isfinite(speed) and speed > 0):
        raise ModelError(f"{model.name}: the running speed must be positive and finite (rad/s), got {speed!r}")
    pr_probes = parse_probes(model, probes)
    if not weight and unbalance is None:
        raise ModelError(f"{model.name}: nothing loads the rotor (weight=False and no unbalance)")
    pr = _periodic_matrices(model, speed, values)
    forces = {}
    if weight:
        forces[0] = weight_force(model, pr.M)
    if unbalance is not None:
        items = [unbalance] if not isinstance(unbalance, list) else unbalance
        ub = []
        for it in items:
            if not isinstance(it, (tuple, list)) or len(it) not in (2, 3):
                raise ModelError(f"{model.name}: unbalance must be (station, kg_m) or (station, kg_m, phase_rad), "
                                 f"got {it!r}")
            ub += _unbalances(model, it[0], it[1], it[2] if len(it) == 3 else 0.0)
        forces[1] = unbalance_force(model, ub, speed)
    Q = periodic_steady_state(pr, forces, harmonics)
    N = int(harmonics)
    one = np.concatenate([Q[N:N + 1].real, 2.0 * Q[N + 1:]])       # one-sided: order 0 real, k >= 1 doubled
    iu = [model.layout.dof(s, "u") for s, _ in pr_probes]
    iv = [model.layout.dof(s, "v") for s, _ in pr_probes]
    return PeriodicResponse(speed, pr_probes, one[:, iu], one[:, iv], N, model.name)
