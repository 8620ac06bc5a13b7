r"""The descent of the fast D-G bound: BFGS with the weak Wolfe line search on a maximum
eigenvalue ([LO]_), and where the two largest eigenvalues nearly coincide, a step on their model
(Overton's, with the Hessian of the cluster's Lagrangian near the kink).

The function and its model come from :class:`mutext.mu._fast._DGParams`; nothing here knows
about scalings.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg.lapack import dsyev as _dsyev


#: relative gap of the two largest eigenvalues below which the descent steps on their
#: first-order model (the kink of lambda_max) instead of the gradient of the largest
_CLUSTER_GAP = 0.05
#: "stall": the model step only once a line search along the BFGS direction failed or needed
#: more than _KINK_TRIALS trials (a kink); "always": wherever the gap is below _CLUSTER_GAP
_CLUSTER_MODE = "stall"
#: trials of a line search along the BFGS direction beyond which the point counts as at a kink
#: (one refused trial: with 3, bench_mu case 509 zigzagged across the kink for 60 evaluations,
#: each line search refusing the full step once, before the model step was tried)
_KINK_TRIALS = 1
#: the descent also stops when a step gained less than ftol and the next BFGS step is predicted
#: (-g'p, twice the quadratic model's decrease) to gain less than _PRED_STOP * ftol
_PRED_STOP = 1.0
#: relative gap of the two largest eigenvalues below which the model step uses the Hessian of the
#: cluster's Lagrangian (:meth:`_DGParams.cluster_hessian`) instead of the BFGS metric
_HESSIAN_GAP = 1e-2
#: a step gaining less than this multiple of the rounding noise of the bound counts as no gain
_NOISE_FACTOR = 10.0


def _cluster_step(cl, B):
    r"""Step on the model of the two largest eigenvalues (Overton's idea, for a cluster of two).

    ``cl = (r, C[, W])``: :math:`\lambda_2/\lambda_1`, a function returning the ``2 x 2``
    matrices :math:`C_k = Q^H\partial_kHQ/\lambda_1` and optionally one returning the Hessian of
    the cluster's Lagrangian for a multiplier ``U`` (:meth:`_DGParams.cluster_hessian`).  The
    model of :math:`\lambda_{\max}/\lambda_1` is :math:`c(d) + \|\rho(d)\|` (the largest
    eigenvalue of a ``2 x 2`` Hermitian matrix, affine in the step :math:`d`); the step
    minimises it plus :math:`\frac12 d^TB^{-1}d`, then, with ``W``, again with the Hessian of
    the Lagrangian at the multiplier found (second order along the kink: the BFGS metric,
    built from gradients of :math:`\lambda_{\max}` that jump across it, gave linear
    convergence at a rate of 0.89 on bench_mu case 89).  Returns (d, predicted change of the model).
    """
    r, C = cl[0], cl[1]()
    c00, c11, c01 = C[:, 0, 0].real, C[:, 1, 1].real, C[:, 0, 1]
    gc = 0.5 * (c00 + c11)
    J = np.array([0.5 * (c00 - c11), c01.real, c01.imag])
    r0 = np.array([0.5 * (1.0 - r), 0.0, 0.0])
    d, pred, u = _cluster_solve(gc, J, r0, r, B)
    if len(cl) > 2 and cl[2] is not None and 1.0 - r < _HESSIAN_GAP and np.all(np.isfinite(u)):
        U = 0.5 * np.array([[1.0 + u[0], u[1] + 1j * u[2]], [u[1] - 1j * u[2], 1.0 - u[0]]])
        W = cl[2](U)
        q, V, info = _dsyev(W)
        if info == 0 and np.all(np.isfinite(q)) and q[-1] > 0:
            # positive definite: along the kink the Lagrangian is convex at a minimiser; a small
            # shift where it is not (far from one)
            tau = max(0.0, -q[0]) + 1e-10 * q[-1]
            d2, pred2, _ = _cluster_solve(gc, J, r0, r, (V / (q + tau)) @ V.T)
            if np.all(np.isfinite(d2)) and pred2 < 0:
                return d2, pred2
    return d, pred


def _cluster_solve(gc, J, r0, r, B):
    """The step of :func:`_cluster_step` for the metric ``B``: (d, predicted change, u), ``u`` the
    dual vector (the multiplier of the cluster in the Pauli basis)."""
    BJ = B @ J.T
    Q3 = J @ BJ
    Q3 = 0.5 * (Q3 + Q3.T)
    b = r0 - BJ.T @ gc
    q, V, info = _dsyev(Q3)
    if info != 0:
        q, V = np.linalg.eigh(Q3)
    bb = V.T @ b
    top = float(q[-1])
    nb = float(np.sqrt(b @ b))
    if not top > 1e-14 * nb:
        # the model's curvature vanishes (or is negligible): the linear part alone
        u = b / nb if nb > 0 else np.zeros(3)
    elif q[0] > 1e-12 * top and float((bq := bb / q) @ bq) <= 1.0:
        u = V @ bq
    else:
        # ||(Q3 + mu I)^-1 b|| = 1: Newton on 1 / ||u(mu)|| (More and Sorensen)
        # (three terms, written out: Python floats, faster than numpy calls on 3-vectors)
        q0, q1, q2 = q.tolist()
        b0, b1, b2 = bb.tolist()
        mu0 = max(0.0, -q0)
        mu = mu0 + 1e-12 * top
        for _ in range(60):
            a0, a1, a2 = q0 + mu, q1 + mu, q2 + mu
            z0, z1, z2 = b0 / a0, b1 / a1, b2 / a2
            nu = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
            if not nu > 0:
                break
            dn = -(z0 * z0 / a0 + z1 * z1 / a1 + z2 * z2 / a2) / nu
            step = (1.0 / nu - 1.0) * nu * nu / dn
            mu_new = max(mu + step, mu0 + 0.5 * (mu - mu0))
            if abs(mu_new - mu) <= 1e-14 * max(mu, 1e-300):
                mu = mu_new
                break
            mu = mu_new
        u = V @ (bb / (q + mu))
        nu = float(np.sqrt(u @ u))
        if nu > 1.0:
            u = u / nu
    d = -(B @ gc + BJ @ u)
    rd = r0 + J @ d
    pred = 0.5 * (r - 1.0) + float(gc @ d) + math.sqrt(float(rd @ rd))
    return d, pred, u


def _absmax(v) -> float:
    """max |v_i| of a short vector (0 if empty): a Python loop over a few floats is several
    times cheaper than numpy's reductions, called a few times per iteration of the descent."""
    a = v.tolist()
    if sum(a) != sum(a):
        return float(np.abs(v).max())       # a NaN (or inf - inf): numpy's propagation
    return max(map(abs, a), default=0.0)


def _bfgs_update(B, s, y):
    """The BFGS update of the inverse Hessian approximation ``B`` for the step ``s`` and the change
    of gradient ``y`` (``B`` unchanged where the curvature ``s'y`` is not positive)."""
    sy = float(s @ y)
    if not sy > 1e-14 * float(s @ s):
        return B
    By = B @ y
    rho = 1.0 / sy
    T = By[:, None] * s                 # B y s^T; with its transpose the symmetric rank-two term
    return B + ((sy + y @ By) * rho * rho) * (s[:, None] * s) - rho * (T + T.T)


def _model_search(fun, x, f, d, pred, max_step, cluster, B):
    """Armijo backtracking along the model step ``d`` (predicted change ``pred`` < 0):
    (point, value, gradient, evaluations), value inf if no trial was accepted.  Where the full
    step is refused, the model step from the refused point is tried first (accepted on the
    decrease predicted from ``x``): near the kink the full step converges quadratically but can
    raise ``lambda_max`` through the second-order change of the pair's split (the Maratos
    effect), and halving it would make the convergence linear (bench_mu case 1081: 71 -> 49
    evaluations)."""
    big = _absmax(d)
    t = min(1.0, max_step / big) if big > 0 else 1.0
    nev = 0
    for ls in range(8):
        xt = x + t * d
        ft, gt = fun(xt)
        nev += 1
        if ft <= f + 1e-4 * t * pred:
            return xt, ft, gt, nev
        if ls == 0 and t == 1.0 and ft < np.inf:
            clt = cluster()
            if clt is not None and clt[1] is not None:
                d2, pred2 = _cluster_step(clt, B)
                if pred2 < 0 and np.all(np.isfinite(d2)):
                    big = _absmax(d2)
                    x2 = xt + (d2 * (max_step / big) if big > max_step else d2)
                    f2, g2 = fun(x2)
                    nev += 1
                    if f2 <= f + 1e-4 * pred:
                        return x2, f2, g2, nev
        t *= 0.5
    return x, np.inf, None, nev


def _floored_spectrum(W, floor: float = 1e-3):
    """(eigenvalues, eigenvectors, absolute eigenvalues floored at ``floor`` times the largest) of the
    symmetric ``W`` (one triangle read); None if they are not finite or ``W`` has no positive scale."""
    q, V, info = _dsyev(W)
    if info != 0 or not np.all(np.isfinite(q)):
        return None
    a = np.abs(q)
    top = float(a.max()) if a.size else 0.0
    if not top > 0:
        return None
    return q, V, np.maximum(a, floor * top)


def _inverse_metric(W):
    """A positive definite inverse of the symmetric ``W`` (a Hessian): its eigenvalues by absolute
    value, floored at 1e-3 of the largest (a Newton metric that never points uphill, and bounded
    along flat or concave directions); None if ``W`` has no positive scale."""
    sp = _floored_spectrum(W)
    if sp is None:
        return None
    _, V, a = sp
    return (V / a) @ V.T


def _opened_metric(B):
    """``B`` (a BFGS inverse Hessian approximation) with its eigenvalues floored at 1e-3 of the
    largest, for a descent on another function (a warm start at the next frequency): at a kink
    BFGS closes the directions across it (their eigenvalues go to 0), and carried to where the kink
    has moved a closed direction keeps the descent from following the optimum (bench_mu_sweep
    seed 0: a real block's G-hat stuck near 0 for 70 frequencies, 0.2-0.8 % above AB13MD).  None
    stays None; a metric without a positive scale gives None (the identity)."""
    if B is None:
        return None
    sp = _floored_spectrum(B)
    if sp is None:
        return None
    q, V, a = sp
    if np.array_equal(q, a):
        return B                    # positive definite, nothing below the floor: kept as it is
    return (V * a) @ V.T


def _first_metric(B0, hessian, n: int):
    """(inverse metric, whether it is the identity): a copy of ``B0``; without it the inverse of
    ``hessian()`` (:func:`_inverse_metric`) where that exists, else the identity."""
    if B0 is not None:
        return B0.copy(), False
    W = hessian() if hessian is not None else None
    B = None if W is None else _inverse_metric(W)
    return (np.eye(n), True) if B is None else (B, False)


def _bfgs(fun, x0, B0=None, max_iter: int = 100, ftol: float = 1e-10, max_step: float = 1.0,
          max_eval: int = 400, info: dict | None = None, cluster=None, noise=None, hessian=None):
    r"""Minimise a (possibly nonsmooth at optimum) function by BFGS with a weak Wolfe line search.

    The line search of Lewis and Overton [LO]_ (bisection/doubling on the
    Armijo and weak curvature conditions), which keeps BFGS working on max
    eigenvalue functions.  Stops when an iteration lowers ``f`` by less than
    ``ftol`` (absolute: ``f`` is a logarithm) twice in a row or the line search fails.
    ``max_eval`` bounds the function evaluations (the result is then the best
    point found, still a valid bound).  Returns (f, x, inverse Hessian
    approximation, evaluations); ``info["stop"]`` (if given) says why it stopped:
    ``"ftol"`` (converged), ``"stall"`` (the line search failed, typically at a kink of
    the largest eigenvalue) or ``"budget"``; ``info["moved"]`` whether any step was taken.
    ``cluster`` (optional) returns the model of the two largest eigenvalues at the point
    last evaluated (see :func:`_cluster_step`); where their gap is below ``_CLUSTER_GAP``
    the step is taken on that model (Armijo backtracking on its predicted decrease,
    :func:`_model_search`; no BFGS update from it), with the gradient step as fallback.  ``noise`` (optional) returns the rounding noise of ``f`` at
    the point last evaluated: a step gaining less than ``_NOISE_FACTOR`` times it counts as
    gaining less than ``ftol`` (a descent in rounding noise only wanders).  ``hessian``
    (optional, with ``B0`` None) returns the Hessian of ``f`` at the point last evaluated (or
    None): the first metric is then its inverse (:func:`_inverse_metric`), not the identity.
    """
    def tol_here():
        return max(ftol, _NOISE_FACTOR * noise()) if noise is not None else ftol

    x = x0.copy()
    f, g = fun(x)
    tol = tol_here()
    cl = cluster() if cluster is not None else None
    nev, n, small = 1, x.size, 0
    # the Hessian only where a step will be taken (not at a stationary start)
    B, reset = _first_metric(B0, hessian if _absmax(g) > 1e-13 else None, n)
    stop, moved = "budget", False
    kinked = _CLUSTER_MODE == "always"
    cl_fail = False         # the model step failed at the current point
    for _ in range(max_iter):
        if nev >= max_eval:
            break
        if not _absmax(g) > 1e-13:
            stop = "ftol"           # a smooth stationary point (no line search can go down)
            break
        if kinked and not cl_fail and cl is not None and 1.0 - cl[0] < _CLUSTER_GAP:
            d, pred = _cluster_step(cl, B)
            if (pred >= 0.0 or (small and -pred < _PRED_STOP * tol)) and np.all(np.isfinite(d)):
                # the model of the two top eigenvalues has its minimum here (a stationary point
                # of lambda_max; without this stop a failing line search along -B g and this
                # step alternated until the evaluation budget was spent), or the last step
                # gained less than tol and this one is predicted to gain less
                stop = "ftol"
                break
            if pred < 0 and np.all(np.isfinite(d)):
                xt, ft, gt, k = _model_search(fun, x, f, d, pred, max_step, cluster, B)
                nev += k
                cl_fail = ft == np.inf
                if ft < np.inf:
                    drop = f - ft
                    moved = True
                    x, f, g = xt, ft, gt
                    tol = tol_here()
                    cl = cluster()
                    # no BFGS update from a step across the kink: its change of gradient mixes the
                    # two eigenvalues' and spoils the metric (warm-started sweep descents then crept
                    # and stopped on two small gains, 198 of 500 frequencies up to 11 % high)
                    small = small + 1 if drop < tol else 0
                    if small >= 2:
                        stop = "ftol"
                        break
                    continue
        p = -B @ g
        gp = float(g @ p)
        if small and -gp < _PRED_STOP * tol:
            stop = "ftol"           # the last step gained < ftol and the next is predicted to gain less
            break
        if not gp < 0:
            B = np.eye(n)
            p = -g
            gp = float(g @ p)
            if not gp < 0:
                stop = "stall"
                break
        # at most a factor e^max_step in any scaling per step (a stale or nearly
        # singular Hessian approximation points far out along flat directions)
        big = _absmax(p)
        t = min(1.0, max_step / big) if big > 0 else 1.0
        lo, hi = 0.0, np.inf
        ok = False
        for _ls in range(30):
            xt = x + t * p
            ft, gt = fun(xt)
            nev += 1
            if not ft <= f + 1e-4 * t * gp:
                hi = t
            elif float(gt @ p) < 0.9 * gp:
                lo = t
            else:
                ok = True
                break
            t = 0.5 * (lo + hi) if np.isfinite(hi) else 2.0 * lo
        if _ls >= _KINK_TRIALS:
            kinked = True
        if not ok:
            if ft < f:          # a decrease without the curvature condition: keep it
                # (gt is the gradient there: xt was the last point evaluated)
                x, f, g = xt, ft, gt
                moved = True
                cl = cluster() if cluster is not None else None
                cl_fail = False
            if not cl_fail and cl is not None and 1.0 - cl[0] < _CLUSTER_GAP:
                continue        # at a kink: the model step next
            if reset:
                stop = "stall"
                break
            # a stale Hessian approximation (a warm start from another matrix): restart once
            B = np.eye(n)
            reset = True
            continue
        s, y = t * p, gt - g
        drop = f - ft
        moved = True
        x, f, g = xt, ft, gt
        tol = tol_here()
        cl = cluster() if cluster is not None else None
        cl_fail = False
        B = _bfgs_update(B, s, y)
        small = small + 1 if drop < tol else 0
        if small >= 2:
            stop = "ftol"
            break
    if info is not None:
        info["stop"] = stop
        info["moved"] = moved
    return f, x, B, nev
