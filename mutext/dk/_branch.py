r"""The loop's mu by branch and bound on its real parameters, on the final grid of a D-K result."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..lti import freqresp
from ..mu import BlockStructure, branch_peak, BranchPeak
from ._loop import DKResult
from ._sweep import _dg_refined_peak


def branch_mu(result: "DKResult", structure: BlockStructure, *, rtol: float = 1e-3,
              max_boxes: int = 2000) -> BranchPeak:
    r"""The loop's :math:`\mu` by branch and bound on its real parameters, on the final grid.

    The D-G bound of a loop with real parameters can lie well above :math:`\mu`
    when their ranges are wide; :func:`mutext.mu.branch_peak` closes that gap
    with a certified bound (the boxes of the parameters' ranges bounded one by
    one).  The grid is that of the result's final analysis (``result.sweep``),
    with the D-G bound's largest maxima refined as in :func:`dk_iteration`; the
    complex bound of the sweep spares the points that cannot decide the peak.

    Parameters
    ----------
    result : DKResult
        From :func:`dk_iteration`, :func:`dgk_iteration` or :func:`refine_controller`.
    structure : BlockStructure
        The structure the result was computed for.
    rtol, max_boxes
        As for :func:`mutext.mu.mu_upper_branch`.

    Returns
    -------
    mutext.mu.BranchPeak
        ``value`` bounds :math:`\mu` of ``result.CL`` at every frequency of the grid; ``dg``
        is the D-G peak on the same grid.

    Examples
    --------
    The three-mass rig with 10 % uncertainty (trial 5) at :math:`W_z` = 4.7 mm: the D-G bound of
    the D-K loop reads 1.006, branch and bound proves :math:`\mu < 1`, within 1 % of the
    lower bound (about 20 s, so not run with the other examples; ``tests/test_mu_branch.py`` checks
    a loop of this rig against brute force and AB13MD):

    >>> from mutext.examples import three_mass as tm
    >>> from mutext.mbi import mbi_plant
    >>> args = tm.mbi_arguments(tm.TRIALS["5"])
    >>> plant = mbi_plant(args.pop("true"), args.pop("engineering"), Wz=4.7e-3, **args)
    >>> res = dk_iteration(plant.P, plant.structure, 1, 1, max_iter=2,
    ...                    synthesis="lmi-first")  # doctest: +SKIP
    >>> b = branch_mu(res, plant.structure)  # doctest: +SKIP
    >>> print(f"D-G {b.dg:.4f}, branch and bound {b.value:.4f}, lower {res.mu_lower:.4f}")  # doctest: +SKIP
    D-G 1.0056, branch and bound 0.9955, lower 0.9881
    """
    S = structure
    if not isinstance(S, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(S).__name__}")
    CL, sweep = result.CL, result.sweep
    if CL.noutputs != S.ncols or CL.ninputs != S.nrows:
        raise ModelError(f"the result's loop has {CL.noutputs} outputs and {CL.ninputs} inputs, but the "
                         f"structure needs {S.ncols} and {S.nrows}")
    w = np.asarray(sweep.omega, float)
    H = np.moveaxis(freqresp(CL, w), -1, 0)
    upper = np.asarray(sweep.upper, float)
    if S.has_real:
        # the D-G bound's maxima, refined: their frequencies join the grid
        _, _, added = _dg_refined_peak(CL, H, S, w, upper)
        if added.size:
            Ha = np.moveaxis(freqresp(CL, added), -1, 0)
            w, H = np.concatenate([w, added]), np.concatenate([H, Ha])
            upper = np.concatenate([upper, np.full(added.size, np.inf)])
    return branch_peak(H, S, upper=upper, rtol=rtol, max_boxes=max_boxes)
