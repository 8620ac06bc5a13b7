r"""Time simulation of a Jeffcott rotor with a breathing crack.

The simulations of the package sit apart from the element formulas they
integrate: this module integrates the two-DOF Jeffcott rotor whose shaft
stiffness follows a breathing law of :mod:`mutext.rotor.crack`
(:func:`simulate_breathing_jeffcott`, a steady-state record with its
harmonics); :func:`mutext.rotor.periodic.stepped_sine` integrates the
finite-element rotor at speed.

Units are SI throughout: metres, newtons, radians, seconds.

References
----------
.. [Ga93] R. Gasch, "A survey of the dynamic behaviour of a simple rotating
   shaft with a transverse crack", *Journal of Sound and Vibration* 160(2)
   (1993) 313-332 (switching "hinge" crack; Jeffcott rotor with a crack).
.. [PF02] J. E. T. Penny and M. I. Friswell, "Simplified modelling of rotor
   cracks", *Proceedings of ISMA 2002*, Leuven, 607-615 (comparison of the
   hinge, Mayes and fracture-mechanics crack models on a Jeffcott rotor).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import ModelError, SolverError
from .crack import _MODELS, _positive, open_fraction

__all__ = ["JeffcottResult", "simulate_breathing_jeffcott"]


@dataclass
class JeffcottResult:
    r"""Steady-state record of :func:`simulate_breathing_jeffcott`.

    Attributes
    ----------
    t : ndarray
        Sample times [s] over ``n_record`` whole revolutions after settling.
    x, y : ndarray
        Disk displacements [m] (``y`` vertical, up).
    speed : float
        Running speed :math:`\Omega` [rad/s].
    natural_frequency : float
        :math:`\omega_0 = \sqrt{k_0/m}` of the healthy shaft [rad/s].
    model : str
    params : dict
        The remaining inputs, for the record.
    """
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    speed: float
    natural_frequency: float
    model: str
    params: dict = field(default_factory=dict)

    def harmonic(self, order: int) -> np.ndarray:
        r"""Complex amplitudes :math:`[X_n, Y_n]` (m) of the component at ``order`` x speed.

        :math:`x(t) \approx \sum_n \mathrm{Re}(X_n e^{j n\Omega t})`; computed
        exactly as a DFT bin because the record spans whole revolutions
        sampled uniformly (order 0 is the mean).

        Parameters
        ----------
        order : int
            Multiple of the running speed (0 for the mean).
        """
        ph = np.exp(-1j * order * self.speed * self.t)
        scale = 1.0 if order == 0 else 2.0
        return scale * np.array([np.mean(self.x * ph), np.mean(self.y * ph)])

    def amplitude(self, order: int) -> float:
        r"""Size :math:`\sqrt{|X_n|^2 + |Y_n|^2}` (m) of the ``order`` x component.

        Parameters
        ----------
        order : int
            Multiple of the running speed.
        """
        return float(np.linalg.norm(self.harmonic(order)))


def simulate_breathing_jeffcott(mass, k0, dk_xi, speed, *, dk_eta=0.0, damping_ratio=0.02,
                                eccentricity=0.0, unbalance_angle=0.0, gravity=9.81,
                                model: str = "mayes", crack_angle0=0.0,
                                n_settle: int | None = None, n_record: int = 8,
                                samples_per_rev: int = 64, rtol=1e-9, atol=None) -> JeffcottResult:
    r"""Time-domain response of a Jeffcott rotor with a breathing crack.

    A disk of mass :math:`m` at mid-span of a massless shaft turning at the
    constant speed :math:`\Omega`; fixed frame :math:`x` horizontal,
    :math:`y` vertical up:

    .. math::
        m\ddot{\mathbf r} + c\,\dot{\mathbf r} + K(\theta,\psi)\,\mathbf r =
        m e\Omega^2\begin{bmatrix}\cos(\theta+\beta)\\ \sin(\theta+\beta)
        \end{bmatrix} - \begin{bmatrix}0\\ m g\end{bmatrix},

    with :math:`K` from :func:`~mutext.rotor.crack.fixed_frame_stiffness`,
    :math:`\theta = \Omega t + \theta_0` the angle of the crack normal
    :math:`\xi` from :math:`x`, :math:`c = 2\zeta\sqrt{k_0 m}` and
    :math:`\beta` the angle of the unbalance from the crack normal.
    Breathing follows **weight dominance** ([Ga93]_, [PF02]_): the static
    sag is downward, the cracked side is in tension when :math:`\xi` points
    down, so :math:`\psi = \theta + \pi/2`.

    Physical signatures reproduced (see the tests):

    * A breathing crack under gravity turns the static sag into a periodic
      force at 1X, 2X and 3X (products of the :math:`\psi`- and
      :math:`2\theta`-dependence of :math:`K`); the 2X component resonates
      when :math:`2\Omega` equals the natural frequency, i.e. at half the
      critical speed, which is the classical crack indicator ([Ga93]_).
    * An always-open crack (asymmetric shaft) loaded only by unbalance has
      a constant stiffness and a constant load in the rotating frame, so the
      steady response is pure 1X: no 2X without gravity.

    Parameters
    ----------
    mass : float
        Disk mass [kg].
    k0 : float
        Healthy shaft stiffness at the disk [N/m].
    dk_xi, dk_eta : float
        Stiffness loss of the fully open crack across and along the crack
        edge [N/m] (``dk_eta`` defaults to 0).
    speed : float
        Running speed :math:`\Omega` [rad/s], > 0.
    damping_ratio : float
        :math:`\zeta` of the healthy rotor [-].
    eccentricity : float
        Mass eccentricity :math:`e` [m].
    unbalance_angle : float
        :math:`\beta` [rad], unbalance direction relative to the crack normal.
    gravity : float
        [m/s^2]; 0 for a vertical rotor / no weight.
    model : {"mayes", "gasch", "open", "closed"}
        Breathing law (:func:`~mutext.rotor.crack.open_fraction`).
    crack_angle0 : float
        :math:`\theta_0` [rad].
    n_settle : int, optional
        Revolutions discarded as transient; default: enough for the free
        vibration to decay by :math:`e^{-12}`.
    n_record : int
        Revolutions recorded.
    samples_per_rev : int
        Uniform samples per revolution in the record.
    rtol, atol : float
        Integrator tolerances (``atol`` defaults to 1e-9 of the static sag
        or of the unbalance response scale).

    Returns
    -------
    JeffcottResult
    """
    m, k0, W, dk_xi, dk_eta, zeta = _checked_jeffcott(mass, k0, dk_xi, speed, dk_eta, damping_ratio, model)
    w0 = np.sqrt(k0 / m)
    cdamp = 2.0 * zeta * np.sqrt(k0 * m)
    period = 2.0 * np.pi / W
    if n_settle is None:
        n_settle = int(np.ceil(12.0 / (zeta * w0) / period))
    scale = max(m * abs(gravity) / k0, m * abs(eccentricity) * W**2 / k0, 1e-12)
    atol = 1e-9 * scale if atol is None else atol
    rhs = _jeffcott_rhs(m, k0, dk_xi, dk_eta, cdamp, W, eccentricity, unbalance_angle, gravity, crack_angle0,
                        model)
    z0 = [0.0, -m * gravity / k0, 0.0, 0.0]
    t_end_settle = n_settle * period
    t_rec = t_end_settle + period * np.arange(n_record * samples_per_rev) / samples_per_rev
    # the Gasch law switches twice per turn: cap the step so no switch is stepped over blindly
    max_step = period / 16.0 if model == "gasch" else np.inf
    sol = solve_ivp(rhs, (0.0, t_rec[-1]), z0, method="DOP853", t_eval=t_rec, rtol=rtol,
                    atol=atol, max_step=max_step)
    if not sol.success:
        raise SolverError(f"simulate_breathing_jeffcott: integration failed: {sol.message}")
    return JeffcottResult(t=sol.t, x=sol.y[0], y=sol.y[1], speed=W, natural_frequency=w0,
                          model=model,
                          params=dict(mass=m, k0=k0, dk_xi=dk_xi, dk_eta=dk_eta,
                                      damping_ratio=zeta, eccentricity=eccentricity,
                                      unbalance_angle=unbalance_angle, gravity=gravity,
                                      crack_angle0=crack_angle0, n_settle=n_settle))


def _checked_jeffcott(mass, k0, dk_xi, speed, dk_eta, damping_ratio, model):
    """``(m, k0, speed, dk_xi, dk_eta, damping_ratio)`` of :func:`simulate_breathing_jeffcott` as floats, checked."""
    m = float(_positive(mass, "mass", "kg"))
    k0 = float(_positive(k0, "k0", "N/m"))
    W = float(_positive(speed, "speed", "rad/s"))
    dk_xi, dk_eta = float(dk_xi), float(dk_eta)
    if not (0 <= dk_xi < k0 and 0 <= dk_eta < k0):
        raise ModelError(f"the crack stiffness losses must satisfy 0 <= dk < k0 = {k0} N/m, "
                         f"got dk_xi={dk_xi}, dk_eta={dk_eta}")
    if model not in _MODELS:
        raise ModelError(f"crack model must be one of {_MODELS}, got {model!r}")
    zeta = float(damping_ratio)
    if zeta <= 0:
        raise ModelError(f"damping_ratio must be > 0 for a steady state to exist, got {zeta}")
    return m, k0, W, dk_xi, dk_eta, zeta


def _jeffcott_rhs(m, k0, dk_xi, dk_eta, cdamp, W, eccentricity, unbalance_angle, gravity, crack_angle0, model):
    """The right-hand side ``f(t, [x, y, vx, vy])`` of the Jeffcott rotor's equations of motion."""
    s = 0.5 * (dk_xi + dk_eta)
    d = 0.5 * (dk_xi - dk_eta)
    ue = m * eccentricity * W**2

    def rhs(t, z):
        x, y, vx, vy = z
        th = W * t + crack_angle0
        f = open_fraction(th + np.pi / 2.0, model)
        c2, s2 = np.cos(2 * th), np.sin(2 * th)
        kxx = k0 - f * (s + d * c2)
        kyy = k0 - f * (s - d * c2)
        kxy = -f * d * s2
        fx = ue * np.cos(th + unbalance_angle)
        fy = ue * np.sin(th + unbalance_angle) - m * gravity
        ax = (fx - cdamp * vx - kxx * x - kxy * y) / m
        ay = (fy - cdamp * vy - kxy * x - kyy * y) / m
        return [vx, vy, ax, ay]

    return rhs
