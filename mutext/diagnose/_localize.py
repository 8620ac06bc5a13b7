r"""Where the unexplained misfit lives: the station whose receptance explains it best, and what it asks for.

When no hypothesis explains the data, the thesis's method puts a controller
where the model is unsure and lets it absorb what is missing
(:mod:`mutext.mbi`).  Its first question is *where*.  An unknown impedance
:math:`z(\omega)` to ground at one translational degree of freedom :math:`s`
changes every channel exactly (Sherman-Morrison):

.. math::
    H_c = H^0_c - \frac{z\,R_{o s} R_{s b}}{1 + z R_{ss}}
        = H^0_c - q\,R_{o s} R_{s b},\qquad q = \frac{z}{1 + z R_{ss}},

which is *linear* in :math:`q` at each frequency.  With two or more channels
:math:`q(\omega)` is fitted per frequency by weighted least squares (weights
:math:`1/|\hat H_c|`); the station whose fit leaves the least misfit is where
the missing dynamics act, as seen from the channels measured.  The impedance
it requires, :math:`z = q/(1 - qR_{ss})`, is then read as a mass, damper and
spring to ground, :math:`z \approx k + j\omega c - \omega^2 m` (linear least
squares, the relative residual of that reading reported), and the element is
judged on the held-out data like any effect.  With one channel any station
fits exactly: the localisation needs two.

The result is what the thesis's controller is placed to find: with
``mbi=True`` :func:`mutext.diagnose.diagnose` also runs model-based
identification (D-K iteration) at the station found (lumped chains).
"""
from __future__ import annotations

import math

import numpy as np


def _pieces(rec, data, s_dof):
    """Per channel: (a = R_os R_sb, R_ss) at its frequencies."""
    out = []
    for k, (ch, idx) in enumerate(zip(data.chans, data.idx)):
        Rb, Ro = data.columns(rec, k)
        out.append((Ro[:, s_dof] * Rb[:, s_dof], rec.block(idx, [s_dof], [s_dof])[:, 0, 0]))
    return out


def _fit_q(data, pieces):
    """q per distinct frequency index by weighted least squares over the channels that share it."""
    num, den = {}, {}
    for (a, _), idx, H0, m in zip(pieces, data.idx, data.H0, data.meas):
        w = 1.0 / np.abs(m) ** 2
        for j, i in enumerate(idx):
            # minimise sum |H0 - q a - m|^2 / |m|^2 over q
            num[i] = num.get(i, 0.0) + w[j] * np.conj(a[j]) * (H0[j] - m[j])
            den[i] = den.get(i, 0.0) + w[j] * abs(a[j]) ** 2
    return {i: num[i] / den[i] for i in num if den[i] > 0}


def localize(rec, fit, held, model, s2: float, stations=None):
    """The station that explains the fitted data's misfit best, its required impedance and its reading.

    Returns a dict (see the module docstring) or None when fewer than two channels share a frequency."""
    lay = model.layout
    shared = {}
    for idx in fit.idx:
        for i in idx:
            shared[i] = shared.get(i, 0) + 1
    if sum(1 for v in shared.values() if v >= 2) < 8:
        return None
    stations = range(1, lay.n_nodes + 1) if stations is None else stations
    rows = []
    for s in stations:
        d = lay.dof(s, "x" if lay.kind == "lumped" else "u")
        pieces = _pieces(rec, fit, d)
        q = _fit_q(fit, pieces)
        rss = 0.0
        for (a, _), idx, H0, m in zip(pieces, fit.idx, fit.H0, fit.meas):
            qq = np.array([q.get(i, 0.0) for i in idx])
            with np.errstate(all="ignore"):
                r = np.log((H0 - qq * a) / m)
            rss += float(np.sum(np.abs(r) ** 2)) if np.all(np.isfinite(r)) else math.inf
        rows.append((rss, s, d, q, pieces))
    rows.sort(key=lambda x: x[0])
    rss, s, d, q, pieces = rows[0]
    # the required impedance per frequency and its reading as mass, damper and spring to ground
    idx_all = sorted(q)
    Rss = {}
    for (_, r_ss), idx in zip(pieces, fit.idx):
        for j, i in enumerate(idx):
            Rss[i] = r_ss[j]
    w = rec.omega[idx_all]
    qv = np.array([q[i] for i in idx_all])
    z = qv / (1 - qv * np.array([Rss[i] for i in idx_all]))
    A = np.column_stack([np.ones_like(w), 1j * w, -w * w])
    wt = 1.0 / np.maximum(np.abs(z), 1e-300)
    Ar = np.vstack([(A * wt[:, None]).real, (A * wt[:, None]).imag])
    br = np.concatenate([(z * wt).real, (z * wt).imag])
    (k, c, m), *_ = np.linalg.lstsq(Ar, br, rcond=None)
    zf = A @ np.array([k, c, m])
    msd_residual = float(np.sqrt(np.mean(np.abs(zf - z) ** 2 / np.maximum(np.abs(z), 1e-300) ** 2)))

    def with_element(data):
        out = []
        for k_, (ch, idx) in enumerate(zip(data.chans, data.idx)):
            Rb, Ro = data.columns(rec, k_)
            ww = rec.omega[idx]
            ze = k + 1j * ww * c - ww * ww * m
            out.append(data.H0[k_] - ze * Ro[:, d] * Rb[:, d] / (1 + ze * rec.block(idx, [d], [d])[:, 0, 0]))
        return out

    def rss_of(Hs, meas):
        with np.errstate(all="ignore"):
            v = float(sum(np.sum(np.abs(np.log(h / mm)) ** 2) for h, mm in zip(Hs, meas)))
        return v if math.isfinite(v) else math.inf
    before = rss_of(held.H0, held.meas)
    after = rss_of(with_element(held), held.meas)
    # degrees of freedom: two real residuals per point, less two per frequency for q
    dof = max(2 * sum(len(i) for i in fit.idx) - 2 * len(q), 1)
    return {"station": int(s), "dof": int(d), "misfit": rss / (dof * s2),
            "ranking": [{"station": int(x[1]), "misfit": x[0] / (dof * s2)} for x in rows[:5]],
            "freq_hz": (w / (2 * np.pi)).tolist(), "required_impedance": z, "msd": {"m": float(m), "c": float(c),
                                                                                       "k": float(k)},
            "msd_residual": msd_residual, "held_out_misfit_ratio": after / before if before > 0 else math.nan,
            "msd_fit": zf}


def describe(loc: dict) -> str:
    """The localisation in one sentence."""
    m = loc["msd"]
    others = ", ".join(f"station {r['station']} {r['misfit']:.3g}" for r in loc["ranking"][1:3])
    return (f"the misfit is best explained at station {loc['station']} (an impedance to ground there, any value "
            f"per frequency, leaves {loc['misfit']:.3g} times the noise; next: {others}); read as mass "
            f"{m['m']:+.4g} kg, damper {m['c']:+.4g} N s/m and spring {m['k']:+.4g} N/m to ground (that reading "
            f"misses the required impedance by {100 * loc['msd_residual']:.2g} % rms); with that element the "
            f"held-out residual is {loc['held_out_misfit_ratio']:.3g} times what it was")
