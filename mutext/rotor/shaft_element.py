r"""The Timoshenko shaft element: section properties, plane matrices, shape functions, :class:`ShaftElement`.

A uniform circular tube with shear deformation and rotary inertia; in the
two-plane rotor layout the plane matrices act in both planes (maps
:data:`T_XZ`, :data:`T_YZ`) and the spinning shaft adds the gyroscopic
matrix.

References
----------
.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees,
   *Dynamics of Rotating Machines*, Cambridge University Press, 2010, ch. 5
   (disks, bearings, Timoshenko shaft elements, example 5.9.1).
.. [Prz] J. S. Przemieniecki, *Theory of Matrix Structural Analysis*,
   McGraw-Hill, 1968, ch. 5 (beam element with shear deformation).
.. [Nel] H. D. Nelson, "A finite rotating shaft element using Timoshenko beam
   theory", *J. Mech. Design* 102 (1980) 793-803.
.. [Cow] G. R. Cowper, "The shear coefficient in Timoshenko's beam theory",
   *J. Appl. Mech.* 33 (1966) 335-340.
"""
from __future__ import annotations

import functools
import math

import casadi as ca

from ..errors import ModelError
from .element import Element, _positive

__all__ = ["ShaftElement", "section_properties", "cowper_shear_coefficient", "timoshenko_plane_matrices",
           "timoshenko_shape_functions", "plane_to_rotor", "T_XZ", "T_YZ"]


# ---------------------------------------------------------------------------
# section properties and the Timoshenko element
# ---------------------------------------------------------------------------

def section_properties(do, di):
    r"""Area and second moment of area of a circular tube.

    .. math:: A = \frac{\pi}{4}(d_o^2 - d_i^2),\qquad I = \frac{\pi}{64}(d_o^4 - d_i^4)

    Diameters in m; returns ``(A [m^2], I [m^4])``.  Works on floats and CasADi expressions.

    Parameters
    ----------
    do, di : float or casadi.SX
        Outer and inner diameters [m] (``di = 0`` for a solid section).
    """
    return math.pi / 4.0 * (do**2 - di**2), math.pi / 64.0 * (do**4 - di**4)


def cowper_shear_coefficient(nu, do=None, di=None):
    r"""Shear coefficient of a circular tube (Cowper 1966 [Cow]_).

    .. math::
        \kappa = \frac{6(1+\nu)(1+m^2)^2}{(7+6\nu)(1+m^2)^2 + (20+12\nu)m^2},
        \qquad m = d_i/d_o ,

    which for a solid section (:math:`m = 0`) is Friswell's
    :math:`\kappa = 6(1+\nu)/(7+6\nu)` ([Fri]_ ch. 5).

    Parameters
    ----------
    nu : float
        Poisson's ratio.
    do, di : float, optional
        Outer and inner diameters [m]; without them the solid-section formula.
    """
    if do is None or di is None:
        return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)
    m2 = (di / do) ** 2
    a = (1.0 + m2) ** 2
    return 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)


def timoshenko_plane_matrices(E, G, rho, L, do, di, kappa, shear=True):
    r"""Timoshenko beam element in one plane: ``(Mt, Mr, K)``, each 4x4.

    DOFs :math:`(w_1, \varphi_1, w_2, \varphi_2)`, with :math:`\varphi` the
    cross-section rotation (equal to :math:`\partial w/\partial z` when shear
    deformation vanishes).  With :math:`\Phi = 12EI/(\kappa G A L^2)`
    (Przemieniecki [Prz]_; Friswell [Fri]_ ch. 5):

    .. math::
        K = \frac{EI}{(1+\Phi)L^3}\begin{bmatrix}
        12 & 6L & -12 & 6L\\ 6L & (4+\Phi)L^2 & -6L & (2-\Phi)L^2\\
        -12 & -6L & 12 & -6L\\ 6L & (2-\Phi)L^2 & -6L & (4+\Phi)L^2\end{bmatrix},

    .. math::
        M_t = \frac{\rho A L}{840(1+\Phi)^2}\begin{bmatrix}
        m_1 & m_2L & m_3 & -m_4L\\ m_2L & m_5L^2 & m_4L & -m_6L^2\\
        m_3 & m_4L & m_1 & -m_2L\\ -m_4L & -m_6L^2 & -m_2L & m_5L^2\end{bmatrix},

    :math:`m_1 = 312+588\Phi+280\Phi^2`, :math:`m_2 = 44+77\Phi+35\Phi^2`,
    :math:`m_3 = 108+252\Phi+140\Phi^2`, :math:`m_4 = 26+63\Phi+35\Phi^2`,
    :math:`m_5 = 8+14\Phi+7\Phi^2`, :math:`m_6 = 6+14\Phi+7\Phi^2`, and the
    rotary inertia

    .. math::
        M_r = \frac{\rho I}{30(1+\Phi)^2L}\begin{bmatrix}
        36 & (3-15\Phi)L & -36 & (3-15\Phi)L\\
        (3-15\Phi)L & (4+5\Phi+10\Phi^2)L^2 & -(3-15\Phi)L & (-1-5\Phi+5\Phi^2)L^2\\
        -36 & -(3-15\Phi)L & 36 & -(3-15\Phi)L\\
        (3-15\Phi)L & (-1-5\Phi+5\Phi^2)L^2 & -(3-15\Phi)L & (4+5\Phi+10\Phi^2)L^2
        \end{bmatrix}.

    These are the consistent matrices of the interdependent shape functions of
    :func:`timoshenko_shape_functions` (the tests integrate them numerically).
    ``shear=False`` sets :math:`\Phi = 0`: the Euler-Bernoulli element with
    rotary inertia (Rayleigh beam); drop ``Mr`` too for Euler-Bernoulli.

    Parameters are SI (Pa, Pa, kg/m^3, m, m, m, -); floats or CasADi expressions.

    Parameters
    ----------
    E : float or casadi.SX
        Young's modulus [Pa].
    G : float or casadi.SX
        Shear modulus [Pa].
    rho : float or casadi.SX
        Density [kg/m^3].
    L : float or casadi.SX
        Element length [m].
    do, di : float or casadi.SX
        Outer and inner diameters [m].
    kappa : float or casadi.SX
        Shear coefficient (:func:`cowper_shear_coefficient`).
    shear : bool, optional
        Include shear deformation; False gives the Euler-Bernoulli element
        (:math:`\Phi = 0`).
    """
    A, I = section_properties(do, di)
    phi = 12.0 * E * I / (kappa * G * A * L**2) if shear else 0.0
    k = E * I / ((1.0 + phi) * L**3)
    K = k * ca.blockcat([
        [12.0, 6.0 * L, -12.0, 6.0 * L],
        [6.0 * L, (4.0 + phi) * L**2, -6.0 * L, (2.0 - phi) * L**2],
        [-12.0, -6.0 * L, 12.0, -6.0 * L],
        [6.0 * L, (2.0 - phi) * L**2, -6.0 * L, (4.0 + phi) * L**2]])
    m1 = 312.0 + 588.0 * phi + 280.0 * phi**2
    m2 = (44.0 + 77.0 * phi + 35.0 * phi**2) * L
    m3 = 108.0 + 252.0 * phi + 140.0 * phi**2
    m4 = (26.0 + 63.0 * phi + 35.0 * phi**2) * L
    m5 = (8.0 + 14.0 * phi + 7.0 * phi**2) * L**2
    m6 = (6.0 + 14.0 * phi + 7.0 * phi**2) * L**2
    Mt = rho * A * L / (840.0 * (1.0 + phi) ** 2) * ca.blockcat([
        [m1, m2, m3, -m4],
        [m2, m5, m4, -m6],
        [m3, m4, m1, -m2],
        [-m4, -m6, -m2, m5]])
    r1 = (3.0 - 15.0 * phi) * L
    r2 = (4.0 + 5.0 * phi + 10.0 * phi**2) * L**2
    r3 = (-1.0 - 5.0 * phi + 5.0 * phi**2) * L**2
    Mr = rho * I / (30.0 * (1.0 + phi) ** 2 * L) * ca.blockcat([
        [36.0, r1, -36.0, r1],
        [r1, r2, -r1, r3],
        [-36.0, -r1, 36.0, -r1],
        [r1, r3, -r1, r2]])
    return Mt, Mr, K


@functools.lru_cache(maxsize=None)
def _timoshenko_function(shear: bool) -> ca.Function:
    """:func:`timoshenko_plane_matrices` as one CasADi function of ``(E, G, rho, L, do, di, kappa)``:
    called on an element's symbols it copies the expression graph in compiled code, where building
    the expressions again in Python for each element took most of a rotor's assembly time."""
    args = [ca.SX.sym(n) for n in ("E", "G", "rho", "L", "do", "di", "kappa")]
    return ca.Function("timoshenko_plane", args, list(timoshenko_plane_matrices(*args, shear=shear)))


def timoshenko_shape_functions(xi, L, phi):
    r"""Interdependent Timoshenko shape functions at :math:`\xi = z/L \in [0, 1]`.

    Returns ``(N, P)``: lists of 4 values such that
    :math:`w(z) = \sum_j N_j q_j` and :math:`\varphi(z) = \sum_j P_j q_j` for
    :math:`q = (w_1, \varphi_1, w_2, \varphi_2)` (Friswell [Fri]_ ch. 5;
    they solve the static Timoshenko equations exactly):

    .. math::
        N_1 = \frac{1 - 3\xi^2 + 2\xi^3 + \Phi(1-\xi)}{1+\Phi},\quad
        N_2 = L\frac{\xi - 2\xi^2 + \xi^3 + \Phi(\xi-\xi^2)/2}{1+\Phi},

    .. math::
        N_3 = \frac{3\xi^2 - 2\xi^3 + \Phi\xi}{1+\Phi},\quad
        N_4 = L\frac{-\xi^2 + \xi^3 - \Phi(\xi-\xi^2)/2}{1+\Phi},

    .. math::
        P_1 = \frac{6(\xi^2-\xi)}{L(1+\Phi)},\ 
        P_2 = \frac{1 - 4\xi + 3\xi^2 + \Phi(1-\xi)}{1+\Phi},\ 
        P_3 = -P_1,\ 
        P_4 = \frac{-2\xi + 3\xi^2 + \Phi\xi}{1+\Phi}.

    Parameters
    ----------
    xi : float or casadi.SX
        Position along the element, 0 at the first node and 1 at the second.
    L : float or casadi.SX
        Element length [m].
    phi : float or casadi.SX
        Shear parameter :math:`\Phi = 12EI/(\kappa G A L^2)` (0: Euler-Bernoulli).
    """
    d = 1.0 + phi
    N = [(1 - 3 * xi**2 + 2 * xi**3 + phi * (1 - xi)) / d,
         L * (xi - 2 * xi**2 + xi**3 + phi * (xi - xi**2) / 2) / d,
         (3 * xi**2 - 2 * xi**3 + phi * xi) / d,
         L * (-xi**2 + xi**3 - phi * (xi - xi**2) / 2) / d]
    p1 = 6 * (xi**2 - xi) / (L * d)
    P = [p1,
         (1 - 4 * xi + 3 * xi**2 + phi * (1 - xi)) / d,
         -p1,
         (-2 * xi + 3 * xi**2 + phi * xi) / d]
    return N, P


def _selector(rows: int, cols: int, entries) -> ca.DM:
    T = ca.DM.zeros(rows, cols)
    for r, c, v in entries:
        T[r, c] = v
    return T


# Two-node maps from the rotor layout (u1 v1 th1 psi1 u2 v2 th2 psi2) to the beam plane (w1 phi1 w2 phi2).
# x-z plane: (w, phi) = (u, psi); y-z plane: (w, phi) = (v, -theta)  (dv/dz = -theta).
T_XZ = _selector(4, 8, [(0, 0, 1.0), (1, 3, 1.0), (2, 4, 1.0), (3, 7, 1.0)])
T_YZ = _selector(4, 8, [(0, 1, 1.0), (1, 2, -1.0), (2, 5, 1.0), (3, 6, -1.0)])


def plane_to_rotor(Mxz, Myz=None):
    r"""Two-plane (8x8) matrix from plane (4x4) matrices: :math:`T_{xz}^T M_{xz} T_{xz} + T_{yz}^T M_{yz} T_{yz}`.

    Parameters
    ----------
    Mxz : (4, 4) casadi.SX or array_like
        Plane matrix acting in the x-z plane.
    Myz : (4, 4) casadi.SX or array_like, optional
        Plane matrix acting in the y-z plane (default: ``Mxz``).
    """
    Myz = Mxz if Myz is None else Myz
    return ca.mtimes([T_XZ.T, Mxz, T_XZ]) + ca.mtimes([T_YZ.T, Myz, T_YZ])


class ShaftElement(Element):
    r"""Timoshenko shaft element between stations ``station`` and ``station + 1``.

    Uniform circular tube with shear deformation and rotary inertia.  In the
    ``"plane"`` layout the matrices are those of
    :func:`timoshenko_plane_matrices` (mass :math:`M_t + M_r`); in the
    ``"rotor"`` layout the same plane matrices act in both planes,
    :math:`M = T_{xz}^T M_p T_{xz} + T_{yz}^T M_p T_{yz}`, and the spinning
    shaft adds the gyroscopic matrix (Nelson [Nel]_; Friswell [Fri]_ ch. 5)

    .. math::
        G_e = \int_0^L \rho I_p\,(b\,a^T - a\,b^T)\,dz
            = 2\left(T_{xz}^T M_r T_{yz} - T_{yz}^T M_r T_{xz}\right),

    where :math:`\psi(z) = a(z)^T q_e` and :math:`\theta(z) = b(z)^T q_e` are
    the interpolated rotations and :math:`I_p = 2I`.

    Parameters
    ----------
    station : int
        Left station (1-based).
    L : float or Param
        Length [m].
    do, di : float or Param
        Outer and inner diameter [m] (``di = 0``: solid).
    E : float or Param
        Young's modulus [Pa].
    rho : float or Param
        Mass density [kg/m^3].
    nu : float or Param, optional
        Poisson's ratio; the shear modulus is :math:`G = E/(2(1+\nu))`.
    G : float or Param, optional
        Shear modulus [Pa] (instead of ``nu``).
    kappa : float or Param, optional
        Shear coefficient; default :func:`cowper_shear_coefficient` of
        :math:`\nu` and :math:`d_i/d_o` (Friswell's formula for a solid shaft).
    shear : bool
        False neglects shear deformation (:math:`\Phi = 0`).
    rotary_inertia : bool
        False drops :math:`M_r` from the mass matrix (and the gyroscopic
        matrix); with ``shear=False`` this is the Euler-Bernoulli element.
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"shaft3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "shaft"
    FIELDS = {
        "L": ("m", "element length"),
        "do": ("m", "outer diameter"),
        "di": ("m", "inner diameter"),
        "E": ("Pa", "Young's modulus"),
        "rho": ("kg/m^3", "mass density"),
        "nu": ("1", "Poisson's ratio"),
        "G": ("Pa", "shear modulus"),
        "kappa": ("1", "shear coefficient"),
    }

    def __init__(self, station: int, L, do, di=0.0, *, E, rho, nu=None, G=None, kappa=None,
                 shear: bool = True, rotary_inertia: bool = True, name: str | None = None):
        if (nu is None) == (G is None):
            raise ModelError(f"{name or f'shaft{station}'}: give exactly one of nu (Poisson's ratio) "
                             "and G (shear modulus)")
        super().__init__((station, station + 1), name, L=L, do=do, di=di, E=E, rho=rho, nu=nu, G=G,
                         kappa=kappa)
        self.shear = bool(shear)
        self.rotary_inertia = bool(rotary_inertia)
        self._plane = None
        _positive(self, "L", "do", "E", "rho", "G", "kappa")
        _positive(self, "di", allow_zero=True)
        if self.nominal("di") >= self.nominal("do"):
            raise ModelError(f"{self.name}: inner diameter {self.nominal('di'):g} m must be smaller than "
                             f"the outer diameter {self.nominal('do'):g} m")
        if nu is not None and not -1.0 < self.nominal("nu") < 0.5:
            raise ModelError(f"{self.name}.nu must be in (-1, 0.5), got {self.nominal('nu'):g}")

    def __getstate__(self):
        # the symbolic matrices of the last assembly are not part of the element (copies and pickles
        # rebuild them)
        state = dict(self.__dict__)
        state["_plane"] = None
        return state

    def plane_matrices(self, p):
        """``(Mt, Mr, K)`` of :func:`timoshenko_plane_matrices` for this element.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol.
        """
        # the mass, stiffness and gyroscopic matrices all start from these: built once per assembly
        if self._plane is not None and self._plane[0] is p:
            return self._plane[1]
        E, rho, L = self.sym(p, "E"), self.sym(p, "rho"), self.sym(p, "L")
        do, di = self.sym(p, "do"), self.sym(p, "di")
        if self.has("G"):
            G = self.sym(p, "G")
            nu = E / (2.0 * G) - 1.0
        else:
            nu = self.sym(p, "nu")
            G = E / (2.0 * (1.0 + nu))
        kappa = self.sym(p, "kappa") if self.has("kappa") else cowper_shear_coefficient(nu, do, di)
        self._plane = (p, tuple(_timoshenko_function(self.shear)(E, G, rho, L, do, di, kappa)))
        return self._plane[1]

    def mass_matrix(self, p, layout):
        Mt, Mr, _ = self.plane_matrices(p)
        Mp = Mt + Mr if self.rotary_inertia else Mt
        if layout.kind == "plane":
            return Mp
        if layout.kind == "rotor":
            return plane_to_rotor(Mp)
        raise ModelError(f"{self.name}: a shaft element needs a 'rotor' or 'plane' layout, not '{layout.kind}'")

    def stiffness_matrix(self, p, layout):
        _, _, K = self.plane_matrices(p)
        if layout.kind == "plane":
            return K
        if layout.kind == "rotor":
            return plane_to_rotor(K)
        raise ModelError(f"{self.name}: a shaft element needs a 'rotor' or 'plane' layout, not '{layout.kind}'")

    def gyroscopic_matrix(self, p, layout):
        if layout.kind != "rotor" or not self.rotary_inertia:
            return None
        _, Mr, _ = self.plane_matrices(p)
        return 2.0 * (ca.mtimes([T_XZ.T, Mr, T_YZ]) - ca.mtimes([T_YZ.T, Mr, T_XZ]))
