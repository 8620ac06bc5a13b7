"""What every kind of effect shares: the hypothesis, *kind at location*, with a size to fit."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Param:
    """One parameter of a k-parameter hypothesis: name, unit, bounds and typical size (SI).

    Attributes
    ----------
    name : str
        Name of the parameter (e.g. ``"mass"``).
    unit : str
        Its unit.
    lower, upper : float
        Bounds of the fit (SI).
    scale : float
        Typical size (SI), the scale of the fit's variable.
    """
    name: str
    unit: str
    lower: float
    upper: float
    scale: float


@dataclass
class Hypothesis:
    """One candidate cause: a *kind* at a *location*, with a size to fit.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    station : int or None
        1-based station (rotor) or mass index (lumped chain), as numbered in the model file.
    element : str or None
        The model element changed (``"k1"``, ``"bearing2"``) or the name of the added one.
    description : str
        Plain-language description, e.g. ``"grounded spring added at m2"``.
    unit : str
        Unit of the size (``N/m``, ``kg``, ``N s/m``, ``1`` for a depth ratio or a gain).
    added : bool
        True when the hypothesis adds an element (size 0 = no effect), False
        when it changes an existing value (the size is the change).
    lower, upper : float
        Bounds of the size (SI).
    scale : float
        Typical size (for the scan and the reporting of relative sizes).
    dofs : list of int
        DOFs U touched (0-based).
    pattern : ndarray
        The real matrix S on U (structural hypotheses).
    order : int
        0 stiffness, 1 damping, 2 mass (D = S, j w S, -w^2 S).
    gain : tuple or None
        Effects on the measurement chain (:mod:`mutext.diagnose.faults.channel`):
        ``("sensor", out_dof)``, ``("exciter", input column spec)``, ``("channel", FRF)`` or
        ``("delay", out_dof)``; ``("sensor_mass", None)``: a mass that moves with the sensor.
    glob : str or None
        A change of the whole structure, evaluated by a full solve
        (:mod:`mutext.diagnose.faults.structure`): ``"frequency_scale"``, ``"damping_scale"``.
    parameter : str or None
        Parameter of the *extended* model that holds the size (for the full fit).
    nominal : float
        Value of the existing parameter (changes) or 0 (added elements); the
        new value is ``nominal + size`` (gains: ``nominal * size``).
    params : tuple of Param
        A hypothesis with k > 1 parameters (e.g. a tuned-mass absorber's mass,
        spring and damper): their names, units, bounds and scales.  Its size is
        then a vector of k values in this order; ``lower``, ``upper``, ``scale``
        and ``unit`` describe the first.  Empty for one-parameter hypotheses.
    change : callable or None
        ``change(theta, w)``: the change of dynamic stiffness on ``dofs`` at
        the parameter vector ``theta``, ``(w.size, |U|, |U|)`` complex (k > 1).
    starts : list of ndarray
        Starting parameter vectors for the fit (k > 1): the best by the
        residual starts a bounded least-squares fit.
    nested : tuple of (kind, element)
        One-parameter hypotheses this one reduces to in a limit of its
        parameters (a pedestal of no mass is a softer spring): with several
        effects, the simpler reading replaces it when the data cannot tell
        them apart (:func:`mutext.diagnose._decision._simplify`).
    crack : callable or None
        Depth ratio -> stiffness change on ``dofs`` (crack hypotheses).
    run : tuple of str
        The springs of a run, in chain order (distributed kinds).
    """
    kind: str
    station: int | None
    element: str | None
    description: str
    unit: str
    added: bool
    lower: float
    upper: float
    scale: float
    dofs: list = field(default_factory=list)
    pattern: np.ndarray | None = None
    order: int = 0
    gain: tuple | None = None
    parameter: str | None = None
    nominal: float = 0.0
    crack: object = None          # callable depth -> dK on dofs (crack hypotheses)
    glob: str | None = None       # a change of the whole structure (:mod:`mutext.diagnose.faults.structure`)
    params: tuple = ()            # k > 1 parameters (Param each); empty for a scalar size
    change: object = None         # callable (theta vector, w) -> D(w) on dofs (k > 1)
    starts: list = field(default_factory=list, repr=False)
    run: tuple = ()               # the elements of a run (distributed kinds), in order
    nested: tuple = ()            # (kind, element) of the one-parameter hypotheses it reduces to (k > 1)

    @property
    def n_params(self) -> int:
        """Number of parameters fitted (k)."""
        return max(1, len(self.params))

    @property
    def label(self) -> str:
        return f"{self.kind} at {self.station}" + (f" ({self.element})" if self.element else "")


def local_change(h: Hypothesis, theta: float, w) -> np.ndarray:
    """The change of dynamic stiffness of a local hypothesis on its DOFs at size ``theta``, per frequency:
    ``(w.size, |U|, |U|)`` (a crack's exact stiffness change, else ``theta (1, j w, -w^2)[order] S``).

    Parameters
    ----------
    h : Hypothesis
        A local hypothesis (a pattern, a crack or a k-parameter change).
    theta : float or ndarray
        Its size (a vector for k > 1 parameters).
    w : array_like
        Frequencies [rad/s].
    """
    w = np.asarray(w, float)
    if h.change is not None:
        return np.asarray(h.change(np.asarray(theta, float), w), complex)
    if h.crack is not None:
        dK = np.asarray(h.crack(theta))
        return np.broadcast_to(dK, (w.size,) + dK.shape).astype(complex)
    s = (np.ones_like(w), 1j * w, -w * w)[h.order]
    return (theta * s)[:, None, None] * h.pattern[None]


def model_poles(model, speed: float = 0.0):
    r"""Undamped natural frequencies [Hz] and damping ratios of the model's oscillating poles.

    From :meth:`modes` (M, C, K) when it can; a model holding a rational
    impedance element (a model extended by model-based identification) has
    states outside M, C, K, and its poles come from the state space instead:
    for each pole :math:`p` with :math:`\Im p > 0`, :math:`f = |p|/2\pi` and
    :math:`\zeta = -\Re p/|p|`.

    Parameters
    ----------
    model : mutext.rotor.assembly.Structure or Rotor
        The engineering model.
    speed : float, optional
        Spin speed [rad/s] (rotors).

    Returns
    -------
    f : ndarray
        Undamped natural frequencies [Hz].
    zeta : ndarray
        Damping ratios.
    """
    from ...rotor.lumped_elements import impedances
    if not impedances(model):
        md = model.modes(speed=speed)
        return np.abs(md.eigenvalues) / (2 * np.pi), np.asarray(md.damping_ratio, float)
    p = np.linalg.eigvals(np.asarray(model.state_space().A, float))
    p = p[p.imag > 0]
    p = p[np.argsort(np.abs(p))]
    return np.abs(p) / (2 * np.pi), -p.real / np.abs(p)
