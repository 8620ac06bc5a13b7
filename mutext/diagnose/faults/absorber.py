r"""A tuned-mass absorber: a mass on a spring and a damper, attached at one mass of a chain.

==================  ===================================================================  ==================
kind                change of dynamic stiffness at the host DOF *i*                       candidates
==================  ===================================================================  ==================
``absorber``        :math:`Z(\omega) = -\omega^2 m_a\,\dfrac{k_a + j\omega c_a}            every mass of a
                    {k_a + j\omega c_a - \omega^2 m_a}`                                  lumped chain
==================  ===================================================================  ==================

The absorber is an added degree of freedom :math:`x_a` with
:math:`m_a\ddot x_a + c_a(\dot x_a - \dot x_i) + k_a(x_a - x_i) = 0`.
Eliminating :math:`x_a` (it carries no force input and no sensor) leaves the
host's dynamic stiffness changed by the impedance :math:`Z(\omega)\,e_ie_i^T`
(den Hartog, *Mechanical Vibrations*, 1956, sec. 3.3): rank one on the
existing DOFs, so the exact Woodbury screen of the other local kinds applies
unchanged.  :math:`Z \to -\omega^2 m_a` well below the absorber's own
frequency :math:`\sqrt{k_a/m_a}` (a mass) and :math:`\to k_a + j\omega c_a`
well above it (a spring and a damper to ground): the absorber is what
neither reading can be, a resonance of its own.

The hypothesis has three parameters, :math:`\theta = (m_a, k_a, c_a)`, all
positive.  Bounds: :math:`m_a` up to the chain's total mass, the tuning
frequency :math:`\sqrt{k_a/m_a}` within a decade of the model's band, the
damping ratio :math:`c_a/(2\sqrt{k_a m_a})` in :math:`[10^{-4}, 2]`.  The
fit starts from a grid of tuning frequencies over the model's band, mass
ratios 1-30 % of the host and a damping ratio of 5 %
(:attr:`~mutext.diagnose.faults._base.Hypothesis.starts`).

Written into the model file (:mod:`mutext.rotor.model_writer`) as an added
``[[mass]]`` with a ``[[spring]]`` and a ``[[damper]]`` between it and its
host: the model the user receives has the extra degree of freedom itself.
"""
from __future__ import annotations

import math

import numpy as np

from ._base import Hypothesis, Param, model_poles

KINDS = ("absorber",)

#: Mass ratios (absorber over host mass) of the fit's starting grid.
START_MASS_RATIOS = (0.01, 0.05, 0.3)
#: Damping ratio of the fit's starting grid.
START_ZETA = 0.05


def impedance(theta, w) -> np.ndarray:
    r"""The absorber's impedance at the host, :math:`Z(\omega)` above, for ``theta = (m_a, k_a, c_a)``.

    Parameters
    ----------
    theta : (3,) array_like
        Absorber mass [kg], stiffness [N/m] and damping [N s/m].
    w : array_like
        Frequencies [rad/s].
    """
    ma, ka, ca = (float(x) for x in theta)
    w = np.asarray(w, float)
    s = ka + 1j * w * ca
    return -w * w * ma * s / (s - w * w * ma)


def _change(theta, w):
    return impedance(theta, w)[:, None, None]


def candidates(model) -> list[Hypothesis]:
    """An absorber at every mass of a lumped chain ``model`` (none for a rotor).

    Parameters
    ----------
    model : Structure
        The engineering model (a lumped chain; a rotor gives none).
    """
    lay = model.layout
    if lay.kind != "lumped":
        return []
    M, C, K, _ = model.matrices()
    total = float(np.trace(M))
    fn = np.asarray(model_poles(model)[0], float)
    fn = fn[np.isfinite(fn) & (fn > 0)]
    lo, hi = (0.5 * fn.min(), 2.0 * fn.max()) if fn.size else (0.1, 1e3)
    tunes = 2 * np.pi * np.geomspace(lo, hi, 40)
    out = []
    for i, name in enumerate(lay.node_names, start=1):
        mi = float(M[i - 1, i - 1])
        wlo, whi = tunes[0] / 10, 10 * tunes[-1]
        m_lo = 1e-4 * mi
        params = (Param("m_a", "kg", m_lo, total, 0.05 * mi),
                  Param("k_a", "N/m", m_lo * wlo ** 2, total * whi ** 2, 0.05 * mi * tunes[20] ** 2),
                  Param("c_a", "N s/m", 2e-4 * m_lo * wlo, 4.0 * total * whi, 2 * START_ZETA * 0.05 * mi * tunes[20]))
        starts = [np.array([r * mi, r * mi * wt * wt, 2 * START_ZETA * r * mi * wt])
                  for wt in tunes for r in START_MASS_RATIOS]
        p0 = params[0]
        out.append(Hypothesis("absorber", i, f"absorber_{name}", f"tuned-mass absorber added at {name}", "kg",
                              True, p0.lower, p0.upper, p0.scale, [i - 1], np.ones((1, 1)), 0,
                              parameter=None, nominal=0.0, params=params, change=_change, starts=starts,
                              nested=(("mass", name),)))          # k_a -> infinity: the host's mass changed
    return out


def write(mf, finding, model, note: str) -> None:
    """Write the absorber into the model file ``mf``: a ``[[mass]]``, and a ``[[spring]]`` and a ``[[damper]]``
    between it and its host (:class:`~mutext.rotor.model_writer.ModelFile`).

    Parameters
    ----------
    mf : mutext.rotor.model_writer.ModelFile
        The model file being extended (edited in place).
    finding : Finding
        The accepted finding (its hypothesis and fitted size).
    model : Structure or Rotor
        The engineering model the finding refers to.
    note : str
        Comment written next to the change in the file.
    """
    h = finding.hypothesis
    ma, ka, ca = (float(x) for x in finding.values)
    host = model.layout.node_names[h.station - 1]
    name = h.element
    mf.append("mass", {"name": name, "mass": ma}, note, si=True)
    mf.append("spring", {"name": f"k_{name}", "stiffness": ka, "between": [host, name]},
              f"the spring of {name}", si=True)
    mf.append("damper", {"name": f"c_{name}", "damping": ca, "between": [host, name]},
              f"the damper of {name}", si=True)
