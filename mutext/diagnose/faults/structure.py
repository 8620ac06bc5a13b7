r"""Changes of the whole structure or of the frequency axis: evaluated on the whole model.

================== ========================================================= =====================
kind               the measured response is that of                          size
================== ========================================================= =====================
``damping_scale``  :math:`K - \omega^2 M + j\omega (1 + a)(C + \Omega G)`    :math:`a` (all damping,
                                                                             modal or discrete,
                                                                             scaled by :math:`1+a`)
``frequency_scale`` the model at :math:`\omega (1 + \epsilon)`, labelled      :math:`\epsilon` (an
                   :math:`\omega`                                            analyser's clock)
================== ========================================================= =====================

Neither is a low-rank change, so the Woodbury screen of the local kinds does
not apply: the response is :math:`e_o^T Z(\omega)^{-1} b` with the whole dynamic
stiffness (local effects and a mass that moves with the sensor added to it).
A lumped chain's is one solve per frequency.  A rotor's comes from the modes of
the model with its damping scaled (:class:`mutext.diagnose._screen._Modal`, one
eigen-decomposition per damping scale, about 0.03 s at 120 DOFs and 0.15 s at
236), read at the scaled frequencies; local effects and a sensor's mass join by
Woodbury on their DOFs.  (A full solve per frequency took 0.2 s per evaluation
at 120 DOFs and 1 s at 236.)

A damping scale is written into the model file by scaling every damping value
it holds (dampers, bearings' damping, the ``[damping]`` table;
:class:`mutext.rotor.model_writer.ModelFile`); a frequency scale is a
correction of the measurement and leaves the model unchanged.
"""
from __future__ import annotations

import numpy as np

from ...errors import ModelError
from ...rotor.lumped_elements import add_impedances
from ...rotor.model_writer import ModelFile
from ._base import Hypothesis, local_change

KINDS = ("damping_scale", "frequency_scale")


def candidates(model) -> list[Hypothesis]:
    """The structure-wide hypotheses (one each).

    Parameters
    ----------
    model : Structure or Rotor
        The engineering model.
    """
    return [Hypothesis("damping_scale", None, "damping", "all damping of the structure scaled by (1 + a)", "1",
                       False, -0.9, 10.0, 0.2, glob="damping_scale"),
            Hypothesis("frequency_scale", None, "frequency axis",
                       "frequency axis off: data at f (1 + e) labelled f", "1", False, -0.05, 0.05, 1e-3,
                       glob="frequency_scale")]


def responses(rec, data, hyps: list, thetas: list) -> list:
    """Per channel response with every hypothesis of ``hyps`` at its size (any family), by full solves.

    Channels on the same frequencies (and, with a sensor's mass, the same output) share one dynamic
    stiffness: one factorisation per frequency, their input vectors solved together.

    Parameters
    ----------
    rec : receptance
        The engineering model's matrices and frequencies (``M``, ``K``, ``D``, ``omega``).
    data : data set
        The channels and their frequency indices (``chans``, ``idx``).
    hyps : list of Hypothesis
        The effects, of any family.
    thetas : list
        Their sizes.
    """
    eps = sum(t for h, t in zip(hyps, thetas) if h.glob == "frequency_scale")
    a = sum(t for h, t in zip(hyps, thetas) if h.glob == "damping_scale")
    from .channel import factor            # the measurement chain multiplies afterwards
    moving = [t for h, t in zip(hyps, thetas) if h.gain is not None and h.gain[0] == "sensor_mass"]
    groups: dict = {}
    for k, (ch, idx) in enumerate(zip(data.chans, data.idx)):
        key = (np.asarray(idx).tobytes(), ch.out_dof if moving else None)
        groups.setdefault(key, []).append(k)
    out = [None] * len(data.chans)
    if getattr(rec, "modal", None) is not None:
        return _modal_responses(rec, data, hyps, thetas, eps, a, moving, factor)
    for ks in groups.values():
        idx = data.idx[ks[0]]
        w = rec.omega[idx] * (1 + eps)
        Z = rec.K[None] - (w * w)[:, None, None] * rec.M[None] + 1j * w[:, None, None] * ((1 + a) * rec.D)[None]
        add_impedances(Z, rec.model, w)     # a rational element of the model: K(jw) at the scaled axis too
        for h, t in zip(hyps, thetas):
            if h.gain is not None or h.glob is not None:
                continue
            U = np.asarray(h.dofs)
            Z[:, U[:, None], U[None, :]] += local_change(h, t, w)
        if moving:                          # a mass that moves with the sensor: at this group's output
            o = data.chans[ks[0]].out_dof
            Z[:, o, o] += -w * w * sum(moving)
        B = np.column_stack([data.b[k] for k in ks]).astype(complex)
        X = np.linalg.solve(Z, np.broadcast_to(B, (w.size,) + B.shape))
        for j, k in enumerate(ks):
            ch = data.chans[k]
            H = X[:, ch.out_dof, j]
            for h, t in zip(hyps, thetas):
                if h.gain is not None and h.gain[0] != "sensor_mass":
                    g, _ = factor(h, ch, data.freq_hz[k], t)
                    if g is not None:
                        H = H * g
            out[k] = H
    return out


def _modal_responses(rec, data, hyps, thetas, eps, a, moving, factor) -> list:
    """:func:`responses` from the modes of the model with its damping scaled (one eigen-decomposition per
    scale, :meth:`mutext.diagnose._screen._Receptance.scaled`), at the scaled frequency axis; the local effects
    and a sensor's mass join exactly by Woodbury on the DOFs they touch (what a full solve with them added to
    the dynamic stiffness gives)."""
    md = rec.scaled(a)
    local = [(h, t) for h, t in zip(hyps, thetas) if h.gain is None and h.glob is None]
    out = []
    for k, (ch, idx) in enumerate(zip(data.chans, data.idx)):
        w = rec.omega[idx] * (1 + eps)
        o = ch.out_dof
        U = sorted({d for h, _ in local for d in h.dofs} | ({o} if moving else set()))
        Rb = md.apply(w, np.asarray(data.b[k], float), rows=[o] + U)     # R b at the output and on U only
        H = Rb[:, 0]
        if U:
            pos = {d: i for i, d in enumerate(U)}
            Dm = np.zeros((w.size, len(U), len(U)), complex)
            for h, t in local:
                p = [pos[d] for d in h.dofs]
                Dm[:, np.asarray(p)[:, None], np.asarray(p)[None, :]] += local_change(h, t, w)
            if moving:
                Dm[:, pos[o], pos[o]] += -w * w * sum(moving)
            RUU = md.block(w, U, U)
            RoU = md.block(w, [o], U)[:, 0, :]
            u = np.linalg.solve(np.eye(len(U))[None] + RUU @ Dm, Rb[:, 1:, None])
            H = H - np.einsum("ku,ku->k", RoU, (Dm @ u)[:, :, 0])
        for h, t in zip(hyps, thetas):
            if h.gain is not None and h.gain[0] != "sensor_mass":
                g, _ = factor(h, ch, data.freq_hz[k], t)
                if g is not None:
                    H = H * g
        out.append(H)
    return out


def model_text(text: str, finding, note: str) -> str:
    """The model file with the finding written in (damping scaled; a frequency scale only noted).

    Parameters
    ----------
    text : str
        The model file's text.
    finding : Finding
        A whole-structure finding (damping or frequency scale).
    note : str
        Comment written next to the change.
    """
    if finding.kind == "frequency_scale":
        return "# (the analyser's frequency axis: the model itself is unchanged)\n" + text
    mf = ModelFile(text)
    count = mf.scale({"damper": ("damping",), "bearing": ("damping", "damping_y"),
                      "damping": ("modal", "alpha", "beta")}, 1 + finding.value, note)
    if count == 0:
        raise ModelError("the model file holds no damping value to scale")
    return mf.text()
