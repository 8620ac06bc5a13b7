r"""Transient run-up and coast-down through critical speeds: the response in time to an unbalance
while the speed changes at a finite rate.

The rotor is driven along a prescribed speed profile, linear in time from
:math:`\Omega_0` to :math:`\Omega_1` (constant angular acceleration
:math:`\alpha = \dot\Omega`, zero for a constant speed), with the shaft angle
:math:`\theta(t) = \Omega_0 t + \alpha t^2/2` from the keyphasor mark.  A mass
:math:`m` at radius :math:`e`, at the angle :math:`\varphi` from the mark,
sits at :math:`e(\cos\vartheta, \sin\vartheta)`, :math:`\vartheta = \theta + \varphi`;
its inertia loads the shaft with :math:`-m` times its acceleration,

.. math::
    f_x = U(\dot\theta^2\cos\vartheta + \ddot\theta\sin\vartheta),\qquad
    f_y = U(\dot\theta^2\sin\vartheta - \ddot\theta\cos\vartheta),\qquad U = me ,

the centrifugal force of :mod:`mutext.rotor.unbalance` (spin from x to y)
plus the tangential force of the acceleration.  The equation of motion is

.. math:: M\ddot q + \left(C + \Omega(t)\,G\right)\dot q + Kq = f(t),

with the gyroscopic matrix at the instantaneous speed.  Neglected: the term
:math:`\dot\Omega K_{st} q` of the disks' and shaft's polar inertia under
angular acceleration (:math:`\dot\Omega I_p` against the bending stiffness,
small for any practical rate), and the
torsional coupling (the speed is imposed, the vibration does not slow the drive).
At a constant speed the response settles to the steady unbalance response
:func:`~mutext.rotor.unbalance.unbalance_response`.

**Reduction.**  The model is projected on the lowest undamped modes of
:math:`(K, M)` at standstill (by default those up to four times the top
speed, at least four) plus, when :math:`K` is nonsingular, the static
deflection shapes :math:`K^{-1}b` of unit forces in x and y at the unbalance
stations, made mass-orthogonal to the modes (the static correction of the
truncated modes: the reduced model's response below its modes is that of
the full model to about the square of the frequency ratio).  Damping and
gyroscopic coupling are projected whole, so :math:`\Omega G` keeps its speed
dependence in the reduced coordinates.  ``modes`` sets the count.

**Integration.**  Newmark's average-acceleration rule (trapezoidal,
:math:`\beta = 1/4,\ \gamma = 1/2`: unconditionally stable, second order, no
numerical damping) with the velocity matrix :math:`C + \Omega_{n+1}G` at the
new step, one small linear solve per step.  Its steady response to a harmonic
force of frequency :math:`\omega` is that of the exact model at
:math:`(2/h)\tan(\omega h/2)`: a relative frequency error of
:math:`(\omega h)^2/12`, about 2e-4 at the default 128 steps per revolution
of the top speed.  The step also resolves every kept mode (16 steps per period).

**What a run-up shows.**  The rotor crosses a critical speed in finite time,
so the resonance has no time to build up: the peak is lower than the steady
one and is reached later, at a higher speed in a run-up and a lower speed in
a coast-down, followed by beats between the 1x response and the free
vibration at the natural frequency (Lewis 1932).  The shift and the
reduction grow with the dimensionless acceleration :math:`\alpha/\omega_n^2`
measured against :math:`\zeta^2`.

The result gives the time histories at the output stations, the envelope
(the largest orbit radius :math:`\sqrt{x^2 + y^2}` in each revolution, the
steady semi-major axis at a constant speed) and the 1x order tracked per
revolution (least squares on :math:`\cos\theta, \sin\theta` over the
revolution: what an order-tracking analyzer shows).

References
----------
F. M. Lewis, "Vibration during acceleration through a critical speed",
*Transactions of the ASME* 54 (1932) 253-261.
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010 (sec. 3.7, run-up).
G. Genta, *Dynamics of Rotating Systems*, Springer, 2005 (ch. 4, acceleration
through the critical speed).
N. M. Newmark, "A method of computation for structural dynamics",
*Journal of the Engineering Mechanics Division* 85 (1959) 67-94.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from .._validation import Integer, check_param
from ..errors import ModelError
from ..lti import blas_single_thread
from .analysis import _finite_number, _values
from .unbalance import UnbalanceResponse, _unbalances, unbalance_response

__all__ = ["TransientRunUp", "transient_run_up"]

#: Steps per period of the highest kept mode (or static shape).
_STEPS_PER_MODE = 16
#: Largest number of steps before the run is refused (a hint to shorten it or reduce more).
MAX_STEPS = 2_000_000


@dataclass
class TransientRunUp:
    r"""Result of :func:`transient_run_up` (see the module docstring).

    Attributes
    ----------
    t : ndarray (n,)
        Times [s], from 0 in steps of ``dt``.
    speed : ndarray (n,)
        Speed :math:`\Omega(t)` [rad/s].
    angle : ndarray (n,)
        Shaft angle :math:`\theta(t)` [rad] from the keyphasor mark.
    stations : list of int
        The output stations.
    x, y : ndarray (n, p)
        Displacements [m] at the output stations.
    acceleration : float
        :math:`\dot\Omega` [rad/s^2] (negative in a coast-down).
    unbalances : list of (station, U [kg m], phase [rad])
    steady : UnbalanceResponse
        The steady unbalance response of the full model at the output stations, on a fine grid
        of the speed range (for comparison: the quasi-steady run-up).
    basis_hz : ndarray
        Natural frequencies [Hz] of the reduced model at standstill (modes and static shapes).
    dt : float
        Time step [s].
    name : str
        Name of the model.
    rev_speed : ndarray (k,)
        Mean speed [rad/s] over each complete revolution.
    envelope : ndarray (k, p)
        Largest orbit radius [m] at each station in each revolution.
    X1, Y1 : complex ndarray (k, p)
        The 1x order per revolution: :math:`x \approx \mathrm{Re}(X_1 e^{j\theta})`, the same for y.
    """
    t: np.ndarray
    speed: np.ndarray
    angle: np.ndarray
    stations: list
    x: np.ndarray
    y: np.ndarray
    acceleration: float
    unbalances: list
    steady: UnbalanceResponse
    basis_hz: np.ndarray
    dt: float
    name: str = ""
    rev_speed: np.ndarray = field(default=None, repr=False)
    envelope: np.ndarray = field(default=None, repr=False)
    X1: np.ndarray = field(default=None, repr=False)
    Y1: np.ndarray = field(default=None, repr=False)

    def __post_init__(self):
        if self.rev_speed is None:
            self.rev_speed, self.envelope, self.X1, self.Y1 = _per_revolution(self.angle, self.speed, self.x,
                                                                               self.y)

    @property
    def speed_rpm(self) -> np.ndarray:
        """Speed [rpm] at each time."""
        return self.speed * 30.0 / np.pi

    @property
    def rev_speed_rpm(self) -> np.ndarray:
        """Mean speed [rpm] of each complete revolution."""
        return self.rev_speed * 30.0 / np.pi

    @property
    def radius(self) -> np.ndarray:
        """Orbit radius :math:`\\sqrt{x^2 + y^2}` [m] at each time and station, shape (n, p)."""
        return np.hypot(self.x, self.y)

    def peak(self, output: int = 0) -> tuple[float, float]:
        """(speed [rad/s], radius [m]) where the orbit radius at ``output`` is largest, refined between
        the samples by a parabola through the largest and its neighbours.

        Parameters
        ----------
        output : int, optional
            Index into ``stations``.
        """
        r = self.radius[:, output]
        i = int(np.argmax(r))
        if 0 < i < r.size - 1:
            a, b, c = r[i - 1], r[i], r[i + 1]
            den = a - 2 * b + c
            d = 0.5 * (a - c) / den if den < 0 else 0.0
            d = float(np.clip(d, -0.5, 0.5))
            amp = b - 0.25 * (a - c) * d
            w = self.speed[i] + d * (self.speed[i + 1] - self.speed[i])
            return float(w), float(amp)
        return float(self.speed[i]), float(r[i])

    def steady_peak(self, output: int = 0) -> tuple[float, float]:
        """(speed [rad/s], semi-major axis [m]) of the steady response's largest orbit at ``output``
        on the grid of ``steady``.

        Parameters
        ----------
        output : int, optional
            Index into ``stations``.
        """
        a = self.steady.semi_major[:, output]
        i = int(np.argmax(a))
        return float(self.steady.speeds[i]), float(a[i])

    def to_dict(self) -> dict:
        """The run, the peaks and the envelope per revolution (not the time histories) as plain data."""
        out = []
        for j, s in enumerate(self.stations):
            w, a = self.peak(j)
            ws, as_ = self.steady_peak(j)
            out.append({"station": s, "peak_speed_rad_s": w, "peak_speed_rpm": w * 30 / np.pi,
                        "peak_radius_m": a, "steady_peak_speed_rad_s": ws, "steady_peak_speed_rpm": ws * 30 / np.pi,
                        "steady_peak_m": as_, "envelope_m": self.envelope[:, j].tolist()})
        return {"model": self.name, "start_rad_s": float(self.speed[0]), "stop_rad_s": float(self.speed[-1]),
                "duration_s": float(self.t[-1]), "acceleration_rad_s2": self.acceleration, "dt_s": self.dt,
                "steps": int(self.t.size - 1), "basis_hz": self.basis_hz.tolist(),
                "unbalances": [{"station": s, "kg_m": u, "phase_rad": p} for s, u, p in self.unbalances],
                "rev_speed_rad_s": self.rev_speed.tolist(), "rev_speed_rpm": self.rev_speed_rpm.tolist(),
                "outputs": out}


def _per_revolution(angle, speed, x, y):
    """Per complete revolution: mean speed, largest radius, and the 1x components by least squares."""
    k = np.floor(angle / (2 * np.pi) + 1e-9).astype(int)
    nrev = int(k[-1])                                           # the last one is incomplete (or just begun)
    p = x.shape[1]
    if nrev < 1:
        z = np.zeros((0, p))
        return np.zeros(0), z, z.astype(complex), z.astype(complex)
    keep = k < nrev
    k, c, s = k[keep], np.cos(angle[keep]), np.sin(angle[keep])
    xs, ys = x[keep], y[keep]

    def sums(w):
        return np.bincount(k, weights=w, minlength=nrev)
    cnt = sums(np.ones_like(c))
    speed_mean = sums(speed[keep]) / cnt
    r = np.hypot(xs, ys)
    env = np.zeros((nrev, p))
    for j in range(p):
        np.maximum.at(env[:, j], k, r[:, j])
    scc, sss, scs = sums(c * c), sums(s * s), sums(c * s)
    det = scc * sss - scs ** 2
    X1 = np.zeros((nrev, p), complex)
    Y1 = np.zeros((nrev, p), complex)
    for j in range(p):
        for sig, dest in ((xs[:, j], X1), (ys[:, j], Y1)):
            bc, bs = sums(sig * c), sums(sig * s)
            a = (sss * bc - scs * bs) / det                     # sig ~ a cos + b sin = Re((a - jb) e^{j theta})
            b = (scc * bs - scs * bc) / det
            dest[:, j] = a - 1j * b
    return speed_mean, env, X1, Y1


def _unbalance_list(model, unbalance):
    """``[(station, mass_kg, radius_m[, phase_rad]), ...]`` -> ``[(station, U, phase)]`` checked."""
    if isinstance(unbalance, tuple) and unbalance and not isinstance(unbalance[0], (tuple, list)):
        unbalance = [unbalance]
    try:
        items = list(unbalance)
    except TypeError:
        raise ModelError(f"{model.name}: unbalance must be a list of (station, mass_kg, radius_m[, phase_rad]), "
                         f"got {unbalance!r}") from None
    if not items:
        raise ModelError(f"{model.name}: unbalance needs at least one (station, mass_kg, radius_m[, phase_rad])")
    st, U, ph = [], [], []
    for it in items:
        if not isinstance(it, (tuple, list)) or len(it) not in (3, 4):
            raise ModelError(f"{model.name}: each unbalance is (station, mass_kg, radius_m[, phase_rad]), got {it!r}")
        m = _finite_number(it[1], f"{model.name}: unbalance {it!r}: the mass", "kg")
        e = _finite_number(it[2], f"{model.name}: unbalance {it!r}: the radius", "m")
        if m < 0 or e < 0:
            raise ModelError(f"{model.name}: unbalance {it!r}: the mass and the radius must be non-negative")
        st.append(it[0])
        U.append(m * e)
        ph.append(it[3] if len(it) == 4 else 0.0)
    return _unbalances(model, st, U, ph)


def _outputs(model, outputs):
    if isinstance(outputs, (int, np.integer)):
        outputs = [outputs]
    try:
        items = list(outputs)
    except TypeError:
        raise ModelError(f"{model.name}: outputs must be a station or a list of stations, got {outputs!r}") from None
    if not items:
        raise ModelError(f"{model.name}: outputs needs at least one station")
    for s in items:
        check_param(model.name, "output station", s, Integer(1, model.layout.n_nodes))
    return [int(s) for s in items]


def _basis(M, K, n_modes, cutoff, loads, static_correction):
    """Mass-orthonormal reduction basis: lowest modes of (K, M) plus static shapes of ``loads``;
    returns (T, eigenvalues of the reduced (K, M))."""
    ndof = M.shape[0]
    try:
        lam, Phi = sla.eigh(K, M)
    except (np.linalg.LinAlgError, ValueError):
        raise ModelError("the mass matrix is not positive definite (a massless DOF): the transient run-up "
                         "needs every DOF to carry mass") from None
    lam = np.maximum(lam, 0.0)
    if n_modes is None:
        n_modes = max(4, int(np.sum(np.sqrt(lam) <= cutoff)))
    n_modes = min(n_modes, ndof)
    T = Phi[:, :n_modes]
    if static_correction and n_modes < ndof:
        try:
            R = sla.cho_solve(sla.cho_factor(K), loads)
        except np.linalg.LinAlgError:
            R = None                                            # a free rotor: no static correction
        if R is not None:
            R = R - T @ (T.T @ (M @ R))
            g = R.T @ M @ R
            w, V = np.linalg.eigh(0.5 * (g + g.T))
            ok = w > 1e-10 * max(w.max(), 1e-300)
            if ok.any():
                R = R @ (V[:, ok] / np.sqrt(w[ok]))
                T = np.hstack([T, R])
    Kr = T.T @ K @ T
    Mr = T.T @ M @ T
    lr, Psi = sla.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    return T @ Psi, np.maximum(lr, 0.0)


def _checked_run(model, name, speeds, duration, acceleration, modes, steps_per_rev, initial, dt, steps):
    """The run's options checked (a named ModelError for each), as ``(start, stop, duration)``."""
    if getattr(getattr(model, "layout", None), "kind", "") != "rotor":
        raise ModelError(f"{name!r}: a run-up needs a rotor with two bending planes (planes = 2)")
    try:
        w0, w1 = speeds
    except (TypeError, ValueError):
        raise ModelError(f"{name}: speeds must be (start, stop) in rad/s, got {speeds!r}") from None
    w0 = _finite_number(w0, f"{name}: the start speed", "rad/s")
    w1 = _finite_number(w1, f"{name}: the stop speed", "rad/s")
    if w0 < 0 or w1 < 0:
        raise ModelError(f"{name}: speeds must be non-negative (rad/s), got ({w0}, {w1})")
    if (duration is None) == (acceleration is None):
        raise ModelError(f"{name}: give either duration (s) or acceleration (rad/s^2), not both or neither")
    if duration is not None:
        T = _finite_number(duration, f"{name}: duration", "s")
        if T <= 0:
            raise ModelError(f"{name}: duration must be positive (s), got {T!r}")
    else:
        a = _finite_number(acceleration, f"{name}: acceleration", "rad/s^2")
        if a <= 0:
            raise ModelError(f"{name}: acceleration must be positive (rad/s^2, its sign follows the speeds), "
                             f"got {a!r}")
        if w0 == w1:
            raise ModelError(f"{name}: at a constant speed give the duration, not an acceleration")
        T = abs(w1 - w0) / a
    if max(w0, w1) <= 0:
        raise ModelError(f"{name}: the rotor never turns (both speeds 0): an unbalance exerts no force")
    if modes is not None:
        check_param(name, "modes", modes, Integer(1, None))
    check_param(name, "steps_per_rev", steps_per_rev, Integer(8, None))
    if initial not in ("steady", "rest"):
        raise ModelError(f"{name}: initial must be 'steady' or 'rest', got {initial!r}")
    if dt is not None and steps is not None:
        raise ModelError(f"{name}: give dt or steps, not both")
    if steps is not None:
        check_param(name, "steps", steps, Integer(1, None))
    if dt is not None:
        dt = _finite_number(dt, f"{name}: dt", "s")
        if dt <= 0:
            raise ModelError(f"{name}: dt must be positive (s), got {dt!r}")
    return w0, w1, T


def _newmark(q, qd, qdd, lam, Cr, Gr, h, n, force, theta, speed, const, report):
    """Newmark's average-acceleration steps of the reduced equations (``C + Omega G`` at the new step):
    the reduced displacements at every step, ``(n + 1, len(q))``."""
    nr = q.size
    beta, gamma = 0.25, 0.5
    H = np.empty((n + 1, nr))
    H[0] = q
    A0 = np.eye(nr) + gamma * h * Cr + np.diag(beta * h * h * lam)
    Gh = gamma * h * Gr
    if const:
        lu = sla.lu_factor(A0 + speed[0] * Gh)
    chunk = 4096
    tick = max(1, n // 100)
    for k0 in range(1, n + 1, chunk):
        k1 = min(n + 1, k0 + chunk)
        Fk = force(theta[k0:k1], speed[k0:k1])
        for i, k in enumerate(range(k0, k1)):
            om = speed[k]
            xp = q + h * qd + (0.5 - beta) * h * h * qdd
            vp = qd + (1 - gamma) * h * qdd
            rhs = Fk[i] - Cr @ vp - om * (Gr @ vp) - lam * xp
            qdd = sla.lu_solve(lu, rhs) if const else np.linalg.solve(A0 + om * Gh, rhs)
            q = xp + beta * h * h * qdd
            qd = vp + gamma * h * qdd
            H[k] = q
            if k % tick == 0:
                report("integrate", k / n)
    return H


def transient_run_up(model, speeds, unbalance, outputs, *, duration: float | None = None,
                     acceleration: float | None = None, modes: int | None = None, static_correction: bool = True,
                     steps_per_rev: int = 128, dt: float | None = None, steps: int | None = None,
                     initial: str = "steady", values=None, progress=None) -> TransientRunUp:
    r"""Run the rotor from ``speeds[0]`` to ``speeds[1]`` at constant acceleration with an unbalance,
    integrating the response in time (see the module docstring).

    Parameters
    ----------
    model : Rotor
        A rotor with two bending planes.
    speeds : (float, float)
        Start and stop speeds [rad/s], non-negative; stop below start is a coast-down, equal is a
        constant speed (then give ``duration``).
    unbalance : (station, mass_kg, radius_m[, phase_rad]) or list of them
        Each unbalance: its 1-based station, mass [kg], radius [m] and angle from the keyphasor
        mark [rad] (default 0).
    outputs : int or sequence of int
        Stations whose x and y displacements are recorded.
    duration : float, optional
        Length of the run [s], positive.  Give it or ``acceleration``.
    acceleration : float, optional
        Rate of the speed change :math:`|\dot\Omega|` [rad/s^2], positive (its sign follows the
        speeds).
    modes : int, optional
        Undamped modes kept (default: those up to four times the top speed, at least four).
    static_correction : bool, optional
        Add the static shapes of the unbalance forces to the basis (if ``K`` is nonsingular).
    steps_per_rev : int, optional
        Steps per revolution at the top speed (default 128); the step also resolves every kept
        mode (16 steps per period).
    dt : float, optional
        Time step [s], instead of the default rule.
    steps : int, optional
        Number of steps over the run, instead of the default rule.
    initial : {"steady", "rest"}, optional
        Start from the steady response at the start speed (with the acceleration's tangential
        force), or from rest.
    values : mapping or array_like, optional
        Parameter values (see :meth:`~mutext.rotor.assembly.Structure.values`).
    progress : callable, optional
        Called as ``progress(stage, fraction)`` with stage ``"reduce"``, ``"integrate"``,
        ``"steady"``.

    Examples
    --------
    >>> from mutext.examples.friswell import rotor
    >>> from mutext.rotor.transient import transient_run_up
    >>> r = transient_run_up(rotor(), (0.0, 100.0), (3, 1e-3, 0.1), 3, duration=1.0)
    >>> r.x.shape[1], round(float(r.speed[-1]), 6)
    (1, 100.0)
    """
    name = getattr(model, "name", repr(model))
    w0, w1, T = _checked_run(model, name, speeds, duration, acceleration, modes, steps_per_rev, initial, dt, steps)
    if dt is not None:
        dt = float(dt)
    alpha = (w1 - w0) / T
    wmax = max(w0, w1)
    ub = _unbalance_list(model, unbalance)
    outs = _outputs(model, outputs)
    v = _values(model, values)
    report = progress if callable(progress) else (lambda stage, fraction: None)

    lay = model.layout
    with blas_single_thread():
        report("reduce", 0.0)
        M, C, K, G = model.matrices(v)
        loads = np.zeros((model.ndof, 2 * len({s for s, _, _ in ub})))
        for i, s in enumerate(sorted({s for s, _, _ in ub})):
            loads[lay.dof(s, "u"), 2 * i] = 1.0
            loads[lay.dof(s, "v"), 2 * i + 1] = 1.0
        Tb, lam = _basis(M, K, modes, 4.0 * wmax, loads, static_correction)
        Cr, Gr = Tb.T @ C @ Tb, Tb.T @ G @ Tb
        report("reduce", 1.0)

        # ------------------------------------------------------------- time step
        if steps is not None:
            n = int(steps)
        else:
            if dt is None:
                wtop = np.sqrt(lam.max()) if lam.size else 0.0
                dt = min(2 * np.pi / (steps_per_rev * wmax),
                         2 * np.pi / (_STEPS_PER_MODE * wtop) if wtop > 0 else np.inf)
            n = max(1, int(np.ceil(T / dt - 1e-9)))
        if n > MAX_STEPS:
            raise ModelError(f"{name}: {n} steps (more than {MAX_STEPS}): shorten the run, keep fewer modes "
                             "(modes=) or give a larger dt")
        h = T / n
        t = np.linspace(0.0, T, n + 1)
        speed = w0 + alpha * t
        theta = w0 * t + 0.5 * alpha * t * t

        nr = Tb.shape[1]
        Fu = [(u, p, Tb[lay.dof(s, "u")], Tb[lay.dof(s, "v")]) for s, u, p in ub]

        def force(th, om):                                      # reduced force at angles th, speeds om
            f = np.zeros((th.size, nr))
            for u, p, tu, tv in Fu:
                c, s = np.cos(th + p), np.sin(th + p)
                fx = u * (om * om * c + alpha * s)
                fy = u * (om * om * s - alpha * c)
                f += fx[:, None] * tu[None] + fy[:, None] * tv[None]
            return f

        # ------------------------------------------------------------- initial state
        if initial == "steady" and w0 > 0:
            Fc = np.zeros(nr, complex)
            for u, p, tu, tv in Fu:
                A = u * (w0 * w0 - 1j * alpha) * np.exp(1j * p)
                Fc += A * tu - 1j * A * tv
            Z = np.diag(lam) - w0 * w0 * np.eye(nr) + 1j * w0 * (Cr + w0 * Gr)
            try:
                Q = np.linalg.solve(Z, Fc)
            except np.linalg.LinAlgError:
                raise ModelError(f"{name}: the start speed {w0} rad/s is an undamped critical speed: start "
                                 "from rest (initial='rest') or elsewhere") from None
            q, qd = Q.real.copy(), (1j * w0 * Q).real
        else:
            q, qd = np.zeros(nr), np.zeros(nr)
        f0 = force(theta[:1], speed[:1])[0]
        qdd = f0 - (Cr + w0 * Gr) @ qd - lam * q

        H = _newmark(q, qd, qdd, lam, Cr, Gr, T / n, n, force, theta, speed, alpha == 0.0, report)
        if not np.all(np.isfinite(H[-1])):
            raise ModelError(f"{name}: the run-up response is not finite (an unstable rotor at these speeds?)")
        iu = [lay.dof(s, "u") for s in outs]
        iv = [lay.dof(s, "v") for s in outs]
        x, y = H @ Tb[iu].T, H @ Tb[iv].T

        report("steady", 0.0)
        lo, hi = min(w0, w1), wmax
        grid = np.linspace(max(lo, 1e-3 * hi), hi, 801) if hi > lo else np.array([hi])
        steady = unbalance_response(model, [s for s, _, _ in ub], [u for _, u, _ in ub], grid, outs,
                                    phase=[p for _, _, p in ub], values=v)
        report("steady", 1.0)
    return TransientRunUp(t, speed, theta, outs, x, y, float(alpha), ub, steady,
                          np.sqrt(lam) / (2 * np.pi), float(h), model.name)
