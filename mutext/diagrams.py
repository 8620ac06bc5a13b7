r"""Block diagrams of the book's interconnections, drawn with schemdraw.

Each diagram is data first (:class:`Diagram`: blocks, summing junctions and
wires with their corner points) and a picture second (:func:`draw`).  The data
form lets the signal-flow graph be read back from the geometry
(:func:`signal_graph`: which block feeds which, through which signal), so a test
can check that a drawing is the interconnection it claims to be, for instance
that the generalized plant's drawing closes :math:`u = K y` and nothing else.

The diagrams (keys of :data:`DIAGRAMS`):

``generalized_plant``
    :math:`P` and :math:`K`, the lower LFT :math:`\mathcal F_\ell(P, K)`
    (thesis fig. 2.1; [ZDG]_ sec. 10.1).
``lft_upper``, ``lft_lower``
    The two linear fractional transformations (thesis fig. 2.4):
    :math:`\mathcal F_u(P, \Delta)` and :math:`\mathcal F_\ell(P, K)`.
``m_delta``
    The :math:`M`-:math:`\Delta` loop of robust stability ([ZDG]_ sec. 9.2).
``m_delta_performance``
    :math:`M` with the uncertainty :math:`\Delta` above and the fictitious
    performance block :math:`\Delta_P` below: the main loop theorem
    ([PD]_ sec. 9).
``two_mass_mu``
    The two-mass problem of the thesis (sec. 2.3.2, fig. 2.2): weights
    :math:`W_w`, :math:`W_z^{-1}`, the plant :math:`G` with its parameter block
    :math:`\Delta = \operatorname{diag}(\delta_{m_1}, \delta_{m_2},
    \delta_{k_1}, \delta_{k_2})` and the controller.
``dk_scaled``
    The K step of D-K iteration: :math:`\hat D P \hat D^{-1}` (thesis fig. 2.3).
``mbi``
    Model-based identification by mu-synthesis (thesis figs. 3.2-3.3): true
    system with its uncertainty, engineering model with the controller at the
    suspect place, the difference of the measured outputs weighted by
    :math:`W_z^{-1}`.
``crack_mbi``
    The same interconnection for the cracked rotor (thesis figs. 4.8-4.9):
    exciter current in, sensor displacement out, controller at the crack.

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996.
.. [PD] A. Packard and J. Doyle, "The complex structured singular value",
   *Automatica* 29(1), 71-109, 1993.
.. [M] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University, 2010.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .errors import UsageError

__all__ = ["Block", "Sum", "Wire", "Frame", "Diagram", "DIAGRAMS", "diagram", "draw", "signal_graph",
           "Edge"]

_TOL = 1e-9


@dataclass(frozen=True)
class Block:
    """A rectangular block: ``name`` (for the graph), centre ``(x, y)``, width, height, TeX ``text``.

    Attributes
    ----------
    name : str
        Name of the block in the signal graph.
    x, y : float
        Centre (drawing units).
    w, h : float
        Width and height (drawing units).
    text : str
        TeX label drawn inside.
    """
    name: str
    x: float
    y: float
    w: float
    h: float
    text: str

    def on_boundary(self, p) -> bool:
        """Whether point ``p`` lies on the block's outline.

        Parameters
        ----------
        p : (float, float)
            The point.
        """
        x, y = p
        l, r, b, t = self.x - self.w / 2, self.x + self.w / 2, self.y - self.h / 2, self.y + self.h / 2
        on_v = (abs(x - l) < _TOL or abs(x - r) < _TOL) and b - _TOL <= y <= t + _TOL
        on_h = (abs(y - b) < _TOL or abs(y - t) < _TOL) and l - _TOL <= x <= r + _TOL
        return on_v or on_h


@dataclass(frozen=True)
class Sum:
    """A summing junction: a circle of radius ``r`` at ``(x, y)``; ``signs`` maps an inlet side
    (``"top"``, ``"bottom"``, ``"left"``) to ``"+"`` or ``"-"``.

    Attributes
    ----------
    name : str
        Name of the junction in the signal graph.
    x, y : float
        Centre (drawing units).
    r : float
        Radius (drawing units).
    signs : tuple of (str, str)
        Pairs (inlet side, ``"+"`` or ``"-"``).
    """
    name: str
    x: float
    y: float
    r: float = 0.25
    signs: tuple = ()

    def on_boundary(self, p) -> bool:
        """Whether point ``p`` lies on the circle.

        Parameters
        ----------
        p : (float, float)
            The point.
        """
        return abs(((p[0] - self.x) ** 2 + (p[1] - self.y) ** 2) ** 0.5 - self.r) < 1e-6


@dataclass(frozen=True)
class Wire:
    """A signal: a polyline from its source to its target (arrow at the end).

    ``points`` are the corners; ``text`` labels it at the middle of segment ``seg``
    (default: the longest), on ``side`` (``"top"``, ``"bottom"``, ``"left"``,
    ``"right"``; default above a horizontal and outside a vertical segment).
    A wire that starts on another wire is a branch of it (drawn with a dot).

    Attributes
    ----------
    points : tuple of (float, float)
        The corners, from source to target.
    text : str
        TeX label.
    seg : int or None
        Index of the labelled segment (None: the longest).
    side : str or None
        Side of the label (None: the default for the segment's direction).
    """
    points: tuple
    text: str = ""
    seg: int | None = None
    side: str | None = None


@dataclass(frozen=True)
class Frame:
    """A dashed rectangle grouping blocks, given by its corners, labelled at its top-left.

    Attributes
    ----------
    x0, y0 : float
        One corner (drawing units).
    x1, y1 : float
        The opposite corner.
    text : str
        Label at the top-left.
    """
    x0: float
    y0: float
    x1: float
    y1: float
    text: str = ""


@dataclass(frozen=True)
class Diagram:
    """One block diagram: its parts, a caption and the size it is drawn at (inches).

    Attributes
    ----------
    name : str
        Key of the diagram in :data:`DIAGRAMS`.
    caption : str
        Caption in the book.
    blocks : tuple of Block
        The blocks.
    wires : tuple of Wire
        The signals.
    sums : tuple of Sum
        The summing junctions.
    frames : tuple of Frame
        The dashed groups.
    size : (float, float)
        Width and height of the drawing [in].
    """
    name: str
    caption: str
    blocks: tuple
    wires: tuple
    sums: tuple = ()
    frames: tuple = ()
    size: tuple = (5.0, 2.6)


@dataclass(frozen=True)
class Edge:
    """One signal of the graph: from block ``source`` to block ``target`` (None: outside).

    Attributes
    ----------
    source : str or None
        Name of the block the signal leaves (None: an external input).
    target : str or None
        Name of the block it enters (None: an external output).
    signal : str
        The wire's label.
    """
    source: str | None
    target: str | None
    signal: str


def _loop(cx, y_port, top_x, far_y, box_half_w, *, right: bool):
    """Corner points of a feedback wire from a port at height ``y_port`` on the block edge
    ``cx`` out to ``top_x`` and to a block at height ``far_y`` whose near edge is at
    ``box_half_w`` from the axis (right side going out, left side coming back)."""
    if right:
        return ((cx, y_port), (top_x, y_port), (top_x, far_y), (box_half_w, far_y))
    return ((-box_half_w, far_y), (top_x, far_y), (top_x, y_port), (cx, y_port))


def _plant_with(lower: Block | None, upper: Block | None, ext_in: str, ext_out: str, *,
                name: str, caption: str, p_text: str, labels=("", "", "", ""), size=(4.6, 3.0)):
    """A plant ``P`` (2 x 1.8 at the origin) with an optional block above (loop through its top
    ports) and below (loop through its bottom ports), and the remaining ports as external
    signals ``ext_in`` -> P -> ``ext_out``.  ``labels``: (upper out, upper in, lower out, lower in)."""
    P = Block("P", 0.0, 0.0, 2.0, 1.8, p_text)
    blocks = [P]
    wires = []
    top, bot = 0.45, -0.45
    if upper is not None:
        blocks.append(upper)
        hw = upper.w / 2
        wires.append(Wire(_loop(1.0, top, 1.8, upper.y, hw, right=True), labels[0], seg=1))
        wires.append(Wire(_loop(-1.0, top, -1.8, upper.y, hw, right=False), labels[1], seg=1))
    else:
        wires.append(Wire(((-3.0, top), (-1.0, top)), ext_in))
        wires.append(Wire(((1.0, top), (3.0, top)), ext_out))
    if lower is not None:
        blocks.append(lower)
        hw = lower.w / 2
        wires.append(Wire(_loop(1.0, bot, 1.8, lower.y, hw, right=True), labels[2], seg=1))
        wires.append(Wire(_loop(-1.0, bot, -1.8, lower.y, hw, right=False), labels[3], seg=1))
    else:
        wires.append(Wire(((-3.0, bot), (-1.0, bot)), ext_in, side="bottom"))
        wires.append(Wire(((1.0, bot), (3.0, bot)), ext_out, side="bottom"))
    return Diagram(name, caption, tuple(blocks), tuple(wires), size=size)


def _generalized_plant():
    return _plant_with(Block("K", 0.0, -2.2, 1.2, 0.9, "$K$"), None, "$w$", "$z$",
                       name="generalized_plant", p_text="$P$",
                       labels=("", "", "$y$", "$u$"),
                       caption="Generalized plant and controller: z = F_l(P, K) w")


def _lft_upper():
    return _plant_with(None, Block("Delta", 0.0, 2.2, 1.2, 0.9, r"$\Delta$"), "$w$", "$z$",
                       name="lft_upper", p_text="$P$", labels=(r"$z_\Delta$", r"$w_\Delta$", "", ""),
                       caption="Upper LFT: z = F_u(P, Delta) w")


def _lft_lower():
    return _plant_with(Block("K", 0.0, -2.2, 1.2, 0.9, "$K$"), None, "$w$", "$z$",
                       name="lft_lower", p_text="$P$", labels=("", "", "$y$", "$u$"),
                       caption="Lower LFT: z = F_l(P, K) w")


def _m_delta():
    M = Block("M", 0.0, 0.0, 1.6, 1.0, "$M$")
    D = Block("Delta", 0.0, 1.9, 1.2, 0.8, r"$\Delta$")
    wires = (Wire(((0.8, 0.0), (1.6, 0.0), (1.6, 1.9), (0.6, 1.9)), r"$z_\Delta$", seg=1),
             Wire(((-0.6, 1.9), (-1.6, 1.9), (-1.6, 0.0), (-0.8, 0.0)), r"$w_\Delta$", seg=1))
    return Diagram("m_delta", "The M-Delta loop", (M, D), wires, size=(3.0, 2.4))


def _m_delta_performance():
    M = Block("M", 0.0, 0.0, 1.8, 1.8, "$M$")
    D = Block("Delta", 0.0, 2.2, 1.2, 0.8, r"$\Delta$")
    DP = Block("Delta_P", 0.0, -2.2, 1.2, 0.8, r"$\Delta_P$")
    wires = (Wire(_loop(0.9, 0.45, 1.8, 2.2, 0.6, right=True), r"$z_\Delta$", seg=1),
             Wire(_loop(-0.9, 0.45, -1.8, 2.2, 0.6, right=False), r"$w_\Delta$", seg=1),
             Wire(_loop(0.9, -0.45, 1.8, -2.2, 0.6, right=True), "$z$", seg=1),
             Wire(_loop(-0.9, -0.45, -1.8, -2.2, 0.6, right=False), "$w$", seg=1))
    return Diagram("m_delta_performance", "Robust performance as robust stability: Delta_P closes w and z",
                   (M, D, DP), wires, size=(3.4, 3.4))


def _two_mass_mu():
    G = Block("G", 0.0, 0.0, 2.0, 2.0, "$G$")
    D = Block("Delta", 0.0, 2.4, 1.2, 0.8, r"$\Delta$")
    K = Block("K", 0.0, -2.4, 1.2, 0.8, "$K$")
    Ww = Block("W_w", -3.4, 0.0, 1.2, 0.8, "$W_w$")
    Wz = Block("W_z_inv", 3.4, 0.0, 1.2, 0.8, "$W_z^{-1}$")
    wires = (
        Wire(((-5.4, 0.0), (-4.0, 0.0)), "$w$"),
        Wire(((-2.8, 0.0), (-1.0, 0.0)), r"$f_e,\ \eta$"),
        Wire(((1.0, 0.0), (2.8, 0.0)), r"$x_1,\ u$"),
        Wire(((4.0, 0.0), (5.4, 0.0)), "$z$"),
        Wire(_loop(1.0, 0.6, 1.8, 2.4, 0.6, right=True), r"$z_\Delta$", seg=1),
        Wire(_loop(-1.0, 0.6, -1.8, 2.4, 0.6, right=False), r"$w_\Delta$", seg=1),
        Wire(_loop(1.0, -0.6, 1.8, -2.4, 0.6, right=True), "$y$", seg=1),
        Wire(_loop(-1.0, -0.6, -1.8, -2.4, 0.6, right=False), "$u$", seg=1),
    )
    frame = Frame(-4.3, -1.35, 4.3, 1.35, "$P$")
    return Diagram("two_mass_mu", "The two-mass problem of the thesis (fig. 2.2): weights, plant, "
                   "parameter block and controller", (G, D, K, Ww, Wz), wires, frames=(frame,),
                   size=(5.6, 3.4))


def _dk_scaled():
    P = Block("P", 0.0, 0.0, 2.0, 1.8, "$P$")
    Di = Block("D_inv", -3.0, 0.45, 1.2, 0.7, r"$\hat D^{-1}$")
    Do = Block("D", 3.0, 0.45, 1.2, 0.7, r"$\hat D$")
    K = Block("K", 0.0, -2.2, 1.2, 0.9, "$K$")
    wires = (
        Wire(((-5.0, 0.45), (-3.6, 0.45)), ""),
        Wire(((-2.4, 0.45), (-1.0, 0.45)), r"$w_\Delta,\ w$"),
        Wire(((1.0, 0.45), (2.4, 0.45)), r"$z_\Delta,\ z$"),
        Wire(((3.6, 0.45), (5.0, 0.45)), ""),
        Wire(_loop(1.0, -0.45, 1.8, -2.2, 0.6, right=True), "$y$", seg=1),
        Wire(_loop(-1.0, -0.45, -1.8, -2.2, 0.6, right=False), "$u$", seg=1),
    )
    return Diagram("dk_scaled", "K step of D-K iteration: the plant scaled by the fitted D(s)",
                   (P, Di, Do, K), wires, size=(6.0, 2.8))


def _mbi(name, caption, *, w_text, f_text, true_text, eng_text, xt, xe, k_text, uncertain, size):
    g = 1.6                                     # half width of the two system blocks
    Ww = Block("W_w", -5.0, 0.0, 1.2, 0.8, "$W_w$")
    Gt = Block("G_t", 0.0, 1.8, 2 * g, 1.2, true_text)
    Ge = Block("G_e", 0.0, -1.2, 2 * g, 1.2, eng_text)
    K = Block("K", 0.0, -3.2, 1.6, 0.8, k_text)
    Wz = Block("W_z_inv", 5.2, 0.0, 1.2, 0.8, "$W_z^{-1}$")
    S = Sum("sum", 3.4, 0.0, 0.25, (("top", "+"), ("bottom", "-")))
    blocks = [Ww, Gt, Ge, K, Wz]
    wires = [
        Wire(((-7.0, 0.0), (-5.6, 0.0)), w_text),
        Wire(((-4.4, 0.0), (-3.4, 0.0), (-3.4, 1.5), (-g, 1.5)), f_text, seg=2),
        Wire(((-3.4, 0.0), (-3.4, -0.9), (-g, -0.9)), "", seg=1),
        Wire(((g, 1.5), (3.4, 1.5), (3.4, 0.25)), xt, seg=0),
        Wire(((g, -0.9), (3.4, -0.9), (3.4, -0.25)), xe, seg=0, side="bottom"),
        Wire(((3.65, 0.0), (4.6, 0.0)), "$e$", side="bottom"),
        Wire(((5.8, 0.0), (7.0, 0.0)), "$z$"),
        Wire(_loop(g, -1.5, g + 0.7, -3.2, 0.8, right=True), "$y$", seg=1),
        Wire(_loop(-g, -1.5, -g - 0.7, -3.2, 0.8, right=False), "$-u$", seg=1),
    ]
    if uncertain:
        blocks.append(Block("Delta", 0.0, 3.5, 1.2, 0.8, r"$\Delta_t$"))
        wires.append(Wire(((g, 2.1), (g + 0.7, 2.1), (g + 0.7, 3.5), (0.6, 3.5)), r"$z_\Delta$", seg=1))
        wires.append(Wire(((-0.6, 3.5), (-g - 0.7, 3.5), (-g - 0.7, 2.1), (-g, 2.1)), r"$w_\Delta$", seg=1))
    return Diagram(name, caption, tuple(blocks), tuple(wires), sums=(S,), size=size)


def _mbi_three_mass():
    return _mbi("mbi", "Model-based identification by mu-synthesis (thesis figs. 3.2-3.3)",
                w_text="$w$", f_text="$f$ [N]", true_text="true rig $G_t$",
                eng_text="model $G_e$", xt="$x_t$", xe="$x_e$", k_text="$K$",
                uncertain=True, size=(6.4, 4.4))


def _crack_mbi():
    return _mbi("crack_mbi", "Identification of the crack (thesis figs. 4.8-4.9): exciter current in, "
                "sensor displacement out, controller at the crack station",
                w_text="$w$", f_text="$i$ [A]", true_text="cracked\nrotor",
                eng_text="healthy\nmodel", xt="$x_{13,t}$", xe="$x_{13,e}$",
                k_text="$K$", uncertain=False, size=(6.4, 3.6))


_BUILDERS = {
    "generalized_plant": _generalized_plant,
    "lft_upper": _lft_upper,
    "lft_lower": _lft_lower,
    "m_delta": _m_delta,
    "m_delta_performance": _m_delta_performance,
    "two_mass_mu": _two_mass_mu,
    "dk_scaled": _dk_scaled,
    "mbi": _mbi_three_mass,
    "crack_mbi": _crack_mbi,
}
#: Names of the diagrams :func:`draw` knows.
DIAGRAMS = tuple(_BUILDERS)


def diagram(name: str) -> Diagram:
    """The :class:`Diagram` called ``name`` (one of :data:`DIAGRAMS`).

    Parameters
    ----------
    name : str
        One of :data:`DIAGRAMS`.

    Raises
    ------
    UsageError
        ``name`` is not a known diagram (the message lists them).
    """
    if name not in _BUILDERS:
        raise UsageError(f"diagram {name!r} unknown; known diagrams: {', '.join(DIAGRAMS)}")
    return _BUILDERS[name]()


def _on_wire(p, wire: Wire) -> bool:
    pts = wire.points
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if (min(x0, x1) - _TOL <= p[0] <= max(x0, x1) + _TOL and min(y0, y1) - _TOL <= p[1] <= max(y0, y1) + _TOL
                and abs((x1 - x0) * (p[1] - y0) - (y1 - y0) * (p[0] - x0)) < _TOL):
            return True
    return False


def _part_at(d: Diagram, p):
    hits = [b.name for b in d.blocks + d.sums if b.on_boundary(p)]
    return hits[0] if len(hits) == 1 else (None if not hits else "|".join(hits))


def _branch_source(d: Diagram, wire: Wire):
    """The wire a branch starts on (its first point lies on another wire), or None."""
    for other in d.wires:
        if other is not wire and _on_wire(wire.points[0], other) and other.points[0] != wire.points[0]:
            return other
    return None


def signal_graph(d: Diagram) -> list[Edge]:
    r"""The signal-flow graph a diagram draws, read from its geometry.

    A wire's source is the block (or summing junction) on whose outline its first
    point lies, its target the one its last point touches; a wire that starts on
    another wire is a branch and has that wire's source.  A free end is ``None``
    (an external input or output).  The label of a branch is that of the wire it
    leaves.

    Parameters
    ----------
    d : Diagram
        The diagram.

    Returns
    -------
    list of Edge

    Examples
    --------
    >>> from mutext.diagrams import diagram, signal_graph
    >>> for e in signal_graph(diagram("generalized_plant")):
    ...     print(e.source, "->", e.target, e.signal)
    None -> P $w$
    P -> None $z$
    P -> K $y$
    K -> P $u$
    """
    edges = []
    for w in d.wires:
        src_wire, seen = w, set()
        while (parent := _branch_source(d, src_wire)) is not None and id(parent) not in seen:
            seen.add(id(parent))
            src_wire = parent
        source = _part_at(d, src_wire.points[0])
        target = _part_at(d, w.points[-1])
        edges.append(Edge(source, target, w.text or src_wire.text))
    return edges


def _schemdraw():
    try:
        import schemdraw
        import schemdraw.elements as elm
        from schemdraw import flow
    except ImportError:
        raise UsageError("block diagrams need schemdraw: pip install -e '.[book]' "
                         "(or pip install schemdraw)") from None
    return schemdraw, elm, flow


def _label_spot(wire: Wire):
    pts = wire.points
    segs = list(zip(pts, pts[1:]))
    k = wire.seg if wire.seg is not None else max(range(len(segs)), key=lambda i: abs(segs[i][1][0] - segs[i][0][0])
                                                  + abs(segs[i][1][1] - segs[i][0][1]))
    (x0, y0), (x1, y1) = segs[k]
    xm, ym = (x0 + x1) / 2, (y0 + y1) / 2
    horizontal = abs(y1 - y0) < _TOL
    side = wire.side or ("top" if horizontal else ("right" if xm > 0 else "left"))
    off = 0.22
    dx, dy, ha, va = {"top": (0, off, "center", "bottom"), "bottom": (0, -off, "center", "top"),
                      "left": (-off, 0, "right", "center"), "right": (off, 0, "left", "center")}[side]
    return xm + dx, ym + dy, ha, va


def draw(name: str, ax=None, fontsize: float = 12.0):
    r"""Draw diagram ``name`` (one of :data:`DIAGRAMS`) on matplotlib axes; return the figure.

    Parameters
    ----------
    name : str
        The diagram (see the module docstring).
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure of the diagram's size is made if omitted.
    fontsize : float
        Text size in points (12 pt prints at body-text size in the book's column).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    UsageError
        Unknown ``name``, or schemdraw is not installed.
    """
    d = diagram(name)
    schemdraw, elm, flow = _schemdraw()
    from ._mpl import pyplot
    plt = pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=d.size)
    fig = ax.figure
    schemdraw.use("matplotlib")
    dr = schemdraw.Drawing(canvas=ax, show=False)
    dr.config(fontsize=fontsize, lw=1.4)
    for b in d.blocks:
        dr.add(flow.Box(w=b.w, h=b.h).at((b.x, b.y)).anchor("center").label(b.text, fontsize=fontsize))
    for s in d.sums:
        dr.add(flow.Circle(r=s.r).at((s.x, s.y)).anchor("center"))
        for side, sign in s.signs:
            dx, dy = {"top": (-0.3, 0.42), "bottom": (-0.3, -0.42), "left": (-0.42, 0.3)}[side]
            dr.add(elm.Label().at((s.x + dx, s.y + dy)).label(sign, fontsize=fontsize))
    for w in d.wires:
        pts = w.points
        for i, (p0, p1) in enumerate(zip(pts, pts[1:])):
            last = i == len(pts) - 2
            dr.add(elm.Line(arrow="->" if last else None).at(p0).to(p1))
        if _branch_source(d, w) is not None:
            dr.add(flow.Dot(radius=0.07).at(pts[0]))
        if w.text:
            x, y, ha, va = _label_spot(w)
            ax.text(x, y, w.text, ha=ha, va=va, fontsize=fontsize)
    for f in d.frames:
        ax.add_patch(plt.Rectangle((f.x0, f.y0), f.x1 - f.x0, f.y1 - f.y0, fill=False, ls="--", lw=1.0,
                                   color="0.4"))
        if f.text:
            ax.text(f.x0 + 0.1, f.y1 - 0.1, f.text, ha="left", va="top", fontsize=fontsize, color="0.3")
    dr.draw()
    ax.set_aspect("equal")
    ax.axis("off")
    ax.autoscale()
    ax.margins(0.03)
    return fig
