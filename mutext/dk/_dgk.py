r"""Real parameters kept real: D-G-K by a search over the range the K steps see."""
from __future__ import annotations

import time

import control as ct
import numpy as np

from ..errors import IllPosedError, InfeasibleError, ModelError, SolverError
from ..lti import as_ss, blas_single_thread, ss
from ..mu import BlockStructure
from ._dscale import _check_sizes
from ._loop import _arguments, _dk, dk_iteration, DKResult
from ._report import _print


def real_scaled_plant(P, structure: BlockStructure, scale: float, nmeas: int, ncon: int) -> ct.StateSpace:
    r"""``P`` with the outputs of its real blocks multiplied by ``scale``.

    The loop :math:`\mathcal F_u(P_c, \Delta)` with :math:`P_c` the returned
    plant and a real block :math:`|\delta| \le 1` is the loop of ``P`` with
    :math:`|\delta| \le c`: the parameters' ranges shrunk by the factor
    :math:`c` = ``scale``, every other block unchanged.  No states are added.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant with inputs ``[w_Delta; u]`` and outputs
        ``[z_Delta; y]``, the ``Delta`` channels following ``structure``.
    structure : BlockStructure
        The blocks; the output rows (``z_Delta``) of its real blocks are scaled.
    scale : float
        The factor :math:`c` on the real parameters' ranges, in (0, 1].
    nmeas, ncon : int
        Number of measurements (last outputs) and controls (last inputs).

    Returns
    -------
    control.StateSpace
        Same states, inputs and outputs (and labels) as ``P``.

    Raises
    ------
    ModelError
        Sizes of ``P`` and ``structure`` that do not match, ``scale`` outside
        (0, 1].
    """
    P = as_ss(P, "P")
    if not isinstance(structure, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(structure).__name__}")
    _check_sizes(P, structure, nmeas, ncon)
    if not (np.isfinite(scale) and 0.0 < scale <= 1.0):
        raise ModelError(f"scale must lie in (0, 1], got {scale!r}")
    rows = np.ones(P.noutputs)
    for k, b in enumerate(structure.blocks):
        if b.kind == "real":
            rows[structure.col_slices[k]] = scale
    L = np.diag(rows)
    return ss(P.A, P.B, L @ np.asarray(P.C, float), L @ np.asarray(P.D, float),
              inputs=P.input_labels, outputs=P.output_labels)


def dgk_iteration(P, structure: BlockStructure, nmeas: int, ncon: int, *, step: float = 0.03,
                  max_tries: int = 6, out=None, progress=None, **options) -> DKResult:
    r"""Mu-synthesis with the real parameters kept real (D-G-K by a search over their range).

    D-K iteration (:func:`dk_iteration`) scales real parameters as complex
    ones.  That costs nothing where the loop is nearly real (at low frequency)
    and much where it is not: the D-G bound of an equalised D-K loop often lies
    well below its complex bound over a band, and a controller could trade that
    slack for a lower peak.  Here the K steps see the real parameters as
    complex scalars over :math:`c` times their range
    (:func:`real_scaled_plant`), and :math:`c` is chosen by the number that
    matters: the D-G bound (real blocks real) of the loop of the plant *as
    given* with the resulting controller.  The tries are :math:`c = 1` (plain
    D-K), then :math:`1 - \text{step}, 1 - 2\,\text{step}, \dots` while the D-G
    bound falls (if the first step does not help, :math:`1 - \text{step}/2,
    1 - \text{step}/4, \dots` until one does), and one parabolic step between
    the best and its neighbours.

    The approximation: a K step at :math:`c < 1` optimises a problem in which
    the parameters vary less than they do (the one-dimensional counterpart of
    the "mu-K" scaling of Lin, Postlethwaite and Gu [LPG]_, which shrinks the
    real channels by the pointwise ratio of the bounds).  Its level is not a
    bound for the real problem; only the D-G analysis of the loop as given is
    (``mutext.mu.mu_upper(method="fast")`` at every frequency where the complex
    bound could decide the peak, pointwise no higher than the certified complex
    bound).  The controller returned is the try with the lowest D-G bound, so
    never worse than plain D-K with the same options.  A pointwise G fit
    (Young's affine form) or the disc transform (:func:`mutext.mu.dg_disc`)
    would let each frequency use its own disc; the fits of their para-skew
    filters were the obstacle (see the mu chapter of the book).
    :func:`refine_controller` uses the scalings of every frequency without
    fits, by moving the controller this search returns.

    Parameters
    ----------
    P, structure, nmeas, ncon
        As for :func:`dk_iteration`.
    step : float
        Step of the range factor :math:`c` (0 < step < 0.5).
    max_tries : int
        Largest number of D-K runs, the plain one included (>= 2).
    out : file or None
        Where to print each try's iteration table and a summary row.
    progress : callable, optional
        ``progress(stage, fraction)``; stages start with ``"D-G-K try k/n"``.
    **options
        Passed to :func:`dk_iteration` for every try (``max_states``,
        ``fit_tol``, ``max_iter``, ...; ``dg`` must stay True).

    Returns
    -------
    DKResult
        For the best try: ``K`` and ``CL`` (the loop of ``P`` as given),
        ``mu_upper_dg`` its D-G bound, ``mu_upper`` its complex bound,
        ``history`` the iterations of that try (K-step levels and ``mu`` on the
        scaled plant), ``real_scale`` its :math:`c`, ``tries`` all tries,
        ``seconds`` the whole search.

    Raises
    ------
    ModelError
        Bad options (as :func:`dk_iteration`, and ``step``, ``max_tries``), a
        structure without real blocks.

    References
    ----------
    .. [LPG] J. L. Lin, I. Postlethwaite and D.-W. Gu, "mu-K iteration: a new
       algorithm for mu-synthesis", *Automatica* 29 (1993) 219-224.
    .. [Y] P. M. Young, "Controller design with real parametric uncertainty",
       *Int. J. Control* 65 (1996) 469-509.

    Examples
    --------
    The two-mass problem at 0.043 m, plain D-K and one try at c = 0.97, one D-K
    iteration each on a coarse grid of 12 frequencies (the H-infinity designs, a
    few seconds, most of it the D-G bounds; ``max_iter=2`` on the default grids
    brings the D-G bound from 2.93 to 1.004):

    >>> from mutext.examples import two_mass_uncertain as tmu
    >>> res = dgk_iteration(tmu.plant(0.043), tmu.structure(), 1, 1, max_tries=2, max_iter=1,
    ...                     grid_points=12, final_points=12)
    >>> [round(t["scale"], 2) for t in res.tries]
    [1.0, 0.97]
    >>> bool(res.mu_upper_dg <= min(t["mu_dg"] for t in res.tries) + 1e-12)
    True
    """
    t0 = time.perf_counter()
    P, S, args = _dgk_arguments(P, structure, nmeas, ncon, step, max_tries, options)
    tries = _Tries(P, S, nmeas, ncon, args, max_tries, out, progress)
    v1 = tries.value(1.0)
    _search_scale(tries, v1, step, max_tries)
    _parabolic_step(tries, step, max_tries)
    return _best_try(tries, v1, out, t0)


def _dgk_arguments(P, structure, nmeas, ncon, step, max_tries, options):
    """Checked options of :func:`dgk_iteration`: the plant, the structure and the positional
    arguments of :func:`_dk` (as :func:`_arguments` returns them, ``dg`` True)."""
    if "dg" in options and not options["dg"]:
        raise ModelError("dgk_iteration judges every try by the D-G bound: dg must be True")
    options.pop("dg", None)
    # the options of dk_iteration's own signature, less those dgk_iteration takes itself
    defaults = {k: v for k, v in dk_iteration.__kwdefaults__.items() if k not in ("dg", "out", "progress")}
    unknown = sorted(set(options) - set(defaults))
    if unknown:
        raise ModelError(f"unknown option(s) for dk_iteration: {', '.join(unknown)}")
    P, S, args = _arguments(P, structure, nmeas, ncon, dg=True, **{**defaults, **options})
    if not S.has_real:
        raise ModelError(f"the structure {S!r} has no real blocks: use dk_iteration")
    if not (isinstance(step, (int, float, np.floating)) and 0.0 < step < 0.5):
        raise ModelError(f"step must lie in (0, 0.5), got {step!r}")
    if not (isinstance(max_tries, (int, np.integer)) and max_tries >= 2):
        raise ModelError(f"max_tries must be an integer >= 2, got {max_tries!r}")
    return P, S, args


class _Tries:
    """The D-K runs of :func:`dgk_iteration`, one per range factor ``c``: ``results`` those that
    finished (by ``c``), ``failed`` a line per failed try."""

    def __init__(self, P, S, nmeas, ncon, args, max_tries, out, progress):
        self.P, self.S, self.nmeas, self.ncon, self.args = P, S, nmeas, ncon, args
        self.max_tries, self.out, self.progress = max_tries, out, progress
        self.results, self.failed = {}, []

    def tried(self) -> int:
        return len(self.results) + len(self.failed)

    def value(self, c) -> float:
        """The D-G bound of the loop of the plant as given for the try at ``c`` (rounded to
        1e-6), run if new; inf for a failed try."""
        c = float(round(c, 6))
        return self.results[c].mu_upper_dg if c in self.results else self.run(c)

    def run(self, c) -> float:
        P, S, out, max_tries = self.P, self.S, self.out, self.max_tries
        i = self.tried() + 1
        _print(out, f"D-G-K try {i}/{max_tries}: the K steps see the real parameters over {c:.4f} x their range")
        rep = None if self.progress is None else (
            lambda stage, f: self.progress(f"D-G-K try {i}/{max_tries} (c = {c:.3f}): {stage}",
                                           min(1.0, (i - 1 + f) / max_tries)))
        ti = time.perf_counter()
        Pc = P if c == 1.0 else real_scaled_plant(P, S, c, self.nmeas, self.ncon)
        try:
            with blas_single_thread():
                r = _dk(Pc, S, self.nmeas, self.ncon, *self.args, out, ti, rep, as_given=P, real_scale=c)
        except (InfeasibleError, SolverError, IllPosedError) as exc:
            if c == 1.0:
                raise
            self.failed.append(f"c = {c:.4f}: {str(exc)[:120]}")
            _print(out, f"D-G-K try {i}: the D-K run failed ({str(exc)[:90]})")
            return np.inf
        self.results[c] = r
        _print(out, f"D-G-K try {i}: loop of the plant as given: mu <= {r.mu_upper_dg:.5f} (D-G), "
                    f"{r.mu_upper:.5f} (complex); controller order {r.K.nstates}; "
                    f"{time.perf_counter() - ti:.1f} s")
        return r.mu_upper_dg


def _search_scale(tries: _Tries, v1, step, max_tries):
    """From ``c = 1`` (bound ``v1``): steps of ``step`` down while the bound falls, or, if the
    first does not help, the step halved towards 1 until one does (see :func:`dgk_iteration`)."""
    c = 1.0 - step
    if tries.value(c) < v1:
        while tries.tried() < max_tries - 1 and c - step > 0.0:
            if tries.value(c - step) >= tries.value(c):
                break
            c -= step
    else:
        # no gain one step away: halve the step towards 1 while tries are left
        h = step / 2
        while tries.tried() < max_tries - 1 and h >= step / 16:
            if tries.value(1.0 - h) < v1:
                break
            h /= 2


def _parabolic_step(tries: _Tries, step, max_tries):
    """One parabolic step through the best try and its neighbours, if a try is left."""
    results = tries.results
    cs = sorted(results)
    best = min(cs, key=lambda x: results[x].mu_upper_dg)
    k = cs.index(best)
    if tries.tried() < max_tries and 0 < k < len(cs) - 1:
        (a, fa), (b, fb), (d, fd) = [(x, results[x].mu_upper_dg) for x in cs[k - 1:k + 2]]
        den = (b - a) * (fb - fd) - (b - d) * (fb - fa)
        if den != 0.0:
            cn = b - 0.5 * ((b - a) ** 2 * (fb - fd) - (b - d) ** 2 * (fb - fa)) / den
            if a < cn < d and min(abs(cn - a), abs(cn - b), abs(cn - d)) > 0.1 * step:
                tries.value(cn)


def _best_try(tries: _Tries, v1, out, t0) -> DKResult:
    """The result of the try with the lowest D-G bound, with the table of all tries and notes."""
    results, failed = tries.results, tries.failed
    best = min(results, key=lambda x: results[x].mu_upper_dg)
    r = results[best]
    r.tries = [{"scale": c, "mu_dg": results[c].mu_upper_dg, "mu": results[c].mu_upper,
                "mu_lower": results[c].mu_lower, "controller_order": results[c].K.nstates,
                "iterations": len(results[c].history), "seconds": results[c].seconds}
               for c in results]
    r.seconds = time.perf_counter() - t0
    if failed:
        r.notes.append("D-G-K: failed tries (" + "; ".join(failed) + ")")
    r.notes.append(f"D-G-K: {len(results)} D-K runs with the real parameters' ranges scaled by "
                   + ", ".join(f"{c:.4f}" for c in results) + f"; the best, {best:.4f}, gives the loop of "
                   f"the plant as given mu <= {r.mu_upper_dg:.5f} with D-G scalings (plain D-K: {v1:.5f})")
    _print(out, f"D-G-K best: c = {best:.4f}, mu <= {r.mu_upper_dg:.5f} (D-G), plain D-K {v1:.5f}")
    return r
