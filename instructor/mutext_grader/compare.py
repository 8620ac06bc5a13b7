"""Comparison of returned models with reference models, with feedback that names the channel.

Models are compared through their frequency responses, so the student is free
to choose the state coordinates.  A mismatching channel is described in the
terms a student can act on: missing, should be zero, off by a constant factor
(with a guess of which weight or scaling causes it), or different dynamics.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from mutext.lti import check_finite, freqresp, ss
from mutext.response import frequency_grid

__all__ = ["build_ss", "fmt", "ChannelCheck", "compare_responses", "matches", "permutation_hint",
           "resonance_safe_grid"]


def fmt(x) -> str:
    """A number for feedback: 4 significant digits, complex only if it really is."""
    x = complex(x)
    if x.imag == 0 or (np.isfinite(abs(x)) and abs(x.imag) <= 1e-9 * max(abs(x), 1e-300)):
        v = x.real
        return "0" if v == 0 else f"{v:.4g}"      # nan and inf print as such
    return f"{x.real:.4g}{x.imag:+.4g}j"


def build_ss(value, what: str):
    """Rebuild a StateSpace from the child's plain matrices.

    Returns ``(sys, None)`` or ``(None, message)``.
    """
    try:
        sys_ = ss(value["A"], value["B"], value["C"], value["D"])
    except Exception as exc:   # noqa: BLE001 - any malformed payload is the submission's fault
        return None, f"{what}: the returned matrices do not form a state-space model ({exc})"
    dt = value.get("dt")
    if dt not in (None, 0, 0.0):
        return None, f"{what}: the model is discrete-time (dt={dt:g}); a continuous-time model (dt=0) is expected"
    try:
        check_finite(sys_, what)
    except Exception as exc:   # noqa: BLE001
        return None, str(exc)
    return sys_, None


def resonance_safe_grid(ref_sys, lo=-1.0, hi=3.0, num=40, gap=0.05):
    """Log-spaced frequencies (rad/s) that stay ``gap`` (relative) away from the reference's poles.

    The undamped models of the exercises have infinite gain at their natural
    frequencies; comparing there would compare rounding errors.
    """
    poles = np.linalg.eigvals(np.asarray(ref_sys.A, float)) if ref_sys.nstates else ()
    return np.concatenate([[0.0], frequency_grid((10.0 ** lo, 10.0 ** hi), num, poles=poles, avoid=gap)])


def matches(Gs, Gr, rtol, atol) -> bool:
    """Elementwise ``|Gs - Gr| <= rtol |Gr| + atol`` at every frequency (False on NaN)."""
    if Gs.shape != Gr.shape:
        return False
    with np.errstate(invalid="ignore"):
        return bool(np.all(np.abs(Gs - Gr) <= rtol * np.abs(Gr) + atol))


@dataclass
class ChannelCheck:
    """Outcome of one input -> output channel."""
    inp: str
    out: str
    ok: bool
    message: str = ""


def _constant(g, tol=1e-9):
    return bool(np.all(np.abs(g - g[0]) <= tol * max(np.abs(g).max(), 1e-300)))


def _describe(gs, gr, w, label, rtol, atol, hints):
    """Message for one mismatching channel ``label`` (e.g. ``"f2 -> y (sensor noise)"``)."""
    small = atol
    ref_zero = np.all(np.abs(gr) <= small)
    got_zero = np.all(np.abs(gs) <= small)
    if not np.all(np.isfinite(gs)):
        return f"channel {label}: the response is not finite at some test frequencies"
    if ref_zero:
        k = int(np.argmax(np.abs(gs)))
        return (f"channel {label} should be zero, got a response of magnitude {abs(gs[k]):.3g}"
                + (f" at {w[k]:.3g} rad/s" if not _constant(gs) else ""))
    if got_zero:
        if _constant(gr):
            return f"channel {label} is missing: expected {fmt(gr[0])}, got 0"
        k = int(np.argmax(np.abs(gr)))
        return (f"channel {label} is missing: expected a response (e.g. |G| = {abs(gr[k]):.3g} at "
                f"{w[k]:.3g} rad/s), got 0")
    if _constant(gr) and _constant(gs):
        msg = f"channel {label} differs: expected {fmt(gr[0])}, got {fmt(gs[0])}"
    else:
        msg = None
    nz = np.abs(gr) > small
    r = gs[nz] / gr[nz]
    if r.size and np.all(np.abs(r - r[0]) <= 1e-4 * abs(r[0])):
        factor = r[0].real if abs(r[0].imag) <= 1e-6 * abs(r[0]) else r[0]
        if msg is None:
            msg = f"channel {label} is {fmt(factor)} times the expected response"
        for f, text in hints:
            if np.isreal(factor) and abs(factor - f) <= 1e-4 * abs(f):
                return f"{msg}: {text}"
        return msg
    if msg is not None:
        return msg
    err = np.abs(gs - gr) / (rtol * np.abs(gr) + atol)
    k = int(np.argmax(err))
    return (f"channel {label} has different dynamics: at {w[k]:.3g} rad/s expected {fmt(gr[k])}, "
            f"got {fmt(gs[k])}")


def compare_responses(Gs, Gr, w, inputs, outputs, *, rtol=1e-4, atol=None, hints=None):
    """Compare two frequency responses channel by channel.

    Parameters
    ----------
    Gs, Gr : ndarray (nout, nin, nw)
        Submitted and reference responses at the frequencies ``w`` (rad/s).
    inputs, outputs : list of str
        Channel names used in the feedback (e.g. ``"f2 (sensor noise)"``).
    rtol, atol : float
        Tolerances of :func:`matches`; ``atol`` defaults to ``1e-9`` times the
        largest reference gain.
    hints : callable (out_index, in_index) -> list of (factor, text), optional
        Known mistakes that scale a channel by a constant factor.

    Returns
    -------
    list of ChannelCheck
    """
    if atol is None:
        atol = 1e-9 * max(np.abs(Gr).max(), 1e-300)
    out = []
    for i, j in itertools.product(range(Gr.shape[0]), range(Gr.shape[1])):
        gs, gr = Gs[i, j], Gr[i, j]
        ok = matches(gs, gr, rtol, atol)
        label = f"{inputs[j]} -> {outputs[i]}"
        msg = "" if ok else _describe(gs, gr, w, label, rtol, atol, hints(i, j) if hints else [])
        out.append(ChannelCheck(inputs[j], outputs[i], ok, msg))
    return out


def permutation_hint(Gs, Gr, in_names, out_names, rtol=1e-4):
    """If the submission is the reference with reordered inputs or outputs, say so (else None)."""
    atol = 1e-9 * max(np.abs(Gr).max(), 1e-300)
    if Gs.shape != Gr.shape or matches(Gs, Gr, rtol, atol):
        return None
    for po in itertools.permutations(range(Gr.shape[0])):
        for pi in itertools.permutations(range(Gr.shape[1])):
            if matches(Gs, Gr[np.ix_(po, pi)], rtol, atol):
                parts = []
                if list(pi) != sorted(pi):
                    parts.append(f"inputs in the order [{', '.join(in_names[k] for k in pi)}] instead of "
                                 f"[{', '.join(in_names)}]")
                if list(po) != sorted(po):
                    parts.append(f"outputs in the order [{', '.join(out_names[k] for k in po)}] instead of "
                                 f"[{', '.join(out_names)}]")
                return "your model is right but has its " + " and ".join(parts)
    return None


def response(sys_, w):
    """:func:`mutext.lti.freqresp` that reports failure as a message instead of raising."""
    try:
        with np.errstate(all="ignore"):
            return freqresp(sys_, w), None
    except Exception as exc:   # noqa: BLE001
        return None, f"the frequency response could not be evaluated ({exc})"


def as_array(value, what: str):
    """A returned array payload as a float ndarray, or ``(None, message)`` naming ``what``."""
    try:
        return np.asarray(value["data"], dtype=float).reshape(value["shape"]), None
    except Exception as exc:   # noqa: BLE001 - malformed payload is the submission's fault
        return None, f"{what}: the returned value is not an array of numbers ({exc})"


def returned(outcomes, calls, feedback: list, parse=None, what: str = ""):
    """The calls that returned a usable value, as ``(call, tag, value)``.

    A call that raised, or whose value ``parse(value, what)`` rejects (it returns
    ``(obj, error)``, e.g. :func:`as_array`, :func:`build_ss`), adds one line
    ``"[label] message"`` to ``feedback`` and is skipped."""
    for call, oc in zip(calls, outcomes):
        tag = f"[{call.label}]"
        if not oc["ok"]:
            feedback.append(f"{tag} {oc['error']}")
            continue
        value = oc["value"]
        if parse is not None:
            value, err = parse(value, what)
            if err:
                feedback.append(f"{tag} {err}")
                continue
        yield call, tag, value
