r"""What every rotor element shares: parameters, the DOF layout, ports and the :class:`Element` interface.

:class:`Param` and :class:`ParameterSet` name the model parameters and hold
their CasADi symbols; :class:`Layout` numbers the degrees of freedom (see
:mod:`mutext.rotor.elements` for the three layouts); :class:`InputPort` and
:class:`OutputPort` name the inputs and outputs; :class:`Element` is the
interface each physical part implements (the shaft, disk, bearing, exciter
and lumped elements beside this module, and user elements such as the crack
of :mod:`mutext.rotor.crack`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import casadi as ca

from .._validation import AnyOf, InstanceOf, Integer, Real, check_param
from ..errors import ModelError

__all__ = ["Param", "ParameterSet", "Layout", "InputPort", "OutputPort", "Element"]


# ---------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Param:
    """A named model parameter with its nominal value (SI units).

    Pass the same :class:`Param` to several elements to make them share one
    symbol (e.g. one density for the whole shaft, tuned once).

    Attributes
    ----------
    name : str
        Name of the parameter (e.g. ``"shaft.E"``, ``"bearing1.k"``).
    value : float
        Nominal value (SI).
    unit : str
        Unit, for reports.
    doc : str
        What the parameter is, for reports.
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
        """Register ``param`` (once per name) and create its CasADi symbol.

        Parameters
        ----------
        param : Param
            The parameter; a second one of the same name must have the same nominal value.

        Returns
        -------
        str
            The parameter's name.
        """
        if not isinstance(param.name, str) or not param.name:
            raise ModelError(f"a parameter needs a non-empty name, got {param.name!r}")
        v = param.value
        check_param(f"parameter '{param.name}'", "nominal value", v, Real())
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
        """The layout's own name of a DOF label (aliases resolved); raises for a label the layout lacks.

        Parameters
        ----------
        label : str
            A DOF label or one of its aliases (``"x"`` for ``"u"``, ``"y"`` for ``"v"``).
        """
        lab = self.ALIASES[self.kind].get(label, label)
        if lab not in self.labels:
            raise ModelError(f"direction '{label}' does not exist in a '{self.kind}' model "
                             f"(DOFs per node: {', '.join(self.labels)})")
        return lab

    def check_node(self, node: int, what: str = "node") -> int:
        """``node`` if it lies in 1..n_nodes, else :class:`~mutext.errors.ModelError`.

        Parameters
        ----------
        node : int
            1-based node number.
        what : str, optional
            Name of the caller in the error message.
        """
        within = Integer(1, self.n_nodes)
        if not within.is_satisfied_by(node):
            raise ModelError(f"{what}: station/node {node!r} is outside 1..{self.n_nodes} "
                             f"(it must be {within.describe()})")
        return int(node)

    def dof(self, node: int, label: str) -> int:
        """0-based global index of DOF ``label`` at 1-based ``node``.

        Parameters
        ----------
        node : int
            1-based node number.
        label : str
            DOF label (or alias) at the node.
        """
        self.check_node(node)
        return (node - 1) * self.per_node + self.labels.index(self.label(label))

    def node_dofs(self, node: int) -> list[int]:
        """0-based global indices of all DOFs of ``node``.

        Parameters
        ----------
        node : int
            1-based node number.
        """
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

    Attributes
    ----------
    name : str
        Name of the port.
    node : int
        1-based station (node).
    direction : str
        DOF label at the node (``"u"``/``"x"``, ``"v"``/``"y"``, ``"theta"``, ``"psi"``).
    gain : str or None
        Name of the parameter multiplying the input, or None.
    unit : str
        Unit of the input (``"N"``, ``"N m"``, ``"A"``).
    """
    name: str
    node: int
    direction: str = "u"
    gain: str | None = None
    unit: str = "N"


@dataclass(frozen=True)
class OutputPort:
    """A named output: the displacement [m] or rotation [rad] of one DOF.

    Attributes
    ----------
    name : str
        Name of the port.
    node : int
        1-based station (node).
    direction : str
        DOF label at the node (``"u"``/``"x"``, ``"v"``/``"y"``, ``"theta"``, ``"psi"``).
    unit : str
        Unit of the output (``"m"`` or ``"rad"``).
    """
    name: str
    node: int
    direction: str = "u"
    unit: str = "m"


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

    Parameters
    ----------
    nodes : sequence of int
        1-based station (node) numbers the element occupies.
    name : str, optional
        Name of the element (default: its ``KIND`` and first node, e.g. ``"bearing3"``).
    **values
        One value per field of ``FIELDS``: a number (SI) or a :class:`Param` shared
        with other elements; ``None`` leaves the field out.
    """
    KIND = "element"
    FIELDS: dict[str, tuple[str, str]] = {}

    def __init__(self, nodes: Sequence[int], name: str | None = None, **values):
        self.nodes = tuple(int(check_param(self.KIND, "station/node number", n, Integer(lo=1))) for n in nodes)
        self.name = name if name is not None else f"{self.KIND}{self.nodes[0]}"
        self.values: dict[str, float | Param] = {}
        for f, v in values.items():
            if f not in self.FIELDS:
                raise ModelError(f"{self.name}: unknown field '{f}' (fields: {', '.join(self.FIELDS)})")
            if v is None:
                continue
            check_param(self.name, f, v, AnyOf(Real(), InstanceOf(Param)))
            self.values[f] = v
        self._pnames: dict[str, str] = {}

    def __repr__(self):
        vals = ", ".join(f"{k}={v.name}" if isinstance(v, Param) else f"{k}={v:g}"
                         for k, v in self.values.items())
        return f"{type(self).__name__}({self.name}: nodes {self.nodes}, {vals})"

    # -- parameters
    def nominal(self, field: str) -> float:
        """Nominal value (SI) of one of the element's fields.

        Parameters
        ----------
        field : str
            A field of ``FIELDS`` given to the element.
        """
        v = self.values[field]
        return v.value if isinstance(v, Param) else float(v)

    def declare(self, params: ParameterSet) -> None:
        """Register the element's parameters in ``params``.

        Parameters
        ----------
        params : ParameterSet
            The structure's parameters.
        """
        for f, v in self.values.items():
            unit, doc = self.FIELDS[f]
            if isinstance(v, Param):
                par = Param(v.name, v.value, v.unit or unit, v.doc or doc)
            else:
                par = Param(f"{self.name}.{f}", float(v), unit, f"{doc} ({self.name})")
            self._pnames[f] = params.add(par)

    def param_name(self, field: str) -> str:
        """Name of the structure parameter behind ``field`` (after :meth:`declare`).

        Parameters
        ----------
        field : str
            A field of ``FIELDS`` given to the element.
        """
        return self._pnames[field]

    def has(self, field: str) -> bool:
        """Whether the element was given a value for ``field``.

        Parameters
        ----------
        field : str
            A field of ``FIELDS``.
        """
        return field in self.values

    def sym(self, p: Mapping[str, ca.SX], field: str) -> ca.SX:
        """The CasADi symbol of one of the element's fields.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol.
        field : str
            A field of ``FIELDS`` given to the element.
        """
        return p[self._pnames[field]]

    # -- topology
    def check(self, layout: Layout) -> None:
        """Raise :class:`~mutext.errors.ModelError` if a node of the element is not in ``layout``.

        Parameters
        ----------
        layout : Layout
            The DOF numbering of the structure.
        """
        for n in self.nodes:
            layout.check_node(n, f"{self.name}")

    def dofs(self, layout: Layout) -> list[int]:
        """0-based global DOFs of the element's local matrices (default: all DOFs of its nodes).

        Parameters
        ----------
        layout : Layout
            The DOF numbering of the structure.
        """
        return [d for n in self.nodes for d in layout.node_dofs(n)]

    # -- matrices (override)
    def mass_matrix(self, p, layout):
        """Local mass matrix (CasADi ``SX``, ``len(dofs) x len(dofs)``) or None.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol (the structure's symbols; see :meth:`Element.sym`).
        layout : Layout
            The DOF numbering of the structure.
        """
        return None

    def damping_matrix(self, p, layout):
        """Local damping matrix (CasADi ``SX``, ``len(dofs) x len(dofs)``) or None.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol (the structure's symbols; see :meth:`Element.sym`).
        layout : Layout
            The DOF numbering of the structure.
        """
        return None

    def stiffness_matrix(self, p, layout):
        """Local stiffness matrix (CasADi ``SX``, ``len(dofs) x len(dofs)``) or None.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol (the structure's symbols; see :meth:`Element.sym`).
        layout : Layout
            The DOF numbering of the structure.
        """
        return None

    def gyroscopic_matrix(self, p, layout):
        """Local gyroscopic matrix per unit speed (CasADi ``SX``) or None.

        Parameters
        ----------
        p : mapping of str to casadi.SX
            Parameter name -> symbol (the structure's symbols; see :meth:`Element.sym`).
        layout : Layout
            The DOF numbering of the structure.
        """
        return None

    def input_ports(self) -> list[InputPort]:
        return []


def _positive(el: Element, *fields, allow_zero=False):
    # the sign rule is kept: values set later (``Structure.values``) obey it too
    rules = el.__dict__.setdefault("_sign_rules", {})
    for f in fields:
        rules[f] = allow_zero
        if f in el.values:
            v = el.nominal(f)
            if v < 0 or (v == 0 and not allow_zero):
                raise ModelError(f"{el.name}.{f} must be {'non-negative' if allow_zero else 'positive'}, got {v:g}")


def _translational(el: Element, layout: Layout, node: int) -> list[int]:
    if layout.kind == "rotor":
        return [layout.dof(node, "u"), layout.dof(node, "v")]
    return [layout.dof(node, layout.labels[0])]
