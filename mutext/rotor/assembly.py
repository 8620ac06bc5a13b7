r"""Assembly of elements into a model with symbolic parameters.

:class:`Structure` assembles any list of :class:`~mutext.rotor.elements.Element`
objects on a DOF :class:`~mutext.rotor.elements.Layout`; :class:`Rotor` is a
structure whose nodes are the stations of a shaft (two bending planes, or
one).  Assembly is the usual direct stiffness summation

.. math::
    M(p) = \sum_e L_e^T M_e(p) L_e,\qquad \text{likewise } C(p), K(p), G(p),

with :math:`L_e` the Boolean map of the element's DOFs into the global ones
(Friswell et al. 2010, ch. 5).  The element matrices are CasADi ``SX``
expressions of the parameter vector :math:`p`, so the global ones are too;
CasADi ``Function`` objects for :math:`M, C, K, G` and the input matrix
:math:`B` are built once in the constructor, and every numeric evaluation
(:meth:`Structure.matrices`) is a call of those compiled expression graphs
(tens of microseconds).  The same functions give exact derivatives with
respect to any parameter (``casadi.jacobian``) for model updating with IPOPT.

The equation of motion at spin speed :math:`\Omega` [rad/s] is

.. math::
    M\ddot q + (C + \Omega G)\dot q + K q = B\,u,\qquad y = C_y q ,

where :math:`u` stacks the named inputs (forces [N], moments [N m], exciter
currents [A]) and :math:`y` the named outputs (displacements [m], rotations [rad]).

Extension hook (cracks and other local flexibilities)
-----------------------------------------------------
Any object that follows the :class:`~mutext.rotor.elements.Element`
protocol can be passed in ``elements``; its ``stiffness_matrix(p, layout)``
(and the mass/damping/gyroscopic methods) return CasADi expressions that are
*added* to the global matrices on the DOFs returned by its ``dofs(layout)``.
Before anything is built, the assembly calls ``element.bind(structure)`` if
the element defines it, so an element can look up the shaft element it sits
in (:meth:`Rotor.shaft_element`) and reuse that element's parameter symbols.
A crack at a station is then an element whose stiffness is the *difference*
between the stiffness of the host shaft element with an extra local
rotational compliance and the intact one; :class:`ShaftFlexibility` below is
that element for a given compliance (see :func:`shaft_stiffness_with_compliance`).

References
----------
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010, ch. 5.
C. A. Papadopoulos and A. D. Dimarogonas, "Coupled longitudinal and bending
vibrations of a rotating shaft with an open crack", *J. Sound Vib.* 117 (1987)
81-93 (local flexibility of a crack inside a beam element).
"""
from __future__ import annotations

import difflib
import math
import time
from dataclasses import dataclass
from typing import Mapping, NamedTuple, Sequence

import casadi as ca
import numpy as np

from ..errors import ModelError
from .elements import (Element, InputPort, Layout, OutputPort, Param, ParameterSet, ShaftElement,
                       plane_to_rotor)

__all__ = ["Matrices", "ProportionalDamping", "ModalDamping", "Structure", "Rotor",
           "modal_damping_matrix", "shaft_stiffness_with_compliance", "ShaftFlexibility"]


class Matrices(NamedTuple):
    """Numeric model matrices (SI), each ``ndof x ndof``.

    ``C`` is the non-rotating damping (discrete dampers, proportional and
    modal damping); the rotating system's velocity matrix is ``C + speed * G``.

    Attributes
    ----------
    M : (ndof, ndof) ndarray
        Mass matrix [kg, kg m^2].
    C : (ndof, ndof) ndarray
        Non-rotating damping matrix [N s/m].
    K : (ndof, ndof) ndarray
        Stiffness matrix [N/m].
    G : (ndof, ndof) ndarray
        Gyroscopic matrix per unit speed (multiplied by the speed in rad/s).
    """
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    G: np.ndarray


@dataclass(frozen=True)
class ProportionalDamping:
    r"""Rayleigh damping :math:`C \mathrel{+}= \alpha M + \beta K`.

    ``alpha`` [1/s] and ``beta`` [s] become the parameters
    ``damping.alpha`` and ``damping.beta`` (symbolic, like all others).
    A mode of frequency :math:`\omega` gets the damping ratio
    :math:`\zeta = \alpha/(2\omega) + \beta\omega/2`.

    Attributes
    ----------
    alpha : float
        Mass-proportional coefficient [1/s].
    beta : float
        Stiffness-proportional coefficient [s].
    """
    alpha: float = 0.0
    beta: float = 0.0


@dataclass(frozen=True)
class ModalDamping:
    r"""The same damping ratio :math:`\zeta` in every mode of the non-rotating structure.

    .. math:: C_m = M\Phi\,\mathrm{diag}(2\zeta\omega_r)\,\Phi^T M,\qquad \Phi^T M\Phi = I,

    from the undamped modes :math:`(\omega_r, \Phi)` of :math:`(K, M)` at the
    evaluated parameters (rigid-body modes get none).  It depends on the
    eigenvectors, so it is added numerically by :meth:`Structure.matrices`
    and is *not* part of the symbolic function ``C(p)``.

    Attributes
    ----------
    ratio : float
        Damping ratio of every mode (0.01 is 1 %).
    """
    ratio: float = 0.01

    def __post_init__(self):
        if not (isinstance(self.ratio, (int, float)) and 0 <= self.ratio < 1):
            raise ModelError(f"modal damping ratio must be in [0, 1), got {self.ratio!r}")


def _dense(dm: ca.DM) -> np.ndarray:
    """A CasADi matrix as a dense numpy array, filled from its nonzeros (``DM.full`` goes through a
    Python list of every entry: a tenth of a second for a 200-element rotor's matrices)."""
    out = np.zeros(dm.shape)
    r, c = dm.sparsity().get_triplet()
    out[r, c] = dm.nonzeros()
    return out


class _Assembler:
    """Sums element matrices into a global ``n x n`` SX matrix in one step.

    Each element's local matrix is kept with its global DOFs; :meth:`matrix` sums the entries that
    share a global position (one sparse product) and builds the matrix from the triplets: setting
    the global matrix element by element cost a copy of its sparsity per element."""

    def __init__(self, n: int):
        self.n = n
        self.rows: list[np.ndarray] = []
        self.cols: list[np.ndarray] = []
        self.values: list = []

    def add(self, idx: list[int], local, who: str, what: str) -> None:
        local = ca.SX(local)
        k = len(idx)
        if local.shape != (k, k):
            raise ModelError(f"{who}: {what} matrix is {local.shape[0]}x{local.shape[1]} but the element has "
                             f"{k} DOFs")
        idx = np.asarray(idx, dtype=np.int64)
        # column-major, as ca.vec orders the entries
        self.rows.append(np.tile(idx, k))
        self.cols.append(np.repeat(idx, k))
        self.values.append(ca.vec(local))

    def matrix(self) -> ca.SX:
        if not self.values:
            return ca.SX(self.n, self.n)
        r, c = np.concatenate(self.rows), np.concatenate(self.cols)
        key = c * self.n + r
        uniq, where = np.unique(key, return_inverse=True)
        summing = ca.DM(ca.Sparsity.triplet(uniq.size, key.size, where.tolist(), list(range(key.size))),
                        np.ones(key.size))
        entries = ca.densify(ca.mtimes(summing, ca.vertcat(*self.values)))
        return ca.SX.triplet((uniq % self.n).tolist(), (uniq // self.n).tolist(), entries, self.n, self.n)


class Structure:
    """A linear mechanical model assembled from elements, with symbolic parameters.

    Parameters
    ----------
    elements : sequence of Element
    layout : {"rotor", "plane", "lumped"}
        DOFs per node (see :class:`~mutext.rotor.elements.Layout`).
    n_nodes : int, optional
        Number of nodes (default: the largest node number used by an element).
    node_names : sequence of str, optional
    inputs : sequence of InputPort
        Force/moment inputs (elements such as exciters add their own ports).
    outputs : sequence of OutputPort
        Displacement/rotation outputs.
    damping : ProportionalDamping or ModalDamping, optional
    name : str

    Attributes
    ----------
    parameters : list of Param
        Names, nominal values (SI) and units, in the order of the parameter vector.
    functions : dict of casadi.Function
        ``"M"``, ``"C"``, ``"K"``, ``"G"`` (``ndof x ndof``) and ``"B"``
        (``ndof x ninputs``), each a function of the parameter vector ``p``
        (``functions["K"](p)``).  ``C`` excludes modal damping.
    p : casadi.SX
        The parameter vector (symbols); ``symbolic`` holds ``M, C, K, G, B`` as expressions of it.
    build_seconds : float
        Time spent building the symbolic model and its functions.
    """

    def __init__(self, elements: Sequence[Element], *, layout: str = "rotor", n_nodes: int | None = None,
                 node_names: Sequence[str] | None = None, inputs: Sequence[InputPort] = (),
                 outputs: Sequence[OutputPort] = (), damping=None, name: str = "model"):
        t0 = time.perf_counter()
        self.name = name
        self.elements = list(elements)
        if not self.elements:
            raise ModelError(f"{name}: a model needs at least one element")
        for el in self.elements:
            if not hasattr(el, "nodes") or not hasattr(el, "name"):
                raise ModelError(f"{name}: {el!r} is not an element (needs 'nodes' and 'name')")
        used = max(max(el.nodes) for el in self.elements)
        n_nodes = used if n_nodes is None else n_nodes
        self.layout = Layout(layout, n_nodes, node_names)
        seen = {}
        for el in self.elements:
            if el.name in seen:
                raise ModelError(f"{name}: two elements are named '{el.name}' ({seen[el.name]!r} and {el!r}); "
                                 "element names must be unique (they prefix the parameter names)")
            seen[el.name] = el
            el.check(self.layout)
        self.element_by_name = seen
        if damping is not None and not isinstance(damping, (ProportionalDamping, ModalDamping)):
            raise ModelError(f"{name}: damping must be ProportionalDamping or ModalDamping, got {damping!r}")
        self.damping = damping
        for el in self.elements:
            if hasattr(el, "bind"):
                el.bind(self)

        # parameters
        ps = ParameterSet()
        for el in self.elements:
            el.declare(ps)
        if isinstance(damping, ProportionalDamping):
            for f, unit in (("alpha", "1/s"), ("beta", "s")):
                v = getattr(damping, f)
                par = v if isinstance(v, Param) else Param(f"damping.{f}", float(v), unit,
                                                             "proportional damping coefficient")
                ps.add(par)
        self._ps = ps
        self.parameters: list[Param] = ps.params
        self.parameter_names: list[str] = ps.names
        self.nominal = np.array([q.value for q in self.parameters], dtype=float)
        self._index = {n: i for i, n in enumerate(self.parameter_names)}
        # parameters whose sign the elements restrict (a bearing's stiffness, a mass): values set
        # through ``values=`` are held to the same rule as the model file's
        self._sign_rules: dict[int, tuple[bool, str]] = {}
        for el in self.elements:
            for f, allow_zero in getattr(el, "_sign_rules", {}).items():
                if el.has(f):
                    i = self._index[el.param_name(f)]
                    old = self._sign_rules.get(i)
                    self._sign_rules[i] = (allow_zero and (old is None or old[0]), f"{el.name}.{f}")
        self._ruled = np.zeros(self.nominal.size, bool)
        self._strict = np.zeros(self.nominal.size, bool)
        for i, (allow_zero, _) in self._sign_rules.items():
            self._ruled[i], self._strict[i] = True, not allow_zero
        p = ps.symbols
        self.p = ps.vector

        # assembly
        n = self.layout.ndof
        parts = {meth: _Assembler(n) for meth in ("mass_matrix", "damping_matrix", "stiffness_matrix",
                                                  "gyroscopic_matrix")}
        for el in self.elements:
            idx = el.dofs(self.layout)
            for meth, part in parts.items():
                loc = getattr(el, meth)(p, self.layout)
                if loc is not None:
                    part.add(idx, loc, el.name, meth.split("_")[0])
        M, C, K, G = (part.matrix() for part in parts.values())
        if isinstance(damping, ProportionalDamping):
            C = C + p[self._ps_name(damping.alpha, "alpha")] * M + p[self._ps_name(damping.beta, "beta")] * K

        # ports
        ins = list(inputs)
        for el in self.elements:
            if hasattr(el, "input_ports"):
                ins.extend(el.input_ports())
        self.inputs = self._check_ports(ins, "input")
        self.outputs = self._check_ports(list(outputs), "output")
        B = ca.SX(n, max(len(self.inputs), 0))
        for j, port in enumerate(self.inputs):
            d = self.layout.dof(port.node, port.direction)
            B[d, j] = p[port.gain] if port.gain is not None else 1.0
        self.input_names = [q.name for q in self.inputs]
        self.output_names = [q.name for q in self.outputs]
        self.output_dofs = [self.layout.dof(q.node, q.direction) for q in self.outputs]

        self.symbolic = {"M": M, "C": C, "K": K, "G": G, "B": B}
        self.functions = {k: ca.Function(k, [self.p], [v], ["p"], [k]) for k, v in self.symbolic.items()}
        self._all = ca.Function("MCKGB", [self.p], [M, C, K, G, B], ["p"], ["M", "C", "K", "G", "B"])
        self._modal_cache = None
        self.build_seconds = time.perf_counter() - t0

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _ps_name(v, field):
        return v.name if isinstance(v, Param) else f"damping.{field}"

    def _check_ports(self, ports, kind):
        out, names = [], set()
        for port in ports:
            if port.name in names:
                raise ModelError(f"{self.name}: two {kind}s are named '{port.name}'")
            names.add(port.name)
            self.layout.check_node(port.node, f"{kind} '{port.name}'")
            self.layout.label(port.direction)
            if kind == "input" and port.gain is not None and port.gain not in self._index:
                raise ModelError(f"{self.name}: input '{port.name}' has gain parameter '{port.gain}', "
                                 "which no element declares")
            out.append(port)
        return out

    @property
    def ndof(self) -> int:
        return self.layout.ndof

    @property
    def dof_names(self) -> list[str]:
        return self.layout.dof_names

    def parameter(self, name: str) -> Param:
        """The :class:`Param` called ``name``.

        Parameters
        ----------
        name : str
            Parameter name (e.g. ``"bearing1.k"``).
        """
        return self.parameters[self._lookup(name)]

    def _lookup(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            close = difflib.get_close_matches(name, self.parameter_names, n=3, cutoff=0.5)
            hint = f"; did you mean {', '.join(close)}?" if close else ""
            raise ModelError(f"{self.name}: unknown parameter '{name}'{hint}") from None

    def values(self, values=None) -> np.ndarray:
        """Parameter vector: nominal values, updated by ``values``.

        ``values`` is ``None``, a mapping ``name -> value`` (SI) overriding some
        nominal values, or a full vector in the order of :attr:`parameters`.

        Parameters
        ----------
        values : mapping, array_like or None, optional
            Overrides of nominal values by name, or the full vector.
        """
        if values is None:
            return self.nominal.copy()
        if isinstance(values, Mapping):
            v = self.nominal.copy()
            changed = []
            for k, x in values.items():
                i = self._lookup(k)
                try:
                    v[i] = float(x)
                except (TypeError, ValueError):
                    raise ModelError(f"{self.name}: parameter '{k}' must be a number, got {x!r}") from None
                changed.append(i)
            self._check_values(v, changed)
            return v
        try:
            v = np.asarray(values, dtype=float).ravel()
        except (TypeError, ValueError):
            raise ModelError(f"{self.name}: parameter values must be numbers, got {values!r}") from None
        if v.shape != self.nominal.shape:
            raise ModelError(f"{self.name}: expected {self.nominal.size} parameter values, got {v.size}")
        self._check_values(v, range(v.size))
        return v

    def _check_values(self, v: np.ndarray, indices) -> None:
        """Named error for a value that is not finite or breaks its element's sign rule."""
        idx = np.asarray(list(indices), dtype=int)
        if idx.size == 0:
            return
        x = v[idx]
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(x) | (self._ruled[idx] & ((x < 0) | (self._strict[idx] & (x == 0))))
        if not bad.any():
            return
        i = int(idx[np.argmax(bad)])
        x = v[i]
        if not np.isfinite(x):
            raise ModelError(f"{self.name}: parameter '{self.parameter_names[i]}' must be finite, got {x:g}")
        allow_zero, where = self._sign_rules[i]
        need = "non-negative" if allow_zero else "positive"
        name = self.parameter_names[i]
        where = f" ({where})" if where != name else ""
        raise ModelError(f"{self.name}: parameter '{name}'{where} must be {need}, got {x:g}")

    # ------------------------------------------------------------------ numeric
    def evaluate(self, values=None):
        """``(M, C, K, G, B)`` as numpy arrays at ``values``, without modal damping.

        Parameters
        ----------
        values : mapping or array_like, optional
            Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
            vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).
        """
        out = self._all(self.values(values))
        return tuple(_dense(x) for x in out)

    def matrices(self, values=None) -> Matrices:
        """Numeric ``Matrices(M, C, K, G)`` [SI] at ``values`` (default: nominal).

        ``C`` includes modal damping if the model has :class:`ModalDamping`.

        Parameters
        ----------
        values : mapping or array_like, optional
            Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
            vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).
        """
        v = self.values(values)
        M, C, K, G, _ = self.evaluate(v)
        if isinstance(self.damping, ModalDamping) and self.damping.ratio > 0:
            key = v.tobytes()
            if self._modal_cache is None or self._modal_cache[0] != key:
                self._modal_cache = (key, modal_damping_matrix(M, K, self.damping.ratio))
            C = C + self._modal_cache[1]
        return Matrices(M, C, K, G)

    def input_matrix(self, values=None) -> np.ndarray:
        """``B`` (``ndof x ninputs``): column j is the generalized force of a unit input j.

        Parameters
        ----------
        values : mapping or array_like, optional
            Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
            vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).
        """
        return np.asarray(self.functions["B"](self.values(values)).full())

    def output_matrix(self) -> np.ndarray:
        """``C_y`` (``noutputs x ndof``) selecting the output DOFs."""
        Cy = np.zeros((len(self.outputs), self.ndof))
        for i, d in enumerate(self.output_dofs):
            Cy[i, d] = 1.0
        return Cy

    # ------------------------------------------------------------------ analysis shortcuts
    def modes(self, **kw):
        """See :func:`mutext.rotor.analysis.modes`.

        Parameters
        ----------
        **kw
            Keyword arguments of the function referred to.
        """
        from .analysis import modes
        return modes(self, **kw)

    def natural_frequencies(self, **kw) -> np.ndarray:
        """See :func:`mutext.rotor.analysis.natural_frequencies` (Hz).

        Parameters
        ----------
        **kw
            Keyword arguments of the function referred to.
        """
        from .analysis import natural_frequencies
        return natural_frequencies(self, **kw)

    def frf(self, freqs_hz, **kw):
        """See :func:`mutext.rotor.analysis.frf`.

        Parameters
        ----------
        freqs_hz : array_like
            Frequencies [Hz].
        **kw
            Keyword arguments of the function referred to.
        """
        from .analysis import frf
        return frf(self, freqs_hz, **kw)

    def state_space(self, **kw):
        """See :func:`mutext.rotor.analysis.state_space`.

        Parameters
        ----------
        **kw
            Keyword arguments of the function referred to.
        """
        from .analysis import state_space
        return state_space(self, **kw)

    def __repr__(self):
        return (f"{type(self).__name__}('{self.name}': {len(self.elements)} elements, {self.layout.n_nodes} "
                f"nodes, {self.ndof} DOFs, {len(self.parameters)} parameters, inputs {self.input_names}, "
                f"outputs {self.output_names})")


def modal_damping_matrix(M: np.ndarray, K: np.ndarray, ratio: float) -> np.ndarray:
    r""":math:`C = M\Phi\,\mathrm{diag}(2\zeta\omega_r)\,\Phi^T M` from the modes of ``(K, M)``.

    Modes with :math:`\omega_r^2 \le 10^{-12}\max\omega^2` (rigid-body or
    unstable) get no damping.

    Parameters
    ----------
    M : (ndof, ndof) ndarray
        Mass matrix (symmetric positive definite).
    K : (ndof, ndof) ndarray
        Stiffness matrix (its symmetric part is used).
    ratio : float
        Damping ratio of every mode.
    """
    import scipy.linalg as sla

    from .analysis import blas_single_thread
    Ks = 0.5 * (K + K.T)
    with blas_single_thread():
        try:
            lam, Phi = sla.eigh(Ks, M)
        except np.linalg.LinAlgError:
            raise ModelError("modal damping needs a positive definite mass matrix (every DOF needs mass "
                             "or rotary inertia)") from None
    lam_max = max(float(np.max(np.abs(lam))), 1e-300)
    w = np.where(lam > 1e-12 * lam_max, np.sqrt(np.maximum(lam, 0.0)), 0.0)
    MPhi = M @ Phi
    return MPhi @ np.diag(2.0 * ratio * w) @ MPhi.T


class Rotor(Structure):
    """A shaft model whose nodes are stations.

    Parameters
    ----------
    elements : sequence of Element
        Shaft, disk, bearing, exciter elements (and any hook element).
    planes : {2, 1}
        2: two bending planes with gyroscopic coupling (4 DOF per station);
        1: the x-z plane only (2 DOF per station).
    speed : float
        Default spin speed [rad/s] for the analyses.
    n_stations : int, optional
        Default: the largest station number used.
    inputs, outputs, damping, name
        As for :class:`Structure`.

    Attributes
    ----------
    positions : numpy.ndarray
        Axial position of each station [m] (from the shaft element lengths).
    """

    def __init__(self, elements: Sequence[Element], *, planes: int = 2, speed: float = 0.0,
                 n_stations: int | None = None, inputs: Sequence[InputPort] = (),
                 outputs: Sequence[OutputPort] = (), damping=None, name: str = "rotor"):
        if planes not in (1, 2):
            raise ModelError(f"{name}: planes must be 1 or 2, got {planes!r}")
        if not (isinstance(speed, (int, float)) and math.isfinite(speed)):
            raise ModelError(f"{name}: speed must be a finite number [rad/s], got {speed!r}")
        self.planes = planes
        self.speed = float(speed)
        self._shafts: dict[int, ShaftElement] = {}
        for el in elements:
            if isinstance(el, ShaftElement):
                s = el.nodes[0]
                if s in self._shafts:
                    raise ModelError(f"{name}: two shaft elements start at station {s} "
                                     f"('{self._shafts[s].name}' and '{el.name}')")
                self._shafts[s] = el
        super().__init__(elements, layout="rotor" if planes == 2 else "plane", n_nodes=n_stations,
                         inputs=inputs, outputs=outputs, damping=damping, name=name)
        pos = np.zeros(self.layout.n_nodes)
        for s in range(1, self.layout.n_nodes):
            el = self._shafts.get(s)
            pos[s] = pos[s - 1] + (el.nominal("L") if el is not None else 0.0)
        self.positions = pos

    @property
    def n_stations(self) -> int:
        return self.layout.n_nodes

    def shaft_element(self, station: int) -> ShaftElement:
        """The shaft element that starts at ``station`` (1-based).

        Parameters
        ----------
        station : int
            1-based station where the element starts.
        """
        try:
            return self._shafts[station]
        except KeyError:
            raise ModelError(f"{self.name}: no shaft element starts at station {station} "
                             f"(stations with one: {sorted(self._shafts)[:3]}...)") from None

    def campbell(self, speeds, n_modes: int = 6, **kw):
        """See :func:`mutext.rotor.campbell` (the Campbell diagram with its critical speeds).

        Parameters
        ----------
        speeds : sequence of float
            Spin speeds [rad/s].
        n_modes : int, optional
            Number of lowest modes kept at each speed.
        **kw
            Keyword arguments of the function referred to.
        """
        from .campbell_diagram import campbell
        return campbell(self, speeds, n_modes, **kw)


# ---------------------------------------------------------------------------
# local rotational flexibility inside a shaft element (the crack hook)
# ---------------------------------------------------------------------------

def shaft_stiffness_with_compliance(shaft: ShaftElement, p, c_rot, xi=0.0):
    r"""Plane stiffness (4x4) of a shaft element with an extra rotational compliance.

    A hinge spring of compliance :math:`c` [rad/(N m)] at :math:`z = \xi L`
    adds the rotation jump :math:`c\,M(\xi L)` to the cantilever flexibility of
    the element.  Clamping node 1 and loading node 2 with shear force
    :math:`P` and moment :math:`M_2`, the bending moment at the hinge is
    :math:`M_2 + P(1-\xi)L`, so (Papadopoulos and Dimarogonas 1987)

    .. math::
        F = F_0 + c\begin{bmatrix}((1-\xi)L)^2 & (1-\xi)L\\ (1-\xi)L & 1\end{bmatrix},
        \qquad F_0 = K_{22}^{-1},

    where :math:`K_{22}` is the node-2 block of the intact Timoshenko
    stiffness, and the element stiffness is :math:`T F^{-1} T^T` with the
    equilibrium matrix :math:`T = [-1, 0; -L, -1; 1, 0; 0, 1]` mapping the
    node-2 forces to all four nodal forces.  ``c_rot = 0`` returns the intact
    matrix.  ``p`` maps parameter names to symbols; ``c_rot`` and ``xi`` are
    CasADi expressions or floats.

    Parameters
    ----------
    shaft : ShaftElement
        The host element.
    p : mapping of str to casadi.SX
        Parameter name -> symbol.
    c_rot : casadi.SX or float
        Rotational compliance of the hinge [rad/(N m)].
    xi : casadi.SX or float, optional
        Position of the hinge, 0 (first node) to 1 (second node).
    """
    Mt, Mr, K0 = shaft.plane_matrices(p)
    L = shaft.sym(p, "L")
    K22 = K0[2:4, 2:4]
    det = K22[0, 0] * K22[1, 1] - K22[0, 1] * K22[1, 0]
    F0 = ca.blockcat([[K22[1, 1], -K22[0, 1]], [-K22[1, 0], K22[0, 0]]]) / det
    a = (1.0 - xi) * L
    F = F0 + c_rot * ca.blockcat([[a * a, a], [a, 1.0]])
    detF = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    Kc = ca.blockcat([[F[1, 1], -F[0, 1]], [-F[1, 0], F[0, 0]]]) / detF
    T = ca.blockcat([[-1.0, 0.0], [-L, -1.0], [1.0, 0.0], [0.0, 1.0]])
    return ca.mtimes([T, Kc, T.T])


class ShaftFlexibility(Element):
    r"""Extra local rotational compliance inside the shaft element starting at ``station``.

    The hook for crack models: adds :math:`\Delta K = K(c) - K(0)` (see
    :func:`shaft_stiffness_with_compliance`) on the two stations of the host
    element, where the compliances ``c_x`` (bending in the x-z plane) and
    ``c_y`` (y-z plane) [rad/(N m)] are parameters.  A crack model (e.g.
    ``mutext.rotor.crack``) computes the compliance from the depth ratio and
    either subclasses this element or returns such a matrix from its own
    ``stiffness_matrix(p, layout)``.

    Parameters
    ----------
    station : int
        Left station of the host shaft element.
    c_x : float or Param
        Compliance for bending in the x-z plane [rad/(N m)].
    c_y : float or Param, optional
        Compliance in the y-z plane (default: the same parameter as ``c_x``).
    xi : float
        Position of the hinge in the element, 0 (at ``station``) to 1.
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"flexibility3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "flexibility"
    FIELDS = {"c_x": ("rad/(N m)", "rotational compliance, x-z plane"),
              "c_y": ("rad/(N m)", "rotational compliance, y-z plane")}

    def __init__(self, station: int, c_x, c_y=None, *, xi: float = 0.0, name: str | None = None):
        super().__init__((station, station + 1), name, c_x=c_x, c_y=c_y)
        if not 0.0 <= xi <= 1.0:
            raise ModelError(f"{self.name}: xi must be in [0, 1], got {xi}")
        for f in ("c_x", "c_y"):
            if f in self.values and self.nominal(f) < 0:
                raise ModelError(f"{self.name}.{f} must be non-negative, got {self.nominal(f):g}")
        self.xi = float(xi)
        self.host: ShaftElement | None = None

    def bind(self, structure):
        """Find the host shaft element (the one starting at ``station``) in ``structure``.

        Parameters
        ----------
        structure : Rotor
            The structure the element is part of.
        """
        if not isinstance(structure, Rotor):
            raise ModelError(f"{self.name}: a shaft flexibility needs a Rotor")
        self.host = structure.shaft_element(self.nodes[0])

    def plane_delta(self, p, c):
        """Plane (4x4) stiffness change of the host element for the compliance ``c``.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol.
        c : casadi.SX or float
            Rotational compliance of the hinge [rad/(N m)].
        """
        K0 = self.host.plane_matrices(p)[2]
        return shaft_stiffness_with_compliance(self.host, p, c, self.xi) - K0

    def stiffness_matrix(self, p, layout):
        cx = self.sym(p, "c_x")
        cy = self.sym(p, "c_y") if self.has("c_y") else cx
        dx = self.plane_delta(p, cx)
        if layout.kind == "plane":
            return dx
        return plane_to_rotor(dx, self.plane_delta(p, cy))
