r"""The IPOPT driver of :func:`mutext.rotor.tuning.tune`: a bounded nonlinear least-squares solve.

The residual and its Jacobian are Python functions (one complex LU
factorisation per frequency, :class:`mutext.rotor._tune_objective._LogResidual`);
they enter CasADi's NLP as ``casadi.Callback`` objects: :class:`_Residual`
(:math:`\theta \mapsto r`), whose Jacobian is :class:`_Jacobian`
(:math:`\theta \mapsto \partial r/\partial\theta`), and :class:`_Iteration`,
IPOPT's iteration callback, which reports every iterate.  :class:`_LeastSquares`
builds ``nlpsol`` with the objective :math:`\tfrac12\|r\|^2` and the
Gauss-Newton Hessian :math:`J^TJ` (or IPOPT's limited-memory one) and runs it.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping

import casadi as ca
import numpy as np

from ..errors import ModelError

#: IPOPT return statuses that count as converged.
_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


class _Callback(ca.Callback):
    """A CasADi callback over ``residual`` (a :class:`_LogResidual`), constructed on creation."""

    def __init__(self, name, residual, opts=None):
        ca.Callback.__init__(self)
        self.residual = residual
        self.construct(name, opts or {})

    def get_n_out(self):
        return 1


class _Jacobian(_Callback):
    """:math:`\\partial r/\\partial\\theta` (inputs: ``theta`` and the unused nominal output ``r``)."""

    def get_n_in(self):
        return 2

    def get_sparsity_in(self, i):
        res = self.residual
        return ca.Sparsity.dense(res.n_unknowns, 1) if i == 0 else ca.Sparsity.dense(res.n_residuals, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.residual.n_residuals, self.residual.n_unknowns)

    def eval(self, arg):
        return [ca.DM(self.residual.evaluate(np.array(arg[0]).ravel(), True)[2])]


class _Residual(_Callback):
    """The real residual vector :math:`r(\\theta)`, with :class:`_Jacobian` as its exact Jacobian."""

    def get_n_in(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self.residual.n_unknowns, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self.residual.n_residuals, 1)

    def eval(self, arg):
        return [ca.DM(self.residual.evaluate(np.array(arg[0]).ravel(), False)[0])]

    def has_jacobian(self):
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._jac = _Jacobian(name, self.residual, opts)    # kept alive as long as the residual
        return self._jac


class _Iteration(ca.Callback):
    """IPOPT's iteration callback: ``on_iterate(objective, theta)`` at every iterate."""

    def __init__(self, name, n_unknowns: int, on_iterate: Callable[[float, np.ndarray], None]):
        ca.Callback.__init__(self)
        self.n_unknowns, self.on_iterate = n_unknowns, on_iterate
        self.construct(name, {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        n = ca.nlpsol_out(i)
        if n == "f":
            return ca.Sparsity.scalar()
        if n in ("x", "lam_x"):
            return ca.Sparsity.dense(self.n_unknowns, 1)
        return ca.Sparsity(0, 0)

    def eval(self, arg):
        self.on_iterate(float(arg[1]), np.array(arg[0]).ravel())
        return [0]


def _base_options(max_iter: int, tol: float, iteration) -> dict:
    """IPOPT options: quiet, with an acceptable level that stops a line search stalled on round-off."""
    return {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.max_iter": int(max_iter),
            "ipopt.tol": float(tol), "ipopt.acceptable_tol": max(1e-6, float(tol)), "ipopt.acceptable_iter": 2,
            "ipopt.accept_after_max_steps": 5, "iteration_callback": iteration}


def _user_options(ipopt_options: Mapping | None) -> dict:
    """The caller's options, an IPOPT option name prefixed with ``ipopt.``."""
    return {(k if "." in k or k in ("print_time",) else f"ipopt.{k}"): x for k, x in (ipopt_options or {}).items()}


def _gauss_newton_hessian(r_mx, th) -> ca.Function:
    """IPOPT's Hessian of the Lagrangian for :math:`\\tfrac12\\|r\\|^2`: :math:`\\lambda_f J^TJ` (upper triangle)."""
    J = ca.jacobian(r_mx, th)
    lam_f = ca.MX.sym("lam_f")
    return ca.Function("nlp_hess_l", [th, ca.MX.sym("p", 0), lam_f, ca.MX.sym("lam_g", 0)],
                       [ca.triu(lam_f * ca.mtimes(J.T, J))],
                       ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"])


class _LeastSquares:
    """``min 1/2 |r(theta)|^2`` subject to bounds, solved by IPOPT through CasADi.

    Parameters
    ----------
    residual : _LogResidual
    on_iterate : callable(objective, theta)
        Called at every IPOPT iterate.
    max_iter, tol, hessian, ipopt_options
        As in :func:`mutext.rotor.tuning.tune`.
    """

    def __init__(self, residual, on_iterate, *, max_iter: int, tol: float, hessian: str,
                 ipopt_options: Mapping | None):
        # the callbacks must outlive the solver: CasADi holds them by reference only
        self.residual_cb = _Residual("frf_log_residual", residual)
        self.iteration_cb = _Iteration("progress", residual.n_unknowns, on_iterate)
        th = ca.MX.sym("theta", residual.n_unknowns)
        r_mx = self.residual_cb(th)
        f_mx = 0.5 * ca.sumsqr(r_mx)
        opts = _base_options(max_iter, tol, self.iteration_cb)
        if hessian == "gauss-newton":
            opts["hess_lag"] = _gauss_newton_hessian(r_mx, th)
        elif hessian == "limited-memory":
            opts["ipopt.hessian_approximation"] = "limited-memory"
        else:
            raise ModelError(f"hessian must be 'gauss-newton' or 'limited-memory', got {hessian!r}")
        opts.update(_user_options(ipopt_options))
        self.solver = ca.nlpsol("tune", "ipopt", {"x": th, "f": f_mx}, opts)

    def solve(self, theta0, lo, hi):
        """``(theta, status, iterations)`` from the start ``theta0`` within ``[lo, hi]``."""
        sol = self.solver(x0=theta0, lbx=lo, ubx=hi)
        stats = self.solver.stats()
        status = str(stats.get("return_status", "unknown"))
        iters = int(stats.get("iter_count", -1))
        return np.array(sol["x"]).ravel(), status, iters
