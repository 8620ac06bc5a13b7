r"""Breathing laws of a crack that turns with the shaft, and their Fourier series.

:func:`open_fraction` is the fraction of the open crack's stiffness loss that
is active at an angle (Mayes-Davies [MD84]_, Gasch [Ga93]_, always open,
closed); :func:`rotating_frame_stiffness` and :func:`fixed_frame_stiffness`
apply it to a Jeffcott shaft; :func:`breathing_weights` and
:func:`breathing_fourier` give the weights of a finite-element crack over one
revolution (:mod:`mutext.rotor.periodic`).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ...errors import ModelError
from ._common import _symbolic

_MODELS = ("mayes", "gasch", "gaping", "open", "notch", "closed")


def open_fraction(psi, model: str = "mayes"):
    r"""Fraction :math:`f(\psi)\in[0, 1]` of the crack stiffness loss that is active.

    :math:`\psi` is the angle between the crack normal :math:`\xi` (pointing
    from the shaft axis to the crack mouth) and the direction in which the
    shaft is bent (the static deflection under weight dominance).  At
    :math:`\psi = 0` the cracked side is on the tension side and the crack is
    fully open; at :math:`\psi = \pi` it is closed.

    * ``"mayes"`` (Mayes & Davies [MD84]_):
      :math:`f = \tfrac12(1+\cos\psi)`, a smooth transition.
    * ``"gasch"`` (switching hinge, Gasch [Ga93]_): :math:`f = 1` for
      :math:`\cos\psi \ge 0` (open during the half turn in which the crack
      is in tension), :math:`f = 0` otherwise.
    * ``"gaping"`` (aliases ``"open"``, ``"notch"``): :math:`f = 1` (always
      open: a notch whose faces never touch, an asymmetric shaft).
    * ``"closed"``: :math:`f = 0` (healthy).

    Works on floats, numpy arrays and CasADi expressions.

    Parameters
    ----------
    psi : float, ndarray or casadi expression
        Angle [rad] between the crack normal and the direction of the bending deflection.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    if model not in _MODELS:
        raise ModelError(f"crack model must be one of {_MODELS}, got {model!r}")
    sym = _symbolic(psi)
    cos = ca.cos if sym else np.cos
    if model == "mayes":
        return 0.5 * (1.0 + cos(psi))
    if model == "gasch":
        return ca.if_else(cos(psi) >= 0, 1.0, 0.0) if sym else np.where(np.cos(psi) >= 0, 1.0, 0.0)
    one = 0.0 if model == "closed" else 1.0
    return one + 0.0 * psi


def rotating_frame_stiffness(k0, dk_xi, dk_eta, psi, model: str = "mayes"):
    r"""Shaft stiffnesses :math:`(k_\xi, k_\eta)` in the rotating crack frame, in N/m.

    .. math::
        k_\xi = k_0 - f(\psi)\,\Delta k_\xi,\qquad
        k_\eta = k_0 - f(\psi)\,\Delta k_\eta,

    with :math:`f` from :func:`open_fraction`.  For ``model="mayes"`` this is
    the Mayes-Davies law :math:`k = k_0 - \tfrac{\Delta k}{2}(1+\cos\psi)`;
    for ``"gasch"`` the stiffness switches between :math:`k_0` (closed) and
    :math:`k_0 - \Delta k` (open).  :math:`\Delta k_\xi` is the loss of the
    fully open crack for bending across the crack edge; :math:`\Delta k_\eta`
    (bending in the plane of the crack edge, from the compliance
    :math:`c_{44}`) is often taken as zero ([Ga93]_), which holds for shallow
    cracks only: for the rig's crack (:math:`a/D = 0.4`) it is about 0.44
    :math:`\Delta k_\xi` (see :class:`Crack`).

    Parameters
    ----------
    k0 : float
        Stiffness of the healthy shaft [N/m].
    dk_xi : float
        Stiffness loss of the fully open crack for bending across the crack edge [N/m].
    dk_eta : float
        Stiffness loss for bending in the plane of the crack edge [N/m].

    psi : float or ndarray
        Angle [rad] between the crack normal and the bending direction.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    f = open_fraction(psi, model)
    return k0 - f * dk_xi, k0 - f * dk_eta


def fixed_frame_stiffness(k0, dk_xi, dk_eta, theta, psi, model: str = "mayes"):
    r"""2x2 shaft stiffness in the fixed frame :math:`(x, y)`, in N/m.

    The crack frame :math:`(\xi, \eta)` rotates with the shaft; :math:`\xi`
    makes the angle :math:`\theta` (rad) with :math:`x`, so
    :math:`[\xi, \eta]^T = R(\theta)[x, y]^T` with
    :math:`R = [[\cos\theta, \sin\theta], [-\sin\theta, \cos\theta]]` and

    .. math::
        K(\theta,\psi) = R^T \mathrm{diag}(k_\xi, k_\eta) R
        = k_0 I - f(\psi)\left[\frac{\Delta k_\xi+\Delta k_\eta}{2} I
        + \frac{\Delta k_\xi-\Delta k_\eta}{2}
        \begin{bmatrix}\cos 2\theta & \sin 2\theta\\ \sin 2\theta & -\cos 2\theta
        \end{bmatrix}\right].

    The :math:`2\theta` terms are the parametric excitation at twice the
    running speed; multiplied by the :math:`\psi`-dependence of
    :math:`f` they produce the 1X, 2X and 3X components of a breathing
    crack.  Returns a numpy (2, 2) array (or an array of shape (2, 2, n)
    for arrays of angles).

    Parameters
    ----------
    k0 : float
        Stiffness of the healthy shaft [N/m].
    dk_xi : float
        Stiffness loss of the fully open crack for bending across the crack edge [N/m].
    dk_eta : float
        Stiffness loss for bending in the plane of the crack edge [N/m].

    theta : float or ndarray
        Angle [rad] of the crack normal from x (the shaft's rotation angle).
    psi : float or ndarray
        Angle [rad] between the crack normal and the bending direction.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    f = open_fraction(psi, model)
    s = 0.5 * (dk_xi + dk_eta)
    d = 0.5 * (dk_xi - dk_eta)
    c2, s2 = np.cos(2 * np.asarray(theta)), np.sin(2 * np.asarray(theta))
    return np.array([[k0 - f * (s + d * c2), -f * d * s2],
                     [-f * d * s2, k0 - f * (s - d * c2)]])


#: Breathing laws a crack in a model file may declare (``breathing = ...``).  ``"gaping"``: a
#: notch whose faces never touch (a wire-EDM slot wider than the faces move), always open and
#: turning with the shaft, so its stiffness varies at twice the running speed only; ``"mayes"``
#: and ``"gasch"``: a crack that opens and closes under the shaft's weight (once per revolution).
BREATHING_LAWS = ("gaping", "mayes", "gasch")

#: Other names accepted for a law: ``"open"`` (the name used before ``"gaping"``) and ``"notch"``.
BREATHING_ALIASES = {"open": "gaping", "notch": "gaping"}


def breathing_law(name) -> str:
    """The documented name of breathing law ``name`` (an alias resolved), or a :class:`ModelError`.

    Parameters
    ----------
    name : str
        A law of :data:`BREATHING_LAWS` or an alias of :data:`BREATHING_ALIASES`.

    Examples
    --------
    >>> from mutext.rotor.crack import breathing_law
    >>> breathing_law("mayes"), breathing_law("notch")
    ('mayes', 'gaping')
    """
    if isinstance(name, str):
        name = BREATHING_ALIASES.get(name, name)
        if name in BREATHING_LAWS:
            return name
    raise ModelError(f"breathing law must be one of {', '.join(BREATHING_LAWS)} (or the aliases "
                     f"{', '.join(BREATHING_ALIASES)}), got {name!r}")


def breathing_weights(theta, law: str):
    r"""Weights :math:`(g_{xx}, g_{yy}, g_{xy})` of a turning crack at shaft angle ``theta``.

    A crack whose normal makes the angle :math:`\theta` with :math:`x` adds, in
    the fixed frame,

    .. math::
        \Delta K(\theta) = f(\psi)\left[\cos^2\theta\,A_{xx} + \sin^2\theta\,A_{yy}
        + \sin\theta\cos\theta\,A_{xy}\right],\qquad \psi = \theta + \pi/2,

    where :math:`A_{xx}, A_{yy}, A_{xy}` are the changes of the fully open
    crack facing :math:`x`, :math:`y` and the coupling (see
    :meth:`Crack.directional_deltas`), and :math:`f` is the open fraction of
    ``law`` (:func:`open_fraction`) under weight dominance (:math:`y` up: the
    crack is open when its normal points down, :math:`\theta = -\pi/2`).
    Returns the three weights :math:`f\cos^2\theta`, :math:`f\sin^2\theta`,
    :math:`f\sin\theta\cos\theta` (arrays shaped like ``theta``).

    Parameters
    ----------
    theta : float or ndarray
        Shaft angle [rad] (the angle of the crack normal from x).
    law : str
        A breathing law (:func:`breathing_law`).
    """
    law = breathing_law(law)
    th = np.asarray(theta, dtype=float)
    f = open_fraction(th + np.pi / 2.0, law)
    c, s = np.cos(th), np.sin(th)
    return f * c * c, f * s * s, f * s * c


def breathing_fourier(law: str, n_terms: int = 16, *, samples: int = 4096) -> np.ndarray:
    r"""Fourier coefficients of :func:`breathing_weights` over one revolution.

    Returns ``c`` of shape ``(2 n_terms + 1, 3)``: row ``n_terms + m`` holds
    :math:`c_m = \frac{1}{2\pi}\int_0^{2\pi} g(\theta) e^{-jm\theta}\,d\theta` for
    the three weights, so that :math:`g(\theta) = \sum_m c_m e^{jm\theta}`.
    The Mayes law and the open crack are trigonometric polynomials (orders 3
    and 2), so their coefficients are exact; the Gasch law switches at
    :math:`\theta = 0, \pi` and its coefficients decay like :math:`1/m`
    (trapezoidal rule with the jumps on samples: error :math:`O(\text{samples}^{-2})`).

    Parameters
    ----------
    law : str
        A breathing law (:func:`breathing_law`).
    n_terms : int, optional
        Highest order m kept.
    samples : int, optional
        Samples over the revolution of the quadrature.
    """
    law = breathing_law(law)
    if isinstance(n_terms, bool) or not isinstance(n_terms, (int, np.integer)) or n_terms < 0:
        raise ModelError(f"n_terms must be a non-negative integer, got {n_terms!r}")
    samples = max(int(samples), 4 * n_terms + 8)
    samples += samples % 2                      # the jumps at 0 and pi fall on samples
    th = 2.0 * np.pi * np.arange(samples) / samples
    g = np.stack(breathing_weights(th, law), axis=1)
    if law == "gasch":
        for j in (0, samples // 2):             # the mean of both sides at a jump
            g[j] = 0.5 * (np.stack(breathing_weights(th[j] - 1e-9, law)) +
                          np.stack(breathing_weights(th[j] + 1e-9, law)))
    F = np.fft.fft(g, axis=0) / samples
    m = np.arange(-n_terms, n_terms + 1)
    return F[m % samples]
