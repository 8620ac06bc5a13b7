"""The book's block diagrams draw the interconnections they name.

The reference for each diagram is its signal-flow graph written out by hand from the
definitions (lower and upper LFT, Zhou, Doyle and Glover sec. 10.1; the model-based
identification plant of ``mutext.mbi``, thesis fig. 3.3); the graph of the drawing is
read back from its geometry (which block outline each wire starts and ends on).
"""
import sys

import pytest

from mutext import diagrams
from mutext.errors import UsageError

# (source, target) of every signal; None is the outside of the diagram
EXPECTED = {
    "generalized_plant": {(None, "P"), ("P", None), ("P", "K"), ("K", "P")},
    "lft_lower": {(None, "P"), ("P", None), ("P", "K"), ("K", "P")},
    "lft_upper": {(None, "P"), ("P", None), ("P", "Delta"), ("Delta", "P")},
    "m_delta": {("M", "Delta"), ("Delta", "M")},
    "m_delta_performance": {("M", "Delta"), ("Delta", "M"), ("M", "Delta_P"), ("Delta_P", "M")},
    "two_mass_mu": {(None, "W_w"), ("W_w", "G"), ("G", "W_z_inv"), ("W_z_inv", None),
                    ("G", "Delta"), ("Delta", "G"), ("G", "K"), ("K", "G")},
    "dk_scaled": {(None, "D_inv"), ("D_inv", "P"), ("P", "D"), ("D", None), ("P", "K"), ("K", "P")},
    "mbi": {(None, "W_w"), ("W_w", "G_t"), ("W_w", "G_e"), ("G_t", "sum"), ("G_e", "sum"),
            ("sum", "W_z_inv"), ("W_z_inv", None), ("G_e", "K"), ("K", "G_e"),
            ("G_t", "Delta"), ("Delta", "G_t")},
    "crack_mbi": {(None, "W_w"), ("W_w", "G_t"), ("W_w", "G_e"), ("G_t", "sum"), ("G_e", "sum"),
                  ("sum", "W_z_inv"), ("W_z_inv", None), ("G_e", "K"), ("K", "G_e")},
}


def test_every_diagram_has_a_reference_graph():
    assert set(diagrams.DIAGRAMS) == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_drawn_graph_is_the_interconnection(name):
    edges = diagrams.signal_graph(diagrams.diagram(name))
    got = [(e.source, e.target) for e in edges]
    assert len(got) == len(set(got)), f"{name}: a signal drawn twice: {got}"
    assert set(got) == EXPECTED[name]
    # every signal between two blocks is named (the outside ends may be unnamed only in dk_scaled)
    unnamed = [e for e in edges if not e.signal and e.source and e.target]
    assert not unnamed, unnamed


def test_loop_signals_follow_the_lft_convention():
    # F_l(P, K): P's lower output y goes to K, K's output u comes back (not the other way round)
    edges = {(e.source, e.target): e.signal for e in diagrams.signal_graph(diagrams.diagram("lft_lower"))}
    assert edges[("P", "K")] == "$y$" and edges[("K", "P")] == "$u$"
    edges = {(e.source, e.target): e.signal for e in diagrams.signal_graph(diagrams.diagram("lft_upper"))}
    assert edges[("P", "Delta")] == r"$z_\Delta$" and edges[("Delta", "P")] == r"$w_\Delta$"
    # the identification error is the true response minus the model's, in that order
    d = diagrams.diagram("mbi")
    (s,) = d.sums
    assert dict(s.signs) == {"top": "+", "bottom": "-"}
    into_sum = {e.source for e in diagrams.signal_graph(d) if e.target == "sum"}
    assert into_sum == {"G_t", "G_e"}
    top_wire = next(w for w in d.wires if w.points[-1] == (s.x, s.y + s.r))
    assert d.blocks[[b.name for b in d.blocks].index("G_t")].on_boundary(top_wire.points[0])


def test_graph_reader_catches_a_dangling_wire():
    # the check itself: a wire whose arrow stops short of its block is an open end, not an edge
    d = diagrams.diagram("generalized_plant")
    y = d.wires[2]
    broken = diagrams.Wire(y.points[:-1] + ((y.points[-1][0] + 0.3, y.points[-1][1]),), y.text, seg=1)
    bad = diagrams.Diagram(d.name, d.caption, d.blocks, d.wires[:2] + (broken,) + d.wires[3:])
    got = {(e.source, e.target) for e in diagrams.signal_graph(bad)}
    assert ("P", "K") not in got and ("P", None) in got


def test_unknown_diagram_is_a_named_error():
    with pytest.raises(UsageError, match="known diagrams: generalized_plant"):
        diagrams.diagram("nyquist")


def test_missing_schemdraw_is_a_named_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "schemdraw", None)
    with pytest.raises(UsageError, match="pip install"):
        diagrams.draw("m_delta")


@pytest.mark.parametrize("name", ["generalized_plant", "mbi"])
def test_draw_puts_every_label_on_the_figure(name):
    pytest.importorskip("schemdraw")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = diagrams.diagram(name)
    fig = diagrams.draw(name)
    try:
        texts = {t.get_text() for ax in fig.axes for t in ax.texts}
        wanted = {w.text for w in d.wires if w.text} | {b.text for b in d.blocks}
        assert wanted <= texts, wanted - texts
        w, h = fig.get_size_inches()
        assert w <= 6.5, "wider than the book's text column"
    finally:
        plt.close(fig)
