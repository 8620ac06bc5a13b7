r"""The one place the package hands a convex program to a conic solver.

Every LMI, SOCP and constrained least-squares problem of the package (the
H-infinity LMIs, the mu upper bound's LMI, the D-G model step of
:func:`mutext.dk.refine_controller`, the convex model matching of
:func:`mutext.mbi.identify_convex`, the magnitude fit of :mod:`mutext.frfit`)
is written in cvxpy and solved here: which solver, with which options for the
accuracy the caller needs (:data:`ACCURACY`), cvxpy's warnings silenced (an
"inaccurate" solution is accepted, and every caller checks its result
independently), and cvxpy's own errors turned into
:class:`mutext.errors.SolverError` with the caller's words.  The default solver is
Clarabel, an interior-point method for conic programs written in Rust, shipped
with cvxpy.

Examples
--------
>>> import cvxpy as cp
>>> from mutext._solver import solve
>>> x = cp.Variable()
>>> prob = cp.Problem(cp.Minimize(cp.square(x - 2)), [x >= 3])
>>> solve(prob, "a small example")
'optimal'
>>> round(float(x.value), 6)
3.0
"""
from __future__ import annotations

import warnings

from .errors import SolverError

#: the solver used unless a caller is told otherwise (``hinfsyn(solver=...)``)
DEFAULT_SOLVER = "CLARABEL"

#: solver options by the accuracy a caller asks for.  ``"default"``: the solver's own
#: tolerances; ``"tight"``: more iterations (the H-infinity level LMIs, badly conditioned near
#: the optimum); ``"loose"``: 1e-6 gaps (the controller LMI of hinfsyn: any strictly feasible
#: point does); ``"step"``: a few digits (a model step of refine_controller, checked on the true
#: bound afterwards), and ``"step-regularised"`` the same with ten times Clarabel's static
#: regularisation (where its factorisation fails); SCS capped (uncapped it took 37 s for a step
#: Clarabel solves in 0.7 s).
ACCURACY = {
    "default": {},
    "tight": {"CLARABEL": {"max_iter": 400}},
    "loose": {"CLARABEL": {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-7, "max_iter": 400}},
    "step": {"CLARABEL": {"tol_feas": 1e-6, "tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "reduced_tol_feas": 1e-3,
                          "reduced_tol_gap_abs": 1e-3, "reduced_tol_gap_rel": 1e-3},
             "SCS": {"max_iters": 2500}},
}
ACCURACY["step-regularised"] = {"CLARABEL": {**ACCURACY["step"]["CLARABEL"], "static_regularization_constant": 1e-7}}


def options(solver: str | None = None, accuracy: str = "default") -> dict:
    """The keyword options :func:`solve` passes to ``solver`` for ``accuracy``.

    Parameters
    ----------
    solver : str, optional
        A cvxpy solver name (default :data:`DEFAULT_SOLVER`).
    accuracy : str
        A key of :data:`ACCURACY`.

    Returns
    -------
    dict
        Empty for a solver the profile does not name (its own defaults).
    """
    if accuracy not in ACCURACY:
        raise ValueError(f"accuracy must be one of {sorted(ACCURACY)}, got {accuracy!r}")
    return dict(ACCURACY[accuracy].get((solver or DEFAULT_SOLVER).upper(), {}))


def solve(prob, what: str, *, solver: str | None = None, accuracy: str = "default") -> str:
    """Solve the cvxpy problem ``prob``; returns its status.

    Parameters
    ----------
    prob : cvxpy.Problem
        The program.
    what : str
        What is being solved, for the error message.
    solver : str, optional
        A cvxpy solver name (default :data:`DEFAULT_SOLVER`).
    accuracy : str
        A key of :data:`ACCURACY` (the options passed).

    Returns
    -------
    str
        cvxpy's status (``"optimal"``, ``"optimal_inaccurate"``, ``"infeasible"``, ...): the
        caller decides what each means for it.

    Raises
    ------
    SolverError
        The solver failed (cvxpy's error, or a numerical exception inside it), with ``what``
        and the solver named.
    """
    import cvxpy as cp
    name = (solver or DEFAULT_SOLVER).upper()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prob.solve(solver=name, **options(name, accuracy))
    except (cp.error.SolverError, ValueError, ArithmeticError) as exc:
        raise SolverError(f"{what}: solver {name} failed ({exc})") from None
    return prob.status
