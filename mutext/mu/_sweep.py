r"""Frequency sweeps: :func:`default_grid`, :func:`mu_sweep` and its result :class:`MuSweep`.

Bounds on :math:`\mu(M(j\omega))` over a grid densified at lightly damped
poles, the largest local maxima refined by golden-section search; with
``method="fast"``, warm-started descents whose largest values are polished and
checked by the LMI.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validation import Integer, Options, validate_params
from ..errors import IllPosedError, ModelError, SolverError
from ..response import frequency_grid, resonance_points
from ._bounds import _both, _both_lower
from ._certificate import MuUpper
from ._descent import _opened_metric
from ._fast import _DGParams, _fast_at, _fast_polish
from ._lmi import _lmi_bisect
from ._lower import mu_lower
from ._structure import BlockStructure, _as_structure
from ._upper import _certify, mu_upper


#: Multiples of a resonance's half-width sampled around it (``response.resonance_points``): a
#: resonance of half-power width :math:`2|\Re p|` cannot fall between them.
RESONANCE_OFFSETS = (-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0)


def _poles(sys) -> np.ndarray:
    return np.linalg.eigvals(np.asarray(sys.A, float)) if sys.nstates else np.zeros(0)


def default_grid(sys, n: int = 200, decades: float = 1.5) -> np.ndarray:
    """Log-spaced frequencies spanning the pole magnitudes, plus each pole's frequency.

    :func:`mutext.response.frequency_grid` over the poles of ``sys``: lightly
    damped poles (resonances) get extra points at :math:`|\\Im p|` and
    :math:`|\\Im p| \\pm k|\\Re p|`, :math:`k \\in \\{\\frac12, 1, 2\\}`, so that a
    narrow peak is not stepped over (undamped poles: 0.1 % either side).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The system whose poles set the range.
    n : int, optional
        Number of log-spaced points (the resonance points are added to them).
    decades : float, optional
        How far the grid reaches below the smallest and above the largest pole magnitude.

    Examples
    --------
    >>> from mutext.lti import ss
    >>> from mutext.mu import default_grid
    >>> G = ss([[0.0, 1.0], [-100.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])   # 10 rad/s, 1 % damping
    >>> w = default_grid(G, n=50)
    >>> bool(w.min() < 1.0 and w.max() > 100.0), bool(abs(w - 10.0).min() < 0.01)
    (True, True)
    """
    from ..lti import as_ss
    return frequency_grid(n=n, poles=_poles(as_ss(sys)), margin=(10.0 ** decades, 10.0 ** decades),
                          resonance_offsets=RESONANCE_OFFSETS)


@dataclass
class MuSweep:
    r"""Bounds on :math:`\mu(M(j\omega))` over frequency.

    Attributes
    ----------
    omega : ndarray
        Frequencies (rad/s), sorted, including refinement points.
    upper, lower : ndarray
        Bounds at each frequency (``lower`` is nan where it was not computed).
    d : ndarray
        Diagonal scaling per block at each frequency, shape (len(omega), nblocks),
        normalised so the last block has d = 1.
    method : str
        Upper-bound methods used, joined by ``+`` (``"osborne"``, ``"lmi-d"``,
        ``"lmi-dg"``, ``"sigma"`` where the single-block or ``M = 0`` shortcut applied).
    peak_upper, peak_frequency : float
        Largest upper bound and where.
    peak_lower, lower_frequency : float
        Largest lower bound and where; ``lower_delta`` proves it.
    lower_delta : ndarray or None
    methods : list of str
        Upper-bound method at each frequency.
    peak : MuUpper or None
        The bound at ``peak_frequency`` with its scalings (the certificate:
        :func:`dg_bound` on the response there returns ``peak_upper``).
    """
    omega: np.ndarray
    upper: np.ndarray
    lower: np.ndarray
    d: np.ndarray
    method: str
    peak_upper: float
    peak_frequency: float
    peak_lower: float
    lower_frequency: float
    lower_delta: np.ndarray | None = None
    methods: list = field(default_factory=list)
    peak: MuUpper | None = None


def _freqresp_fn(sys):
    from ..lti import as_ss, freqresp
    sys = as_ss(sys)

    def f(w):
        return freqresp(sys, np.atleast_1d(w))[:, :, 0]
    return f, sys


def _local_maxima(values) -> list:
    n = len(values)
    return [i for i in range(n) if (i == 0 or values[i] >= values[i - 1]) and
            (i == n - 1 or values[i] >= values[i + 1])]


#: fast sweep: function evaluations per frequency of the warm-started descent (40, with half of
#: them below half the peak, left values up to 3 % above AB13MD's at 6 of 500 frequencies of
#: benchmarks/bench_mu_sweep.py; 60 everywhere: 0.03 % at most)
_GRID_EVALS = 60
#: fast sweep: a value this fraction above both neighbours is a spike, redone from their
#: scalings (at most _SPIKE_MAX, the largest first)
_SPIKE, _SPIKE_MAX = 1e-3, 12
#: fast sweep: spikes this fraction above both neighbours are redone wherever they are
_STEEP = 0.05
#: fast sweep: values within this fraction of the largest are polished
_POLISH_BAND = 0.01
#: at most this many points polished, and this many LMI checks
_POLISH_MAX, _LMI_MAX = 12, 4


def _fast_peaks(res, coords, response, S: BlockStructure, params: _DGParams, certify: bool,
                checked: bool = False):
    """Polish the largest values of a fast sweep and check them by the LMI (in place).

    The grid pass stops each descent after a few dozen evaluations (a valid
    bound, possibly a little above the optimum where the descent is slow); only
    the values that decide the peak are worth more.  Spikes (values above both
    neighbours by ``_SPIKE``) are first redone from the neighbours' scalings.  Those within
    ``_POLISH_BAND`` of the largest get a longer descent from their own
    scalings and from a cold (Osborne) start; then, from the largest down, the
    LMI is run from the polished scalings until the largest value left
    unchecked is below the largest checked value.  ``checked``: a polished value is kept
    only if its scalings reproduce it (:func:`_certify`).
    """
    # a descent that stalled shows as a spike above both neighbours: redo the largest
    # spikes from the neighbours' scalings
    # two passes: a bump two points wide is a spike once its higher point is redone
    for _pass in range(2):
        grid = sorted(res)
        vals = np.array([res[w][0].value for w in grid])
        spikes = [i for i in range(1, len(grid) - 1)
                  if vals[i] > (1 + _SPIKE) * max(vals[i - 1], vals[i + 1])]
        # the largest spikes, and the steepest ones (a warm start lost far from the peak)
        top_spikes = sorted(spikes, key=lambda i: -vals[i])[:_SPIKE_MAX]
        steep = sorted((i for i in spikes if vals[i] > (1 + _STEEP) * max(vals[i - 1], vals[i + 1])),
                       key=lambda i: -vals[i] / max(vals[i - 1], vals[i + 1]))[:_SPIKE_MAX]
        for i in top_spikes + [i for i in steep if i not in top_spikes]:
            w = grid[i]
            M = response([w])[:, :, 0]
            starts = [coords.get(grid[i - 1]), coords.get(grid[i + 1])]
            starts = [x0 for x0 in starts if x0 is not None] + ([None] if i in steep else [])
            for x0 in starts:
                # (a steep spike also from a cold start: the neighbours' scalings may be as lost)
                up, x, _ = _fast_at(M, S, params, x0, None, ftol=1e-10, max_eval=2 * _GRID_EVALS)
                if up.value < res[w][0].value and (not checked or _certify(M, S, up) is not None):
                    res[w], coords[w] = (up, res[w][1]), x
    ws = sorted(res, key=lambda w: -res[w][0].value)
    top = res[ws[0]][0].value
    for w in [w for w in ws if res[w][0].value >= (1 - _POLISH_BAND) * top][:_POLISH_MAX]:
        M = response([w])[:, :, 0]
        best = res[w][0]
        for x0 in (coords.get(w), None):
            up, x = _fast_polish(M, S, params, x0)
            if up.value < best.value and (not checked or _certify(M, S, up) is not None):
                best, coords[w] = up, x
        res[w] = (best, res[w][1])
    if not certify:
        return
    checked, level = set(), -np.inf
    while len(checked) < _LMI_MAX:
        rest = [w for w in res if w not in checked]
        if not rest:
            break
        w = max(rest, key=lambda v: res[v][0].value)
        up = res[w][0]
        if up.value <= level:
            break
        checked.add(w)
        if up.method == "sigma":
            level = max(level, up.value)
            continue
        M = response([w])[:, :, 0]
        try:
            lmi = _lmi_bisect(M, S, params.use_g, up.d, None, 1e-7, start=up, first=1 - 1e-5)
        except SolverError:
            level = max(level, up.value)
            continue
        if lmi.value < up.value:
            up = lmi
        else:
            up.lower_level = lmi.lower_level
        res[w] = (up, res[w][1])
        level = max(level, up.value)


@validate_params({"method": Options(("auto", "lmi", "osborne", "fast")), "real": Options(("dg", "complex")),
                  "npeaks": Integer(lo=0)})
def mu_sweep(sys, structure: BlockStructure, omega=None, *, method: str = "auto", real: str = "dg",
             lower="peaks", refine: bool = True, npeaks: int = 3, rng=0, xtol: float = 1e-7,
             certify: bool = True) -> MuSweep:
    r"""Bounds on :math:`\mu` of a system's frequency response over a frequency grid.

    Parameters
    ----------
    sys : control.StateSpace
        Stable system ``M(s)`` with ``structure.ncols`` outputs and
        ``structure.nrows`` inputs.
    structure : BlockStructure
    omega : array_like, optional
        Frequencies (rad/s, non-negative).  Default: :func:`default_grid`.
    method, real
        Upper-bound method (see :func:`mu_upper`).  ``"auto"`` (default): the
        ``"fast"`` sweep below, with every value recomputed from its scalings
        (the generalised eigenvalue of the D-G inequality, as :func:`dg_bound`)
        and the LMI at the frequencies where that does not reproduce it.  ``"fast"``: the D-G (or D)
        bound by quasi-Newton descent (BFGS with the weak Wolfe line search of
        Lewis and Overton [LO]_) on :math:`\log\lambda_{\max}` of the scaled
        form, warm-started from the previous frequency's scalings and
        Hessian approximation; the frequencies within 1 % of the largest value
        are then polished (a cold start as well) and the largest are checked by
        the LMI (``certify``).  Every value is the bound of explicit scalings.
        Away from the peak each descent stops after a few dozen evaluations
        (half as many below half the largest value so far), so single values
        there can stay above the optimal D-G bound: on the 500-frequency
        problem of ``benchmarks/bench_mu_sweep.py``, 5 of 500 values are more
        than 0.1 % above AB13MD's and the worst 4.6 % above, at 27 % of the
        peak; on coarse grids (poor warm starts) and with real blocks only,
        more.
    lower : {"peaks", "all", "none"} or bool
        Where to compute lower bounds (:func:`mu_lower`): at the ``npeaks``
        largest local maxima of the upper bound (default), at every frequency
        (``"all"`` or True) or nowhere.
    refine : bool
        Add the frequencies around the lightly damped poles of ``sys`` that lie
        within the grid (:math:`|\Im p| + k|\Re p|`, so that a resonance narrower
        than the grid spacing is not stepped over), then refine the ``npeaks``
        largest local maxima of the upper bound by golden-section search in
        :math:`\log\omega` between the neighbouring points, down to a relative
        bracket of ``xtol``.
    npeaks : int
    rng : int or Generator
        Seed for the lower bounds.
    xtol : float
        Relative frequency tolerance of the peak refinement.
    certify : bool
        ``method="fast"`` or ``"auto"``: run the LMI (:func:`mu_upper`, ``method="lmi"``)
        at the largest values, from the fast scalings, until the largest value
        left unchecked is below the largest checked one.  The LMI either lowers
        the bound there or confirms it within ``1e-5`` relative (its
        ``lower_level`` is then recorded in the point's :class:`MuUpper`).

    Returns
    -------
    MuSweep

    Raises
    ------
    ModelError
        Sizes not matching the structure, an empty grid, negative or non-finite
        frequencies, an unknown ``lower``, a response that is singular or not
        finite on the grid (a pole on the imaginary axis).
    """
    structure = _as_structure(structure)
    _, sysss = _freqresp_fn(sys)
    poles = _poles(sysss)
    unstable = poles[poles.real > 1e-9 * np.maximum(np.abs(poles), 1e-300)] if poles.size else poles
    if unstable.size:
        raise IllPosedError("mu_sweep needs a stable system M(s) (mu of the frequency response says nothing "
                            "about robust stability when the nominal loop is unstable); unstable pole(s) at s = "
                            + ", ".join(f"{p:.6g}" for p in unstable[:6]))
    if sysss.noutputs != structure.ncols or sysss.ninputs != structure.nrows:
        raise ModelError(f"the system has {sysss.noutputs} outputs and {sysss.ninputs} inputs; the "
                         f"block structure {structure!r} needs {structure.ncols} outputs and "
                         f"{structure.nrows} inputs")
    if omega is None:
        omega = default_grid(sysss)
    omega = np.asarray(omega, dtype=float).ravel()
    if omega.size == 0:
        raise ModelError("the frequency grid is empty")
    if not np.all(np.isfinite(omega)) or np.any(omega < 0):
        raise ModelError("frequencies must be finite and non-negative")
    if lower is True:
        lower = "all"
    elif lower is False or lower is None:
        lower = "none"
    if lower not in ("peaks", "all", "none"):
        raise ModelError(f"lower must be 'peaks', 'all' or 'none', got {lower!r}")
    omega = np.unique(omega)
    if refine and omega.size >= 2:
        extra = resonance_points(_poles(sysss), RESONANCE_OFFSETS, (omega[0], omega[-1]))
        omega = np.unique(np.concatenate([omega, extra]))
    rng = np.random.default_rng(rng)

    def response(w):
        try:
            return freqresp(sysss, w)
        except np.linalg.LinAlgError:
            raise ModelError("the frequency response is singular on the grid "
                             f"[{np.min(w):.6g}, {np.max(w):.6g}] rad/s: a pole on the imaginary "
                             "axis") from None

    from ..lti import freqresp
    H = response(omega)
    bounds = _PointBounds(structure, method, real, lower, rng)
    for k, w in enumerate(omega):
        bounds(w, H[:, :, k])
    bounds.forget_warm_start()
    if refine and omega.size >= 3:
        _golden_peaks(bounds, response, npeaks, xtol)
    if bounds.fast:
        _fast_peaks(bounds.res, bounds.coords, response, structure, bounds.params, certify, bounds.checked)
    if lower == "peaks":
        _lower_at_peaks(bounds.res, response, structure, npeaks, rng)
    return _as_sweep(bounds.res)


class _PointBounds:
    """The bounds at single frequencies of :func:`mu_sweep`, kept in ``res`` (frequency ->
    (upper, lower or None)).  With ``method`` "fast" or "auto" the descents are warm-started
    from the last frequency done (a refinement point from the nearest one) with the last
    descent's metric (its closed directions opened, :func:`_opened_metric`), a cold start where
    the warm one did not converge, and ("auto") every value certified by its scalings, the LMI
    where they do not reproduce it."""

    def __init__(self, structure: BlockStructure, method: str, real: str, lower: str, rng):
        self.structure, self.method, self.real, self.lower, self.rng = structure, method, real, lower, rng
        self.res = {}
        self.fast = method in ("fast", "auto")
        self.checked = method == "auto"
        if self.fast:
            self.params = _DGParams(structure, real == "dg" and structure.has_real)
            self.coords = {}                 # frequency -> coordinates of its fast scalings
            self.warm = {"x": None, "B": None}

    def forget_warm_start(self) -> None:
        """The next points (refinements) start from the nearest frequency done, not the last."""
        if self.fast:
            self.warm["x"] = self.warm["B"] = None

    def __call__(self, w, Mw) -> float:
        """Bound(s) at ``w`` from ``Mw = M(jw)``, recorded; returns the upper bound."""
        structure = self.structure
        if not np.all(np.isfinite(Mw)):
            raise ModelError(f"the frequency response is not finite at omega = {w:.6g} rad/s "
                             "(a pole on the imaginary axis?)")
        if self.fast:
            up = self._fast(w, Mw)
            lo = _both_lower(Mw, structure, up, self.rng) if self.lower == "all" else None
        elif self.lower == "all":
            up, lo = _both(Mw, structure, self.method, self.real, self.rng)
        else:
            up, lo = mu_upper(Mw, structure, method=self.method, real=self.real), None
        self.res[float(w)] = (up, lo)
        return up.value

    def _fast(self, w, Mw) -> MuUpper:
        structure, params, warm, coords = self.structure, self.params, self.warm, self.coords
        if coords and warm["x"] is None:
            # a refinement point: start from the nearest frequency done
            near = min(coords, key=lambda v: abs(np.log(max(v, 1e-300)) - np.log(max(w, 1e-300))))
            warm["x"] = coords[near]
        budget = _GRID_EVALS
        # with the model step where the two largest eigenvalues coalesce (the warm start lands near
        # the kink the optimum follows along frequency)
        up, x, B = _fast_at(Mw, structure, params, warm["x"], warm["B"], ftol=1e-9, max_eval=budget,
                            kinks=True)
        if up.iterations >= budget and x is not None:
            # the warm start did not converge (it can lose its way where the infimum is approached
            # as a real block's d -> 0 and G -> infinity): a cold start as mu_upper's, from Osborne
            # balancing with the exact Hessian and the model step at kinks.  Everywhere, not only
            # near the peak so far: tried there only, off-peak frequencies stayed up to 1.8 % above
            # AB13MD (bench_mu_sweep.py seeds 6, 8, 11)
            up2, x2, B2 = _fast_at(Mw, structure, params, None, None, ftol=1e-9, max_eval=4 * _GRID_EVALS,
                                   kinks=True, hessian0=True)
            if up2.value < up.value:
                up, x, B = up2, x2, B2
        if self.checked and _certify(Mw, structure, up) is None:
            # the scalings do not reproduce the value (rounding in badly scaled
            # scalings): the LMI there, and no warm start from them
            up, x, B = mu_upper(Mw, structure, method="lmi", real=self.real), None, None
        coords[float(w)] = x
        warm["x"], warm["B"] = x, _opened_metric(B)
        return up


def _golden_peaks(bounds: _PointBounds, response, npeaks: int, xtol: float) -> None:
    """Golden-section search (in log frequency, to a bracket of ``xtol``) on the ``npeaks``
    largest local maxima of the upper bound recorded in ``bounds``."""
    res = bounds.res
    ws = np.array(sorted(res))
    ups = np.array([res[w][0].value for w in ws])
    gr = (np.sqrt(5) - 1) / 2

    def g(lw):
        w = float(np.exp(lw))
        if w in res:
            return res[w][0].value
        return bounds(w, response([w])[:, :, 0])
    for i in sorted(_local_maxima(ups), key=lambda i: -ups[i])[:npeaks]:
        a = np.log(ws[i - 1] if i > 0 and ws[i - 1] > 0 else ws[i] / 2 if ws[i] > 0 else ws[1] / 2)
        b = np.log(ws[min(i + 1, len(ws) - 1)])
        if b <= a:
            continue
        c, d = b - gr * (b - a), a + gr * (b - a)
        fc, fd = g(c), g(d)
        for _ in range(100):
            if b - a <= xtol:
                break
            if fc > fd:
                b, d, fd = d, c, fc
                c = b - gr * (b - a)
                fc = g(c)
            else:
                a, c, fc = c, d, fd
                d = a + gr * (b - a)
                fd = g(d)


def _lower_at_peaks(res: dict, response, structure: BlockStructure, npeaks: int, rng) -> None:
    """Lower bounds (:func:`mu_lower`) at the ``npeaks`` largest local maxima of the upper bound,
    restarted from the upper bound's scalings where a complex structure's bounds do not meet."""
    ws = np.array(sorted(res))
    ups = np.array([res[w][0].value for w in ws])
    for i in sorted(_local_maxima(ups), key=lambda i: -ups[i])[:npeaks]:
        w = float(ws[i])
        up = res[w][0]
        Mw = response([w])[:, :, 0]
        lo = mu_lower(Mw, structure, rng=rng)
        if not structure.has_real and up.value - lo.value > 1e-7 * up.value:
            lo2 = mu_lower(Mw, structure, rng=rng, scalings=(up.Dl, up.Dr))
            lo = lo2 if lo2.value > lo.value else lo
        res[w] = (up, lo)


def _as_sweep(res: dict) -> MuSweep:
    """The :class:`MuSweep` of the bounds recorded (frequency -> (upper, lower or None))."""
    ws = np.array(sorted(res))
    ups = np.array([res[w][0].value for w in ws])
    lows = np.array([res[w][1].value if res[w][1] is not None else np.nan for w in ws])
    dd = np.array([res[w][0].d for w in ws])
    methods = [res[w][0].method for w in ws]
    k = int(np.argmax(ups))
    if np.any(np.isfinite(lows)):
        kl = int(np.nanargmax(lows))
        pl, wl, dl = float(lows[kl]), float(ws[kl]), res[ws[kl]][1].Delta
    else:
        pl, wl, dl = np.nan, np.nan, None
    used = sorted(set(methods))
    return MuSweep(ws, ups, lows, dd, "+".join(used), float(ups[k]), float(ws[k]), pl, wl, dl, methods,
                   peak=res[ws[k]][0])
