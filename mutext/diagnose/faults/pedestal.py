r"""A pedestal: a chain's spring to ground that stands on a mass with a spring of its own.

=============  ====================================================================  ===================
kind           change of dynamic stiffness at the host DOF *i*                        candidates
=============  ====================================================================  ===================
``pedestal``   :math:`\Delta(\omega) = -\dfrac{k_g^2}{k_g + k_p - \omega^2 m_p}`          every ``[[spring]]``
                                                                                      to ground
=============  ====================================================================  ===================

The spring :math:`k_g` from mass *i* to ground is found to end on a pedestal
of mass :math:`m_p` held by a spring :math:`k_p` to ground (a bearing housing,
a soft foundation).  Eliminating the pedestal's degree of freedom (it has no
force and no sensor) turns the spring's impedance :math:`k_g` into
:math:`k_g (k_p - \omega^2 m_p)/(k_g + k_p - \omega^2 m_p)`: the change above,
rank one at the host, so the exact screen applies.  Two parameters,
:math:`\theta = (m_p, k_p)`, both positive: :math:`m_p` up to the chain's
total mass, :math:`k_p` within :math:`10^{-3}`-:math:`10^{3}` times
:math:`k_g`; starting grid: pedestal frequencies
:math:`\sqrt{(k_g + k_p)/m_p}` over the model's band, :math:`k_p/k_g` of 0.3,
3 and 30.  A rigid pedestal (:math:`k_p \to \infty`) is no change.

Written into the model file (:mod:`mutext.rotor.model_writer`): a new
``[[mass]]`` (the pedestal), the grounded spring's ``between`` moved to
``[host, pedestal]``, and a ``[[spring]]`` from the pedestal to ground.
"""
from __future__ import annotations

import numpy as np

from ...rotor.elements import Spring
from ._base import Hypothesis, Param, model_poles

KINDS = ("pedestal",)

#: Pedestal-over-grounded-spring stiffness ratios of the fit's starting grid.
START_RATIOS = (0.3, 3.0, 30.0)


def change_of(kg: float):
    """The change of dynamic stiffness of a spring ``kg`` to ground set on a pedestal, as ``f(theta, w)``.

    Parameters
    ----------
    kg : float
        Stiffness [N/m] of the spring to ground.
    """
    def change(theta, w):
        mp, kp = (float(x) for x in theta)
        w = np.asarray(w, float)
        return (-kg * kg / (kg + kp - w * w * mp) + 0j)[:, None, None]
    return change


def candidates(model) -> list[Hypothesis]:
    """A pedestal under every spring to ground of a lumped chain ``model``.

    Parameters
    ----------
    model : Structure or Rotor
        The engineering model.
    """
    lay = model.layout
    if lay.kind != "lumped":
        return []
    M = model.matrices()[0]
    total = float(np.trace(M))
    fn = np.asarray(model_poles(model)[0], float)
    fn = fn[np.isfinite(fn) & (fn > 0)]
    lo, hi = (0.5 * fn.min(), 2.0 * fn.max()) if fn.size else (0.1, 1e3)
    wp = 2 * np.pi * np.geomspace(lo, hi, 120)       # fine: a lightly damped peak must be met closely
    out = []
    for el in model.elements:
        if not isinstance(el, Spring) or len(el.nodes) != 1:
            continue
        i = el.nodes[0]
        kg = el.nominal("k")
        if not kg > 0:
            continue
        mi = float(M[i - 1, i - 1])
        params = (Param("m_p", "kg", 1e-4 * mi, total, 0.1 * mi), Param("k_p", "N/m", 1e-3 * kg, 1e3 * kg, kg))
        starts = [np.array([(kg + r * kg) / w ** 2, r * kg]) for w in wp for r in START_RATIOS]
        starts = [s for s in starts if params[0].lower <= s[0] <= params[0].upper]
        name = lay.node_names[i - 1]
        out.append(Hypothesis("pedestal", i, el.name, f"spring {el.name} ({name}-ground) on a pedestal", "kg",
                              True, params[0].lower, params[0].upper, params[0].scale, [i - 1], np.ones((1, 1)),
                              0, parameter=None, nominal=0.0, params=params, change=change_of(kg),
                              starts=starts, nested=(("stiffness", el.name),)))   # m_p -> 0: a softer spring
    return out


def write(mf, finding, model, note: str) -> None:
    """The pedestal into the model file ``mf``: its mass, the spring moved onto it, its spring to ground.

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
    mp, kp = (float(x) for x in finding.values)
    host = model.layout.node_names[h.station - 1]
    ped = f"pedestal_{h.element}"
    mf.append("mass", {"name": ped, "mass": mp}, note, si=True)
    entry = next(t for t in mf.entries("spring") if t.get("name") == h.element)
    entry["between"] = [host, ped]
    mf.append("spring", {"name": f"k_{ped}", "stiffness": kp, "between": [ped, "ground"]},
              f"the spring of {ped} to ground", si=True)
