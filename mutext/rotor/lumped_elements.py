r"""Springs and dampers between the nodes of a lumped chain or to ground: :class:`Spring`, :class:`Damper`.
"""
from __future__ import annotations

import casadi as ca

from ..errors import ModelError
from .element import Element, _positive, _translational

__all__ = ["Spring", "Damper"]


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
