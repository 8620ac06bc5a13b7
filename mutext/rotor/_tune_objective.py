r"""The objective of :func:`mutext.rotor.tuning.tune`: fitted unknowns, fitted channels, log residuals.

Three steps turn the user's request into a least-squares problem in
normalised unknowns :math:`\theta` (see :mod:`mutext.rotor.tuning` for the
formulas):

* :func:`_unknowns`: the fitted quantities (a parameter, or names tied in
  their start ratios), their start values, bounds and scales;
* :func:`_fit_channels`: the measured FRFs as channels of the model, cut to
  the band and thinned to the fitted points;
* :class:`_LogResidual`: the weighted real residual vector
  :math:`[\mathrm{Re}\,r;\ \mathrm{Im}\,r]` and its exact Jacobian, from the
  sensitivities of :mod:`mutext.rotor.sensitivity`, with a one-entry cache
  (IPOPT asks for the residual and its Jacobian at the same point).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, SolverError
from .frf_channels import _Channel, _groups, _Inputs, _lookup, _resolve_channel, select_points
from .sensitivity import _Evaluator


def _entries(model, parameters):
    """Parse ``parameters`` into entries: (label, [member indices])."""
    if isinstance(parameters, str):
        parameters = [parameters]
    try:
        parameters = list(parameters)
    except TypeError:
        raise ModelError(f"parameters must be a list of names, got {parameters!r}") from None
    if not parameters:
        raise ModelError("no parameters to fit")
    entries, seen = [], set()
    for e in parameters:
        names = [e] if isinstance(e, str) else list(e)
        if not names:
            raise ModelError("an empty group in parameters")
        idx = [_lookup(model, nm) for nm in names]
        for nm in names:
            if nm in seen:
                raise ModelError(f"parameter '{nm}' is given twice")
            seen.add(nm)
        entries.append(("+".join(names), idx))
    return entries


def _default_bounds(name, x0):
    if name.endswith("depth_ratio"):
        from .crack import MAX_DEPTH_RATIO
        return (0.0, MAX_DEPTH_RATIO)
    if x0 > 0:
        return (x0 / 10.0, x0 * 10.0)
    if x0 < 0:
        return (x0 * 10.0, x0 / 10.0)
    raise ModelError(f"parameter '{name}' starts at 0: give bounds={{'{name}': (lo, hi)}} (or a nonzero "
                     f"start) so that it can be scaled")


def _check_bound_keys(model, bounds: dict, entries) -> None:
    """Every key of ``bounds`` names a model parameter that is fitted."""
    for k in bounds:
        keys = [k] if isinstance(k, str) else list(k)
        for nm in keys:
            _lookup(model, nm)
        if not any(k == lab or k == lab.split("+")[0] or (not isinstance(k, str) and "+".join(k) == lab)
                   for lab, _ in entries):
            raise ModelError(f"bounds given for '{k}', which is not fitted (fitted: "
                             f"{', '.join(lab for lab, _ in entries)})")


@dataclass
class _Unknowns:
    """The fitted quantities: SI start values, bounds and scales, and the tie matrix.

    The model parameters changed by the fit (``members``, in entry order) are
    ``T @ x`` for the fitted SI values ``x``; the optimiser sees ``x / scale``.
    """
    names: list
    members: list
    T: np.ndarray
    x0: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    scale: np.ndarray
    units: list


def _entry_bounds(lab, name, xl, bounds):
    """``(lo, hi)`` of one fitted quantity, checked against its start value ``xl``."""
    b = bounds.get(lab, bounds.get(name, bounds.get(tuple(lab.split("+")))))
    if b is None:
        b = _default_bounds(name, xl)
    try:
        bl, bh = (float(b[0]), float(b[1]))
    except (TypeError, ValueError, IndexError):
        raise ModelError(f"bounds of '{lab}' must be a pair (lo, hi), got {b!r}") from None
    if math.isnan(bl) or math.isnan(bh) or bl > bh:
        raise ModelError(f"bounds of '{lab}': lo = {bl:g} > hi = {bh:g}")
    if not bl <= xl <= bh:
        raise ModelError(f"start value of '{lab}' ({xl:g}) is outside its bounds [{bl:g}, {bh:g}]")
    return bl, bh


def _unknowns(model, entries, v0, bounds: dict) -> _Unknowns:
    """Scaling, bounds and tie matrix of the ``entries`` (tied names keep their start ratios)."""
    members = [i for _, idx in entries for i in idx]
    T = np.zeros((len(members), len(entries)))
    x0, lo, hi, scale, units = [], [], [], [], []
    row = 0
    for e, (lab, idx) in enumerate(entries):
        lead = idx[0]
        xl = float(v0[lead])
        if len(idx) > 1 and xl == 0.0:
            raise ModelError(f"tied parameters '{lab}': the first one starts at 0, so the ratios are undefined")
        for i in idx:
            T[row, e] = 1.0 if i == lead else float(v0[i]) / xl
            row += 1
        bl, bh = _entry_bounds(lab, model.parameter_names[lead], xl, bounds)
        # a quantity starting at 0 is scaled by its bounds
        s = abs(xl) if xl != 0 else max(abs(bl) if math.isfinite(bl) else 0.0,
                                        abs(bh) if math.isfinite(bh) else 0.0)
        if not (s > 0 and math.isfinite(s)):
            raise ModelError(f"'{lab}' starts at 0 with unbounded or zero bounds: cannot scale it")
        x0.append(xl)
        lo.append(bl)
        hi.append(bh)
        scale.append(s)
        units.append(model.parameters[lead].unit)
    x0, lo, hi, scale = (np.array(a, float) for a in (x0, lo, hi, scale))
    return _Unknowns([lab for lab, _ in entries], members, T, x0, lo, hi, scale, units)


def _in_band(f, Hm, band_hz, k, label):
    """The part of one FRF inside ``band_hz`` (all of it for ``None``)."""
    if band_hz is None:
        return f, Hm
    bl_, bh_ = float(band_hz[0]), float(band_hz[1])
    if not bl_ < bh_:
        raise ModelError(f"band_hz must be (lo, hi) with lo < hi, got {band_hz!r}")
    keep = (f >= bl_) & (f <= bh_)
    if not np.any(keep):
        raise ModelError(f"FRF #{k} ({label}): no frequency inside the fitted band "
                         f"{bl_:g}-{bh_:g} Hz (it covers {f[0]:g}-{f[-1]:g} Hz)")
    return f[keep], Hm[keep]


def _fit_channels(model, frfs, inputs: _Inputs, band_hz, max_points, weights):
    """The measured FRFs as fitted channels; returns ``(channels, output DOFs)``.

    Each channel keeps its points inside ``band_hz`` (at most about
    ``max_points`` of them, :func:`select_points`); repeated labels get ``#k``.
    """
    if weights is not None:
        weights = [float(w) for w in weights]
        if len(weights) != len(frfs) or any(not (w > 0 and math.isfinite(w)) for w in weights):
            raise ModelError(f"weights must be {len(frfs)} positive numbers (one per FRF), got {weights}")
    out_dofs: list[int] = []
    chans: list[_Channel] = []
    for k, frf in enumerate(frfs, start=1):
        col, od, label, speed = _resolve_channel(model, frf, k, inputs)
        f, Hm = _in_band(frf.freq_hz, frf.response, band_hz, k, label)
        if np.any(Hm == 0):
            raise ModelError(f"FRF #{k} ({label}): zero response at {f[np.argmax(Hm == 0)]:g} Hz (the log "
                             "error is undefined)")
        sel = select_points(f, Hm, max_points) if max_points is not None else np.arange(f.size)
        if od not in out_dofs:
            out_dofs.append(od)
        chans.append(_Channel(label, f[sel], Hm[sel], speed, col, out_dofs.index(od),
                              1.0 if weights is None else weights[k - 1], frf))
    labels = [c.label for c in chans]
    for c in chans:
        if labels.count(c.label) > 1:
            c.label = f"{c.label}#{chans.index(c) + 1}"
    return chans, out_dofs


class _LogResidual:
    r"""Weighted log residuals of the fitted channels as a function of the normalised unknowns.

    ``evaluate(theta, jac)`` returns ``(rr, r)`` or, with ``jac``,
    ``(rr, r, JJ)``: the real residual vector :math:`[\sqrt w\,\mathrm{Re}\,r;
    \sqrt w\,\mathrm{Im}\,r]` (length ``n_residuals``), the complex residuals
    :math:`r` and the Jacobian of ``rr`` with respect to ``theta``.  The last
    point is cached.
    """

    def __init__(self, model, unknowns: _Unknowns, v0, chans, inputs: _Inputs, out_dofs):
        self.unknowns, self.v0, self.chans = unknowns, v0, chans
        groups = _groups(chans)
        self.evaluator = _Evaluator(model, unknowns.members, inputs, out_dofs, groups)
        self.pos = [np.searchsorted(groups[c.speed], 2 * np.pi * c.freq_hz) for c in chans]
        self.sqw = np.concatenate([np.full(c.freq_hz.size, math.sqrt(c.weight)) for c in chans])
        self.n_points = sum(c.freq_hz.size for c in chans)
        self.n_residuals = 2 * self.n_points
        self.n_unknowns = len(unknowns.names)
        self._cache: dict = {}

    def full_vector(self, x):
        """The model's parameter vector with the fitted SI values ``x``."""
        v = self.v0.copy()
        v[self.unknowns.members] = self.unknowns.T @ x
        return v

    def _compute(self, theta, jac: bool):
        u = self.unknowns
        x = u.scale * np.asarray(theta, float).ravel()
        res = self.evaluator.evaluate(self.full_vector(x), derivatives=jac)
        rs, Js = [], []
        for c, ps in zip(self.chans, self.pos):
            H, dH = res[c.speed]
            h = H[c.out_dof, c.in_col, ps]
            if np.any(h == 0) or not np.all(np.isfinite(h)):
                raise SolverError("the model response is zero or not finite at some frequency for parameters "
                                  f"{dict(zip(u.names, x))}")
            rs.append(np.log(h / c.measured))
            if jac:
                dh = dH[:, c.out_dof, c.in_col][:, ps]                     # (nmembers, npts)
                Js.append(((u.T * u.scale[None, :]).T @ dh / h[None, :]).T)  # (npts, nentries)
        r = np.concatenate(rs)
        sqw = self.sqw
        rr = np.concatenate([r.real, r.imag]) * np.concatenate([sqw, sqw])
        if not jac:
            return rr, r
        J = np.concatenate(Js)
        JJ = np.vstack([J.real, J.imag]) * np.concatenate([sqw, sqw])[:, None]
        return rr, r, JJ

    def evaluate(self, theta, jac: bool):
        key = np.asarray(theta, float).tobytes()
        hit = self._cache.get(key)
        if hit is not None and (not jac or len(hit) == 3):
            return hit
        out = self._compute(theta, jac)
        self._cache.clear()
        self._cache[key] = out
        return out
