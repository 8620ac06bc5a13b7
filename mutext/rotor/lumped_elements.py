r"""Springs and dampers between the nodes of a lumped chain or to ground: :class:`Spring`, :class:`Damper`;
a rational impedance to ground at one mass: :class:`Impedance`.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from ..errors import ModelError
from .element import Element, _positive, _translational

__all__ = ["Spring", "Damper", "Impedance", "impedances"]


class _TwoNodeTranslational(Element):
    """Linear spring or dashpot on the translational DOFs between a node and another node or ground.

    In the ``"rotor"`` layout the element acts in x (``kxx``) and y (``kyy``,
    default the same parameter); in the other layouts only on ``u``/``x``.
    """
    MATRIX = "stiffness"
    XX, YY = "k", "kyy"

    def __init__(self, node: int, other: int | None = None, *, name: str | None = None, **vals):
        nodes = (node,) if other is None else (node, other)
        if other is not None and other == node:
            raise ModelError(f"{name or self.KIND}: connects node {node} to itself")
        super().__init__(nodes, name, **vals)
        _positive(self, *self.FIELDS, allow_zero=True)

    def dofs(self, layout):
        return [d for n in self.nodes for d in _translational(self, layout, n)]

    def _matrix(self, p, layout):
        kx = self.sym(p, self.XX)
        ky = self.sym(p, self.YY) if self.has(self.YY) else kx
        per = 2 if layout.kind == "rotor" else 1
        vals = [kx, ky][:per]
        n = len(self.nodes)
        Km = ca.SX(n * per, n * per)
        for j, k in enumerate(vals):
            Km[j, j] = k
            if n == 2:
                Km[per + j, per + j] = k
                Km[j, per + j] = -k
                Km[per + j, j] = -k
        return Km


class Spring(_TwoNodeTranslational):
    """Linear spring [N/m] from ``node`` to ``other`` (or to ground if ``other is None``).

    Parameters
    ----------
    node : int
        The first node (1-based: a mass of a lumped chain, a station of a rotor).
    other : int, optional
        The second node (not ``node``); None connects ``node`` to ground.
    k : float or Param
        Stiffness [N/m] (>= 0): a number, or a :class:`mutext.rotor.element.Param`
        shared with other elements.  In the ``"rotor"`` layout the stiffness in x.
    kyy : float or Param, optional
        Stiffness in y [N/m] (``"rotor"`` layout only; default ``k``).
    name : str, optional
        The element's name (default: its kind and first node, e.g. ``"spring2"``).
    """
    KIND = "spring"
    FIELDS = {"k": ("N/m", "stiffness"), "kyy": ("N/m", "stiffness in y")}

    def __init__(self, node: int, other: int | None = None, *, k, kyy=None, name: str | None = None):
        super().__init__(node, other, name=name, k=k, kyy=kyy)

    def stiffness_matrix(self, p, layout):
        return self._matrix(p, layout)


class Damper(_TwoNodeTranslational):
    """Linear viscous damper [N s/m] from ``node`` to ``other`` (or to ground).

    Parameters
    ----------
    node : int
        The first node (1-based: a mass of a lumped chain, a station of a rotor).
    other : int, optional
        The second node (not ``node``); None connects ``node`` to ground.
    c : float or Param
        Damping coefficient [N s/m] (>= 0): a number, or a
        :class:`mutext.rotor.element.Param` shared with other elements.  In the
        ``"rotor"`` layout the damping in x.
    cyy : float or Param, optional
        Damping in y [N s/m] (``"rotor"`` layout only; default ``c``).
    name : str, optional
        The element's name (default: its kind and first node, e.g. ``"damper2"``).
    """
    KIND = "damper"
    FIELDS = {"c": ("N s/m", "damping"), "cyy": ("N s/m", "damping in y")}
    XX, YY = "c", "cyy"

    def __init__(self, node: int, other: int | None = None, *, c, cyy=None, name: str | None = None):
        super().__init__(node, other, name=name, c=c, cyy=cyy)

    def damping_matrix(self, p, layout):
        return self._matrix(p, layout)


class Impedance(Element):
    r"""A grounded rational impedance at one mass of a lumped chain: a dynamic stiffness that adds states.

    The element applies the force :math:`-K(s)\,x_i` to its mass :math:`i`, with

    .. math::
        K(s) = \frac{b_0 s^p + b_1 s^{p-1} + \dots + b_p}{a_0 s^n + a_1 s^{n-1} + \dots + a_n},
        \qquad p \le n,\ a_0 \ne 0,

    coefficients in descending powers of :math:`s` (SI: the ratio is in N/m).
    It is what a controller of model-based identification (:mod:`mutext.mbi`)
    stands for when it is not a mass, a damper and a spring: a frequency-dependent
    dynamic stiffness :math:`K(j\omega)` added to the mass's diagonal term of
    :math:`Z(\omega) = K - \omega^2 M + j\omega C`.  It contributes nothing to the
    constant matrices :math:`M, C, K` (:meth:`mass_matrix` and the others return
    None); the frequency response (:func:`mutext.rotor.analysis.frf`) adds
    :meth:`response` to the dynamic stiffness, and the state space
    (:func:`mutext.rotor.analysis.state_space`) closes the loop
    :math:`f = -K(s)x_i` with :meth:`realisation`, whose states are appended.
    Analyses that need the constant matrices alone (undamped modes, tuning)
    refuse a model that holds one.

    Parameters
    ----------
    node : int
        The mass (1-based).
    numerator, denominator : sequence of float
        Coefficients :math:`b_0..b_p` and :math:`a_0..a_n` (finite; proper: :math:`p \le n`;
        :math:`a_0 \ne 0`; leading zeros of the numerator are dropped).
    name : str, optional

    Raises
    ------
    ModelError
        Coefficients that are not finite numbers, an empty or all-zero polynomial, a
        leading denominator coefficient of zero, an improper ratio (:math:`p > n`: no
        state-space block realises it), a pole on the imaginary axis (the response
        is infinite at a real frequency).
    """
    KIND = "impedance"
    FIELDS: dict = {}

    def __init__(self, node: int, numerator, denominator, *, name: str | None = None):
        super().__init__((node,), name)
        self.numerator = self._coefficients(numerator, "numerator")
        self.denominator = self._coefficients(denominator, "denominator")
        if self.denominator[0] == 0:
            raise ModelError(f"{self.name}.denominator: the leading coefficient (of the highest power of s) "
                             "is 0; drop it or give the intended degree")
        nz = np.flatnonzero(self.numerator)
        if nz.size == 0:
            raise ModelError(f"{self.name}.numerator: all coefficients are 0 (an impedance of zero is no element)")
        self.numerator = self.numerator[nz[0]:]
        if self.numerator.size > self.denominator.size:
            raise ModelError(f"{self.name}.numerator: degree {self.numerator.size - 1} exceeds the denominator's "
                             f"{self.denominator.size - 1}; an improper impedance has no state-space "
                             "realisation (write mass, damper and spring as [[mass]], [[damper]], [[spring]])")
        poles = np.roots(self.denominator) if self.denominator.size > 1 else np.zeros(0)
        scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
        axis = poles[np.abs(poles.real) <= 1e-12 * scale]
        if axis.size:
            raise ModelError(f"{self.name}.denominator: a pole on the imaginary axis at s = {axis[0]:.6g}; the "
                             "impedance would be infinite at a real frequency")

    def _coefficients(self, c, field):
        where = f"{self.name}.{field}"
        if isinstance(c, (str, bytes)) or not hasattr(c, "__len__"):
            raise ModelError(f"{where}: expected a list of coefficients in descending powers of s, got {c!r}")
        if len(c) == 0:
            raise ModelError(f"{where}: the list of coefficients is empty")
        for k, x in enumerate(c):
            if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(float(x)):
                raise ModelError(f"{where}[{k}]: expected a finite number, got {x!r}")
        return np.asarray(c, dtype=float)

    def __repr__(self):
        return (f"Impedance({self.name}: node {self.nodes[0]}, numerator {self.numerator.tolist()}, "
                f"denominator {self.denominator.tolist()})")

    def dofs(self, layout):
        return _translational(self, layout, self.nodes[0])[:1]

    def check(self, layout):
        super().check(layout)
        if layout.kind != "lumped":
            raise ModelError(f"{self.name}: an impedance element belongs to a lumped chain (layout "
                             f"'{layout.kind}')")

    @property
    def order(self) -> int:
        """Number of states the element adds (the denominator's degree)."""
        return self.denominator.size - 1

    def response(self, omega) -> np.ndarray:
        r""":math:`K(j\omega)` [N/m].

        Parameters
        ----------
        omega : array_like
            Frequencies [rad/s].

        Returns
        -------
        ndarray of complex
        """
        s = 1j * np.asarray(omega, float)
        return np.polyval(self.numerator, s) / np.polyval(self.denominator, s)

    def realisation(self):
        r"""``(A, B, C, D)`` of :math:`K(s)`: input the mass's displacement, output the force.

        The controllable canonical form (:func:`scipy.signal.tf2ss`), balanced
        (:func:`scipy.linalg.matrix_balance`) so that high powers of :math:`s`
        do not set the scale of the states."""
        import scipy.linalg as sla
        import scipy.signal as ss
        A, B, C, D = ss.tf2ss(self.numerator, self.denominator)
        if A.size:
            _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
            A = A * (1 / sc)[:, None] * sc[None, :]
            B = B / sc[:, None]
            C = C * sc[None, :]
        return A, B, C, D


def impedances(model) -> list:
    """The :class:`Impedance` elements of a model.

    Parameters
    ----------
    model : mutext.rotor.assembly.Structure
        Any assembled model (a rotor holds none).

    Returns
    -------
    list of Impedance
        Empty for a model without.
    """
    return [el for el in getattr(model, "elements", []) if isinstance(el, Impedance)]


def add_impedances(Z, model, omega):
    r"""Add each impedance element's :math:`K(j\omega)` to a batched dynamic stiffness, in place.

    The one place where a rational element (not part of M, C, K) enters
    :math:`Z(\omega) = K - \omega^2 M + j\omega D`: the model's own FRF, the
    diagnosis's receptance and its structure-wide hypotheses all go through it.

    Parameters
    ----------
    Z : (nfreq, n, n) complex ndarray
        Dynamic stiffness at the frequencies ``omega``; changed in place.
    model : Structure
        The model whose :class:`Impedance` elements are added (none: ``Z`` is unchanged).
    omega : (nfreq,) array_like
        Frequencies [rad/s] of ``Z``'s first axis.

    Returns
    -------
    ndarray
        ``Z``.
    """
    for el in impedances(model):
        d = el.dofs(model.layout)[0]
        Z[:, d, d] += el.response(omega)
    return Z
