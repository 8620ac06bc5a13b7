r"""How tight any identification can be: the spread of the true systems over the uncertainty
box, its widest point (the floor of :math:`W_z`) and the weight that follows it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..frfit import MagnitudeFit, fit_envelope
from ..lti import freqresp
from ..response import frequency_grid
from ._plant import _index


@dataclass
class WzFloor:
    r"""A certified lower bound on the achievable :math:`W_z` (:func:`wz_floor`).

    Attributes
    ----------
    value : float
        No controller can certify robust performance (:math:`\mu \le 1`) with a
        smaller :math:`W_z` (output unit).
    omega : float
        Frequency (rad/s) where the true systems spread most.
    deltas : tuple of numpy.ndarray
        The two normalised perturbations whose responses are farthest apart there.
    samples : int
        Number of true systems compared.
    """
    value: float
    omega: float
    deltas: tuple
    samples: int


def _delta_samples(m: int, rng=0) -> np.ndarray:
    """Perturbations covering the box [-1, 1]^m: a full grid for few parameters, else
    all vertices (up to 2^8) plus random interior points."""
    if m == 0:
        return np.zeros((1, 0))
    if m <= 5:
        levels = np.linspace(-1.0, 1.0, 5 if m <= 3 else 3)
        return np.array(np.meshgrid(*[levels] * m, indexing="ij")).reshape(m, -1).T
    r = np.random.default_rng(rng)
    verts = (r.choice((-1.0, 1.0), size=(256, m)) if m > 8
             else np.array(np.meshgrid(*[[-1.0, 1.0]] * m, indexing="ij")).reshape(m, -1).T)
    return np.vstack([np.zeros((1, m)), verts, r.uniform(-1.0, 1.0, size=(64, m))])


def _true_systems(true, excitation, measurement, who: str, rng=0):
    """The true systems on a grid of the uncertainty box, closed once: ``(systems, deltas, i, o)``."""
    from ..uncertain import UncertainModel
    if not isinstance(true, UncertainModel):
        raise ModelError(f"{who}: the spread of the true systems needs an uncertain true model "
                         f"(mutext.uncertain.UncertainModel), got {type(true).__name__}")
    nom = true.nominal()
    i = _index(nom, excitation, "input", "true system")
    o = _index(nom, measurement, "output", "true system")
    deltas = _delta_samples(len(true.params), rng)
    return [true.close(d) for d in deltas], deltas, i, o


def _half_gaps(systems, i, o, omega):
    """Half the widest gap between the systems' responses at each frequency, and the pair
    that makes it: ``(half (nw,), pair (2, nw) indices into systems)``."""
    R = np.array([freqresp(S, omega)[o, i] for S in systems])      # (samples, nw)
    # widest pair per frequency, one sample against all at a time (memory: samples x nw)
    best, pair = np.zeros(omega.size), np.zeros((2, omega.size), dtype=int)
    for a in range(len(systems)):
        d = np.abs(R - R[a])
        b = np.argmax(d, axis=0)
        da = d[b, np.arange(omega.size)]
        better = da > best
        best[better], pair[0, better], pair[1, better] = da[better], a, b[better]
    return best / 2, pair


def true_spread(true, *, excitation: str, measurement: str, omega=None, rng=0):
    r"""Half the widest gap between the true systems' responses at each frequency.

    .. math::
        r(\omega) = \tfrac12 \max_{\delta_1, \delta_2} |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|,

    over a grid of the uncertainty box (all vertices and interior points for up
    to five parameters): no single controlled response can be closer than
    :math:`r(\omega)` to all of them (:func:`wz_floor` is its maximum,
    :func:`spread_weight` its cover).

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel or control.StateSpace
        The true system (set).
    excitation, measurement : str
        Names of its input and output ports.
    omega : array_like, optional
        Frequencies in rad/s (default: a grid around the nominal poles).
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    (omega, r) : tuple of numpy.ndarray
        The grid (rad/s; default as :func:`wz_floor`) and :math:`r` on it (output unit per input unit).
    """
    return _true_spread(true, excitation, measurement, omega, rng, "true_spread")


def _true_spread(true, excitation, measurement, omega, rng, who):
    systems, _, i, o = _true_systems(true, excitation, measurement, who, rng)
    omega = _floor_grid(true, omega, who)
    return omega, _half_gaps(systems, i, o, omega)[0]


def _floor_grid(true, omega, who: str):
    if omega is None:
        omega = frequency_grid(n=400, poles=np.linalg.eigvals(np.asarray(true.nominal().A, float)))
    omega = np.asarray(omega, float)
    if omega.size == 0:
        raise ModelError(f"{who}: the frequency grid is empty")
    return omega


def wz_floor(true, *, excitation: str, measurement: str, Ww: float = 1.0, omega=None,
             rng=0, shape=None) -> WzFloor:
    r"""The smallest :math:`W_z` that any identification can certify, from the spread of the true set.

    Robust performance at :math:`W_z` means that one controlled response
    :math:`x_c(j\omega)` is within :math:`W_z/W_w` of the response
    :math:`x_t(\delta, j\omega)` of every true system in the uncertainty set.
    Two true systems :math:`\delta_1, \delta_2` whose responses differ by
    :math:`d` therefore force :math:`W_z \ge W_w d/2`, whatever the controller:

    .. math::
        W_z \ge W_w \max_\omega \tfrac12 \max_{\delta_1, \delta_2}
        |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|.

    With a shaped bound :math:`W_z|S(j\omega)|` (``shape``) the same argument
    holds at each frequency, and the floor is the largest of the half-gaps
    divided by :math:`|S(j\omega)|`.  Any finite set of samples and
    frequencies gives a valid (lower) bound; the grid is refined around the
    widest spread.  A true system without uncertainty gives 0.

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel or control.StateSpace
    excitation, measurement : str
        The shared input and measured output.
    Ww : float
        Size of the excitation.
    omega : array_like, optional
        Frequencies (rad/s); default: two decades around the true system's poles.
    shape : mutext.frfit.MagnitudeFit, optional
        The frequency shape of the bound (:func:`spread_weight`); default flat.
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    WzFloor
    """
    from ..uncertain import UncertainModel
    if not isinstance(true, UncertainModel):
        return WzFloor(0.0, float("nan"), (), 1)
    omega = _floor_grid(true, omega, "wz_floor")
    systems, deltas, i, o = _true_systems(true, excitation, measurement, "wz_floor", rng)

    half, wk, pair = _widest(systems, deltas, i, o, omega, shape)
    for _ in range(2):       # lightly damped resonances: zoom in around the widest spread
        h2, w2, p2 = _widest(systems, deltas, i, o, wk * np.logspace(-0.02, 0.02, 81), shape)
        if h2 > half:
            half, wk, pair = h2, w2, p2
    return WzFloor(float(Ww * half), float(wk), pair, len(systems))


def _widest(systems, deltas, i, o, omega, shape):
    """The widest half-gap on ``omega`` (divided by ``|shape|`` when given): ``(half, frequency,
    (delta_1, delta_2))``, the two perturbations whose responses make it."""
    half, pair = _half_gaps(systems, i, o, omega)
    if shape is not None:
        half = half / np.abs(shape(omega))
    k = int(np.argmax(half))
    return half[k], omega[k], (deltas[pair[0, k]], deltas[pair[1, k]])


def spread_weight(true, *, excitation: str, measurement: str, omega=None, floor: float = 0.02,
                  max_sections: int = 4, rng=0) -> MagnitudeFit:
    r"""The frequency shape of the error bound that follows the spread of the true set.

    A flat bound :math:`W_z` can be no tighter than the spread of the true
    systems where they differ most (:func:`wz_floor`), usually at a resonance;
    everywhere else it is loose, and there the identification leaves ``K``
    free.  Shaped by the spread itself, :math:`W_z|S(j\omega)|` with

    .. math::
        |S(j\omega)| \ge \frac{\tfrac12 \max_{\delta_1, \delta_2}
        |x_t(\delta_1, j\omega) - x_t(\delta_2, j\omega)|}{\max_\omega(\ldots)},

    the bound asks at every frequency for as much as the uncertainty allows,
    and ``K`` is pinned down over the whole band where the true systems' spread
    is resolved.  :math:`S` is the stable, minimum-phase cover of the half-gaps
    on the grid by :func:`mutext.frfit.fit_envelope` (one peaking section per
    resonance of the spread), normalised to a peak of about 1, so that
    :math:`W_z` keeps its meaning at the widest spread.

    Parameters
    ----------
    true : mutext.uncertain.UncertainModel
        The uncertain true system.
    excitation, measurement : str
        The shared input and measured output.
    omega : array_like, optional
        Frequencies (rad/s); default as :func:`wz_floor`.
    floor : float
        Relative level below which the spread is not followed (beyond the last
        resonance it falls to zero, which no proper weight can follow).
    max_sections : int
        Peaking sections of the cover (two poles each; they add to the
        plant's and the controller's order).
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the interior samples of the uncertainty box (used
        only above five parameters; fixed by default, so that the result is repeatable).

    Returns
    -------
    mutext.frfit.MagnitudeFit
        ``error``: how loose the cover is where it is loosest (log).

    Raises
    ------
    ModelError
        A true system without uncertainty (no spread to follow), a bad grid.
    """
    omega, half = _true_spread(true, excitation, measurement, omega, rng, "spread_weight")
    if not half.max() > 0:
        raise ModelError("spread_weight: the true systems do not spread on this grid: no shape to follow")
    return fit_envelope(omega, half / half.max(), floor=floor, max_sections=max_sections)
