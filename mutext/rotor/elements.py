r"""Finite elements of a rotor (and of lumped chains), as CasADi expressions.

One class per physical part, in the style of ROSS: :class:`ShaftElement`
(Timoshenko beam), :class:`DiskElement` (rigid lumped disk),
:class:`BearingElement` (linear springs and dampers to ground),
:class:`ExciterElement` (magnetic actuator: force per ampere and negative
stiffness), and for lumped mass-spring-damper chains :class:`PointMass`,
:class:`Spring` and :class:`Damper`.  :class:`mutext.rotor.assembly.Structure`
assembles them.

Every numeric field of an element is a *parameter*: a plain number becomes a
parameter private to the element (named ``"<element>.<field>"``, e.g.
``"shaft3.L"``); a :class:`Param` can be shared by several elements (e.g. one
Young's modulus ``"E"`` for the whole shaft).  Element matrices are CasADi
``SX`` expressions of the parameter symbols, so that the assembled matrices
are functions :math:`M(p), C(p), K(p), G(p)` with exact derivatives.

Degrees of freedom (the *layout*)
---------------------------------
``"rotor"`` (two bending planes, 4 DOF per station)
    :math:`(u, v, \theta, \psi)`: displacement along x and y, rotation about x
    and about y.  With the shaft along z, the slopes are
    :math:`\partial u/\partial z = \psi` and :math:`\partial v/\partial z = -\theta`
    (right-handed rotations, as in Friswell et al. 2010, ch. 5).  The rotor spins
    at :math:`\Omega` about +z.
``"plane"`` (one bending plane, 2 DOF per station)
    :math:`(u, \psi)`: the x-z plane of the rotor layout.  No gyroscopic effect.
``"lumped"`` (1 DOF per node)
    :math:`x`: translation of a lumped mass.

Equation of motion (SI: m, rad, kg, N, N m)

.. math::
    M\ddot q + (C + \Omega G)\dot q + K q = f .

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

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import casadi as ca

from ..errors import ModelError

__all__ = [
    "Param", "ParameterSet", "Layout", "InputPort", "OutputPort", "Element",
    "ShaftElement", "DiskElement", "BearingElement", "ExciterElement",
    "PointMass", "Spring", "Damper",
    "section_properties", "cowper_shear_coefficient", "timoshenko_plane_matrices",
    "timoshenko_shape_functions", "plane_to_rotor",
]


# ---------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Param:
    """A named model parameter with its nominal value (SI units).

    Pass the same :class:`Param` to several elements to make them share one
    symbol (e.g. one density for the whole shaft, tuned once).
    """
    name: str
    value: float
    unit: str = ""
    doc: str = ""


class ParameterSet:
    """Ordered parameters of an assembled model, with CasADi symbols.

    ``add`` registers a parameter (or returns the existing one of the same
    name, if its nominal value agrees); ``symbols[name]`` is its ``SX``
    symbol; ``vector`` stacks them in declaration order.
    """

    def __init__(self):
        self._params: dict[str, Param] = {}
        self.symbols: dict[str, ca.SX] = {}

    def add(self, param: Param) -> str:
        if not isinstance(param.name, str) or not param.name:
            raise ModelError(f"a parameter needs a non-empty name, got {param.name!r}")
        v = param.value
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
            raise ModelError(f"parameter '{param.name}': nominal value must be a finite number, got {v!r}")
        old = self._params.get(param.name)
        if old is not None:
            if old.value != param.value:
                raise ModelError(f"parameter '{param.name}' is declared twice with different nominal values "
                                 f"({old.value:g} and {param.value:g} {param.unit})")
            return param.name
        self._params[param.name] = Param(param.name, float(v), param.unit, param.doc)
        self.symbols[param.name] = ca.SX.sym(param.name)
        return param.name

    def __contains__(self, name):
        return name in self._params

    def __len__(self):
        return len(self._params)

    @property
    def params(self) -> list[Param]:
        return list(self._params.values())

    @property
    def names(self) -> list[str]:
        return list(self._params)

    @property
    def vector(self) -> ca.SX:
        return ca.vertcat(*self.symbols.values()) if self.symbols else ca.SX(0, 1)


# ---------------------------------------------------------------------------
# layouts and ports
# ---------------------------------------------------------------------------

class Layout:
    """Numbering of the degrees of freedom.

    Parameters
    ----------
    kind : {"rotor", "plane", "lumped"}
        4, 2 or 1 DOF per node (see the module docstring).
    n_nodes : int
        Number of nodes (stations or lumped masses), numbered 1..n_nodes.
    node_names : sequence of str, optional
        Names used for the DOF names (default: the numbers).
    """
    LABELS = {"rotor": ("u", "v", "theta", "psi"), "plane": ("u", "psi"), "lumped": ("x",)}
    ALIASES = {"rotor": {"x": "u", "y": "v"}, "plane": {"x": "u"}, "lumped": {"u": "x"}}

    def __init__(self, kind: str, n_nodes: int, node_names: Sequence[str] | None = None):
        if kind not in self.LABELS:
            raise ModelError(f"unknown layout '{kind}'; expected one of {sorted(self.LABELS)}")
        if n_nodes < 1:
            raise ModelError(f"a model needs at least one node, got {n_nodes}")
        self.kind = kind
        self.labels = self.LABELS[kind]
        self.per_node = len(self.labels)
        self.n_nodes = int(n_nodes)
        self.ndof = self.per_node * self.n_nodes
        names = [str(i) for i in range(1, n_nodes + 1)] if node_names is None else list(node_names)
        if len(names) != n_nodes:
            raise ModelError(f"{len(names)} node names for {n_nodes} nodes")
        self.node_names = names

    def label(self, label: str) -> str:
        lab = self.ALIASES[self.kind].get(label, label)
        if lab not in self.labels:
            raise ModelError(f"direction '{label}' does not exist in a '{self.kind}' model "
                             f"(DOFs per node: {', '.join(self.labels)})")
        return lab

    def check_node(self, node: int, what: str = "node") -> int:
        if isinstance(node, bool) or not isinstance(node, int) or not 1 <= node <= self.n_nodes:
            raise ModelError(f"{what}: station/node {node!r} is outside 1..{self.n_nodes}")
        return node

    def dof(self, node: int, label: str) -> int:
        """0-based global index of DOF ``label`` at 1-based ``node``."""
        self.check_node(node)
        return (node - 1) * self.per_node + self.labels.index(self.label(label))

    def node_dofs(self, node: int) -> list[int]:
        self.check_node(node)
        return list(range((node - 1) * self.per_node, node * self.per_node))

    @property
    def dof_names(self) -> list[str]:
        if self.kind == "lumped":
            return list(self.node_names)
        return [f"{lab}{n}" for n in self.node_names for lab in self.labels]


@dataclass(frozen=True)
class InputPort:
    """A named input: a generalized force at one DOF.

    ``gain`` is a parameter name (e.g. an exciter's force per ampere) or
    ``None`` for a unit force [N] / moment [N m].  ``unit`` is the unit of the input.
    """
    name: str
    node: int
    direction: str = "u"
    gain: str | None = None
    unit: str = "N"


@dataclass(frozen=True)
class OutputPort:
    """A named output: the displacement [m] or rotation [rad] of one DOF."""
    name: str
    node: int
    direction: str = "u"
    unit: str = "m"


# ---------------------------------------------------------------------------
# section properties and the Timoshenko element
# ---------------------------------------------------------------------------

def section_properties(do, di):
    r"""Area and second moment of area of a circular tube.

    .. math:: A = \frac{\pi}{4}(d_o^2 - d_i^2),\qquad I = \frac{\pi}{64}(d_o^4 - d_i^4)

    Diameters in m; returns ``(A [m^2], I [m^4])``.  Works on floats and CasADi expressions.
    """
    return math.pi / 4.0 * (do**2 - di**2), math.pi / 64.0 * (do**4 - di**4)


def cowper_shear_coefficient(nu, do=None, di=None):
    r"""Shear coefficient of a circular tube (Cowper 1966 [Cow]_).

    .. math::
        \kappa = \frac{6(1+\nu)(1+m^2)^2}{(7+6\nu)(1+m^2)^2 + (20+12\nu)m^2},
        \qquad m = d_i/d_o ,

    which for a solid section (:math:`m = 0`) is Friswell's
    :math:`\kappa = 6(1+\nu)/(7+6\nu)` ([Fri]_ ch. 5).
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
    r"""Two-plane (8x8) matrix from plane (4x4) matrices: :math:`T_{xz}^T M_{xz} T_{xz} + T_{yz}^T M_{yz} T_{yz}`."""
    Myz = Mxz if Myz is None else Myz
    return ca.mtimes([T_XZ.T, Mxz, T_XZ]) + ca.mtimes([T_YZ.T, Myz, T_YZ])


# ---------------------------------------------------------------------------
# elements
# ---------------------------------------------------------------------------

class Element:
    """Base class of all elements (and the hook for user elements such as cracks).

    An element occupies the nodes ``self.nodes`` (1-based station numbers) and
    contributes local matrices on the DOFs returned by :meth:`dofs` (by default
    all DOFs of its nodes, node by node, in the layout's order).  Subclasses
    declare their parameters in ``FIELDS``: ``{field: (unit, description)}``.

    The matrix methods take ``p`` (a mapping parameter name -> CasADi symbol)
    and the :class:`Layout`, and return a CasADi ``SX`` matrix of size
    ``len(dofs) x len(dofs)`` or ``None`` (no contribution).  Use
    ``self.sym(p, field)`` to get the symbol of one of the element's fields.

    An element may also define ``bind(structure)``, called by the assembly
    before any matrix is built (e.g. to find the shaft element it modifies),
    and ``input_ports()`` returning :class:`InputPort` objects.
    """
    KIND = "element"
    FIELDS: dict[str, tuple[str, str]] = {}

    def __init__(self, nodes: Sequence[int], name: str | None = None, **values):
        self.nodes = tuple(nodes)
        for n in self.nodes:
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise ModelError(f"{self.KIND}: station/node numbers are integers >= 1, got {n!r}")
        self.name = name if name is not None else f"{self.KIND}{self.nodes[0]}"
        self.values: dict[str, float | Param] = {}
        for f, v in values.items():
            if f not in self.FIELDS:
                raise ModelError(f"{self.name}: unknown field '{f}' (fields: {', '.join(self.FIELDS)})")
            if v is None:
                continue
            if not isinstance(v, Param):
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ModelError(f"{self.name}.{f}: expected a finite number or a Param, got {v!r}")
            self.values[f] = v
        self._pnames: dict[str, str] = {}

    def __repr__(self):
        vals = ", ".join(f"{k}={v.name}" if isinstance(v, Param) else f"{k}={v:g}"
                         for k, v in self.values.items())
        return f"{type(self).__name__}({self.name}: nodes {self.nodes}, {vals})"

    # -- parameters
    def nominal(self, field: str) -> float:
        v = self.values[field]
        return v.value if isinstance(v, Param) else float(v)

    def declare(self, params: ParameterSet) -> None:
        """Register the element's parameters in ``params``."""
        for f, v in self.values.items():
            unit, doc = self.FIELDS[f]
            if isinstance(v, Param):
                par = Param(v.name, v.value, v.unit or unit, v.doc or doc)
            else:
                par = Param(f"{self.name}.{f}", float(v), unit, f"{doc} ({self.name})")
            self._pnames[f] = params.add(par)

    def param_name(self, field: str) -> str:
        return self._pnames[field]

    def has(self, field: str) -> bool:
        return field in self.values

    def sym(self, p: Mapping[str, ca.SX], field: str) -> ca.SX:
        return p[self._pnames[field]]

    # -- topology
    def check(self, layout: Layout) -> None:
        for n in self.nodes:
            layout.check_node(n, f"{self.name}")

    def dofs(self, layout: Layout) -> list[int]:
        return [d for n in self.nodes for d in layout.node_dofs(n)]

    # -- matrices (override)
    def mass_matrix(self, p, layout):
        return None

    def damping_matrix(self, p, layout):
        return None

    def stiffness_matrix(self, p, layout):
        return None

    def gyroscopic_matrix(self, p, layout):
        return None

    def input_ports(self) -> list[InputPort]:
        return []


def _positive(el: Element, *fields, allow_zero=False):
    for f in fields:
        if f in el.values:
            v = el.nominal(f)
            if v < 0 or (v == 0 and not allow_zero):
                raise ModelError(f"{el.name}.{f} must be {'non-negative' if allow_zero else 'positive'}, got {v:g}")


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
        _positive(self, "L", "do", "E", "rho", "G", "kappa")
        _positive(self, "di", allow_zero=True)
        if self.nominal("di") >= self.nominal("do"):
            raise ModelError(f"{self.name}: inner diameter {self.nominal('di'):g} m must be smaller than "
                             f"the outer diameter {self.nominal('do'):g} m")
        if nu is not None and not -1.0 < self.nominal("nu") < 0.5:
            raise ModelError(f"{self.name}.nu must be in (-1, 0.5), got {self.nominal('nu'):g}")

    def plane_matrices(self, p):
        """``(Mt, Mr, K)`` of :func:`timoshenko_plane_matrices` for this element."""
        E, rho, L = self.sym(p, "E"), self.sym(p, "rho"), self.sym(p, "L")
        do, di = self.sym(p, "do"), self.sym(p, "di")
        if self.has("G"):
            G = self.sym(p, "G")
            nu = E / (2.0 * G) - 1.0
        else:
            nu = self.sym(p, "nu")
            G = E / (2.0 * (1.0 + nu))
        kappa = self.sym(p, "kappa") if self.has("kappa") else cowper_shear_coefficient(nu, do, di)
        return timoshenko_plane_matrices(E, G, rho, L, do, di, kappa, shear=self.shear)

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


class DiskElement(Element):
    r"""Rigid disk lumped at a station (Friswell [Fri]_ ch. 5).

    .. math::
        M = \mathrm{diag}(m, m, I_d, I_d),\qquad
        G = \begin{bmatrix} 0&0&0&0\\0&0&0&0\\0&0&0&I_p\\0&0&-I_p&0\end{bmatrix}

    on :math:`(u, v, \theta, \psi)`, i.e. :math:`I_d\ddot\theta + \Omega I_p\dot\psi = M_\theta`
    and :math:`I_d\ddot\psi - \Omega I_p\dot\theta = M_\psi`.  In the
    ``"plane"`` layout :math:`M = \mathrm{diag}(m, I_d)`; in the ``"lumped"``
    layout :math:`M = m`.

    Parameters
    ----------
    station : int
    m : float or Param
        Mass [kg].
    Ip, Id : float or Param
        Polar and diametral (transverse) moments of inertia [kg m^2].
    """
    KIND = "disk"
    FIELDS = {"m": ("kg", "mass"), "Ip": ("kg m^2", "polar moment of inertia"),
              "Id": ("kg m^2", "diametral moment of inertia")}

    def __init__(self, station: int, m, Ip=0.0, Id=0.0, *, name: str | None = None):
        super().__init__((station,), name, m=m, Ip=Ip, Id=Id)
        _positive(self, "m", "Ip", "Id", allow_zero=True)

    @classmethod
    def from_geometry(cls, station: int, width: float, do: float, di: float, rho: float, *,
                      name: str | None = None) -> "DiskElement":
        r"""Disk of uniform density: :math:`m = \rho\pi(d_o^2-d_i^2)h/4`,
        :math:`I_p = m(d_o^2+d_i^2)/8`, :math:`I_d = I_p/2 + m h^2/12` (SI)."""
        if not (width > 0 and do > 0 and 0 <= di < do and rho > 0):
            raise ModelError(f"disk at station {station}: need width > 0, 0 <= di < do and rho > 0, got "
                             f"width={width}, do={do}, di={di}, rho={rho}")
        m = rho * math.pi * (do**2 - di**2) * width / 4.0
        Ip = m * (do**2 + di**2) / 8.0
        Id = Ip / 2.0 + m * width**2 / 12.0
        return cls(station, m, Ip, Id, name=name)

    def mass_matrix(self, p, layout):
        m = self.sym(p, "m")
        if layout.kind == "lumped":
            return ca.reshape(m, 1, 1)
        Id = self.sym(p, "Id")
        if layout.kind == "plane":
            return ca.diag(ca.vertcat(m, Id))
        return ca.diag(ca.vertcat(m, m, Id, Id))

    def gyroscopic_matrix(self, p, layout):
        if layout.kind != "rotor":
            return None
        Ip = self.sym(p, "Ip")
        G = ca.SX(4, 4)
        G[2, 3] = Ip
        G[3, 2] = -Ip
        return G


class PointMass(DiskElement):
    """A lumped mass [kg] without rotary inertia (for lumped chains; in a rotor: mass in x and y only)."""
    KIND = "mass"
    FIELDS = {"m": ("kg", "mass")}

    def __init__(self, node: int, m, *, name: str | None = None):
        Element.__init__(self, (node,), name, m=m)
        _positive(self, "m", allow_zero=True)

    def mass_matrix(self, p, layout):
        m = self.sym(p, "m")
        if layout.kind == "lumped":
            return ca.reshape(m, 1, 1)
        if layout.kind == "plane":
            return ca.diag(ca.vertcat(m, 0.0))
        return ca.diag(ca.vertcat(m, m, 0.0, 0.0))

    def gyroscopic_matrix(self, p, layout):
        return None


def _translational(el: Element, layout: Layout, node: int) -> list[int]:
    if layout.kind == "rotor":
        return [layout.dof(node, "u"), layout.dof(node, "v")]
    return [layout.dof(node, layout.labels[0])]


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
    """Linear spring [N/m] from ``node`` to ``other`` (or to ground if ``other is None``)."""
    KIND = "spring"
    FIELDS = {"k": ("N/m", "stiffness"), "kyy": ("N/m", "stiffness in y")}

    def __init__(self, node: int, other: int | None = None, *, k, kyy=None, name: str | None = None):
        super().__init__(node, other, name=name, k=k, kyy=kyy)

    def stiffness_matrix(self, p, layout):
        return self._matrix(p, layout)


class Damper(_TwoNodeTranslational):
    """Linear viscous damper [N s/m] from ``node`` to ``other`` (or to ground)."""
    KIND = "damper"
    FIELDS = {"c": ("N s/m", "damping"), "cyy": ("N s/m", "damping in y")}
    XX, YY = "c", "cyy"

    def __init__(self, node: int, other: int | None = None, *, c, cyy=None, name: str | None = None):
        super().__init__(node, other, name=name, c=c, cyy=cyy)

    def damping_matrix(self, p, layout):
        return self._matrix(p, layout)


class BearingElement(Element):
    r"""Linear bearing at a station: springs and dampers to ground (Friswell [Fri]_ ch. 5).

    .. math::
        K = \begin{bmatrix} k_{xx} & 0\\ 0 & k_{yy}\end{bmatrix},\quad
        C = \begin{bmatrix} c_{xx} & 0\\ 0 & c_{yy}\end{bmatrix}

    on :math:`(u, v)`; in the ``"plane"`` layout :math:`k_{xx}, c_{xx}` on :math:`u`.

    Parameters
    ----------
    station : int
    k : float or Param
        Stiffness [N/m] (x, and y unless ``kyy`` is given).
    c : float or Param
        Damping [N s/m] (x, and y unless ``cyy`` is given).
    kyy, cyy : float or Param, optional
        Stiffness and damping in y for an anisotropic bearing.
    """
    KIND = "bearing"
    FIELDS = {"k": ("N/m", "bearing stiffness"), "c": ("N s/m", "bearing damping"),
              "kyy": ("N/m", "bearing stiffness in y"), "cyy": ("N s/m", "bearing damping in y")}

    def __init__(self, station: int, k, c=0.0, *, kyy=None, cyy=None, name: str | None = None):
        super().__init__((station,), name, k=k, c=c, kyy=kyy, cyy=cyy)
        _positive(self, *self.FIELDS, allow_zero=True)

    def dofs(self, layout):
        return _translational(self, layout, self.nodes[0])

    def _diag(self, p, layout, xx, yy):
        a = self.sym(p, xx)
        if layout.kind != "rotor":
            return ca.reshape(a, 1, 1)
        b = self.sym(p, yy) if self.has(yy) else a
        return ca.diag(ca.vertcat(a, b))

    def stiffness_matrix(self, p, layout):
        return self._diag(p, layout, "k", "kyy")

    def damping_matrix(self, p, layout):
        return self._diag(p, layout, "c", "cyy")


class ExciterElement(Element):
    r"""Magnetic exciter (actuator) at a station, driven by a current.

    Linearized actuator force :math:`f = k_i\,i + k_x\,x` along ``direction``:
    the current input enters through the *force per ampere* :math:`k_i` [N/A]
    and the *negative stiffness* :math:`k_x \ge 0` [N/m] of a biased magnetic
    actuator is added as :math:`-k_x` to the stiffness matrix.  The element
    provides the input port ``port`` (current [A]).

    Parameters
    ----------
    station : int
    ki : float or Param
        Force per ampere [N/A].
    kx : float or Param
        Negative (open-loop) stiffness magnitude [N/m]; 0 if unknown.
    direction : str
        ``"u"``/``"x"`` (default) or ``"v"``/``"y"``.
    port : str, optional
        Input name (default ``"i<station>"``).
    """
    KIND = "exciter"
    FIELDS = {"ki": ("N/A", "force per ampere"), "kx": ("N/m", "negative stiffness")}

    def __init__(self, station: int, ki, kx=0.0, *, direction: str = "u", port: str | None = None,
                 name: str | None = None):
        super().__init__((station,), name, ki=ki, kx=kx)
        _positive(self, "ki", "kx", allow_zero=True)
        self.direction = direction
        self.port = port or f"i{station}"

    def dofs(self, layout):
        return [layout.dof(self.nodes[0], self.direction)]

    def stiffness_matrix(self, p, layout):
        return ca.reshape(-self.sym(p, "kx"), 1, 1)

    def input_ports(self):
        return [InputPort(self.port, self.nodes[0], self.direction, gain=self.param_name("ki"), unit="A")]
