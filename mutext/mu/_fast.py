r"""Upper bound by D-G scalings without an SDP: quasi-Newton descent ([YND]_, [LO]_).

BFGS with the weak Wolfe line search on :math:`\log\lambda_{\max}` of the
congruent form, in coordinates that carry over from one frequency to the next
(``mu_upper(method="fast")`` and the warm-started sweep of :func:`mu_sweep`): here the
coordinates, the form, its gradient and the model of its two largest eigenvalues
(:class:`_DGParams`) and the drivers; the descent itself is in ``_descent.py``.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg.lapack import zheevd as _zheevd

from ._certificate import _EPS, MuUpper, _d_from_matrices, _diag_result
from ._descent import _CLUSTER_GAP, _absmax, _bfgs
from ._osborne import _osborne
from ._structure import BlockStructure, _norm2


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
            self.yidx = np.arange(self.nreal)
            m, r = self.m, self.nreal
            # d c_i / d x_k of the stacked terms' coefficients over c_i (2 on the term's own block)
            self._map2 = np.zeros((m + r, m))
            self._map2[np.arange(m), np.arange(m)] = 2.0
            self._map2[m + np.arange(r), self.real_idx] = 2.0
            # 2 E_r with each row twice: |v|^2 over each block's rows from v viewed as floats
            self._er2d = np.repeat(2.0 * self.Er, 2, axis=0)
            # flat indices into an N x N Hessian of the x-x diagonal and the (x_k, y_j), (y_j, x_k),
            # (y_j, y_j) entries (see _lagrangian_hessian)
            N, j = self.size, self.m + self.yidx
            self._dcy = j * (N + 1)
            self._hidx = np.concatenate((np.arange(self.m) * (N + 1), self.real_idx * N + j,
                                         j * N + self.real_idx, j * (N + 1)))

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
        self._stack_m, self._stack_of = St, M
        self._sflat_r = St.reshape(m + r, n * n).view(float)

    def model(self, gap: float):
        """(lambda_2/lambda_1, C, W) at the point last evaluated: C a function returning the
        matrices of :meth:`_cluster` and W one returning :meth:`cluster_hessian` for a multiplier
        (both for this evaluation, built only when the descent steps on them) if the relative gap
        of the two is below ``gap``, else (lambda_2/lambda_1, None, None); None without that
        evaluation."""
        cl = self.cluster
        if cl is None:
            return None
        w = cl[0]
        if w.size < 2 or not w[-1] > 0:
            return None
        r = float(w[-2] / w[-1])
        if not 1.0 - r < gap:
            return r, None, None
        return r, lambda: self._cluster(cl)[1], lambda U: self.cluster_hessian(U, cl)

    def _terms(self, w, V, k, coef, ri, cp, Su=None):
        r"""What the first- and second-order models of the ``k`` largest eigenvalues (1 or 2) are
        built from: Q the top eigenvectors (largest first), their eigenvalues, :math:`u = RQ`,
        :math:`P_{\alpha} = \partial_\alpha K\,u` ``(N, n, k)``, :math:`u^HS_iu` ``(T, k, k)``,
        :math:`Q^HE_\alpha Q` ``(m, k, k)``, the sums of the eigenvalue pairs and the derivatives
        of the coefficients :math:`\partial_\alpha c_i` ``(N, T)``.  ``Su``: :math:`S_iu` ``(T, n, k)``
        if already computed."""
        n, m, N = w.size, self.m, self.size
        Q = V[:, :-k - 1:-1]
        lq = w[:-k - 1:-1]
        uq = ri[:, None] * Q
        if Su is None:
            Su = self._stack_m @ uq                                  # (T, n, k), T = N terms
        Dc = np.zeros((N, N))
        Dc[:m] = self._map2.T * coef
        if self.nreal:
            Dc.ravel()[self._dcy] = cp                               # d c_{m+j} / d y_j
        P = (Dc @ Su.reshape(N, k * n)).reshape(N, n, k)
        Qi = uq.conj().T[None] @ Su
        EQ = ((Q.conj()[:, :, None] * Q[:, None, :]).reshape(n, k * k).T @ self.Er).T.reshape(m, k, k)
        return Q, lq, uq, P, Qi, EQ, lq[:, None] + lq[None, :], Dc

    def _cluster_terms(self, cl):
        """:meth:`_terms` of the top two eigenvalues at the evaluation ``cl`` (kept for the last one
        asked: the model and its Hessian share them)."""
        if self._kept is not None and self._kept[0] is cl:
            return self._kept[1]
        w, V, coef, ri, cp, _ = cl
        out = self._terms(w, V, 2, coef, ri, cp)
        self._kept = (cl, out)
        return out

    _kept = None

    def _cluster(self, cl):
        r"""First-order model of the two largest eigenvalues of H, divided by the largest:
        (w1/w0, C) with :math:`C_\alpha = Q^H\partial_\alpha HQ/\lambda_1` (2 x 2, all
        coordinates), :math:`Q^H\partial_\alpha HQ = \sum_i\partial_\alpha c_i\,u^HS_iu
        - (\lambda_a+\lambda_b)\,Q^HE_\alpha Q` (the terms of :meth:`_stack`, :math:`u = RQ`)."""
        Q, lq, uq, P, Qi, EQ, ls, Dc = self._cluster_terms(cl)
        w, N, m = cl[0], self.size, self.m
        C = (Dc @ Qi.reshape(N, 4)).reshape(N, 2, 2)
        C[:m] -= ls * EQ
        return float(w[-2] / w[-1]), C / w[-1]

    def cluster_hessian(self, U, cl=None):
        r"""Hessian of the Lagrangian :math:`\operatorname{Re}\operatorname{tr}(U\,Q^HH(x)Q)` of the
        two largest eigenvalues at the evaluation ``cl`` (default: the last; diagonal scalings;
        Overton's second-order model of a cluster), divided by the largest eigenvalue: all
        coordinates, ``U`` a Hermitian ``2 x 2`` matrix (the multiplier of the cluster, trace 1).
        See :meth:`_lagrangian_hessian`."""
        if cl is None:
            cl = self.cluster
        w, V, coef, ri, cp, _ = cl
        return self._lagrangian_hessian(w, V, self._cluster_terms(cl), coef, ri, cp, U) / w[-1]

    def _lagrangian_hessian(self, w, V, terms, coef, ri, cp, U):
        r""":math:`W_{\alpha\beta}` of the top ``k`` eigenvalues (``k`` the size of ``U``, 1 or 2),
        from their :meth:`_terms`:

        .. math::
            W_{\alpha\beta} = \operatorname{Re}\operatorname{tr}\bigl(U Q^H\partial_{\alpha\beta}H\,Q\bigr)
            + 2\operatorname{Re}\sum_{l>k}\frac{\operatorname{tr}(U F_{\alpha,l}^H F_{\beta,l})}{\lambda - \lambda_l},
            \qquad F_{\alpha,l} = v_l^H\,\partial_\alpha H\,Q,

        with :math:`(\lambda_l, v_l)` the other eigenpairs (:math:`\lambda` the eigenvalue of each
        column of :math:`Q`, averaged over the pair ``U`` couples).  With :math:`H = RKR`,
        :math:`R = \operatorname{diag}(r)`, :math:`K = \sum_i c_iS_i` (see :meth:`_stack`),
        :math:`u = RQ` and :math:`E_\alpha` the rows of block :math:`\alpha`
        (:math:`\partial_\alpha R = -E_\alpha R`; zero for a G-hat coordinate):
        :math:`F_{\alpha,l} = v_l^H(r\circ P_\alpha) - (\lambda_l+\lambda_b)v_l^HE_\alpha Q`, and
        :math:`q_a^H\partial_{\alpha\beta}Hq_b` has :math:`\delta_{\alpha\beta}(\lambda_a+\lambda_b)
        q_a^HE_\alpha q_b`, :math:`(E_\alpha q_a)^HH(E_\beta q_b)` and its mirror,
        :math:`-(E_\alpha u_a)^HP_{\beta b} - P_{\beta a}^HE_\alpha u_b` and its mirror, and
        :math:`\sum_i\partial_{\alpha\beta}c_i\,u_a^HS_iu_b`."""
        Q, lq, uq, P, Qi, EQ, ls, _ = terms
        k = lq.size
        n, m, N = w.size, self.m, self.size
        UT = U.T
        # one product for V^H E_alpha Q (first k m columns) and V^H (r o P_beta) (the rest)
        Z = np.empty((n, k * (m + N)), complex)
        Z[:, :k * m] = (self.Er[:, :, None] * Q[:, None, :]).reshape(n, k * m)
        Z[:, k * m:] = (ri[:, None, None] * P.transpose(1, 0, 2)).reshape(n, k * N)
        Z = V.conj().T @ Z
        YQ = Z[:, :k * m].reshape(n, m, k)
        F = Z[:, k * m:].reshape(n, N, k)
        F[:, :m] -= (w[:, None, None] + lq[None, None, :]) * YQ
        Fl = F[:-k]
        dl = 1.0 / (lq[None, :] - w[:-k, None])
        Tw = 0.5 * (dl[:, :, None] + dl[:, None, :]) * UT[None]
        W = 2.0 * ((Fl.conj() @ Tw) @ Fl.transpose(0, 2, 1)).sum(0).real
        A_ = (YQ.conj() @ UT) * w[:, None, None]
        Z1 = A_.transpose(1, 0, 2).reshape(m, k * n) @ YQ.transpose(1, 0, 2).reshape(m, k * n).T
        W[:m, :m] += (Z1 + Z1.T).real
        T1 = 2.0 * ((uq.conj()[None] * (P @ U)).sum(2) @ self.Er).real.T   # 2 Re (E_alpha u)^H P_beta
        W[:m] -= T1
        W[:, :m] -= T1.T
        # the terms on the diagonal and, with G-hat, at (x_k, y_j), (y_j, x_k), (y_j, y_j): by flat index
        qU = (Qi.reshape(N, k * k) @ UT.ravel()).real
        cq = coef * qU
        e1 = (EQ.reshape(m, k * k) @ (UT * ls).ravel()).real
        if self.nreal:
            t = 2.0 * cp * qU[m:]
            W.ravel()[self._hidx] += np.concatenate((e1 + 2.0 * (cq @ self._map2), t, t, cq[m:]))
        else:
            W.ravel()[self._hidx] += e1 + 2.0 * (cq @ self._map2)
        return W

    _last = None
    _ONE = np.ones((1, 1))

    def hessian(self):
        r"""Hessian of :math:`\log\lambda_{\max}(H)` at the point last evaluated with its gradient
        (diagonal scalings, all coordinates), or None where the top eigenvalue is not simple.

        The second derivative of a simple eigenvalue (second-order perturbation theory) is
        :meth:`_lagrangian_hessian` with ``k = 1``,

        .. math::
            \lambda_{\alpha\beta} = v^H\partial_{\alpha\beta}H\,v
            + 2\operatorname{Re}\sum_{l\ne 1}\frac{\overline{F_{l\alpha}}F_{l\beta}}{\lambda-\lambda_l},

        and that of the logarithm is :math:`\lambda_{\alpha\beta}/\lambda - g_\alpha g_\beta`.  One
        evaluation's worth of small products; the descent's first metric (BFGS then starts with
        the curvature it would otherwise spend its first iterations learning)."""
        if self._last is None:
            return None
        w, V, u, Su, q, coef, ri, cp, g = self._last
        lam = float(w[-1])
        if not (w.size > 1 and lam > w[-2]):
            return None
        terms = self._terms(w, V, 1, coef, ri, cp, Su=Su[:, :, None])
        W = self._lagrangian_hessian(w, V, terms, coef, ri, cp, self._ONE)
        W /= lam
        W -= np.multiply.outer(g, g)
        return W if math.isfinite(W.sum()) else None

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
                er = e2[self.real_idx]
                coef = np.concatenate((e2, (beta0 * np.sinh(x[m:])) * er))
            else:
                coef = e2
            # real coefficients times the stacked terms as real numbers (no complex copy of coef)
            H = (coef @ self._sflat_r).view(complex).reshape(S.nrows, S.nrows)
            H *= np.multiply.outer(ri, ri)
            w, V, info = _zheevd(H)
            if info != 0:
                raise np.linalg.LinAlgError("eigenvalues of the scaled form did not converge")
            lam, v = float(w[-1]), V[:, -1]
            # rounding noise of log lambda here: eps times the size of H (its extreme eigenvalues)
            # over lambda; a G-hat approaching infinity makes H graded and this large
            self.noise = _EPS * S.nrows * max(-float(w[0]), lam) / lam if lam > 0 else np.inf
            if not grad:
                return lam, None
            # d c_{m+j} / d y_j of the G-hat terms
            cp = (beta0 * np.cosh(x[m:])) * er if self.nreal else None
            if self.want_cluster:
                # kept for the model of the top two eigenvalues, built only where they are close
                self.cluster = (w, V, coef, ri, cp, x)
            # d/dx of u^H (sum c_i S_i) u with u = r o v: the coefficients' own (2 c_i q_i on
            # their block) and -2 lambda |v|^2 over the block's rows from r
            u = ri * v
            Su = self._stack_m @ u
            q = (Su @ u.conj()).real
            # |v|^2 summed over each block's rows: the squared real and imaginary parts (v is a
            # contiguous column of zheevd's Fortran-ordered V) against the rows of E_r doubled
            gx = (coef * q) @ self._map2 - lam * (np.square(v.view(float)) @ self._er2d)
            g = np.concatenate((gx, cp * q[m:])) if self.nreal else gx
            g = g / max(lam, 1e-300)
            self._last = (w, V, u, Su, q, coef, ri, cp, g)
            return lam, g
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


#: restarts of the descent of ``mu_upper(method="fast")``
_FAST_RESTARTS = 6
#: largest |G-hat| entry kept in a warm start of the fast D-G bound
_G_CLIP = 8.0


def _upper_fast(M, S: BlockStructure, params: _DGParams, x0=None, B0=None, ftol: float = 1e-10,
                max_eval: int = 400, info: dict | None = None, osborne_tol: float = 0.0,
                kinks: bool = False, beta0: float | None = None, hessian0: bool = False):
    """Fast D (or D-G) bound at one matrix, from coordinates ``x0`` (None: Osborne balancing).

    Returns (MuUpper, x, inverse Hessian) with the value recomputed from the
    scalings' coordinates (the exact largest eigenvalue of the congruent form).
    With ``kinks`` (diagonal scalings only) the descent steps on the model of the two
    largest eigenvalues where they nearly coincide (:func:`_cluster_step`).
    ``beta0``: the G-hat scale of an earlier descent at the same matrix (``info["beta0"]``
    of it) when ``x0`` is its end point: the restart then starts at exactly that point
    (no clipping of G-hat, which is for warm starts from another matrix).
    ``hessian0`` (diagonal scalings, ``B0`` None): the descent's first metric is the inverse of
    the exact Hessian at ``x0`` (:meth:`_DGParams.hessian`) instead of the identity.
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
        if _absmax(y) > 200.0:
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
    def cluster_model():
        cl = params.model(_CLUSTER_GAP)
        if cl is None or cl[1] is None:
            return cl
        C, W = cl[1], cl[2]
        return cl[0], lambda: C()[free], lambda U: W(U)[ixf]

    def hessian():
        W = params.hessian()
        return None if W is None else W[ixf]
    ixf = np.ix_(free, free)
    cluster = cluster_model if kinks and params.diag and S.nrows >= 2 else None
    params.want_cluster, params.cluster = cluster is not None, None
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            f, y, B, nev = _bfgs(fun, x0[free], B0, ftol=ftol, max_eval=max_eval, info=info, cluster=cluster,
                                 noise=(lambda: params.noise) if params.diag else None,
                                 hessian=hessian if hessian0 and params.diag else None)
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
             kinks: bool = False, nrm: float | None = None, beta0: float | None = None,
             hessian0: bool = False):
    """:func:`_upper_fast` with the shortcuts of :func:`mu_upper` (one full block, ``M = 0``,
    extreme norms); returns (MuUpper, coordinates or None, inverse Hessian or None).
    ``nrm``: sigma_max(M) if already known."""
    if nrm is None:
        nrm = _norm2(M)
    if nrm == 0 or (len(S) == 1 and S.blocks[0].kind == "full"):
        return _diag_result(M, S, np.ones(len(S)), "sigma"), None, None
    if not 1e-100 <= nrm <= 1e100:
        up, x, B = _upper_fast(M / nrm, S, params, x0, B0, ftol, max_eval, info, osborne_tol, kinks, beta0,
                               hessian0)
        return MuUpper(float(up.value * nrm), up.method, d=up.d, Dl=up.Dl, Dr=up.Dr,
                       G=None if up.G is None else up.G * nrm, iterations=up.iterations), x, B
    return _upper_fast(M, S, params, x0, B0, ftol, max_eval, info, osborne_tol, kinks, beta0, hessian0)


def _fast_polish(M, S: BlockStructure, params: _DGParams, x0=None):
    """The fast bound to full accuracy: long descents, restarted from the point reached
    (BFGS can stall at a kink of lambda_max, e.g. with repeated real scalars, and a
    fresh Hessian approximation often continues).  Returns (MuUpper, coordinates)."""
    info = {}
    up, x, _ = _fast_at(M, S, params, x0, None, ftol=1e-12, max_eval=400, info=info)
    b0 = info.get("beta0")
    for _ in range(_FAST_RESTARTS):
        if x is None:
            break
        # a restart at the very point (fresh Hessian approximation; what repeated real scalars
        # need), else one as a warm start (G-hat clipped, its scale taken afresh): a perturbation
        # out of the flat valleys where a real block's d -> 0 (on the loop matrix of
        # tests/test_refine.py restarts at the very point stalled 2e-4 above AB13MD)
        for beta0 in (b0, None):
            info = {}
            up2, x2, _ = _fast_at(M, S, params, x, None, ftol=1e-12, max_eval=400, info=info, beta0=beta0)
            if up2.value < up.value * (1 - 1e-10):
                break
        else:
            break
        up, x, b0 = up2, x2, info.get("beta0")
    return up, x


#: default bound (``mu_upper(method="auto")``): tolerance of the descent on log lambda_max
_AUTO_FTOL = 1e-9
#: evaluations of each restart of the default bound's descent
_RESTART_EVALS = 50
#: the default bound's descents start from the exact Hessian at their first point
_HESSIAN0 = True


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
                        osborne_tol=1e-2, kinks=True, nrm=nrm, hessian0=_HESSIAN0)
    nev = up.iterations
    for _ in range(_FAST_RESTARTS):
        if x is None or (info.get("stop") == "ftol" and not always):
            break
        if not info.get("moved", True):
            # no step taken from x with a fresh Hessian approximation: a restart from x
            # would repeat the same failed line search
            break
        up2, x2, _ = _fast_at(M, S, params, x, None, ftol=_AUTO_FTOL, max_eval=_RESTART_EVALS, info=info, kinks=True,
                              nrm=nrm, beta0=info.get("beta0"), hessian0=_HESSIAN0)
        nev += up2.iterations
        if not up2.value < up.value * (1 - 1e-10):
            break
        up, x = up2, x2
    up.iterations = nev
    return up, x
