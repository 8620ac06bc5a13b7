r"""A hammer test of a free-free steel beam, written as a modal-test analyzer exports it.

Written apart from mutext (numpy and pyuff only) so that it can check the
readers: the file is what the analyzer hands over, the returned dictionary
is the truth the file was made from.

The beam
--------
A uniform steel bar, free at both ends (hung on soft cords), length
:math:`L = 1` m, width 25 mm, height 10 mm, bending in the thin direction
(:math:`I = b h^3/12`), :math:`E = 200` GPa, :math:`\rho = 7850` kg/m^3, so
:math:`m = \rho A L = 1.9625` kg.  Euler-Bernoulli free-free bending modes
([Bl]_ table 8-1):

.. math::
    \cos\beta_n L \cosh\beta_n L = 1, \qquad
    \omega_n = (\beta_n L)^2 \sqrt{\frac{EI}{\rho A L^4}},

:math:`\beta_n L = 4.7300, 7.8532, 10.9956, 14.1372, 17.2788, 20.4204, \dots`,
which gives the six bending resonances below 1000 Hz

    51.88, 143.02, 280.38, 463.48, 692.36, 967.02 Hz

(the seventh is at 1287 Hz), plus the two rigid-body modes (translation and
rotation) at 0 Hz.  Mass-normalised shapes (:math:`\int \rho A \phi^2 = 1`):

.. math::
    \phi_n(x) = \frac{1}{\sqrt m}\Big[\cosh\beta_n x + \cos\beta_n x
      - \sigma_n(\sinh\beta_n x + \sin\beta_n x)\Big],\quad
    \sigma_n = \frac{\cosh\beta_n L - \cos\beta_n L}{\sinh\beta_n L - \sin\beta_n L},

evaluated without the cancellation of the large hyperbolic terms
(:func:`mode_shape`), and the rigid-body shapes :math:`1/\sqrt m` and
:math:`\sqrt{12/m}\,(x/L - 1/2)`.  With modal damping ratios
:math:`\zeta_n` the receptance between points :math:`x_o` and :math:`x_i` is

.. math::
    H(x_o, x_i, \omega) = -\frac{\phi_T(x_o)\phi_T(x_i) + \phi_R(x_o)\phi_R(x_i)}{\omega^2}
      + \sum_{n=1}^{12} \frac{\phi_n(x_o)\phi_n(x_i)}{\omega_n^2 - \omega^2 + 2j\zeta_n\omega_n\omega}

and the accelerance the analyzer measures is :math:`A = -\omega^2 H` (finite
at 0 Hz: the rigid-body mass line).

The file
--------
Universal File with a units data set 164 (SI), a nodes data set 15 (11
points, 0.1 m apart along the bar, node 1 at one end) and three data sets 58
of accelerance from 0 to 1000 Hz in 1600 lines (0.625 Hz) *including the 0
Hz line*, as the analyzer exports them:

* node 1 / node 1: driving point at the free end (sees every mode);
* node 6 / node 6: driving point at the middle (the antisymmetric modes 2, 4,
  6 have a node there: it sees modes 1, 3, 5 only);
* node 9 / node 1: transfer, response at x = 0.8 m, reference at the end.

Directions +2 (Y) for response and reference.  Ordinate specific data type
12 (acceleration) over 13 (excitation force), the ordinate units label
``(1/N)*(m/s²)`` written in Latin-1 (the byte 0xB2 for the superscript two),
the denominator label ``NONE``, and an ID line with a Latin-1 ``ä``.  The
noise is relative, circular complex Gaussian, seeded:
:math:`A_k (1 + \text{noise}\,(e_1 + j e_2)/\sqrt2)`.

References
----------
.. [Bl] R. D. Blevins, *Formulas for Natural Frequency and Mode Shape*,
   Van Nostrand Reinhold, 1979, table 8-1 (free-free beam).
"""
from __future__ import annotations

import os
import warnings

import numpy as np

# the bar
LENGTH = 1.0                 # m
WIDTH = 0.025                # m
HEIGHT = 0.010               # m
E = 200e9                    # Pa
RHO = 7850.0                 # kg/m^3
AREA = WIDTH * HEIGHT
INERTIA = WIDTH * HEIGHT ** 3 / 12
MASS = RHO * AREA * LENGTH

#: roots of cos(x) cosh(x) = 1, x = beta_n L, n = 1..12
N_MODES = 12
#: damping ratios of the bending modes (a few per cent and less, falling with frequency)
DAMPING = np.array([0.020, 0.015, 0.012, 0.010, 0.008, 0.006] + [0.005] * (N_MODES - 6))

#: the analyzer's grid: 0 to 1000 Hz in 1600 lines
F_MAX = 1000.0
LINES = 1600

#: node -> position along the bar [m]
NODES = {k: round(0.1 * (k - 1), 10) for k in range(1, 12)}
#: (response node, reference node) of the three FRFs, in file order
CHANNELS = [(1, 1), (6, 6), (9, 1)]

#: the ordinate units label as the analyzer writes it (Latin-1 in the file)
ORDINATE_LABEL = "(1/N)*(m/s\u00b2)"
ID4 = "Tr\u00e4ger 1000x25x10 mm, free-free"


def beta_l(n_modes: int = N_MODES) -> np.ndarray:
    """The first ``n_modes`` roots of :math:`\\cos x \\cosh x = 1` (bisection on :math:`\\cos x - 1/\\cosh x`)."""
    out = []
    for n in range(1, n_modes + 1):
        lo, hi = (n + 0.5) * np.pi - 0.5, (n + 0.5) * np.pi + 0.5
        g = lambda x: np.cos(x) - 1.0 / np.cosh(x)  # noqa: E731
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if np.sign(g(mid)) == np.sign(g(lo)):
                lo = mid
            else:
                hi = mid
        out.append(0.5 * (lo + hi))
    return np.array(out)


def natural_frequencies(n_modes: int = N_MODES) -> np.ndarray:
    """Bending natural frequencies [Hz] of the free-free bar."""
    return beta_l(n_modes) ** 2 * np.sqrt(E * INERTIA / (RHO * AREA * LENGTH ** 4)) / (2 * np.pi)


def mode_shape(n: int, x) -> np.ndarray:
    r"""Mass-normalised bending mode ``n`` (1-based) at ``x`` [m].

    :math:`\cosh u - \sigma\sinh u = \tfrac12[(1-\sigma)e^{u} + (1+\sigma)e^{-u}]` with
    :math:`1 - \sigma = (\cos\beta L - \sin\beta L - e^{-\beta L})/(\sinh\beta L - \sin\beta L)`,
    so that no two large numbers are subtracted.
    """
    bl = beta_l(n)[n - 1]
    u = bl * np.asarray(x, dtype=float) / LENGTH
    den = np.sinh(bl) - np.sin(bl)
    one_minus = (np.cos(bl) - np.sin(bl) - np.exp(-bl)) / den
    sigma = 1.0 - one_minus
    w = 0.5 * (one_minus * np.exp(u) + (1.0 + sigma) * np.exp(-u)) + np.cos(u) - sigma * np.sin(u)
    return w / np.sqrt(MASS)


def rigid_shapes(x) -> tuple[np.ndarray, np.ndarray]:
    """Mass-normalised translation and rotation shapes at ``x`` [m]."""
    x = np.asarray(x, dtype=float)
    return np.full(x.shape, 1.0 / np.sqrt(MASS)), np.sqrt(12.0 / MASS) * (x / LENGTH - 0.5)


def modal_constants(rsp_node: int, ref_node: int) -> np.ndarray:
    """:math:`\\phi_n(x_o)\\phi_n(x_i)` of the bending modes 1..N_MODES [1/kg]."""
    xo, xi = NODES[rsp_node], NODES[ref_node]
    return np.array([mode_shape(n, xo) * mode_shape(n, xi) for n in range(1, N_MODES + 1)])


def receptance(freq_hz, rsp_node: int, ref_node: int) -> np.ndarray:
    """The exact receptance [m/N] between two nodes (``freq_hz`` > 0)."""
    w = 2 * np.pi * np.asarray(freq_hz, dtype=float)
    xo, xi = NODES[rsp_node], NODES[ref_node]
    (to, ro), (ti, ri) = rigid_shapes(xo), rigid_shapes(xi)
    wn = 2 * np.pi * natural_frequencies()
    H = -(to * ti + ro * ri) / w ** 2 + 0j
    for a, wk, z in zip(modal_constants(rsp_node, ref_node), wn, DAMPING):
        H = H + a / (wk ** 2 - w ** 2 + 2j * z * wk * w)
    return H


def accelerance(freq_hz, rsp_node: int, ref_node: int) -> np.ndarray:
    """The exact accelerance [(m/s^2)/N] between two nodes, 0 Hz included (the rigid-body mass line)."""
    f = np.asarray(freq_hz, dtype=float)
    w = 2 * np.pi * f
    xo, xi = NODES[rsp_node], NODES[ref_node]
    (to, ro), (ti, ri) = rigid_shapes(xo), rigid_shapes(xi)
    wn = 2 * np.pi * natural_frequencies()
    A = np.full(f.shape, to * ti + ro * ri, dtype=complex)
    for a, wk, z in zip(modal_constants(rsp_node, ref_node), wn, DAMPING):
        A = A - w ** 2 * a / (wk ** 2 - w ** 2 + 2j * z * wk * w)
    return A


def write_hammer_test(path, seed: int = 0, noise: float = 0.01, *, binary: bool = False, lines: int = LINES) -> dict:
    """Write the hammer test (module docstring) to ``path``; return the truth.

    ``lines``: the analyzer's lines from 0 to 1000 Hz (1600 by default; the file holds one more, 0 Hz);
    ``binary``: data set 58b instead of ASCII.

    Returns
    -------
    dict
        ``path``; ``freq_hz`` and ``damping``: the six bending resonances below
        1000 Hz and their damping ratios; ``lines``: the frequencies written
        (0 Hz first); ``channels``: (response node, reference node) per data
        set 58, in file order; ``nodes``: node -> x [m]; ``modal_constants``:
        per channel, :math:`\\phi_n(x_o)\\phi_n(x_i)` of the six modes [1/kg];
        ``receptance``: a function (f, rsp_node, ref_node) -> exact m/N;
        ``noise``: the relative noise; ``ordinate_label``: the units label
        written (in Latin-1).
    """
    import pyuff
    path = os.fspath(path)
    f = np.arange(lines + 1) * (F_MAX / lines)
    rng = np.random.default_rng(seed)
    sets = [pyuff.prepare_164(units_code=1, units_description="SI - mks (meter, newton)", temp_mode=2,
                              length=1.0, force=1.0, temp=1.0, temp_offset=273.15),
            pyuff.prepare_15(node_nums=list(NODES), def_cs=[0] * len(NODES), disp_cs=[0] * len(NODES),
                             color=[1] * len(NODES), x=list(NODES.values()), y=[0.0] * len(NODES),
                             z=[0.0] * len(NODES))]
    for rsp, ref in CHANNELS:
        A = accelerance(f, rsp, ref)
        e = rng.standard_normal((2, f.size))
        A = A * (1 + noise * (e[0] + 1j * e[1]) / np.sqrt(2))
        d = pyuff.prepare_58(
            binary=1 if binary else 0, id1=f"FRF BEAM:{rsp}:+Y/BEAM:{ref}:+Y", id2="Hammer impact, 5 averages",
            id3="14-Mar-24 10:21:07", id4=ID4, id5="NONE",
            func_type=4, ver_num=0, load_case_id=0,
            rsp_ent_name="BEAM", rsp_node=rsp, rsp_dir=2, ref_ent_name="BEAM", ref_node=ref, ref_dir=2,
            abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=F_MAX / lines,
            abscissa_spec_data_type=18, abscissa_len_unit_exp=0, abscissa_force_unit_exp=0,
            abscissa_temp_unit_exp=0, abscissa_axis_units_lab="Hz",
            ordinate_spec_data_type=12, ordinate_len_unit_exp=1, ordinate_force_unit_exp=0,
            ordinate_temp_unit_exp=0, ordinate_axis_units_lab=ORDINATE_LABEL,
            orddenom_spec_data_type=13, orddenom_len_unit_exp=0, orddenom_force_unit_exp=1,
            orddenom_temp_unit_exp=0, orddenom_axis_units_lab="NONE",
            z_axis_spec_data_type=0, z_axis_value=0.0,
            data=A, x=f)
        d["ord_data_type"] = 6
        sets.append(d)
    open(path, "wb").close()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)    # pyuff's binary writer leaves a handle open
        pyuff.UFF(path).write_sets(sets, mode="add")
    # pyuff writes its text as UTF-8; the analyzer writes Latin-1, one byte per character (pyuff padded the
    # fields by characters, so the Latin-1 lines are 80 bytes as the format wants)
    with open(path, "rb") as fh:
        fixed = fh.read()
    for text in (ORDINATE_LABEL, ID4):
        u8, l1 = text.encode("utf-8"), text.encode("latin-1")
        assert fixed.count(u8) == len(CHANNELS), "the text must be in the header of every data set 58, once"
        fixed = fixed.replace(u8, l1)
    with open(path, "wb") as fh:
        fh.write(fixed)
    fn = natural_frequencies()
    keep = fn < F_MAX
    return {"path": path, "freq_hz": fn[keep], "damping": DAMPING[keep], "lines": f,
            "channels": list(CHANNELS), "nodes": dict(NODES),
            "modal_constants": [modal_constants(r, q)[keep] for r, q in CHANNELS],
            "receptance": receptance, "noise": noise, "ordinate_label": ORDINATE_LABEL}


if __name__ == "__main__":      # pragma: no cover
    import sys
    truth = write_hammer_test(sys.argv[1] if len(sys.argv) > 1 else "hammer.uff")
    for k, (fn, z) in enumerate(zip(truth["freq_hz"], truth["damping"]), 1):
        print(f"mode {k}: {fn:8.2f} Hz, zeta {z:.3f}")
