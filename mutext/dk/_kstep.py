r"""The K step: an H-infinity controller for the D-scaled plant, with the fallbacks of each
``synthesis`` setting of :func:`mutext.dk.dk_iteration`.
"""
from __future__ import annotations

from dataclasses import dataclass

import control as ct

from ..errors import InfeasibleError, SolverError
from ..hinf import hinfsyn, slycot_hinfsyn


@dataclass
class _KStep:
    K: ct.StateSpace
    gamma: float
    method: str


def _k_step(PD, nmeas, ncon):
    """:func:`mutext.hinf.hinfsyn` at a level 0.1 % above the optimum, slycot as fallback.

    D-K iteration gains nothing from the last 0.1 % of a K step, and a tighter
    target would send hinfsyn through its back-off schedule on the plants
    where only an LMI controller can be built.  If no controller of ours
    passes, slycot's Riccati synthesis is tried;
    :func:`mutext.hinf.slycot_hinfsyn` accepts its controller only after
    rebuilding the closed loop (stability, norm).  ``method`` says how the
    controller was built: ``"central"`` (our Riccati central controller),
    ``"lmi"`` (our LMI reconstruction) or ``"slycot"``.
    """
    try:
        res = hinfsyn(PD, nmeas, ncon, backoff=1e-3, max_backoff=1e-3)
        return _KStep(res.K, float(res.gamma), _construction(res))
    except (InfeasibleError, SolverError) as exc:
        first = exc
    try:
        # the full back-off schedule: singular plants (model-based identification)
        # often need a few percent
        res = hinfsyn(PD, nmeas, ncon, backoff=3e-3)
        return _KStep(res.K, float(res.gamma), _construction(res))
    except (InfeasibleError, SolverError):
        pass
    ref = slycot_hinfsyn(PD, nmeas, ncon, timeout=60.0)
    if ref.status == "verified":
        return _KStep(ref.K, float(ref.achieved), "slycot")
    raise first


def _k_step_lmi_first(PD, nmeas, ncon):
    """The LMI controller (:func:`mutext.hinf.hinfsyn` with ``method="lmi"``, 0.1 %
    above the optimum) where it passes its check, :func:`_k_step` otherwise."""
    try:
        res = hinfsyn(PD, nmeas, ncon, method="lmi", backoff=1e-3, max_backoff=1e-3)
        return _KStep(res.K, float(res.gamma), "lmi")
    except (InfeasibleError, SolverError):
        return _k_step(PD, nmeas, ncon)


def _construction(res) -> str:
    """Short name of how :func:`mutext.hinf.hinfsyn` built its controller."""
    return "central" if res.construction.startswith("central") else "lmi"


def _k_step_riccati(PD, nmeas, ncon):
    """slycot's Riccati synthesis, accepted after :func:`mutext.hinf.slycot_hinfsyn`
    verified it (closed loop rebuilt: stable, norm as claimed); :func:`_k_step` otherwise."""
    ref = slycot_hinfsyn(PD, nmeas, ncon, timeout=60.0)
    if ref.status == "verified":
        return _KStep(ref.K, float(ref.achieved), "slycot")
    return _k_step(PD, nmeas, ncon)
