r"""The vector-fitting core (Gustavsen and Semlyen, see the package docstring): checked data, the
real pole-residue basis and its realisation, the stable poles, the weighted least squares and
one pole relocation, and the fit of an FRF at a given order."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError


def _check_data(omega, response):
    w = np.asarray(omega, dtype=float).ravel()
    G = np.asarray(response, dtype=complex).ravel()
    if w.size != G.size:
        raise ModelError(f"FRF fit: {w.size} frequencies but {G.size} response values")
    if w.size < 4:
        raise ModelError(f"FRF fit: need at least 4 frequencies, got {w.size}")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(G))):
        raise ModelError("FRF fit: non-finite frequency or response value")
    if np.any(w <= 0):
        raise ModelError("FRF fit: frequencies must be positive (rad/s)")
    if np.any(np.abs(G) == 0):
        raise ModelError("FRF fit: zero response values cannot be fitted in relative terms")
    order = np.argsort(w)
    w, G = w[order], G[order]
    if np.any(np.diff(w) == 0):
        raise ModelError("FRF fit: repeated frequencies")
    mag = np.abs(G)
    if not np.isfinite(mag.max()) or mag.min() < 1e-100 * mag.max():
        raise ModelError(f"FRF fit: the response magnitudes span {mag.min():.3g} to {mag.max():.3g}, more "
                         "than 100 decades (or overflow): a relative fit cannot weigh such data (a value "
                         "that should be zero, or wrong units on part of the data?)")
    if w[-1] > 1e100 * w[0]:
        raise ModelError(f"FRF fit: the frequencies span {w[0]:.3g} to {w[-1]:.3g} rad/s, more than 100 "
                         "decades")
    return w, G


def _check_hz(freq_hz, response, who):
    """:func:`_check_data` for frequencies in Hz; returns (omega, G) sorted by frequency."""
    try:
        return _check_data(2.0 * np.pi * np.asarray(freq_hz, dtype=float), response)
    except ModelError as exc:
        raise ModelError(str(exc).replace("FRF fit", who).replace("(rad/s)", "(Hz)")) from None


def _check_int(v, name, lo):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ModelError(f"FRF fit: {name} must be an integer >= {lo}, got {v!r}")


def _basis(s, poles):
    """Real basis: one column per real pole, two per complex pair (upper pole given)."""
    cols = []
    for p in poles:
        if p.imag == 0:
            cols.append(1.0 / (s - p.real))
        else:
            a, b = 1.0 / (s - p), 1.0 / (s - np.conj(p))
            cols += [a + b, 1j * a - 1j * b]
    return np.column_stack(cols)


def _realisation(poles, x):
    """(A, B, C) with C (sI - A)^-1 B = sum of the basis columns times x.

    A pair p = a + jb with coefficients (x1, x2), i.e. residue x1 + j x2, is the
    block A = [[a, b], [-b, a]], B = [2, 0]^T, C = [x1, x2]."""
    n = sum(1 if p.imag == 0 else 2 for p in poles)
    A, B, C = np.zeros((n, n)), np.zeros((n, 1)), np.zeros((1, n))
    k = 0
    for p in poles:
        if p.imag == 0:
            A[k, k], B[k, 0], C[0, k] = p.real, 1.0, x[k]
            k += 1
        else:
            A[k:k + 2, k:k + 2] = [[p.real, p.imag], [-p.imag, p.real]]
            B[k, 0] = 2.0
            C[0, k:k + 2] = x[k:k + 2]
            k += 2
    return A, B, C


def _eval(poles, x, omega):
    return _basis(1j * omega, poles) @ x


def _split_poles(lam, tol=1e-9):
    """Keep real poles and the upper member of each conjugate pair; reflect unstable ones."""
    lam = np.where(lam.real > 0, -lam.real + 1j * lam.imag, lam)
    out = []
    for p in lam:
        if abs(p.imag) <= tol * max(1.0, abs(p)):
            out.append(complex(p.real, 0.0))
        elif p.imag > 0:
            out.append(p)
    # a real pole at the origin would make the model unbounded: nudge it
    return np.array([complex(min(p.real, -1e-9 * max(1.0, abs(p))), p.imag) for p in out])


def _lstsq(M, rhs, wgt):
    Mw = M * wgt[:, None]
    rw = rhs * wgt
    Ar = np.vstack([Mw.real, Mw.imag])
    br = np.concatenate([rw.real, rw.imag])
    scale = np.linalg.norm(Ar, axis=0)
    scale[scale == 0] = 1.0
    sol, *_ = np.linalg.lstsq(Ar / scale, br, rcond=None)
    return sol / scale


def _relocate(z, F, poles, wgt, admissible, const: bool = False):
    r"""One vector-fitting step [GS]_: the new poles from the current ones.

    With :math:`\sigma(z) = 1 + \sum_i \tilde r_i\phi_i(z)` (the real basis
    :func:`_basis` of ``poles``), :math:`\sigma F \approx [c_0 +] \sum_i r_i\phi_i`
    is solved by weighted linear least squares; the zeros of :math:`\sigma`
    (eigenvalues of :math:`A - BC` for its realisation) passed through
    ``admissible`` are the new poles.  ``z`` is :math:`j\omega` for a frequency
    response (:func:`fit_frf`) or a real variable such as :math:`\omega^2`
    (:func:`fit_magnitude`, with the constant ``c_0``).
    """
    Phi = _basis(z, poles)
    m = Phi.shape[1]
    cols = [Phi, -F[:, None] * Phi]
    if const:
        cols.insert(0, np.ones((np.size(z), 1)))
    sol = _lstsq(np.hstack(cols), F.astype(complex), wgt)
    A, B, C = _realisation(poles, sol[-m:])
    return admissible(np.linalg.eigvals(A - B @ C))


def _vf(w, G, order, iterations, tol):
    """Vector fitting on data normalised to frequencies and magnitudes of order one
    (the fit is equivariant: poles scale with the frequency unit, the coefficients
    with the frequency and response units); returns (poles, coefficients, RMS
    relative residual) in the units of the data."""
    w0 = float(np.sqrt(w.min() * w.max()))
    g0 = float(np.abs(G).max())
    poles, x, res = _vf_unit(w / w0, G / g0, order, iterations, tol)
    return poles * w0, x * (g0 * w0), res


def _vf_unit(w, G, order, iterations, tol):
    s = 1j * w
    npairs, nreal = order // 2, order % 2
    beta = np.logspace(np.log10(w.min()), np.log10(w.max()), max(npairs, 1))[:npairs]
    poles = [complex(-0.01 * b, b) for b in beta]
    if nreal:
        poles.append(complex(-np.sqrt(w.min() * w.max()), 0.0))
    poles = np.array(poles)
    wgt = 1.0 / np.abs(G)
    for _ in range(iterations):
        new = _relocate(s, G, poles, wgt, _split_poles)
        if new.size != poles.size:   # a pair became two real poles or vice versa: accept as is
            poles = new
            continue
        moved = np.max(np.abs(np.sort_complex(new) - np.sort_complex(poles)) / np.maximum(np.abs(poles), 1e-12))
        poles = new
        if moved < tol:
            break
    Phi = _basis(s, poles)
    x = _lstsq(Phi, G, wgt)
    H = Phi @ x
    res = float(np.sqrt(np.mean(np.abs(H - G) ** 2 / np.abs(G) ** 2)))
    return poles, x, res
