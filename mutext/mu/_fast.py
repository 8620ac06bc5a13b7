r"""Upper bound by D-G scalings without an SDP: quasi-Newton descent ([YND]_, [LO]_).

BFGS with the weak Wolfe line search on :math:`\log\lambda_{\max}` of the
congruent form, in coordinates that carry over from one frequency to the next
(``mu_upper(method="fast")`` and the warm-started sweep of :func:`mu_sweep`).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg.lapack import dsyev as _dsyev
from scipy.linalg.lapack import zheevd as _zheevd

from ._certificate import MuUpper, _d_from_matrices, _diag_result
from ._osborne import _osborne
from ._structure import BlockStructure, _norm2


_EPS_N = float(np.finfo(float).eps)


class _DGParams:
    r"""Coordinates of the scalings of the fast D-G bound for one structure.

    Block ``k`` has a factor :math:`L_k` with :math:`D_k = L_kL_k^H`: a positive
    scalar :math:`e^{x}` on full and ``1 x 1`` blocks, a lower-triangular
    matrix (log diagonal, complex entries below) on repeated scalars.  A real
    block also has a Hermitian :math:`\hat G_k` (each real coordinate of it the
    ``sinh`` of a coordinate here, so that the flat approach of the bound to its
    infimum as :math:`G\to\infty`, common for nearly real ``M``, takes few
    steps) and :math:`G_k = \beta_0 L_k\hat G_kL_k^H`, so that in the congruent form

    .. math::
        H = A^HA + j\beta_0(\hat GA - A^H\hat G), \qquad A = L_\ell^H M L_r^{-H},

    :math:`\hat G` is dimensionless and independent of :math:`D` (the
    :math:`D,\,G/\beta` form of Young, Newlin and Doyle [YND]_); its value
    carries over from one frequency to the next.  The first coordinate of the
    last block is fixed to 0 (the bound is invariant to scaling all of D).
    """

    def __init__(self, S: BlockStructure, use_g: bool):
        self.S = S
        self.use_g = use_g
        self.diag = S.diagonal_scalings
        self.lslots, self.gslots = [], []
        n = 0
        for b in S.blocks:
            k = 1 if b.diagonal_scaling else b.rows * b.rows
            self.lslots.append(slice(n, n + k))
            n += k
        for b in S.blocks:
            if use_g and b.kind == "real":
                k = b.rows * b.rows
                self.gslots.append(slice(n, n + k))
                n += k
            else:
                self.gslots.append(None)
        self.size = n
        self.fixed = self.lslots[-1].start
        self.free = np.delete(np.arange(n), self.fixed)
        if self.diag:
            # coordinates are [log d per block, G-hat per real block]
            self.m = len(S)
            self.real_idx = np.array([k for k, g in enumerate(self.gslots) if g is not None], int)
            self.nreal = self.real_idx.size
            self.grow = np.array([S.row_slices[k].start for k in self.real_idx], int)
            self.gcol = np.array([S.col_slices[k].start for k in self.real_idx], int)
            self.El = np.eye(self.m)[S.col_block]
            self.Er = np.eye(self.m)[S.row_block]
            # d A / d x_k = A * sel[k] for the log scaling x_k of block k (A = E_l M E_r^-1)
            self.sel = self.El.T[:, :, None] - self.Er.T[:, None, :]
            self.yidx = np.arange(self.nreal)

    #: relative rounding noise of the last value (see value_grad)
    noise = 0.0
    #: set by the caller: value_grad then also keeps what the first-order model of the top two
    #: eigenvalues (diagonal scalings only, :meth:`model`) is built from in ``cluster``
    want_cluster = False
    cluster = None

    _stack_of = None

    def _stack(self, M):
        r"""The terms of the congruent form for diagonal scalings, for the matrix ``M``: with
        :math:`d_k = e^{x_k}` and :math:`r = 1/d` over the rows,

        .. math::
            H = (rr^T)\circ\Bigl(\sum_k d_k^2 M_k^HM_k
                + \sum_j g_j d_{k_j}^2\, j(E_jM - M^HE_j^T)\Bigr),

        :math:`M_k` the rows of block ``k``, :math:`g_j = \beta_0\sinh y_j` the G-hat of real
        block :math:`k_j` and :math:`E_j` its entry (the same products as :math:`A^HA +
        j(\tilde GA - A^H\tilde G^H)`, :math:`A = D_\ell MD_r^{-1}`, entry by entry).  Built once
        per matrix; ``value_grad`` is then one product with the stacked terms, one scaling and
        one eigensolver call."""
        m, r, n = self.m, self.nreal, self.S.nrows
        St = np.empty((m + r, n, n), complex)
        # sum over the rows of each block of the outer products conj(M_a)^T M_a
        St[:m] = (self.El.T @ (M.conj()[:, :, None] * M[:, None, :]).reshape(M.shape[0], n * n)).reshape(m, n, n)
        for j in range(r):
            E = np.zeros((n, n), complex)
            E[self.grow[j]] = M[self.gcol[j]]
            St[m + j] = 1j * (E - E.conj().T)
        self._stack_m, self._sflat, self._stack_of = St, St.reshape(m + r, n * n), M
        if not hasattr(self, "_map2"):
            mp = np.zeros((m + r, m))
            mp[np.arange(m), np.arange(m)] = 2.0
            mp[m + np.arange(r), self.real_idx] = 2.0
            self._map2, self._er2 = mp, 2.0 * self.Er

    def _scaled(self, M, x):
        """A = D_l M D_r^-1 for diagonal scalings (the model of the top two eigenvalues)."""
        e = np.exp(x[:self.m])
        return (e[self.S.col_block][:, None] * M) * (1.0 / e)[self.S.row_block]

    def model(self, gap: float):
        """(lambda_2/lambda_1, C) at the point last evaluated, C a function returning the
        matrices of :meth:`_cluster` (built only when the descent steps on them) if the
        relative gap of the two is below ``gap``, else None; None without that evaluation."""
        cl = self.cluster
        if cl is None:
            return None
        w = cl[1]
        if w.size < 2 or not w[-1] > 0:
            return None
        r = float(w[-2] / w[-1])
        if not 1.0 - r < gap:
            return r, None
        return r, lambda: self._cluster(*cl)[1]

    def _cluster(self, M, w, V, beta0, gs, x):
        r"""First-order model of the two largest eigenvalues of H, divided by the largest:
        (w1/w0, C) with C[k] = Q^H (dH/dx_k) Q / w0 (2 x 2, all coordinates), Q the two top
        eigenvectors (largest first).  With ``A`` and ``Y = AQ - j G'^H Q``,
        :math:`Q^H\partial_kHQ = R_k^HY + Y^HR_k`, :math:`R_k = \partial_kA\,Q`."""
        A = self._scaled(M, x)
        Q = V[:, :-3:-1]
        P = A @ Q
        Y = P.copy()
        if gs is not None:
            Y[self.gcol] -= 1j * (beta0 * gs)[:, None] * Q[self.grow]
        AY = A.conj().T @ Y
        # R_k^H Y summed over the rows of block k: columns (col_block) and rows (row_block)
        T = ((P.conj()[:, :, None] * Y[:, None, :]).reshape(P.shape[0], 4).T @ self.El
             - (Q.conj()[:, :, None] * AY[:, None, :]).reshape(Q.shape[0], 4).T @ self.Er)
        T = T.T.reshape(self.m, 2, 2)
        C = np.empty((self.size, 2, 2), complex)
        C[:self.m] = T + T.conj().transpose(0, 2, 1)
        if gs is not None:
            X = Q[self.grow].conj()[:, :, None] * P[self.gcol][:, None, :]
            C[self.m:] = (1j * beta0 * np.cosh(x[self.m:]))[:, None, None] * (X - X.conj().transpose(0, 2, 1))
        return float(w[-2] / w[-1]), C / w[-1]

    def cluster_hessian(self, U):
        r"""Hessian of the Lagrangian :math:`\operatorname{Re}\operatorname{tr}(U\,Q^HH(x)Q)` of the
        two largest eigenvalues at the point last evaluated (diagonal scalings; Overton's
        second-order model of a cluster), divided by the largest eigenvalue: all coordinates,
        ``U`` a Hermitian ``2 x 2`` matrix (the multiplier of the cluster, trace 1).

        .. math::
            W_{ik} = \operatorname{Re}\operatorname{tr}\bigl(U Q^H\partial_{ik}H\,Q\bigr)
            + 2\operatorname{Re}\sum_{l>2}\frac{\operatorname{tr}(U F_{i,l}^H F_{k,l})}{\lambda - \lambda_l},
            \qquad F_{i,l} = v_l^H\,\partial_iH\,Q,

        with :math:`Q` the top two eigenvectors and :math:`(\lambda_l, v_l)` the other eigenpairs
        (:math:`\lambda` the cluster's eigenvalue of each column of :math:`Q`, averaged over
        the pair ``U`` couples).  Every derivative of ``H`` is :math:`Z + Z^H`, and with
        :math:`K = A^H + j\tilde G`, :math:`Y = K^HQ`, :math:`P = AQ`, :math:`R_k = \partial_kA\,Q`
        (:math:`\partial_kA = A\circ s_k`, ``s_k`` the +-1 pattern of block ``k``):
        :math:`\partial_kH\,Q = \partial_kA^HY + KR_k`; :math:`Q^H\partial_{ik}H\,Q` has
        :math:`Y^H(A\circ s_i\circ s_k)Q + R_i^HR_k` and its transpose; a G-hat coordinate
        ``y`` of entry (r, c) adds :math:`j\beta_0\cosh(y)\,e_r A_{c,:}` (second derivative
        :math:`\sinh` for ``cosh``; :math:`A\to\partial_kA` across)."""
        M, w, V, beta0, gs, x = self.cluster
        A = self._scaled(M, x)
        m, N, n = self.m, self.size, A.shape[1]
        sel = self.sel
        Q = V[:, :-3:-1]
        P = A @ Q
        Y = P.copy()
        if gs is not None:
            jg = 1j * beta0 * gs
            Y[self.gcol] -= jg[:, None] * Q[self.grow]
        dA = A[None] * sel                                      # (m, ncols, nrows)
        R = dA @ Q                                              # (m, ncols, 2)
        DQ = np.empty((N, n, 2), complex)
        # K^H Q = Y (so Q^H K = Y^H) and K R_k = A^H R_k + j G~ R_k
        KR = A.conj().T[None] @ R
        if gs is not None:
            KR[:, self.grow] += jg[:, None] * R[:, self.gcol]
        DQ[:m] = dA.conj().transpose(0, 2, 1) @ Y + KR
        UT = U.T
        # second derivatives, x-x: sum over entries of s_i s_k (A o Psi), Psi = conj(Y) U^T Q^T
        Psi = (Y.conj() @ UT) @ Q.T
        sf = sel.reshape(m, -1)
        W = np.empty((N, N))
        Wxx = 2.0 * ((sf * (A * Psi).ravel()) @ sf.T
                     + R.conj().reshape(m, -1) @ (R @ U).reshape(m, -1).T).real
        W[:m, :m] = Wxx
        if gs is not None:
            c = beta0 * np.cosh(x[m:])
            gr, gc = self.grow, self.gcol
            # D_j Q = j c_j (e_gr P[gc] - conj(A[gc])^T Q[gr])
            jc = 1j * c
            DQy = (-jc[:, None, None] * A[gc].conj()[:, :, None]) * Q[gr][:, None, :]
            DQy[self.yidx, gr] += jc[:, None] * P[gc]
            DQ[m:] = DQy
            qu = Q[gr].conj()                                   # (r, 2)
            # tr(U Q^H E_j B Q) = conj(Q[gr]) . (B[gc] Q U): B = A (y-y) or dA_k (x-y)
            tyy = (qu * (P[gc] @ U)).sum(1)
            W[m:, m:] = np.diag((-2.0 * beta0) * gs * tyy.imag)
            txy = (qu[None] * (R[:, gc] @ U)).sum(2)
            W[:m, m:] = (-2.0 * c) * txy.imag
            W[m:, :m] = W[:m, m:].T
        F = V[:, :-2].conj().T[None] @ DQ                       # (N, n-2, 2)
        dl = 1.0 / (w[-1:-3:-1][None, :] - w[:-2, None])        # (n-2, 2)
        Tw = 0.5 * (dl[:, :, None] + dl[:, None, :]) * UT[None]
        Fl = F.transpose(1, 0, 2)                               # (n-2, N, 2)
        W += 2.0 * ((Fl.conj() @ Tw) @ Fl.transpose(0, 2, 1)).sum(0).real
        return 0.5 * (W + W.T) / w[-1]

    # -- small matrices from coordinates -------------------------------------
    @staticmethod
    def _lower(p, n):
        """Lower-triangular factor: exp(p) on the diagonal, complex entries below."""
        L = np.zeros((n, n), complex)
        L[np.diag_indices(n)] = np.exp(p[:n])
        il = np.tril_indices(n, -1)
        m = len(il[0])
        L[il] = p[n:n + m] + 1j * p[n + m:n + 2 * m]
        return L

    @staticmethod
    def _herm(p, n):
        G = np.zeros((n, n), complex)
        G[np.diag_indices(n)] = p[:n]
        iu = np.triu_indices(n, 1)
        m = len(iu[0])
        G[iu] = p[n:n + m] + 1j * p[n + m:n + 2 * m]
        G[(iu[1], iu[0])] = np.conj(G[iu])
        return G

    def initial(self, d) -> np.ndarray:
        """Coordinates for diagonal scalings ``d`` (one per block, L = d) and G = 0."""
        x = np.zeros(self.size)
        for b, sl, dk in zip(self.S.blocks, self.lslots, d):
            x[sl.start:sl.start + (1 if b.diagonal_scaling else b.rows)] = np.log(dk)
        return x - x[self.fixed] * self._log_mask()

    def _log_mask(self):
        m = np.zeros(self.size)
        for b, sl in zip(self.S.blocks, self.lslots):
            m[sl.start:sl.start + (1 if b.diagonal_scaling else b.rows)] = 1.0
        return m

    # -- the bound and its gradient -------------------------------------------
    @staticmethod
    def _top(A, GA):
        """Largest eigenvalue of H = A^H A + j(GA - (GA)^H) (no G term if ``GA`` is None) and its
        eigenvector: the congruent form whose eigenvalue is the squared bound."""
        H = A.conj().T @ A
        if GA is not None:
            H = H + 1j * (GA - GA.conj().T)
        ev, V = np.linalg.eigh(H)
        return float(ev[-1]), V[:, -1]

    def value_grad(self, x, M, beta0, grad: bool = True):
        r"""(lambda, grad log lambda) with :math:`\lambda = \lambda_{\max}(H)` (the squared bound)."""
        S = self.S
        if self.diag:
            # one scaling per block (coordinates 0..m-1), G-hat on 1 x 1 real blocks after them,
            # H = (r r^T) o sum_i c_i S_i (see _stack): the inner loop of the default bound, in
            # few numpy calls
            if self._stack_of is not M:
                self._stack(M)      # a call from outside a descent (_upper_fast builds it)
            m = self.m
            e2 = np.exp(2.0 * x[:m])
            ri = np.exp(-x[:m])[S.row_block]
            if self.nreal:
                gs = beta0 * np.sinh(x[m:])
                coef = np.concatenate((e2, gs * e2[self.real_idx]))
            else:
                coef = e2
            H = (coef @ self._sflat).reshape(S.nrows, S.nrows) * np.multiply.outer(ri, ri)
            w, V, info = _zheevd(H)
            if info != 0:
                raise np.linalg.LinAlgError("eigenvalues of the scaled form did not converge")
            lam, v = float(w[-1]), V[:, -1]
            # rounding noise of log lambda here: eps times the size of H (its extreme eigenvalues)
            # over lambda; a G-hat approaching infinity makes H graded and this large
            self.noise = _EPS_N * S.nrows * max(-float(w[0]), lam) / lam if lam > 0 else np.inf
            if not grad:
                return lam, None
            if self.want_cluster:
                # kept for the model of the top two eigenvalues, built only where they are close
                self.cluster = (M, w, V, beta0, gs / beta0 if self.nreal else None, x)
            # d/dx of u^H (sum c_i S_i) u with u = r o v: the coefficients' own (2 c_i q_i on
            # their block) and -2 lambda |v|^2 over the block's rows from r
            u = ri * v
            q = ((self._stack_m @ u) @ u.conj()).real
            gx = (coef * q) @ self._map2 - lam * ((v.real * v.real + v.imag * v.imag) @ self._er2)
            if self.nreal:
                g = np.concatenate((gx, (beta0 * np.cosh(x[m:])) * e2[self.real_idx] * q[m:]))
            else:
                g = gx
            return lam, g / max(lam, 1e-300)
        # general structure (repeated scalars): block-diagonal factors
        Lc = np.zeros((S.ncols, S.ncols), complex)
        Lri = np.zeros((S.nrows, S.nrows), complex)
        Gh = np.zeros((S.nrows, S.ncols), complex) if self.use_g else None
        Ls, Ghs = [], []
        for b, rs, cs, sl, gs in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots):
            if b.diagonal_scaling:
                l = np.exp(x[sl.start])
                Lc[cs, cs] = l * np.eye(b.cols)
                Lri[rs, rs] = np.eye(b.rows) / l
                Ls.append(l)
            else:
                L = self._lower(x[sl], b.rows)
                Lc[cs, cs] = L
                Lri[rs, rs] = np.linalg.inv(L)
                Ls.append(L)
            Gk = None
            if gs is not None:
                Gk = self._herm(np.sinh(x[gs]), b.rows)
                Gh[rs, cs] = beta0 * Gk
            Ghs.append(Gk)
        A = Lc.conj().T @ M @ Lri.conj().T
        lam, v = self._top(A, None if Gh is None else Gh @ A)
        if not grad:
            return lam, None
        a = A @ v
        u = Lri.conj().T @ v
        z = M @ u
        g = np.zeros(self.size)
        for b, rs, cs, sl, gs, L, Gk in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots,
                                             Ls, Ghs):
            if b.diagonal_scaling:
                gl = 2.0 * (np.vdot(a[cs], a[cs]).real - lam * np.vdot(v[rs], v[rs]).real)
                if Gk is not None:
                    gl -= 4.0 * beta0 * Gk[0, 0].real * np.imag(np.conj(v[rs][0]) * a[cs][0])
                g[sl.start] = gl
            else:
                n = b.rows
                zk, ak, uk, vk = z[cs], a[cs], u[rs], v[rs]
                gL = 2.0 * (np.outer(zk, ak.conj()) - lam * np.outer(uk, vk.conj()))
                if Gk is not None:
                    gL = gL + 2.0 * beta0 * 1j * (np.outer(zk, vk.conj()) - np.outer(uk, ak.conj())) @ Gk
                il = np.tril_indices(n, -1)
                m = len(il[0])
                p = g[sl]
                p[:n] = np.real(np.diag(gL)) * np.real(np.diag(L))
                p[n:n + m] = gL[il].real
                p[n + m:] = gL[il].imag
                g[sl] = p
            if Gk is not None:
                n = b.rows
                K = beta0 * 1j * (np.outer(a[cs], v[rs].conj()) - np.outer(v[rs], a[cs].conj()))
                iu = np.triu_indices(n, 1)
                m = len(iu[0])
                p = np.empty(n + 2 * m)
                p[:n] = np.real(np.diag(K))
                p[n:n + m] = 2.0 * K[iu].real
                p[n + m:] = 2.0 * K[iu].imag
                g[gs] = p * np.cosh(x[gs])
        return lam, g / max(lam, 1e-300)

    def scalings(self, x, beta0):
        """(Dl, Dr, G) of the LMI form from coordinates."""
        S = self.S
        if self.diag:
            d2 = np.exp(2.0 * x[:self.m])
            G = None
            if self.use_g:
                G = np.zeros((S.nrows, S.ncols), complex)
                G[self.grow, self.gcol] = beta0 * d2[self.real_idx] * np.sinh(x[self.m:])
            return np.diag(d2[S.col_block]).astype(complex), np.diag(d2[S.row_block]).astype(complex), G
        Dl = np.zeros((S.ncols, S.ncols), complex)
        Dr = np.zeros((S.nrows, S.nrows), complex)
        G = np.zeros((S.nrows, S.ncols), complex) if self.use_g else None
        for b, rs, cs, sl, gs in zip(S.blocks, S.row_slices, S.col_slices, self.lslots, self.gslots):
            if b.diagonal_scaling:
                L = np.exp(x[sl.start]) * np.eye(b.rows)
                Dl[cs, cs] = np.exp(2 * x[sl.start]) * np.eye(b.cols)
                Dr[rs, rs] = np.exp(2 * x[sl.start]) * np.eye(b.rows)
            else:
                L = self._lower(x[sl], b.rows)
                Dl[cs, cs] = Dr[rs, rs] = L @ L.conj().T
            if gs is not None:
                G[rs, cs] = beta0 * L @ self._herm(np.sinh(x[gs]), b.rows) @ L.conj().T
        return Dl, Dr, G


#: relative gap of the two largest eigenvalues below which the descent steps on their
#: first-order model (the kink of lambda_max) instead of the gradient of the largest
_CLUSTER_GAP = 0.05
#: "stall": the model step only once a line search along the BFGS direction failed or needed
#: more than 3 trials (a kink); "always": wherever the gap is below _CLUSTER_GAP
_CLUSTER_MODE = "stall"
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
        q = np.linalg.eigvalsh(W)
        if np.all(np.isfinite(q)) and q[-1] > 0:
            # positive definite: along the kink the Lagrangian is convex at a minimiser; a small
            # shift where it is not (far from one)
            tau = max(0.0, -q[0]) + 1e-10 * q[-1]
            Bw = np.linalg.inv(W + tau * np.eye(W.shape[0]))
            d2, pred2, _ = _cluster_solve(gc, J, r0, r, 0.5 * (Bw + Bw.T))
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
        # (three terms: Python floats, faster than numpy calls on 3-vectors)
        qs, bs = q.tolist(), bb.tolist()
        mu0 = max(0.0, -qs[0])
        mu = mu0 + 1e-12 * top
        for _ in range(60):
            zs = [bi / (qi + mu) for bi, qi in zip(bs, qs)]
            nu = math.sqrt(sum(zi * zi for zi in zs))
            if not nu > 0:
                break
            dn = -sum(zi * zi / (qi + mu) for zi, qi in zip(zs, qs)) / nu
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


def _bfgs_update(B, s, y):
    """The BFGS update of the inverse Hessian approximation ``B`` for the step ``s`` and the change
    of gradient ``y`` (``B`` unchanged where the curvature ``s'y`` is not positive)."""
    sy = float(s @ y)
    if not sy > 1e-14 * float(s @ s):
        return B
    By = B @ y
    rho = 1.0 / sy
    return B + ((sy + y @ By) * rho * rho) * (s[:, None] * s) - rho * (By[:, None] * s + s[:, None] * By)


def _bfgs(fun, x0, B0=None, max_iter: int = 100, ftol: float = 1e-10, max_step: float = 1.0,
          max_eval: int = 400, info: dict | None = None, cluster=None, noise=None):
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
    the step is taken on that model (Armijo backtracking on its predicted decrease), with
    the gradient step as fallback.  ``noise`` (optional) returns the rounding noise of ``f`` at
    the point last evaluated: a step gaining less than ``_NOISE_FACTOR`` times it counts as
    gaining less than ``ftol`` (a descent in rounding noise only wanders).
    """
    def tol_here():
        return max(ftol, _NOISE_FACTOR * noise()) if noise is not None else ftol

    x = x0.copy()
    f, g = fun(x)
    tol = tol_here()
    cl = cluster() if cluster is not None else None
    nev, n, small = 1, x.size, 0
    B = np.eye(n) if B0 is None else B0.copy()
    reset = B0 is None
    stop, moved = "budget", False
    kinked = _CLUSTER_MODE == "always"
    cl_fail = False         # the model step failed at the current point
    for _ in range(max_iter):
        if nev >= max_eval:
            break
        if not np.abs(g).max(initial=0.0) > 1e-13:
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
                big = np.abs(d).max()
                t = min(1.0, max_step / big) if big > 0 else 1.0
                for _ls in range(8):
                    xt = x + t * d
                    ft, gt = fun(xt)
                    nev += 1
                    if ft <= f + 1e-4 * t * pred:
                        break
                    t *= 0.5
                else:
                    ft = np.inf
                    cl_fail = True
                if ft < np.inf:
                    s_, y_ = t * d, gt - g
                    drop = f - ft
                    moved = True
                    x, f, g = xt, ft, gt
                    tol = tol_here()
                    cl = cluster()
                    B = _bfgs_update(B, s_, y_)
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
        big = np.abs(p).max()
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
        if _ls >= 3:
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


#: restarts of the descent of ``mu_upper(method="fast")``
_FAST_RESTARTS = 6
#: largest |G-hat| entry kept in a warm start of the fast D-G bound
_G_CLIP = 8.0


def _upper_fast(M, S: BlockStructure, params: _DGParams, x0=None, B0=None, ftol: float = 1e-10,
                max_eval: int = 400, info: dict | None = None, osborne_tol: float = 0.0,
                kinks: bool = False, beta0: float | None = None):
    """Fast D (or D-G) bound at one matrix, from coordinates ``x0`` (None: Osborne balancing).

    Returns (MuUpper, x, inverse Hessian) with the value recomputed from the
    scalings' coordinates (the exact largest eigenvalue of the congruent form).
    With ``kinks`` (diagonal scalings only) the descent steps on the model of the two
    largest eigenvalues where they nearly coincide (:func:`_cluster_step`).
    ``beta0``: the G-hat scale of an earlier descent at the same matrix (``info["beta0"]``
    of it) when ``x0`` is its end point: the restart then starts at exactly that point
    (no clipping of G-hat, which is for warm starts from another matrix).
    """
    if x0 is None:
        x0 = params.initial(np.exp(_osborne(M, S, tol=osborne_tol)))
    elif beta0 is not None:
        x0 = x0.copy()
    else:
        # a warm start: G-hat near a previous frequency's, but not the large values
        # of a frequency where the infimum is approached as G -> infinity (a flat
        # region from which the descent at the next frequency stalls)
        x0 = x0.copy()
        for gs in params.gslots:
            if gs is not None:
                x0[gs] = np.clip(x0[gs], -_G_CLIP, _G_CLIP)
    if params.diag:
        params._stack(M)    # the terms of this matrix (a caller may reuse one array for several)
    if not params.use_g:
        beta0 = 1.0         # no G: beta0 does not enter
    elif beta0 is None:
        beta0 = np.sqrt(max(params.value_grad(x0, M, 1.0, grad=False)[0], 0.0))
        if beta0 == 0:
            beta0 = 1.0
    if info is not None:
        info["beta0"] = beta0
    # the first G-free sigma_max: with a warm start G carries over (it is scaled by beta0)
    free = params.free

    def fun(y):
        if y.size and (y.max() > 200.0 or y.min() < -200.0):
            return np.inf, np.zeros(free.size)     # a line-search trial far out: reject it
        x = x0.copy()
        x[free] = y
        try:
            lam, g = params.value_grad(x, M, beta0)
        except (np.linalg.LinAlgError, ValueError):
            return np.inf, np.zeros(free.size)
        if not math.isfinite(lam):
            return np.inf, np.zeros(free.size)
        if not lam > 0:
            return -np.inf, np.zeros(free.size)
        return math.log(lam), g[free]
    cluster = None
    if kinks and params.diag and S.nrows >= 2:
        def cluster():
            cl = params.model(_CLUSTER_GAP)
            if cl is None or cl[1] is None:
                return cl
            return cl[0], lambda: cl[1]()[free], lambda U: params.cluster_hessian(U)[np.ix_(free, free)]
    params.want_cluster, params.cluster = cluster is not None, None
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            f, y, B, nev = _bfgs(fun, x0[free], B0, ftol=ftol, max_eval=max_eval, info=info, cluster=cluster,
                                 noise=(lambda: params.noise) if params.diag else None)
    finally:
        params.want_cluster, params.cluster = False, None
    x = x0.copy()
    x[free] = y
    # f is log lambda_max evaluated at exactly these coordinates (the descent returns its point
    # and value together): no second eigenvalue solve
    lam = math.exp(f) if math.isfinite(f) else params.value_grad(x, M, beta0, grad=False)[0]
    Dl, Dr, G = params.scalings(x, beta0)
    tag = "fast-dg" if params.use_g else "fast-d"
    # one scaling per block, the last fixed to 1 (its coordinate is 0): exp of the log coordinates
    d = np.exp(x[:params.m]) if params.diag else _d_from_matrices(S, Dr)
    return (MuUpper(float(np.sqrt(max(lam, 0.0))), tag, d=d, Dl=Dl, Dr=Dr, G=G, iterations=nev), x, B)


def _fast_at(M, S: BlockStructure, params: _DGParams, x0=None, B0=None, ftol: float = 1e-10,
             max_eval: int = 400, info: dict | None = None, osborne_tol: float = 0.0,
             kinks: bool = False, nrm: float | None = None, beta0: float | None = None):
    """:func:`_upper_fast` with the shortcuts of :func:`mu_upper` (one full block, ``M = 0``,
    extreme norms); returns (MuUpper, coordinates or None, inverse Hessian or None).
    ``nrm``: sigma_max(M) if already known."""
    if nrm is None:
        nrm = _norm2(M)
    if nrm == 0 or (len(S) == 1 and S.blocks[0].kind == "full"):
        return _diag_result(M, S, np.ones(len(S)), "sigma"), None, None
    if not 1e-100 <= nrm <= 1e100:
        up, x, B = _upper_fast(M / nrm, S, params, x0, B0, ftol, max_eval, info, osborne_tol, kinks, beta0)
        return MuUpper(float(up.value * nrm), up.method, d=up.d, Dl=up.Dl, Dr=up.Dr,
                       G=None if up.G is None else up.G * nrm, iterations=up.iterations), x, B
    return _upper_fast(M, S, params, x0, B0, ftol, max_eval, info, osborne_tol, kinks, beta0)


def _fast_polish(M, S: BlockStructure, params: _DGParams, x0=None):
    """The fast bound to full accuracy: long descents, restarted from the point reached
    (BFGS can stall at a kink of lambda_max, e.g. with repeated real scalars, and a
    fresh Hessian approximation often continues).  Returns (MuUpper, coordinates)."""
    info = {}
    up, x, _ = _fast_at(M, S, params, x0, None, ftol=1e-12, max_eval=400, info=info)
    for _ in range(_FAST_RESTARTS):
        if x is None:
            break
        up2, x2, _ = _fast_at(M, S, params, x, None, ftol=1e-12, max_eval=400, info=info,
                              beta0=info.get("beta0"))
        if not up2.value < up.value * (1 - 1e-10):
            break
        up, x = up2, x2
    return up, x


#: default bound (``mu_upper(method="auto")``): tolerance of the descent on log lambda_max
_AUTO_FTOL = 1e-9
#: evaluations of each restart of the default bound's descent
_RESTART_EVALS = 50


def _fast_default(M, S: BlockStructure, params: _DGParams, always: bool = False, nrm: float | None = None):
    """The fast bound as the default of :func:`mu_upper`: one descent from Osborne balancing,
    restarted from the point reached (fresh Hessian approximation) only while the line search
    stalls at a kink of lambda_max and the restart still lowers the bound.
    Returns (MuUpper with the evaluations of all descents, coordinates or None).
    ``nrm``: sigma_max(M) if already known."""
    info = {}
    if nrm is None:
        nrm = _norm2(M)
    up, x, _ = _fast_at(M, S, params, None, None, ftol=_AUTO_FTOL, max_eval=300, info=info,
                        osborne_tol=1e-2, kinks=True, nrm=nrm)
    nev = up.iterations
    for _ in range(_FAST_RESTARTS):
        if x is None or (info.get("stop") == "ftol" and not always):
            break
        if not info.get("moved", True):
            # no step taken from x with a fresh Hessian approximation: a restart from x
            # would repeat the same failed line search
            break
        up2, x2, _ = _fast_at(M, S, params, x, None, ftol=_AUTO_FTOL, max_eval=_RESTART_EVALS, info=info, kinks=True,
                              nrm=nrm, beta0=info.get("beta0"))
        nev += up2.iterations
        if not up2.value < up.value * (1 - 1e-10):
            break
        up, x = up2, x2
    up.iterations = nev
    return up, x
