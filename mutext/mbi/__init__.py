r"""Model-based identification by mu-synthesis (thesis ch. 3).

A *true* system (measured, or a model standing for the measurement, with its
uncertainty) and an *engineering* model of it are excited by the same input
``w``.  The engineering model gets an extra force input ``u`` and an extra
displacement output ``y`` where it is believed to be wrong; a controller
``u = K y`` is synthesised so that the engineering model's response follows the
true one for every true system in the uncertainty set.  The controller is then
the missing dynamics: with the force applied as :math:`-u`,

.. math::
    K(s) \approx D_u(s) = D_t(s) - D_e(s),

the difference of the local dynamic stiffnesses of the two systems (thesis
eqs. 3.7-3.9; for a mass, damper and spring, :math:`D_u = \Delta m\,s^2 +
\Delta c\,s + \Delta k`).

The generalized plant (thesis fig. 3.3) has inputs ``[w_Delta; w; u]`` and
outputs ``[z_Delta; z; y]``:

.. math::
    A = \begin{bmatrix} A_t & 0\\ 0 & A_e\end{bmatrix},\
    B_1 = \begin{bmatrix} B_t\\ B_{e1}\end{bmatrix} W_w,\
    B_2 = \begin{bmatrix} 0\\ -B_{e2}\end{bmatrix},\
    C_1 = W_z^{-1}\begin{bmatrix} C_t & -C_{e1}\end{bmatrix},\
    C_2 = \begin{bmatrix} 0 & C_{e2}\end{bmatrix},

plus the uncertainty channels ``w_Delta``/``z_Delta`` of the true system's
LFT.  Robust performance (mu at most 1 for the real parameter blocks and a
full complex performance block) means: for every true system in the set,
:math:`|x_t - x_e| \le W_z` for unit excitation :math:`|w| \le W_w`.

The thesis plant has no control penalty and no sensor noise, so ``D12 = 0``
and ``D21 = 0``: a singular H-infinity problem.  Here a small control penalty
:math:`\varepsilon_u u` and sensor noise :math:`\varepsilon_y n` are added
(``regularization``), scaled to the plant so that they change the controller by
far less than the identification error; :func:`identify` reports it and
``tests/test_mbi.py`` measures the effect by halving it.

The package keeps one idea per module: ``_plant`` (:func:`mbi_plant`, the
plant and its regularisation, :func:`controlled_engineering`), ``_impedance``
(the identifiable band and the mass-damper-spring reading of ``K``,
:func:`required_impedance`), ``_floor`` (the spread of the true systems,
:func:`wz_floor`, :func:`spread_weight`), ``_measured`` (a measured FRF as the
true system, :func:`true_from_frf`), ``_search`` (the :math:`W_z` search),
``_result`` (:class:`MBIResult`, the reading of ``K`` on its identifiable band),
``_start`` (the true system, grid, floor and first :math:`W_z` of either route),
``_identify`` (:func:`identify`) and ``_convex`` (the same
identification as convex worst-case model matching in the Youla parameter of ``K``,
:func:`identify_convex`, :func:`chebyshev_radius`; [BB]_).

References
----------
.. [M] R. J. Madden, *Identification of unmodeled dynamics in rotor systems using
   mu-synthesis approach*, M.S. thesis, Cleveland State University, ch. 3.
.. [WPM] Y. Wang, B. Pettinato and E. Maslen, "Model-based identification of
   unmodeled dynamics", 2009 (cited in [M]_).
.. [BB] S. Boyd and C. Barratt, *Linear Controller Design: Limits of Performance*, Prentice
   Hall, 1991.
"""
from __future__ import annotations

from ._convex import ConvexMBIResult, chebyshev_radius, identify_convex, model_matching
from ._floor import WzFloor, spread_weight, true_spread, wz_floor
from ._identify import identify
from ._result import MBIResult
from ._impedance import (ImpedanceFit, fit_impedance, identifiable_band, impedance_response, relative_error,
                         required_impedance)
from ._measured import true_from_frf
from ._plant import MBIPlant, controlled_engineering, mbi_plant
from ._search import WzTry

__all__ = ["MBIPlant", "mbi_plant", "ImpedanceFit", "fit_impedance", "WzTry", "MBIResult", "identify",
           "WzFloor", "wz_floor", "true_spread", "spread_weight", "true_from_frf", "required_impedance",
           "identify_convex", "ConvexMBIResult", "chebyshev_radius", "model_matching"]
