r"""The three-mass rig of thesis chapter 3 (ECP Model 210a rectilinear plant), Table 3.1.

Three carts on a track.  The spring arrangement used here is the chain

.. code-block:: text

    m1 --k1-- m2 --k2-- m3 --k3-- ground,   c_i from cart i to ground,

which is the one the identification arithmetic of Table 3.1 implies: with
the other carts clamped, cart 1 feels ``k1`` only (``k1 = k1eq``), cart 2 feels
``k1 + k2`` (``k2 = k2eq - k1``) and cart 3 feels ``k2 + k3``
(``k3 = k3eq - k2``).  (The thesis text says the grounded spring is on the first
cart; that would contradict its own arithmetic.)  It also puts every trial's
unmodeled dynamics on cart 3 alone: changing ``k3``, ``m3`` or ``c3`` adds a
force that depends on ``x3`` only, which is why the thesis places the
identifying controller there.

Excitation and measurement are at cart 1.  SI units throughout (kg, N/m, N s/m).
The identified values are read from ``mutext/data/three_mass.toml``, the one
copy of Table 3.1 (the model file that ``mutext diagnose`` and the rotor tools
load too).
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields, replace
from importlib import resources

import control as ct
import numpy as np

from ..errors import ModelError
from ..lti import mck_to_ss

__all__ = ["ThreeMass", "TABLE_3_1", "AIR_DAMPER", "mechanical_model", "matrices", "Trial", "TRIALS"]


@dataclass(frozen=True)
class ThreeMass:
    """Parameters of the three-mass rig (SI units).

    Attributes
    ----------
    m1, m2, m3 : float
        Cart masses [kg] (Table 3.1: each with 2 kg added).
    k1, k2, k3 : float
        Springs [N/m]: cart 1 to cart 2, cart 2 to cart 3, cart 3 to ground.
    c1, c2, c3 : float
        Dampers from each cart to ground [N s/m] (``c3`` includes the air damper).
    """
    m1: float
    m2: float
    m3: float
    k1: float
    k2: float
    k3: float
    c1: float
    c2: float
    c3: float

    def with_(self, **kw) -> "ThreeMass":
        """A copy with some fields changed.

        Parameters
        ----------
        **kw
            New values of fields (``m1``, ``k2``, ``c3``, ...).
        """
        return replace(self, **kw)


def _from_model_file(name: str = "three_mass.toml") -> ThreeMass:
    """The rig of a shipped model file: its masses, springs and dampers by name."""
    with resources.files("mutext").joinpath("data", name).open("rb") as fh:
        doc = tomllib.load(fh)
    values = {e["name"]: e[key] for section, key in (("mass", "mass"), ("spring", "stiffness"),
                                                      ("damper", "damping")) for e in doc[section]}
    return ThreeMass(**{f.name: float(values[f.name]) for f in fields(ThreeMass)})


#: Identified parameters of thesis Table 3.1 (from ``mutext/data/three_mass.toml``).
TABLE_3_1 = _from_model_file()

#: The air damper's share of ``c3`` (N s/m), identified by its own decay (thesis eq. 3.6).
AIR_DAMPER = 8.8078


def matrices(p: ThreeMass = TABLE_3_1):
    """Mass, damping and stiffness matrices ``(M, C, K)`` of the chain (SI).

    Parameters
    ----------
    p : ThreeMass, optional
        The rig (default: Table 3.1).

    Examples
    --------
    >>> from mutext.examples.three_mass import TABLE_3_1, matrices
    >>> M, C, K = matrices(TABLE_3_1)
    >>> M.shape, bool((K == K.T).all())
    ((3, 3), True)
    """
    for name in ("m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3"):
        v = getattr(p, name)
        if not np.isfinite(v) or v < 0 or (name.startswith("m") and v == 0):
            raise ModelError(f"three-mass parameter {name} must be {'positive' if name[0] == 'm' else 'non-negative'}"
                             f", got {v}")
    M = np.diag([p.m1, p.m2, p.m3])
    K = np.array([[p.k1, -p.k1, 0.0],
                  [-p.k1, p.k1 + p.k2, -p.k2],
                  [0.0, -p.k2, p.k2 + p.k3]])
    C = np.diag([p.c1, p.c2, p.c3])
    return M, C, K


def mechanical_model(p: ThreeMass = TABLE_3_1) -> ct.StateSpace:
    """Inputs ``f1`` (N on cart 1, the exciter) and ``f3`` (N on cart 3);
    outputs ``x1``, ``x3`` (m).

    Parameters
    ----------
    p : ThreeMass, optional
        The rig (default: Table 3.1).
    """
    M, C, K = matrices(p)
    return mck_to_ss(M, C, K, inputs={"f1": 0, "f3": 2}, outputs={"x1": 0, "x3": 2},
                     dof_names=["x1", "x2", "x3"])


@dataclass(frozen=True)
class Trial:
    """One model-based identification trial of thesis sec. 3.4.

    ``engineering`` and ``true`` are the two rigs; ``uncertainty`` the relative
    uncertainty of the true system's changed parameters; ``Wz`` (m) and
    ``mu`` the thesis's final values; ``Du`` the known difference as the
    added mechanical impedance ``dm s^2 + dc s + dk`` on cart 3.

    Attributes
    ----------
    name : str
        Name of the trial.
    engineering : ThreeMass
        The engineering model's rig.
    true : ThreeMass
        The true rig.
    uncertainty : float
        Relative uncertainty of the true system's changed parameters.
    Wz : float
        The thesis's final error bound [m].
    mu : float
        The thesis's final mu.
    Du : dict
        The known difference: ``{"dm": kg, "dc": N s/m, "dk": N/m}`` on cart 3.
    """
    name: str
    engineering: ThreeMass
    true: ThreeMass
    uncertainty: float
    Wz: float
    mu: float
    Du: dict


def _trials():
    t = TABLE_3_1
    k_g, m_g, c_g = 200.0, 1.6074, 5.7375
    eng4 = t.with_(k3=k_g, m3=m_g, c3=c_g)

    def du(a, b):
        return {"dm": b.m3 - a.m3, "dc": b.c3 - a.c3, "dk": b.k3 - a.k3}

    rows = [
        ("1a", t.with_(k3=k_g), t, 0.01, 0.0004, 0.9337),
        ("1b", t, t.with_(k3=k_g), 0.01, 0.0004, 0.8930),
        ("2", t.with_(m3=m_g), t, 0.01, 0.000091, 0.9492),
        ("3", t.with_(c3=c_g), t, 0.01, 0.00006, 0.9816),
        ("4", eng4, t, 0.01, 0.0005, 0.9881),
        ("5", eng4, t, 0.10, 0.0026, 0.9846),
    ]
    return {n: Trial(n, e, tr, u, wz, mu, du(e, tr)) for n, e, tr, u, wz, mu in rows}


#: Trials 1a-5 with the thesis's guessed (engineering) and true values.
TRIALS = _trials()


def _changed(trial: Trial):
    """Names of the cart-3 parameters that differ between the engineering and true rigs."""
    return [n for n in ("m3", "c3", "k3") if getattr(trial.engineering, n) != getattr(trial.true, n)]


def true_model(trial: Trial):
    """The true rig as an uncertain model: each changed parameter known to
    ``trial.uncertainty`` (relative), inputs ``f1, f3``, outputs ``x1, x3``
    after the uncertainty channels."""
    from dataclasses import replace as _replace
    from ..uncertain import UncertainParameter, uncertain_mck
    params = [UncertainParameter(n, getattr(trial.true, n), rel=trial.uncertainty) for n in _changed(trial)]
    return uncertain_mck(lambda v: matrices(_replace(trial.true, **v)), params,
                         inputs={"f1": 0, "f3": 2}, outputs={"x1": 0, "x3": 2},
                         dof_names=["x1", "x2", "x3"])


def du_box(trial: Trial) -> list[dict]:
    """D_u of the true rigs at the corners of the uncertainty box: what the
    identification may legitimately return, since any of them is consistent with
    the (uncertain) measurement."""
    U = true_model(trial)
    e = trial.engineering
    out = []
    for d in np.array(np.meshgrid(*[[-1.0, 1.0]] * len(U.params), indexing="ij")).reshape(len(U.params), -1).T:
        v = {n: getattr(trial.true, n) for n in ("m3", "c3", "k3")}
        v.update(U.values(d))
        out.append({"dm": v["m3"] - e.m3, "dc": v["c3"] - e.c3, "dk": v["k3"] - e.k3})
    return out


def mbi_arguments(trial: Trial) -> dict:
    """Keyword arguments of :func:`mutext.mbi.identify` for a trial (excitation and
    measurement at cart 1, the unknown dynamics at cart 3, unit excitation force)."""
    return dict(true=true_model(trial), engineering=mechanical_model(trial.engineering),
                excitation="f1", measurement="x1", control_input="f3", control_output="x3", Ww=1.0)
