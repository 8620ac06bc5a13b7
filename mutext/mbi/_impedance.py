r"""Reading the identified controller: the band where the measurement pins it down, its
mass-damper-spring form, and the dynamic stiffness a measured FRF asks for at one port."""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from ..errors import ModelError
from ..lti import as_ss, freqresp
from ._plant import MBIPlant, _channels, _index


@dataclass
class ImpedanceFit:
    r"""Least-squares reading of a controller as a mass, damper and spring.

    :math:`K(j\omega) \approx dk + j\omega\,dc - \omega^2 dm` on ``band``
    (rad/s), each frequency weighted by how much the measured output depends on
    ``K`` there (see :func:`fit_impedance`).

    Attributes
    ----------
    dm, dc, dk : float
        Added mass (kg), damping (N s/m) and stiffness (N/m).
    residual : float
        Weighted relative residual :math:`\|w(K - \hat K)\| / \|w K\|` (0 = perfect).
    band : tuple of float
        Lowest and highest frequency (rad/s) of the identifiable band.
    fits : bool
        ``residual <= tol``: the mass-damper-spring form describes ``K``.
    description : str
    sigma : tuple of float
        Standard uncertainty of ``(dm, dc, dk)``: with the identification
        weights :math:`|s(\omega)|`, the spread that changes the normalised error
        by about one, i.e. what the measurement cannot tell apart.
    omega : ndarray
        The frequencies (rad/s) of the fit.
    weight : ndarray
        The weight :math:`|s(\omega)|` of each frequency.
    """
    dm: float
    dc: float
    dk: float
    residual: float
    band: tuple
    fits: bool
    description: str
    omega: np.ndarray = field(repr=False, default=None)
    weight: np.ndarray = field(repr=False, default=None)
    sigma: tuple = (np.nan, np.nan, np.nan)

    def response(self, omega) -> np.ndarray:
        """:math:`dk + j\\omega dc - \\omega^2 dm`.

        Parameters
        ----------
        omega : float or array_like
            Frequencies in rad/s.
        """
        w = np.asarray(omega, float)
        return self.dk + 1j * w * self.dc - w ** 2 * self.dm


def identifiable_band(plant: MBIPlant, K, omega):
    r"""Sensitivity of the normalised error to the controller, and the band where it matters.

    A change :math:`\delta K` changes the normalised error by
    :math:`\delta z = s(\omega)\,\delta K` with
    :math:`s = P_{zu}P_{yw}/(1 - P_{yu}K)^2` (nominal channels).  ``K`` is
    pinned down where a 100 % error in it would exceed the allowed error:
    :math:`|s(\omega)\,K(j\omega)| \ge 1`.

    Returns
    -------
    sensitivity : ndarray
        :math:`|s(\omega)|` on ``omega``.
    mask : ndarray of bool
        Frequencies inside the identifiable band.
    """
    omega = np.asarray(omega, float)
    _, Pzu, Pyw, Pyu = _channels(plant, omega)
    Kj = freqresp(as_ss(K), omega)[0, 0]
    s = np.abs(Pzu * Pyw / (1 - Pyu * Kj) ** 2)
    return s, s * np.abs(Kj) >= 1.0


def fit_impedance(K, omega, weight=None, tol: float = 0.1) -> ImpedanceFit:
    r"""Fit :math:`K(j\omega) \approx dk + j\omega dc - \omega^2 dm` by weighted least squares.

    Parameters
    ----------
    K : control.StateSpace or array_like of complex
        The controller, or its frequency response on ``omega``.
    omega : array_like
        Frequencies (rad/s) of the band to fit.
    weight : array_like, optional
        Non-negative weight per frequency (default 1).
    tol : float
        Largest weighted relative residual for which the form is accepted.

    Returns
    -------
    ImpedanceFit
    """
    omega = np.asarray(omega, float).ravel()
    if omega.size < 3:
        raise ModelError(f"fit_impedance needs at least 3 frequencies in the band, got {omega.size}")
    Kj = freqresp(as_ss(K), omega)[0, 0] if isinstance(K, (ct.StateSpace, ct.TransferFunction)) \
        else np.asarray(K, complex).ravel()
    if Kj.shape != omega.shape:
        raise ModelError(f"K has {Kj.size} response values for {omega.size} frequencies")
    if not np.all(np.isfinite(omega)) or np.any(omega <= 0) or omega.max() > 1e100:
        raise ModelError("fit_impedance: omega must hold positive, finite frequencies (rad/s, at most 1e100)")
    if not np.all(np.isfinite(Kj)):
        raise ModelError("fit_impedance: K has non-finite response values on omega")
    if weight is None:
        wgt = np.ones_like(omega)
    else:
        try:
            wgt = np.asarray(weight, float).ravel()
        except (TypeError, ValueError):
            raise ModelError(f"fit_impedance: weight must be an array of real numbers, got {weight!r}") from None
        if wgt.size == 1:
            wgt = np.full(omega.size, float(wgt[0]))
        if wgt.shape != omega.shape:
            raise ModelError(f"fit_impedance: weight has {wgt.size} values for {omega.size} frequencies")
        if not np.all(np.isfinite(wgt)):
            i = int(np.flatnonzero(~np.isfinite(wgt))[0])
            raise ModelError(f"fit_impedance: weight[{i}] is {wgt[i]} (weights must be finite)")
        if np.any(wgt < 0):
            i = int(np.flatnonzero(wgt < 0)[0])
            raise ModelError(f"fit_impedance: weight[{i}] = {wgt[i]:g} is negative (weights must be >= 0)")
        # a weight below 1e-8 of the largest counts as zero: two frequencies whose weights differ by
        # 1e13 determine the three values no better than one frequency does (the lesser one's
        # equations are lost in the rounding of the greater's)
        counted = int(np.count_nonzero(wgt > 1e-8 * wgt.max())) if wgt.max() > 0 else 0
        if counted < 2:
            raise ModelError(f"fit_impedance: only {counted} of the {wgt.size} weights are positive and "
                             "within 1e-8 of the largest; at least 2 frequencies must count to determine "
                             "mass, damper and spring")
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol >= 0):
        raise ModelError(f"fit_impedance: tol must be a non-negative finite number, got {tol!r}")
    # real part: dk - w^2 dm; imaginary part: w dc; scale the columns for conditioning
    A = np.zeros((2 * omega.size, 3))
    A[:omega.size, 0] = -omega ** 2
    A[:omega.size, 2] = 1.0
    A[omega.size:, 1] = omega
    b = np.concatenate([Kj.real, Kj.imag])
    # only relative weights shape the fit: normalise them (a weight of 1e152 overflowed)
    wscale = float(wgt.max())
    wn = wgt / wscale
    W = np.concatenate([wn, wn])
    col = np.linalg.norm(A * W[:, None], axis=0)
    col[col == 0] = 1.0
    Aw = A * W[:, None] / col
    x, *_ = np.linalg.lstsq(Aw, b * W, rcond=None)
    dm, dc, dk = x / col
    fit = dk + 1j * omega * dc - omega ** 2 * dm
    res = float(np.linalg.norm(wn * (Kj - fit)) / max(np.linalg.norm(wn * Kj), 1e-300))
    # standard uncertainty: the weights are read as inverse standard deviations of K
    # (for the identification weights 1/|s|: the change of K that moves the
    # normalised error by one); without weights, from the residual variance.  Only the diagonal
    # is needed, and its square root is taken before the column and weight scales are undone:
    # 1/wscale**2 overflows for weights beyond ~1e154 where 1/wscale does not
    P = np.linalg.pinv(Aw.T @ Aw)
    with np.errstate(over="ignore"):        # weights near 5e-324: an unbounded spread is inf
        sigma = np.sqrt(np.maximum(np.diag(P), 0.0)) / col / wscale
    if weight is None:
        dof = max(2 * omega.size - 3, 1)
        sigma = sigma * np.sqrt(float(np.sum(np.abs(Kj - fit) ** 2)) / dof)
    ok = res <= tol
    terms = []
    for val, sd, unit, what in zip((dm, dc, dk), sigma, ("kg", "N s/m", "N/m"), ("mass", "damper", "spring")):
        terms.append(f"{what} {val:+.4g} +/- {sd:.2g} {unit}")
    if ok:
        desc = f"added {', '.join(terms)} (residual {res:.2%})"
    else:
        desc = (f"not a mass-damper-spring: best such fit ({', '.join(terms)}) leaves {res:.0%} of K "
                "unexplained; look at K's shape (resonances, phase) instead")
    return ImpedanceFit(float(dm), float(dc), float(dk), res, (float(omega.min()), float(omega.max())),
                        bool(ok), desc, omega, wgt, tuple(float(v) for v in sigma))


def impedance_response(coeffs: dict, omega) -> np.ndarray:
    """:math:`dk + j\\omega dc - \\omega^2 dm` for ``coeffs = {"dm", "dc", "dk"}`` (missing keys are 0).

    Parameters
    ----------
    coeffs : dict
        ``{"dm": kg, "dc": N s/m, "dk": N/m}``; a missing key counts as 0.
    omega : float or array_like
        Frequencies in rad/s.

    Examples
    --------
    >>> from mutext.mbi import impedance_response
    >>> impedance_response({"dk": 100.0, "dm": 1.0}, [0.0, 10.0])     # a spring and a mass cancel at 10 rad/s
    array([100.+0.j,   0.+0.j])
    """
    w = np.asarray(omega, float)
    return coeffs.get("dk", 0.0) + 1j * w * coeffs.get("dc", 0.0) - w ** 2 * coeffs.get("dm", 0.0)


def relative_error(K, reference, omega, weight=None) -> float:
    r"""Weighted RMS over ``omega`` of :math:`|K(j\omega) - D(j\omega)| / |D(j\omega)|`, with
    ``K`` a system or a response array on ``omega`` and ``reference`` a dict
    ``{"dm", "dc", "dk"}`` or a response array on ``omega``.

    With ``weight`` the sensitivity :math:`|s(\omega)|` of :func:`identifiable_band`
    (as :attr:`ImpedanceFit.weight` holds it), frequencies count by how strongly the
    measurement constrains ``K`` there; without, equally.

    Parameters
    ----------
    K : StateSpace or (N,) complex array_like
        The identified dynamic stiffness (N/m): a SISO system, or its response on ``omega``.
    reference : dict or (N,) complex array_like
        The reference: ``{"dm", "dc", "dk"}`` (see :func:`impedance_response`) or a response on ``omega``.
    omega : (N,) array_like
        Frequencies in rad/s.
    weight : (N,) array_like, optional
        Sensitivity weight per frequency (:attr:`ImpedanceFit.weight`); equal weights if omitted.
    """
    omega = np.asarray(omega, float)
    D = impedance_response(reference, omega) if isinstance(reference, dict) else np.asarray(reference, complex)
    Kj = np.asarray(K, complex) if isinstance(K, np.ndarray) else freqresp(as_ss(K), omega)[0, 0]
    w2 = np.ones_like(omega) if weight is None else np.asarray(weight, float) ** 2
    for name, arr in (("K", Kj), ("reference", D), ("weight", w2)):
        if np.shape(arr) != omega.shape:
            raise ModelError(f"relative_error: {name} has shape {np.shape(arr)}; it must have one value per "
                             f"frequency ({omega.shape})")
    return float(np.sqrt(np.sum(w2 * np.abs(Kj - D) ** 2 / np.abs(D) ** 2) / np.sum(w2)))


def required_impedance(engineering, frf, *, excitation: str, measurement: str, control_input: str,
                       control_output: str) -> np.ndarray:
    r"""The dynamic stiffness a controller at one port must realise to reproduce a measured FRF exactly.

    With the engineering responses :math:`a = H_{me}`, :math:`b = H_{mu}`,
    :math:`c = H_{ye}`, :math:`e = H_{yu}` (measurement/control output per
    excitation/control input) and a dynamic stiffness :math:`D` added at the
    control port (force :math:`-D\,y`), the measured response is
    :math:`H = a - D\,bc/(1 + De)`, so

    .. math::
        D(\omega) = \frac{a - H}{He - ae + bc}.

    This is the :math:`D_u` that :func:`identify`'s controller approximates
    (:math:`K \approx D_u`), frequency by frequency, without any fit.  Where
    :math:`bc - (a - H)e` vanishes (the port does not move in the mode that
    changed) no finite :math:`D` exists and the value grows without bound:
    the port cannot explain the data there.

    Parameters
    ----------
    engineering : control.StateSpace
        With the four named ports.
    frf : mutext.rig.FRF
        The measured response from ``excitation`` to ``measurement`` (SI).
    excitation, measurement : str
        Names of the engineering model's input and output of the measured FRF.
    control_input, control_output : str
        Names of the force input and displacement output of the port where ``D`` acts.

    Returns
    -------
    ndarray (complex)
        :math:`D` [N/m] at ``frf.freq_hz``.
    """
    E = as_ss(engineering, "engineering model")
    ie = _index(E, excitation, "input", "engineering model")
    iu = _index(E, control_input, "input", "engineering model")
    oe = _index(E, measurement, "output", "engineering model")
    oy = _index(E, control_output, "output", "engineering model")
    H = np.asarray(frf.response, complex)
    G = freqresp(E, 2 * np.pi * np.asarray(frf.freq_hz, float))
    a, b, c, e = G[oe, ie], G[oe, iu], G[oy, ie], G[oy, iu]
    return (a - H) / (H * e - a * e + b * c)
