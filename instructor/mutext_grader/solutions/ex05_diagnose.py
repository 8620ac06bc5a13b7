r"""Reference solution of exercise ``ex05_diagnose``: find the effect hidden in measured FRFs.

Every hypothesis (a grounded spring, an added mass or a grounded damper at
each mass) is fitted by a scan of its size over several decades followed by a
bounded one-dimensional minimisation of the log misfit; the best one is kept
when it lowers the misfit by more than 20 sigma^2/2 (the exercise's test).
SI units; frequencies in Hz as given.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

KINDS = ("none", "stiffness", "mass", "damping")


def log_misfit(model_re, model_im, meas_re, meas_im):
    h = np.asarray(model_re, float) + 1j * np.asarray(model_im, float)
    d = np.asarray(meas_re, float) + 1j * np.asarray(meas_im, float)
    return float(np.sum(np.abs(np.log(h / d)) ** 2))


def _responses(M, C, K, f_hz, channels, dof=None, kind=None, size=0.0):
    M, C, K = (np.array(X, float) for X in (M, C, K))
    if dof is not None:
        {"stiffness": K, "mass": M, "damping": C}[kind][dof, dof] += size
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    H = np.linalg.inv(Z)
    return [H[:, o, i] for i, o in channels]


def response_with_grounded_spring(M, C, K, f_hz, i_in, i_out, dof, k):
    h = _responses(M, C, K, f_hz, [(i_in, i_out)], dof, "stiffness", k)[0]
    return np.array([h.real, h.imag])


def _rss(M, C, K, f_hz, channels, data, dof=None, kind=None, size=0.0):
    hs = _responses(M, C, K, f_hz, channels, dof, kind, size)
    return float(sum(np.sum(np.abs(np.log(h / d)) ** 2) for h, d in zip(hs, data)))


def _fit(M, C, K, f_hz, channels, data, dof, kind):
    scale = {"stiffness": np.asarray(K, float)[dof, dof], "mass": np.asarray(M, float)[dof, dof],
             "damping": 0.1 * np.sqrt(np.asarray(K, float)[dof, dof] * np.asarray(M, float)[dof, dof])}[kind]
    grid = scale * np.logspace(-4, 1, 41)
    vals = [_rss(M, C, K, f_hz, channels, data, dof, kind, s) for s in grid]
    j = int(np.argmin(vals))
    lo, hi = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
    res = minimize_scalar(lambda s: _rss(M, C, K, f_hz, channels, data, dof, kind, s), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-9 * scale})
    return float(res.x), float(res.fun)


def fit_grounded_spring(M, C, K, f_hz, i_in, i_out, meas_re, meas_im, dof):
    d = np.asarray(meas_re, float) + 1j * np.asarray(meas_im, float)
    return _fit(M, C, K, f_hz, [(i_in, i_out)], [d], dof, "stiffness")[0]


def find_effect(M, C, K, f_hz, channels, data_re, data_im, noise):
    data = [np.asarray(r, float) + 1j * np.asarray(i, float) for r, i in zip(data_re, data_im)]
    channels = [tuple(c) for c in channels]
    rss0 = _rss(M, C, K, f_hz, channels, data)
    best = (rss0, 0, 0, 0.0)
    for dof in range(len(M)):
        for kind in KINDS[1:]:
            size, rss = _fit(M, C, K, f_hz, channels, data, dof, kind)
            if rss < best[0]:
                best = (rss, KINDS.index(kind), dof + 1, size)
    if (rss0 - best[0]) / (noise ** 2 / 2) <= 20:
        return np.array([0.0, 0.0, 0.0])
    return np.array([best[1], best[2], best[3]], float)
