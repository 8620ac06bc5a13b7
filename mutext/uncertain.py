r"""Uncertain mechanical models as linear fractional transformations.

A model :math:`M(p)\ddot q + C(p)\dot q + K(p) q = F u` whose matrices are
affine in real parameters :math:`p_i = c_i + h_i\delta_i`,
:math:`\delta_i\in[-1, 1]`, is rewritten as the upper LFT

.. math::
    G(s, p) = \mathcal F_u\big(P(s), \Delta\big),\qquad
    \Delta = \operatorname{diag}(\delta_1 I_{r_1}, \dots, \delta_m I_{r_m}),

with a *fixed* system :math:`P` whose first inputs and outputs are the
uncertainty channels ([ZDG]_ ch. 10; [SP]_ ch. 7).  Each parameter's
contribution :math:`\delta_i [K_i\ C_i\ M_i]` is factored as
:math:`L_i\,\delta_i I_{r_i}\,R_i` with :math:`r_i = \operatorname{rank}[K_i\ C_i\ M_i]`,
the smallest repetition for an affine term.  With :math:`w = \Delta z`,

.. math::
    M_0\ddot q + C_0\dot q + K_0 q = F u - \textstyle\sum_i L_i w_i,\qquad
    z_i = R_i \begin{bmatrix} q\\ \dot q\\ \ddot q\end{bmatrix},

which is linear in :math:`(q, \dot q, u, w)` once :math:`\ddot q` is eliminated
with the nominal mass matrix.  The uncertainty channels are named
``w_<parameter>`` / ``z_<parameter>`` (with ``_1``, ``_2``, ... when repeated).

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 10.
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005, ch. 7.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import control as ct
import numpy as np

from .errors import ModelError
from .lti import _port_vector, lft_upper, mck_to_ss, ss
from .mu import Block, BlockStructure

__all__ = ["UncertainParameter", "UncertainModel", "uncertain_mck"]


@dataclass(frozen=True)
class UncertainParameter:
    r"""A real parameter known to lie in an interval.

    ``UncertainParameter("k1", 450.0, rel=0.02)`` is :math:`450 \pm 2\,\%`;
    ``UncertainParameter("k1", 450.0, range=(440, 470))`` an absolute interval
    (the LFT is built around its midpoint, and ``nominal`` must lie in it);
    ``abs=9.0`` a symmetric absolute half-width.  ``range`` takes precedence
    over ``abs``, which takes precedence over ``rel``; giving both ``range`` and
    ``abs`` is an error.

    The normalised perturbation is :math:`\delta = (p - c)/h \in [-1, 1]` with
    centre ``c`` and half-width ``h`` ([SP]_ ch. 7).

    Attributes
    ----------
    name : str
        Name of the parameter (as asked for by the model's ``matrices`` function).
    nominal : float
        Nominal value, in the parameter's unit (kg, N/m, N s/m, ...).
    rel : float or None, optional
        Relative half-width of the interval (0.02 is +-2 %).
    abs : float or None, optional
        Absolute half-width, in the parameter's unit.
    range : (float, float) or None, optional
        Absolute interval ``(low, high)``.

    Raises
    ------
    ModelError
        Empty name, non-finite values, a non-positive ``rel`` or ``abs``, a range
        with ``low >= high`` or not containing ``nominal``.

    Examples
    --------
    >>> from mutext.uncertain import UncertainParameter
    >>> k = UncertainParameter("k1", 450.0, rel=0.02)
    >>> k.value(1.0), k.value(-1.0)          # the ends of 450 N/m +- 2 %
    (459.0, 441.0)
    >>> k.delta(454.5)
    0.5
    """
    name: str
    nominal: float
    rel: float | None = 0.02
    abs: float | None = None
    range: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ModelError("an uncertain parameter needs a non-empty name")
        try:
            nominal = float(self.nominal)
        except (TypeError, ValueError):
            raise ModelError(f"parameter {self.name}: nominal value must be a number, "
                             f"got {self.nominal!r}") from None
        if not np.isfinite(nominal):
            raise ModelError(f"parameter {self.name}: nominal value must be finite, got {self.nominal}")
        if self.range is not None and self.abs is not None:
            raise ModelError(f"parameter {self.name}: give either abs or range, not both")
        if self.range is not None:
            try:
                lo, hi = (float(v) for v in self.range)
            except (TypeError, ValueError):
                raise ModelError(f"parameter {self.name}: range must be a pair (low, high), "
                                 f"got {self.range!r}") from None
            if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
                raise ModelError(f"parameter {self.name}: range must be finite with low < high, "
                                 f"got {self.range}")
            if not lo <= nominal <= hi:
                raise ModelError(f"parameter {self.name}: nominal value {nominal} lies outside "
                                 f"the range {self.range}")
        elif self.abs is not None:
            if not (np.isfinite(self.abs) and self.abs > 0):
                raise ModelError(f"parameter {self.name}: abs (half-width) must be positive and "
                                 f"finite, got {self.abs}")
        elif self.rel is None or not (np.isfinite(self.rel) and self.rel > 0) or nominal == 0:
            raise ModelError(f"parameter {self.name}: rel must be positive and finite and the nominal "
                             f"value nonzero (got rel={self.rel}, nominal={self.nominal}); use abs or range")

    @property
    def center(self) -> float:
        if self.range is not None:
            return 0.5 * (float(self.range[0]) + float(self.range[1]))
        return float(self.nominal)

    @property
    def halfwidth(self) -> float:
        if self.range is not None:
            return 0.5 * (float(self.range[1]) - float(self.range[0]))
        if self.abs is not None:
            return float(self.abs)
        return float(self.rel) * abs(float(self.nominal))

    @property
    def bounds(self) -> tuple[float, float]:
        return self.center - self.halfwidth, self.center + self.halfwidth

    def value(self, delta: float) -> float:
        """Parameter value for a normalised perturbation ``delta``.

        Parameters
        ----------
        delta : float
            Normalised perturbation (-1 and 1 are the ends of the interval).
        """
        return self.center + self.halfwidth * float(delta)

    def delta(self, value: float) -> float:
        """Normalised perturbation of a parameter value.

        Parameters
        ----------
        value : float
            Parameter value, in the parameter's unit.
        """
        return (float(value) - self.center) / self.halfwidth


def _factor(N, tol=1e-12):
    """N = L @ R with the rank of N columns in L (SVD, symmetric split of the singular values)."""
    U, s, Vh = np.linalg.svd(N, full_matrices=False)
    if s.size == 0 or s[0] == 0:
        return np.zeros((N.shape[0], 0)), np.zeros((0, N.shape[1]))
    r = int(np.sum(s > tol * s[0]))
    rs = np.sqrt(s[:r])
    return U[:, :r] * rs[None, :], rs[:, None] * Vh[:r]


@dataclass
class UncertainModel:
    r"""An uncertain model :math:`\mathcal F_u(P, \Delta)`.

    Attributes
    ----------
    P : control.StateSpace
        Inputs ``[w_unc; inputs]``, outputs ``[z_unc; outputs]``; the first
        ``structure.nrows`` inputs and ``structure.ncols`` outputs are the
        uncertainty channels.
    structure : BlockStructure
        One real block per parameter (``Block.real(r_i, name)``).
    params : tuple of UncertainParameter
    repetitions : tuple of int
        How many times each parameter is repeated in ``Delta`` (the size ``r_i`` of its real block).
    """
    P: ct.StateSpace
    structure: BlockStructure
    params: tuple
    _build: Callable
    repetitions: tuple

    @property
    def nunc(self) -> int:
        """Number of uncertainty channels (sum of repetitions)."""
        return self.structure.nrows

    def values(self, delta) -> dict:
        """Parameter values for normalised perturbations (a sequence, one per parameter).

        Parameters
        ----------
        delta : (n_params,) array_like
            Normalised perturbations, one per parameter in the order of ``params``.
        """
        return {p.name: p.value(d) for p, d in zip(self.params, self._deltas(delta))}

    def delta_matrix(self, delta) -> np.ndarray:
        r""":math:`\Delta = \operatorname{diag}(\delta_i I_{r_i})` for normalised perturbations.

        Parameters
        ----------
        delta : (n_params,) array_like
            Normalised perturbations, one per parameter in the order of ``params``.
        """
        return np.diag(np.repeat(self._deltas(delta), self.repetitions))

    def _deltas(self, delta) -> np.ndarray:
        """``delta`` as a flat float array of one perturbation per parameter, or a ModelError."""
        delta = np.asarray(delta, dtype=float).ravel()
        if delta.size != len(self.params):
            raise ModelError(f"expected {len(self.params)} perturbations, got {delta.size}")
        return delta

    def delta_vector(self, Delta, tol: float = 1e-9) -> np.ndarray:
        r"""Normalised perturbations :math:`\delta_i` of a structured ``Delta``, e.g. the
        destabilising perturbation of :func:`mutext.mu.mu_lower` (its first entry per block).

        Parameters
        ----------
        Delta : (nunc, nunc) array_like
            A real block-diagonal perturbation of the model's structure.
        tol : float, optional
            Tolerance of the structure test (:meth:`BlockStructure.contains`).

        Raises
        ------
        ModelError
            ``Delta`` not in the structure (wrong size, not block diagonal, not real).
        """
        Delta = np.asarray(Delta)
        if not self.structure.contains(Delta, tol):
            raise ModelError(f"Delta ({Delta.shape[0]}x{Delta.shape[1] if Delta.ndim == 2 else '?'}) "
                             f"is not in the structure {self.structure!r}")
        return np.array([float(np.real(Delta[rs.start, cs.start]))
                         for rs, cs in zip(self.structure.row_slices, self.structure.col_slices)])

    def close(self, delta) -> ct.StateSpace:
        """The model for normalised perturbations ``delta`` (closing the upper LFT).

        Parameters
        ----------
        delta : (n_params,) array_like
            Normalised perturbations, one per parameter in the order of ``params``.
        """
        D = self.delta_matrix(delta)
        return lft_upper(self.P, D, self.nunc, self.nunc)

    def nominal(self) -> ct.StateSpace:
        """The model at the parameter centres (``delta = 0``)."""
        return self.at({p.name: p.center for p in self.params})

    def at(self, values: Mapping[str, float]) -> ct.StateSpace:
        """The model rebuilt from M, C, K at the given parameter values (independent of the LFT).

        Parameters
        ----------
        values : mapping of str to float
            Parameter values by name; parameters not given stay at their interval's centre.
        """
        full = {p.name: p.center for p in self.params}
        for k in values:
            if k not in full:
                raise ModelError(f"unknown parameter {k!r}; known: {', '.join(full)}")
        full.update({k: float(v) for k, v in values.items()})
        return self._build(full)

    def sample(self, n: int, rng=None, vertices: bool = False) -> np.ndarray:
        """``n`` normalised perturbation vectors, uniform in the box (or random vertices).

        Parameters
        ----------
        n : int
            Number of vectors.
        rng : numpy.random.Generator or int, optional
            Random generator or seed.
        vertices : bool, optional
            Draw corners of the box (every entry -1 or 1) instead of uniform points.
        """
        rng = np.random.default_rng(rng)
        if vertices:
            return rng.choice((-1.0, 1.0), size=(n, len(self.params)))
        return rng.uniform(-1.0, 1.0, size=(n, len(self.params)))

    def corners(self) -> np.ndarray:
        """Every vertex of the normalised parameter box, ``2**len(params)`` rows of +/-1.

        Examples
        --------
        >>> from mutext.examples import two_mass_uncertain as tmu
        >>> tmu.uncertain_model().corners().shape
        (16, 4)
        """
        return np.array(list(itertools.product((-1.0, 1.0), repeat=len(self.params))))


def uncertain_mck(matrices: Callable[[Mapping[str, float]], tuple], params: Sequence[UncertainParameter],
                  inputs: Mapping[str, object], outputs: Mapping[str, object], *,
                  dof_names: Sequence[str] | None = None, affine_tol: float = 1e-9,
                  rng=0) -> UncertainModel:
    r"""LFT model of a mechanical system with affinely uncertain M, C, K.

    Parameters
    ----------
    matrices : callable
        ``matrices(values) -> (M, C, K)`` for a mapping parameter name -> value;
        ``C`` may be ``None``.  The entries must be affine in the parameters
        (checked at random points).
    params : sequence of UncertainParameter
    inputs, outputs : mapping
        Ports as in :func:`mutext.lti.mck_to_ss` (DOF index, distribution
        vector, or ``(quantity, port)`` for outputs).
    dof_names : sequence of str, optional
    affine_tol : float
        Relative tolerance of the affinity check.
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the affinity check's random points (fixed by
        default, so that the check is repeatable).

    Returns
    -------
    UncertainModel

    Raises
    ------
    ModelError
        Duplicate parameter names; ``matrices`` asking for an unknown name; M not
        square or C, K of another size; non-finite entries; matrices not affine
        in a parameter (the message names it) or containing products of
        parameters; a parameter that has no effect; a nominal mass matrix that is
        not symmetric positive definite, or one that loses definiteness at a
        corner of the parameter box.

    Notes
    -----
    Affinity is checked by evaluation: each parameter alone at
    :math:`\delta_i \in \{-1, \tfrac12, 0, 1\}` and all of them at three random
    points.  A dependence that happens to be affine at those points (a
    piecewise-linear one, say) is not detected.

    Examples
    --------
    >>> import numpy as np
    >>> def mck(p):
    ...     return np.diag([p["m"]]), None, np.diag([p["k"]])
    >>> U = uncertain_mck(mck, [UncertainParameter("m", 1.0), UncertainParameter("k", 100.0)],
    ...                   inputs={"f": 0}, outputs={"x": 0})
    >>> U.structure
    BlockStructure[real x1 m, real x1 k]
    """
    params = _checked_ports(params, inputs, outputs)
    evaluate = _mck_evaluator(matrices, [p.name for p in params])
    center = {p.name: p.center for p in params}
    N0 = evaluate(center)
    ndof = N0.shape[0]
    K0, C0, M0 = N0[:, :ndof], N0[:, ndof:2 * ndof], N0[:, 2 * ndof:]
    Ns = _unit_changes(evaluate, params, center, N0)
    _check_affine(evaluate, params, center, N0, Ns, affine_tol, rng)
    _check_mass(M0, Ns, params, ndof)
    P, reps = _mck_lft(K0, C0, M0, Ns, params, inputs, outputs, dof_names)
    structure = BlockStructure([Block.real(r, p.name) for p, r in zip(params, reps)])
    inputs, outputs = dict(inputs), dict(outputs)

    def build(values):
        Nv = evaluate(values)
        return mck_to_ss(Nv[:, 2 * ndof:], Nv[:, ndof:2 * ndof], Nv[:, :ndof], inputs, outputs,
                         dof_names=dof_names)

    return UncertainModel(P, structure, params, build, tuple(reps))


def _checked_ports(params, inputs, outputs) -> tuple:
    """The parameters as a tuple, once there is at least one, with unique names, and ports on both sides."""
    params = tuple(params)
    if not params:
        raise ModelError("at least one uncertain parameter is needed")
    names = [p.name for p in params]
    if len(set(names)) != len(names):
        raise ModelError(f"parameter names must be unique, got {names}")
    if not inputs or not outputs:
        raise ModelError("at least one input and one output port are needed")
    return params


def _mck_evaluator(matrices, names):
    """``evaluate(values) -> [K C M]`` from the user's ``matrices(values) -> (M, C, K)``, checked (sizes,
    finite entries, only the parameters ``names`` asked for)."""
    def evaluate(values):
        try:
            out = matrices(dict(values))
        except KeyError as exc:
            raise ModelError(f"matrices(values) asked for {exc.args[0]!r}, which is not an uncertain "
                             f"parameter; known: {', '.join(names)}") from None
        if not (isinstance(out, (tuple, list)) and len(out) == 3):
            raise ModelError("matrices(values) must return a tuple (M, C, K)")
        M, C, K = out
        M = np.atleast_2d(np.asarray(M, dtype=float))
        if M.ndim != 2 or M.shape[0] != M.shape[1]:
            raise ModelError(f"M must be a square matrix (ndof x ndof), got shape {M.shape}")
        n = M.shape[0]
        C = np.zeros((n, n)) if C is None else np.atleast_2d(np.asarray(C, dtype=float))
        K = np.atleast_2d(np.asarray(K, dtype=float))
        for nm, X in (("C", C), ("K", K)):
            if X.shape != (n, n):
                raise ModelError(f"{nm} must be {n}x{n} (the size of M), got shape {X.shape}")
        for nm, X in (("M", M), ("C", C), ("K", K)):
            if not np.all(np.isfinite(X)):
                raise ModelError(f"{nm} contains non-finite entries at parameter values "
                                 f"{ {k: float(v) for k, v in values.items()} }")
        return np.hstack([K, C, M])
    return evaluate


def _where(N):
    """Names of the matrices (M, C, K) in which N = [K C M] is nonzero."""
    n = N.shape[0]
    return [nm for nm, X in (("K", N[:, :n]), ("C", N[:, n:2 * n]), ("M", N[:, 2 * n:]))
            if np.abs(X).max() > 0]


def _unit_changes(evaluate, params, center, N0) -> list:
    """The change of [K C M] when each parameter alone goes to the edge of its range (delta = 1)."""
    Ns = []
    for p in params:
        v = dict(center)
        v[p.name] = p.value(1.0)
        Ni = evaluate(v) - N0
        if np.abs(Ni).max() == 0:
            raise ModelError(f"parameter {p.name} does not change M, C or K (does matrices() use it?)")
        Ns.append(Ni)
    return Ns


def _check_affine(evaluate, params, center, N0, Ns, affine_tol, rng) -> None:
    """Affinity: each parameter alone (curvature at delta = -1 and 1/2, which names the culprit), then all
    together at random points of the generator or seed ``rng`` (products of parameters)."""
    rng = np.random.default_rng(rng)
    scale = max(np.abs(N0).max(), max(np.abs(N).max() for N in Ns))
    for p, Ni in zip(params, Ns):
        for x in (-1.0, 0.5):
            v = dict(center)
            v[p.name] = p.value(x)
            dev = evaluate(v) - N0 - x * Ni
            err = np.abs(dev).max()
            if err > affine_tol * scale:
                raise ModelError(f"{'/'.join(_where(dev))} not affine in parameter {p.name} (deviation "
                                 f"{err:.3g} at {p.name} = {p.value(x):.6g}); rewrite the model so that "
                                 "every entry is affine in the uncertain parameters (e.g. use 1/m as "
                                 "the parameter)")
    for _ in range(3 if len(params) > 1 else 0):
        d = rng.uniform(-1, 1, len(params))
        Nd = evaluate({p.name: p.value(x) for p, x in zip(params, d)})
        dev = Nd - N0 - sum(x * N for x, N in zip(d, Ns))
        err = np.abs(dev).max()
        if err > affine_tol * scale:
            raise ModelError(f"{'/'.join(_where(dev))} not affine in the parameters jointly (deviation "
                             f"{err:.3g} at delta = {np.round(d, 3).tolist()} for "
                             f"{[p.name for p in params]}): products of parameters cannot be written "
                             "with one real block per parameter")


def _check_mass(M0, Ns, params, ndof) -> None:
    """The nominal mass matrix symmetric positive definite, and positive definite at every corner of the
    box of the parameters that enter it."""
    if not np.allclose(M0, M0.T, rtol=1e-10, atol=0):
        raise ModelError("the nominal mass matrix M is not symmetric")
    try:
        np.linalg.cholesky(0.5 * (M0 + M0.T))
    except np.linalg.LinAlgError:
        raise ModelError("the nominal mass matrix M is not positive definite") from None
    # M(delta) is affine, so it is positive definite on the whole box iff it is at
    # every vertex (the cone is convex); only parameters entering M matter
    in_m = [i for i, N in enumerate(Ns) if np.abs(N[:, 2 * ndof:]).max() > 0]
    if len(in_m) <= 12:
        for signs in itertools.product((-1.0, 1.0), repeat=len(in_m)):
            Mv = M0 + sum(sg * Ns[i][:, 2 * ndof:] for sg, i in zip(signs, in_m))
            try:
                np.linalg.cholesky(0.5 * (Mv + Mv.T))
            except np.linalg.LinAlgError:
                corner = {params[i].name: params[i].value(sg) for sg, i in zip(signs, in_m)}
                raise ModelError(f"the mass matrix is not positive definite at {corner}: the "
                                 "uncertainty ranges of the masses are too wide") from None


def _mck_lft(K0, C0, M0, Ns, params, inputs, outputs, dof_names):
    """The LFT's plant ``[w, u] -> [z, y]`` of the nominal matrices and the factored changes ``Ns``:
    ``(plant, repetitions of each parameter's block)``."""
    Ls, Rs, reps = [], [], []
    for p, Ni in zip(params, Ns):
        L, R = _factor(Ni)
        Ls.append(L)
        Rs.append(R)
        reps.append(L.shape[1])
    L = np.hstack(Ls)
    R = np.vstack(Rs)
    ndof = M0.shape[0]
    nunc = L.shape[1]
    F = np.column_stack([_port_vector(pv, ndof, f"input '{n}'") for n, pv in inputs.items()])
    Mi = np.linalg.inv(M0)
    Z, I = np.zeros((ndof, ndof)), np.eye(ndof)
    A = np.block([[Z, I], [-Mi @ K0, -Mi @ C0]])
    Bw = np.vstack([np.zeros((ndof, nunc)), -Mi @ L])
    Bu = np.vstack([np.zeros((ndof, F.shape[1])), Mi @ F])
    # q'' = Mi (F u - K0 q - C0 v - L w) = Aacc x + Bacc_w w + Bacc_u u
    Aacc, Baw, Bau = A[ndof:], Bw[ndof:], Bu[ndof:]
    RK, RC, RM = R[:, :ndof], R[:, ndof:2 * ndof], R[:, 2 * ndof:]
    Cz = np.hstack([RK, RC]) + RM @ Aacc
    Dzw = RM @ Baw
    Dzu = RM @ Bau
    Cy, Dyw, Dyu = _output_rows(outputs, ndof, Aacc, Baw, Bau, nunc, F.shape[1])
    wn, zn = [], []
    for p, r in zip(params, reps):
        sfx = [""] if r == 1 else [f"_{j + 1}" for j in range(r)]
        wn += [f"w_{p.name}{s}" for s in sfx]
        zn += [f"z_{p.name}{s}" for s in sfx]
    dn = list(dof_names) if dof_names is not None else [f"q{i + 1}" for i in range(ndof)]
    P = ss(A, np.hstack([Bw, Bu]), np.vstack([Cz, Cy]),
           np.block([[Dzw, Dzu], [Dyw, Dyu]]),
           inputs=wn + list(inputs), outputs=zn + list(outputs), states=dn + [f"d{n}" for n in dn])
    return P, reps


def _output_rows(outputs, ndof, Aacc, Baw, Bau, nunc, nin):
    """``(C_y, D_yw, D_yu)`` of the output ports (displacement, velocity or acceleration of a DOF or a
    combination of DOFs); ``Aacc``, ``Baw``, ``Bau``: the acceleration's rows of the state equation."""
    rowsC, rowsDw, rowsDu = [], [], []
    for n_, pv in outputs.items():
        if isinstance(pv, tuple) and len(pv) == 2 and isinstance(pv[0], str):
            q, pv = pv
        else:
            q = "displacement"
        v = _port_vector(pv, ndof, f"output '{n_}'")
        if q == "displacement":
            rowsC.append(np.concatenate([v, np.zeros(ndof)]))
            rowsDw.append(np.zeros(nunc))
            rowsDu.append(np.zeros(nin))
        elif q == "velocity":
            rowsC.append(np.concatenate([np.zeros(ndof), v]))
            rowsDw.append(np.zeros(nunc))
            rowsDu.append(np.zeros(nin))
        elif q == "acceleration":
            rowsC.append(v @ Aacc)
            rowsDw.append(v @ Baw)
            rowsDu.append(v @ Bau)
        else:
            raise ModelError(f"output '{n_}': unknown quantity {q!r}")
    return np.array(rowsC), np.array(rowsDw).reshape(-1, nunc), np.array(rowsDu)
