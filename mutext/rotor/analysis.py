r"""Analyses of an assembled model: modes, FRFs, state space (the Campbell diagram is in
:mod:`mutext.rotor.campbell_diagram`, built on :func:`modes`).

All inputs and outputs are SI: frequencies in Hz where the name says ``_hz``,
otherwise rad/s; speeds in rad/s; displacements in m; forces in N; currents in A.

Eigenvalue problem
------------------
At spin speed :math:`\Omega` the free motion :math:`q = \hat q e^{\lambda t}` satisfies

.. math::
    \left(\lambda^2 M + \lambda (C + \Omega G) + K\right)\hat q = 0 ,

solved in first-order form :math:`\dot x = A x`,
:math:`A = \begin{bmatrix} 0 & I\\ -M^{-1}K & -M^{-1}(C+\Omega G)\end{bmatrix}`
(Friswell et al. 2010, ch. 3 and 5).  Without damping and rotation the
symmetric-definite problem :math:`K\phi = \omega^2 M\phi` is solved instead
(``scipy.linalg.eigh``), which is more accurate.  Natural frequencies are the
imaginary parts :math:`\omega_d = \mathrm{Im}\,\lambda > 0` of the underdamped
modes; two kinds of root are left out:

* rigid-body modes: the modes of the undamped, non-rotating structure whose
  :math:`\omega^2` is zero to rounding, :math:`\omega^2 \le \epsilon_r^2\,\omega_s^2`
  (``rigid_tol`` :math:`= \epsilon_r = 10^{-6}`), with :math:`\omega_s^2` the
  largest eigenvalue of :math:`(K, M)`: the structure's stiffness-to-mass
  scale, which damping and speed leave alone.  A structure without such
  modes (a rotor on bearings, a grounded chain) loses no root as rigid; one
  with them loses its roots with :math:`|\lambda| \le \epsilon_r\omega_s`.  The
  roots of the damped problem set no threshold: with stiffness-proportional
  damping the top modes of a fine mesh are overdamped, with real roots near
  :math:`-\beta\omega^2` far above every vibration, and a cut relative to the
  largest root drops real modes (it took the thesis rotor's 34 Hz pair at
  :math:`\beta = 10^{-4}`).
* overdamped modes: a root whose mode shape :math:`\hat q` has more than
  critical damping,

  .. math:: \hat q^H C_s\,\hat q \ge 2\sqrt{(\hat q^H K\hat q)(\hat q^H M\hat q)} ,

  with :math:`C_s` the symmetric part of :math:`C + \Omega G` (the gyroscopic
  part is skew and drops out), is a creep, not a vibration.  Without rotation
  this is exactly :math:`\mathrm{Im}\,\lambda = 0` (the scalar quadratic
  :math:`m\lambda^2 + c\lambda + k = 0` of the exact eigenvector has complex roots
  only below critical damping); at speed the gyroscopic coupling of the two
  planes makes the overdamped roots slightly complex
  (:math:`\lambda \approx -1/\beta \pm j\,O(\Omega)`), and this test still
  recognises them.

Whirl direction
---------------
For a mode :math:`\lambda = j\omega` (:math:`\omega > 0`) of a rotor spinning
about +z, the station orbit is forward (same sense as the spin) when
:math:`\hat v \approx -j\hat u`.  The index

.. math:: w = \frac{-2\sum_n \mathrm{Im}(\bar{\hat u}_n \hat v_n)}{\sum_n |\hat u_n|^2 + |\hat v_n|^2}
    \in [-1, 1]

is +1 for circular forward whirl, -1 for circular backward whirl and 0 for a
planar (straight-line) orbit.

Frequency response
------------------
.. math::
    H(j\omega) = C_y\left(K - \omega^2 M + j\omega(C + \Omega G)\right)^{-1} B ,

one complex linear solve per frequency (no state-space detour).

References
----------
M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees, *Dynamics of
Rotating Machines*, Cambridge University Press, 2010, ch. 3 and 5.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import scipy.linalg as sla

from ..errors import IllPosedError, ModelError, MutextError
from ..lti import blas_single_thread, mck_to_ss
from ..response import FRFMatrix
from ._shift_invert import shift_invert_roots, state_matrix

__all__ = ["Modes", "modes", "natural_frequencies", "frf",
           "state_space", "whirl_index", "blas_single_thread"]




@dataclass
class Modes:
    """Modes of a model at one speed.

    Attributes
    ----------
    eigenvalues : complex ndarray (n,)
        :math:`\\lambda_r` [rad/s], sorted by increasing :math:`\\mathrm{Im}\\,\\lambda`.
    omega : ndarray (n,)
        Damped natural frequencies :math:`\\mathrm{Im}\\,\\lambda_r` [rad/s].
    frequencies_hz : ndarray (n,)
        The same in Hz.
    damping_ratio : ndarray (n,)
        :math:`-\\mathrm{Re}\\,\\lambda_r/|\\lambda_r|`.
    shapes : complex ndarray (ndof, n)
        Displacement part of the eigenvectors, scaled to a largest entry of 1.
    whirl : ndarray (n,)
        :func:`whirl_index` (rotor layout; NaN otherwise).
    speed : float
        Spin speed [rad/s].
    dof_names : list of str
    """
    eigenvalues: np.ndarray
    omega: np.ndarray
    frequencies_hz: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray
    whirl: np.ndarray
    speed: float
    dof_names: list = field(default_factory=list)

    def whirl_direction(self, threshold: float = 0.5) -> list[str]:
        """``"forward"``, ``"backward"`` or ``"mixed"`` per mode (``""`` when not a rotor).

        Parameters
        ----------
        threshold : float, optional
            Whirl index above which a mode is forward (below minus it, backward).
        """
        return [whirl_label(w, threshold) for w in self.whirl]


def whirl_label(w: float, threshold: float = 0.5) -> str:
    """A mode's whirl index ``w`` (+1 forward circle, -1 backward) read as ``"forward"``, ``"backward"``
    or ``"mixed"`` (``""`` for NaN: no second plane)."""
    if np.isnan(w):
        return ""
    return "forward" if w > threshold else "backward" if w < -threshold else "mixed"


def whirl_index(shape: np.ndarray, layout) -> float:
    """Whirl index of one mode shape (see the module docstring); NaN unless a two-plane rotor.

    Parameters
    ----------
    shape : (ndof,) complex ndarray
        Mode shape (displacement part of the eigenvector).
    layout : Layout
        The model's DOF numbering.
    """
    if layout.kind != "rotor":
        return float("nan")
    u = shape[0::4]
    v = shape[1::4]
    den = float(np.sum(np.abs(u) ** 2 + np.abs(v) ** 2))
    if den == 0.0:
        return 0.0
    return float(-2.0 * np.sum(np.imag(np.conj(u) * v)) / den)


def _check_n(n, what="n"):
    """``n`` (number of modes) as an int >= 1, or a ModelError naming it (a negative n
    used to slice modes away silently)."""
    if n is None:
        return None
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ModelError(f"{what} (number of modes) must be a positive integer or None, got {n!r}")
    return int(n)


def _values(model, values):
    """``model.values(values)`` checked: every parameter a finite number (a NaN used to
    surface as a scipy ValueError from deep inside the assembly)."""
    try:
        v = model.values(values)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ModelError):
            raise
        raise ModelError(f"{model.name}: bad parameter values {values!r} ({exc})") from None
    v = np.asarray(v, dtype=float)
    bad = ~np.isfinite(v)
    if bad.any():
        names = [p.name for p in model.parameters]
        i = int(np.flatnonzero(bad)[0])
        raise ModelError(f"{model.name}: parameter '{names[i] if i < len(names) else i}' has the non-finite "
                         f"value {v[i]}")
    return v


def _finite_number(value, what: str, unit: str) -> float:
    """``value`` as a finite float, or a ModelError saying that ``what`` must be a number, or finite
    (in ``unit``)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what} must be a number ({unit}), got {value!r}") from None
    if not np.isfinite(x):
        raise ModelError(f"{what} must be finite ({unit}), got {x!r}")
    return x


def _speed_array(speeds, name: str) -> np.ndarray:
    """``speeds`` [rad/s] as a non-empty 1-D array of finite floats, or a ModelError naming the model."""
    try:
        s = np.atleast_1d(np.asarray(speeds, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"{name}: speeds must be numbers (rad/s), got {speeds!r}") from None
    if s.ndim != 1 or s.size == 0 or not np.all(np.isfinite(s)):
        raise ModelError(f"{name}: speeds must be a non-empty 1-D array of finite numbers (rad/s)")
    return s


def _speed(model, speed):
    if speed is None:
        return float(getattr(model, "speed", 0.0))
    speed = _finite_number(speed, f"{model.name}: speed", "rad/s")
    if speed != 0.0 and getattr(model.layout, "kind", "") != "rotor":
        raise ModelError(f"{model.name}: a nonzero speed needs a two-plane rotor model (planes=2)")
    return speed


def modes(model, *, speed: float | None = None, values=None, n: int | None = None,
          rigid_tol: float = 1e-6, matrices=None, method: str = "auto") -> Modes:
    """Modes of ``model`` (a :class:`~mutext.rotor.assembly.Structure`) at ``speed`` [rad/s].

    Parameters
    ----------
    model : Structure or Rotor
    speed : float, optional
        Spin speed [rad/s]; default ``model.speed`` (0 for non-rotors).
    values : mapping or array, optional
        Parameter values (see :meth:`Structure.values`).
    n : int, optional
        Keep the ``n`` lowest modes.
    rigid_tol : float
        A mode of the undamped structure whose natural frequency is below
        ``rigid_tol`` times the largest one of :math:`(K, M)` is rigid-body
        (zero to rounding) and is dropped, with or without damping and speed
        (see the module docstring).  Overdamped roots are dropped too.
    matrices : Matrices, optional
        Precomputed ``model.matrices(values)``.
    method : {"auto", "dense", "sparse"}
        ``"dense"``: every root of the first-order system (:math:`O(n^3)`);
        ``"sparse"``: the ``n`` lowest by shift-invert Arnoldi on the sparse pencil
        (:mod:`mutext.rotor.sparse_modal`; needs ``n``, a nonsingular stiffness
        matrix and raises if ARPACK does not converge); ``"auto"``: sparse
        when it pays -- ``n`` given, at least 150 DOFs, ``2n + 8`` at most a fifth of
        them, banded mass and damping matrices (not modal damping, which is dense)
        and a positive definite stiffness matrix (no rigid-body mode) -- falling
        back to dense if the sparse solve fails.  Both give the same modes (to
        about 1e-10 in frequency; shapes normalised alike).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.rotor import data_path, load_model
    >>> from mutext.rotor.analysis import modes
    >>> md = modes(load_model(data_path("three_mass.toml")))
    >>> np.round(md.frequencies_hz, 3)                   # Hz, damped
    array([0.952, 3.12 , 4.919])
    """
    n = _check_n(n)
    _no_impedance(model, "modes")
    if not (isinstance(rigid_tol, (int, float, np.integer, np.floating)) and 0 <= rigid_tol < 1):
        raise ModelError(f"rigid_tol must lie in [0, 1), got {rigid_tol!r}")
    if method not in ("auto", "dense", "sparse"):
        raise ModelError(f"method must be 'auto', 'dense' or 'sparse', got {method!r}")
    if method == "sparse" and n is None:
        raise ModelError("method='sparse' finds the n lowest modes: give n")
    if matrices is None:
        values = _values(model, values)
    with blas_single_thread():
        return _modes(model, _speed(model, speed), values, n, rigid_tol, matrices, method)


def _no_impedance(model, what: str) -> None:
    """A clear error where a rational impedance element (extra states, not in M, C, K) would be left out."""
    from .lumped_elements import impedances
    imp = impedances(model)
    if imp:
        raise ModelError(f"{model.name}: {what} are computed from M, C and K alone, which the impedance element "
                         f"'{imp[0].name}' is not part of (it adds {imp[0].order} states); use "
                         "state_space(model).poles() or frf(model, ...)")


def _modes(model, speed, values, n, rigid_tol, matrices, method="dense") -> Modes:
    M, C, K, G = model.matrices(values) if matrices is None else matrices
    D = C + speed * G
    if method == "sparse" or (method == "auto" and n is not None and _sparse_pays(M, D, K, n)):
        try:
            ev, shapes = shift_invert_roots(M, K, D, n, 0.0, 8, model.name)
        except ModelError:
            if method == "sparse":
                raise
        else:
            return _as_modes(model, ev, shapes, speed)
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ModelError(f"{model.name}: the mass matrix is not positive definite (every DOF needs mass "
                         "or rotary inertia)") from None
    for name, X in (("mass", M), ("damping", D), ("stiffness", K)):
        if not np.all(np.isfinite(X)):
            raise ModelError(f"{model.name}: the {name} matrix has non-finite entries (check the parameter values)")
    Ks = 0.5 * K + 0.5 * K.T        # halves first: K + K.T overflows for stiffnesses near 1e308
    overflow = (f"{model.name}: the natural frequencies overflow double precision (stiffness / mass ratios up to "
                "about 1e308 rad^2/s^2 can be represented): check the units of the masses and stiffnesses")
    with np.errstate(over="ignore", invalid="ignore"):
        skew = float(np.max(np.abs(0.5 * K - 0.5 * K.T))) if K.size else 0.0
    if not np.any(D) and not skew > 1e-12 * float(np.max(np.abs(K))):
        # (a skew part of K -- a bearing's cross-coupling -- is circulatory: the first-order form below;
        # a rounding-level asymmetry is not)
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                lam, Phi = sla.eigh(Ks, M)
        except (ValueError, np.linalg.LinAlgError):
            raise ModelError(overflow) from None
        if not np.all(np.isfinite(lam)):
            raise ModelError(overflow)
        scale = max(float(np.max(np.abs(lam))), 1e-300)
        if lam.min() < -rigid_tol**2 * scale:
            raise IllPosedError(_divergence(model, np.sqrt(-lam[lam < -rigid_tol**2 * scale])))
        keep = lam > rigid_tol**2 * scale
        ev = 1j * np.sqrt(lam[keep])
        shapes = Phi[:, keep].astype(complex)
    else:
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                ev, shapes = _damped_modes(M, D, K, Ks, rigid_tol, model)
        except MutextError:
            raise                   # e.g. a statically unstable model, said as such
        except (ValueError, np.linalg.LinAlgError):
            raise ModelError(overflow) from None
        if not np.all(np.isfinite(ev)):
            raise ModelError(overflow)
    if n is not None:
        ev, shapes = ev[:n], shapes[:, :n]
    return _as_modes(model, ev, shapes, speed)


def _as_modes(model, ev, shapes, speed) -> Modes:
    """:class:`Modes` of the roots ``ev`` (Im > 0, sorted) and their shapes, each scaled to 1 at its largest
    entry."""
    shapes = np.array(shapes, dtype=complex)
    for r in range(shapes.shape[1]):
        k = int(np.argmax(np.abs(shapes[:, r])))
        if shapes[k, r] != 0:
            shapes[:, r] = shapes[:, r] / shapes[k, r]
    w = ev.imag
    zeta = -ev.real / np.abs(ev) + 0.0          # + 0.0: an undamped mode's -0.0 is 0.0
    whirl = np.array([whirl_index(shapes[:, r], model.layout) for r in range(shapes.shape[1])])
    return Modes(ev, w, w / (2 * np.pi), zeta, shapes, whirl, speed, model.dof_names)


def _sparse_pays(M, D, K, n: int) -> bool:
    """Whether a shift-invert solve for ``n`` modes beats the dense one and is safe: see :func:`modes`."""
    N = M.shape[0]
    if N < 150 or 2 * n + 8 > N // 5:
        return False
    if np.count_nonzero(M) > 0.05 * N * N or np.count_nonzero(D) > 0.05 * N * N:
        return False
    # no rigid-body or statically unstable mode (the dense route names them): a banded Cholesky of K
    Ks = 0.5 * K + 0.5 * K.T
    r, c = np.nonzero(Ks)
    b = int(np.max(np.abs(c - r))) if r.size else 0
    if b > N // 10:
        return False
    ab = np.zeros((b + 1, N))
    for d in range(b + 1):
        ab[b - d, d:] = np.diagonal(Ks, d)
    try:
        sla.cholesky_banded(ab, check_finite=True)
    except (np.linalg.LinAlgError, ValueError):
        return False
    return True


def _damped_modes(M, D, K, Ks, rigid_tol, model):
    """Underdamped, non-rigid roots (Im > 0, sorted) and their displacement shapes, from the first-order form.

    Rigid-body roots are recognised against the undamped structure's scale ``omega_s^2`` (the largest
    eigenvalue of (K, M)), overdamped ones by their shape's damping (see the module docstring): the
    roots of the damped problem, whose largest is the overdamped ``-beta omega^2`` of the top mode
    with stiffness-proportional damping, set no threshold."""
    ndof = M.shape[0]
    lam_u = sla.eigvalsh(Ks, M)
    scale = max(float(np.max(np.abs(lam_u))), 1e-300)          # omega_s^2
    n_rigid = int(np.sum(np.abs(lam_u) <= rigid_tol**2 * scale))
    cut = rigid_tol * math.sqrt(scale)                          # rigid_tol * omega_s [rad/s]
    lam, X = sla.eig(state_matrix(M, K, D))
    diverging = lam[(np.abs(lam.imag) <= cut) & (lam.real > cut)]
    if diverging.size:
        raise IllPosedError(_divergence(model, diverging.real))
    cand = np.flatnonzero(lam.imag > 0)
    if n_rigid:
        cand = cand[np.abs(lam[cand]) > cut]
    Q = X[:ndof, cand]
    m = np.real(np.sum(np.conj(Q) * (M @ Q), axis=0))
    k = np.real(np.sum(np.conj(Q) * (Ks @ Q), axis=0))
    c = np.real(np.sum(np.conj(Q) * ((0.5 * (D + D.T)) @ Q), axis=0))
    under = (c <= 0.0) | (c < 2.0 * np.sqrt(np.maximum(k, 0.0) * m))     # no dissipation, or below critical
    keep = cand[under]
    ev = lam[keep]
    order = np.argsort(ev.imag)
    return ev[order], X[:ndof, keep][:, order]


def _divergence(model, rates) -> str:
    return (f"{model.name}: the model is statically unstable (divergent): {rates.size} mode(s) grow without "
            f"oscillating (growth rate up to {float(np.max(rates)):.4g} 1/s); the stiffness "
            "matrix is not positive semidefinite -- check the parameter values (a negative Young's modulus, "
            "bearing or spring stiffness); natural frequencies of such a model would be meaningless")


def natural_frequencies(model, *, speed: float | None = None, values=None, n: int | None = None,
                        matrices=None) -> np.ndarray:
    """Damped natural frequencies [Hz] (rigid-body modes left out), lowest first.

    Parameters
    ----------
    model : Structure or Rotor
        The assembled model, e.g. from :func:`mutext.rotor.load_model`.
    speed : float, optional
        Spin speed [rad/s]; default ``model.speed`` (0 for non-rotors).
    values : mapping or array_like, optional
        Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
        vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).

    n : int, optional
        Keep the ``n`` lowest modes.
    matrices : Matrices, optional
        Precomputed ``model.matrices(values)``.

    Examples
    --------
    >>> from mutext.rotor import data_path, load_model
    >>> from mutext.rotor.analysis import natural_frequencies
    >>> f = natural_frequencies(load_model(data_path("three_mass.toml")))
    >>> f.size, bool(f[0] < f[1] < f[2])            # three carts, three modes [Hz]
    (3, True)
    """
    return modes(model, speed=speed, values=values, n=n, matrices=matrices).frequencies_hz


def _ports(model, inputs, outputs):
    ins = model.input_names if inputs is None else list(inputs)
    outs = model.output_names if outputs is None else list(outputs)
    for q in ins:
        if q not in model.input_names:
            raise ModelError(f"{model.name}: unknown input '{q}' (inputs: {', '.join(model.input_names)})")
    for q in outs:
        if q not in model.output_names:
            raise ModelError(f"{model.name}: unknown output '{q}' (outputs: {', '.join(model.output_names)})")
    if not ins or not outs:
        raise ModelError(f"{model.name}: needs at least one input and one output "
                         f"(has inputs {model.input_names}, outputs {model.output_names})")
    return ins, outs


def frf(model, freqs_hz, *, inputs: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
        speed: float | None = None, values=None) -> FRFMatrix:
    """Frequency responses between named ports at ``freqs_hz`` [Hz].

    Default ports: all inputs and outputs of the model.  Returns an
    :class:`mutext.response.FRFMatrix` with ``H`` of shape
    ``(noutputs, ninputs, nfreq)`` in output units per input unit.

    Parameters
    ----------
    model : Structure or Rotor
        The assembled model, e.g. from :func:`mutext.rotor.load_model`.

    freqs_hz : array_like
        Frequencies [Hz].
    inputs, outputs : sequence of str, optional
        Names of the input and output ports (default: all of the model's).
    speed : float, optional
        Spin speed [rad/s]; default ``model.speed`` (0 for non-rotors).
    values : mapping or array_like, optional
        Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
        vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).

    Examples
    --------
    >>> from mutext.rotor import data_path, load_model
    >>> from mutext.rotor.analysis import frf
    >>> H = frf(load_model(data_path("three_mass.toml")), [1.0, 2.0], inputs=["f1"], outputs=["x1"])
    >>> H.H.shape
    (1, 1, 2)
    >>> x = H.channel("x1", "f1")                       # one channel, as a measured FRF would be
    >>> x.label, x.unit, round(float(abs(x.response[0])), 5)
    ('f1->x1', 'm/N', 0.01369)
    """
    speed = _speed(model, speed)
    ins, outs = _ports(model, inputs, outputs)
    try:
        f = np.atleast_1d(np.asarray(freqs_hz, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"{model.name}: freqs_hz must be numbers (Hz), got {freqs_hz!r}") from None
    if f.ndim != 1 or f.size == 0:
        raise ModelError(f"{model.name}: freqs_hz must be a non-empty 1-D array of frequencies (Hz)")
    bad = ~np.isfinite(f) | (f < 0) | (f > 1e100)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ModelError(f"{model.name}: freqs_hz[{i}] = {f[i]} Hz; frequencies must be finite, "
                         "non-negative and at most 1e100 Hz")
    v = _values(model, values)
    with blas_single_thread():
        try:
            out = _frf(model, f, ins, outs, speed, v)
        except np.linalg.LinAlgError:
            raise ModelError(f"{model.name}: the dynamic stiffness is singular at one of the requested "
                             "frequencies (an undamped resonance, or a rigid-body mode at 0 Hz, hit exactly)") from None
    if not np.all(np.isfinite(out.H)):
        k = int(np.flatnonzero(~np.isfinite(out.H).all(axis=(0, 1)))[0])
        raise ModelError(f"{model.name}: the frequency response at {f[k]:.6g} Hz is not finite (the dynamic "
                         "stiffness is singular or overflows there: an undamped resonance or rigid-body mode "
                         "hit exactly, or an absurd frequency)")
    return out


def _frf(model, f, ins, outs, speed, v) -> FRFMatrix:
    M, C, K, G = model.matrices(v)
    B = model.input_matrix(v)[:, [model.input_names.index(q) for q in ins]]
    Cy = model.output_matrix()[[model.output_names.index(q) for q in outs]]
    D = C + speed * G
    from .lumped_elements import add_impedances
    H = np.empty((len(outs), len(ins), f.size), dtype=complex)
    w = 2 * np.pi * f
    chunk = max(1, int(2_000_000 // max(M.size, 1)))     # about 32 MB of complex matrices at a time
    for k0 in range(0, f.size, chunk):
        wk = w[k0:k0 + chunk, None, None]
        Z = K[None] - wk * wk * M[None] + 1j * wk * D[None]       # dynamic stiffness, batched
        add_impedances(Z, model, w[k0:k0 + chunk])                # rational impedances: K(jw) on their DOF
        X = np.linalg.solve(Z, np.broadcast_to(B, (wk.shape[0],) + B.shape))
        H[:, :, k0:k0 + chunk] = np.moveaxis(Cy[None] @ X, 0, -1)
    return FRFMatrix(f, H, ins, outs, speed, _port_info(model, ins, outs))


def _port_info(model, ins, outs) -> dict:
    """Port name -> (station, direction, quantity) for :meth:`FRFMatrix.channel`."""
    lab = {"u": "x", "v": "y", "x": "x"}
    info = {}
    for q in model.inputs:
        if q.name in ins:
            qty = "current" if q.gain is not None else ("force" if q.direction in lab else None)
            info[q.name] = (q.node, lab.get(q.direction, q.direction), qty)
    for q in model.outputs:
        if q.name in outs:
            info[q.name] = (q.node, lab.get(q.direction, q.direction), "displacement" if q.direction in lab else None)
    return info


def state_space(model, *, inputs: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
                speed: float | None = None, values=None):
    """State-space model with named ports, via :func:`mutext.lti.mck_to_ss`.

    State :math:`x = [q; \\dot q]` (SI); inputs in N, N m or A (exciter
    currents, through the force per ampere); outputs in m or rad.

    Parameters
    ----------
    model : Structure or Rotor
        The assembled model, e.g. from :func:`mutext.rotor.load_model`.
    inputs, outputs : sequence of str, optional
        Names of the input and output ports (default: all of the model's).
    speed : float, optional
        Spin speed [rad/s]; default ``model.speed`` (0 for non-rotors).
    values : mapping or array_like, optional
        Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
        vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).

    Examples
    --------
    >>> from mutext.rotor import data_path, load_model
    >>> from mutext.rotor.analysis import state_space
    >>> G = state_space(load_model(data_path("three_mass.toml")), inputs=["f1"], outputs=["x1"])
    >>> G.nstates, G.input_labels, G.output_labels
    (6, ['f1'], ['x1'])
    """
    speed = _speed(model, speed)
    ins, outs = _ports(model, inputs, outputs)
    v = _values(model, values)
    with blas_single_thread():
        M, C, K, G = model.matrices(v)
    B = model.input_matrix(v)
    in_map = {q: B[:, model.input_names.index(q)] for q in ins}
    out_map = {q: model.output_dofs[model.output_names.index(q)] for q in outs}
    sys = mck_to_ss(M, C + speed * G, K, inputs=in_map, outputs=out_map, dof_names=model.dof_names)
    from .lumped_elements import impedances
    for el in impedances(model):
        sys = _close_impedance(sys, el, M, el.dofs(model.layout)[0])
    return sys


def _close_impedance(sys, el, M, dof: int):
    r"""``sys`` (state :math:`[q; \dot q; \ldots]`) with the force :math:`-K(s)q_d` of impedance ``el`` fed back.

    With :math:`\dot z = A_k z + B_k q_d` and :math:`f = C_k z + D_k q_d`, the force
    enters the acceleration rows as :math:`-M^{-1}e_d f`; with
    :math:`b_d = [0;\ M^{-1}e_d;\ 0]` and :math:`c_d` selecting :math:`q_d`, the closed loop is

    .. math::
        \begin{bmatrix}\dot x\\ \dot z\end{bmatrix} =
        \begin{bmatrix} A - b_d D_k c_d & -b_d C_k\\ B_k c_d & A_k\end{bmatrix}
        \begin{bmatrix} x\\ z\end{bmatrix} + \begin{bmatrix} B\\ 0\end{bmatrix}u.
    """
    import control as ct
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    Ak, Bk, Ck, Dk = (np.asarray(X, float) for X in el.realisation())
    ndof, n, nk = M.shape[0], A.shape[0], el.order
    Ak, Bk, Ck, Dk = Ak.reshape(nk, nk), Bk.reshape(nk, 1), Ck.reshape(1, nk), Dk.reshape(1, 1)
    e = np.zeros(ndof)
    e[dof] = 1.0
    bd = np.zeros((n, 1))
    bd[ndof:2 * ndof, 0] = np.linalg.solve(M, e)
    cd = np.zeros((1, n))
    cd[0, dof] = 1.0
    A2 = np.block([[A - bd @ Dk @ cd, -bd @ Ck], [Bk @ cd, Ak]])
    B2 = np.vstack([B, np.zeros((nk, B.shape[1]))])
    C2 = np.hstack([C, np.zeros((C.shape[0], nk))])
    states = list(sys.state_labels) + [f"{el.name}.z{i + 1}" for i in range(nk)]
    return ct.ss(A2, B2, C2, D, inputs=list(sys.input_labels), outputs=list(sys.output_labels), states=states)
