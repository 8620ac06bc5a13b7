r"""The open crack in a beam model: hinge, cracked beam element, reduced second moment of area.

Each function takes the compliance of :mod:`mutext.rotor.crack._compliance`
(or a depth ratio) and gives the stiffness of the beam that holds the crack;
see :mod:`mutext.rotor.crack` for when to use which.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ...errors import ModelError
from ._common import _matrix, _positive, _scalar, _symbolic
from ._compliance import crack_rotational_stiffness

def open_crack_element(depth_ratio, E, D, nu=0.3, *, n_quad: int = 16):
    r"""Stiffness of a zero-length rotational hinge (one bending plane).

    DOF order ``[w1, theta1, w2, theta2]`` (deflection in m, rotation in rad)
    of the two sides of the crack; the matrix is

    .. math::
        K_c = k_c \begin{bmatrix} 0&0&0&0\\ 0&1&0&-1\\ 0&0&0&0\\ 0&-1&0&1
        \end{bmatrix},\qquad k_c = 1/c(a/D).

    **How to use it.**  A zero-length hinge transmits the shear force, so the
    two sides share one deflection: the crack node gets one translation and
    two rotations (``w1`` and ``w2`` are the *same* global DOF).  Assemble
    the beam element on the left with ``theta1`` and the one on the right
    with ``theta2`` and add :math:`K_c`; the translation rows of :math:`K_c`
    are zero.  The matrix is invariant under the sign change of both
    rotations, so it is the same for the other plane convention
    :math:`\theta = -dw/dz`.  Not usable at zero depth (infinite stiffness):
    for a depth that may reach zero, or for a two-plane rotor, use
    :func:`cracked_element_stiffness` instead.

    Parameters
    ----------
    depth_ratio : float or casadi scalar
        Crack depth over shaft diameter, :math:`a/D \in [0, 0.5]`.
    E : float or casadi scalar
        Young's modulus [Pa].
    D : float or casadi scalar
        Shaft diameter at the crack [m].
    nu : float or casadi scalar, optional
        Poisson's ratio.
    n_quad : int, optional
        Gauss-Legendre points of the strip integration along the crack edge.

    Returns
    -------
    (4, 4) numpy.ndarray or casadi matrix [N m/rad on the rotation DOFs]
    """
    k = crack_rotational_stiffness(depth_ratio, E, D, nu, n_quad=n_quad)
    if not _symbolic(k) and not np.isfinite(k):
        raise ModelError("open_crack_element: the hinge stiffness is infinite at depth_ratio = 0; "
                         "leave the hinge out (no crack) or use cracked_element_stiffness")
    z = 0.0
    return _matrix([[z, z, z, z], [z, k, z, -k], [z, z, z, z], [z, -k, z, k]])


def _element_flexibility(L, E, I, phi):
    # cantilever clamped at node 1, tip force and moment at node 2 (Timoshenko)
    EI = E * I
    return [[L**3 / 3.0 * (1.0 + phi / 4.0) / EI, L**2 / 2.0 / EI],
            [L**2 / 2.0 / EI, L / EI]]


def cracked_element_stiffness(L, E, I, compliance, *, position=1.0, phi=0.0):
    r"""Stiffness of a beam element (one plane) containing an open crack.

    DOF order ``[w1, theta1, w2, theta2]`` with :math:`\theta` the section
    rotation, positive for :math:`\theta = dw/dz` (Euler-Bernoulli).  The
    crack lies at :math:`z_c = \text{position}\cdot L` from node 1.  The
    element clamped at node 1 and loaded at node 2 by a force :math:`F` and
    moment :math:`M` has the flexibility

    .. math::
        C = \frac{1}{EI}\begin{bmatrix} \tfrac{L^3}{3}(1+\tfrac{\phi}{4}) &
        \tfrac{L^2}{2} \\ \tfrac{L^2}{2} & L \end{bmatrix}
        + c\begin{bmatrix} d^2 & d \\ d & 1 \end{bmatrix},\qquad d = L - z_c,

    because the moment at the crack is :math:`M + F d` and the crack adds
    the rotation :math:`c\,(M + F d)` and with it the tip deflection
    :math:`c\,(M+Fd)\,d`.  Equilibrium of the free element gives the
    nodal forces :math:`f = T [F, M]^T` with
    :math:`T = [[-1, 0], [-L, -1], [1, 0], [0, 1]]`, so

    .. math:: K = T\,C^{-1}\,T^T.

    This is the formulation of [PD87]_ for a crack at the element end
    (``position=1``).  With ``compliance=0`` it is the standard
    Euler-Bernoulli (``phi=0``) or Timoshenko element
    (:math:`\phi = 12EI/(\kappa G A L^2)`); the mass matrix is unchanged by
    the crack.  For the other rotation convention (:math:`\theta=-dw/dz`)
    use :math:`S K S` with :math:`S = \mathrm{diag}(1,-1,1,-1)`.

    Parameters
    ----------
    L : float or casadi scalar
        Element length [m].
    E : float or casadi scalar
        Young's modulus [Pa].
    I : float or casadi scalar
        Second moment of area of the healthy section [m^4].
    compliance : float or casadi scalar
        Crack compliance [rad/(N m)], e.g. from :func:`crack_compliance`
        (may be a CasADi expression of a symbolic depth).
    position : float
        Crack location as a fraction of the element length, in [0, 1].
    phi : float or casadi scalar
        Timoshenko shear parameter (0 for Euler-Bernoulli).

    Returns
    -------
    (4, 4) numpy.ndarray or casadi matrix [N/m, N/rad, N m/rad]
    """
    L = _positive(L, "L (element length)", "m")
    E = _positive(E, "E (Young's modulus)", "Pa")
    I = _positive(I, "I (second moment of area)", "m^4")
    c = _scalar(compliance, "compliance")
    phi = _scalar(phi, "phi")
    if not _symbolic(c) and c < 0:
        raise ModelError(f"compliance must be >= 0 [rad/(N m)], got {c}")
    pos = _scalar(position, "position")
    if not _symbolic(pos) and not 0.0 <= pos <= 1.0:
        raise ModelError(f"position must be a fraction of the element length in [0, 1], got {pos}")
    (c11, c12), (_, c22) = _element_flexibility(L, E, I, phi)
    d = L * (1.0 - pos)
    c11, c12, c22 = c11 + c * d**2, c12 + c * d, c22 + c
    det = c11 * c22 - c12**2
    k11, k12, k22 = c22 / det, -c12 / det, c11 / det
    # K = T Kt T^T with T = [[-1, 0], [-L, -1], [1, 0], [0, 1]] written out
    a = [-k11, -k12]                                   # row of T Kt for w1: -[k11, k12]
    b = [-L * k11 - k12, -L * k12 - k22]               # theta1
    e = [k11, k12]                                     # w2
    g = [k12, k22]                                     # theta2
    rows = [a, b, e, g]
    Tcols = [[-1.0, 0.0], [-L, -1.0], [1.0, 0.0], [0.0, 1.0]]
    K = [[r[0] * t[0] + r[1] * t[1] for t in Tcols] for r in rows]
    return _matrix(K)


def cracked_element_stiffness_two_plane(L, E, I, compliance, angle, *, position=1.0, phi=0.0,
                                        compliance_eta=0.0):
    r"""Stiffness of a cracked beam element with two bending planes (fixed frame).

    DOF order (blocked by plane)
    ``[wx1, sx1, wx2, sx2, wy1, sy1, wy2, sy2]``: :math:`w_x, w_y` are the
    deflections (m) along the fixed axes :math:`x, y` and
    :math:`s_x, s_y` the section rotations in the planes :math:`xz` and
    :math:`yz`, with :math:`s_x = dw_x/dz`, :math:`s_y = dw_y/dz` for a
    slender beam (rad).  The crack normal :math:`\xi` (from the shaft axis
    towards the crack mouth) makes the angle ``angle`` with :math:`x`;
    :math:`\eta` is along the crack edge.  Bending in the :math:`\xi z`
    plane (moment vector parallel to the crack edge) sees ``compliance``
    (:math:`c_{55}`), bending in the :math:`\eta z` plane (moment vector
    perpendicular to the edge) sees ``compliance_eta`` (:math:`c_{44}`,
    :func:`crack_compliance` with ``component=44``).  In the crack frame the
    element is the uncoupled pair :math:`K_\xi` =
    :func:`cracked_element_stiffness` with :math:`c_{55}` and :math:`K_\eta`
    = the same element with :math:`c_{44}`; with :math:`\cos, \sin` of
    ``angle``:

    .. math::
        K = \begin{bmatrix} \cos^2 K_\xi + \sin^2 K_\eta &
        \cos\sin\,(K_\xi-K_\eta) \\ \cos\sin\,(K_\xi-K_\eta) &
        \sin^2 K_\xi + \cos^2 K_\eta \end{bmatrix}.

    ``compliance_eta = 0`` (the default of this low-level function, which
    is given compliances, not a depth) treats the :math:`\eta z` plane as
    healthy: the one-compliance model.  That neglect is not small for deep
    cracks: :math:`c_{44}/c_{55}` is about 0.07 at a/D = 0.1, 0.26 at 0.3,
    0.42 at 0.4 and 0.68 at 0.5, and to first order the mean stiffness loss
    grows with :math:`c_{55}+c_{44}` while the twice-per-revolution
    asymmetry grows with :math:`c_{55}-c_{44}` ([PD87]_).  The assembled
    :class:`Crack` includes :math:`c_{44}` by default.

    For a breathing crack in a finite-element rotor use
    ``compliance = open_fraction(psi) * c55``,
    ``compliance_eta = open_fraction(psi) * c44`` and
    ``angle = Omega t + angle0`` (compliance form of the breathing models).
    Parameters as in :func:`cracked_element_stiffness`; ``angle`` in rad,
    ``compliance_eta`` in rad/(N m).

    Parameters
    ----------
    L : float or casadi scalar
        Element length [m].
    E : float or casadi scalar
        Young's modulus [Pa].
    I : float or casadi scalar
        Second moment of area of the healthy section [m^4].
    compliance : float or casadi scalar
        Compliance :math:`c_{55}` [rad/(N m)] for bending in the plane of the crack normal.
    angle : float or casadi scalar
        Angle [rad] of the crack normal from the x axis.
    position : float, optional
        Crack location as a fraction of the element length, in [0, 1].
    phi : float or casadi scalar, optional
        Timoshenko shear parameter (0 for Euler-Bernoulli).
    compliance_eta : float or casadi scalar, optional
        Compliance :math:`c_{44}` [rad/(N m)] for bending in the plane of the crack edge.

    Returns
    -------
    (8, 8) numpy.ndarray or casadi matrix
    """
    Kx = cracked_element_stiffness(L, E, I, compliance, position=position, phi=phi)
    Kh = cracked_element_stiffness(L, E, I, compliance_eta, position=position, phi=phi)
    ang = _scalar(angle, "angle")
    if _symbolic(ang, Kx, Kh):
        co, si = ca.cos(ang), ca.sin(ang)
        Kx = Kx if _symbolic(Kx) else ca.DM(Kx)
        Kh = Kh if _symbolic(Kh) else ca.DM(Kh)
        return ca.vertcat(ca.horzcat(co**2 * Kx + si**2 * Kh, co * si * (Kx - Kh)),
                          ca.horzcat(co * si * (Kx - Kh), si**2 * Kx + co**2 * Kh))
    co, si = np.cos(ang), np.sin(ang)
    return np.block([[co**2 * Kx + si**2 * Kh, co * si * (Kx - Kh)],
                     [co * si * (Kx - Kh), si**2 * Kx + co**2 * Kh]])


def equivalent_reduced_inertia(I, E, compliance, length):
    r"""Second moment of area of a short "crack segment" with the crack's flexibility.

    Some authors replace the crack by a segment of length :math:`\ell`
    (typically of the order of the diameter) with a reduced second moment of
    area :math:`I_c`, chosen so that under a bending moment the segment
    rotates by the healthy amount plus the crack rotation:

    .. math::
        \frac{\ell}{E I_c} = \frac{\ell}{E I} + c
        \quad\Longrightarrow\quad I_c = \frac{I}{1 + E I c/\ell}.

    The equivalence is exact for a uniform moment over the segment and
    approximate otherwise (error of order :math:`\ell` times the moment
    gradient).

    Parameters
    ----------
    I : second moment of area of the healthy shaft [m^4]
    E : Young's modulus [Pa]
    compliance : crack compliance [rad/(N m)]
    length : segment length [m]

    Returns
    -------
    float or casadi expression [m^4]
    """
    I = _positive(I, "I", "m^4")
    E = _positive(E, "E", "Pa")
    length = _positive(length, "length", "m")
    c = _scalar(compliance, "compliance")
    return I / (1.0 + E * I * c / length)
